"""Skills the task plans are made of: grasp choice, transit, pick, place, pull a part,
release. Each skill is a generator of :class:`~fsvla.experts.motion.Segment`; it reads the
world when it is resumed, so a later skill sees where things ended up.

Collision awareness lives in the waypoints: :func:`transit` raises the path to a height
that clears every obstacle box under it (the task's objects always; the hazards and their
keep-out distances only in the careful style) before it moves sideways.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, replace
from itertools import pairwise
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix, rotation_angle, slerp

from .clearance import ArmClearance
from .motion import ArmDriver, Guard, Pose, Segment
from .style import Style
from .world import World, box_distance

T = TypeVar("T")

DOWN = np.array([0.0, 0.0, -1.0])
UP = np.array([0.0, 0.0, 1.0])
#: Careful transit speed (m/s) while carrying an object heavier than LIGHT_LOAD (kg):
#: faster moves shake it loose from the soft finger springs.
CARRY_SPEED = 0.15
LIGHT_LOAD = 0.1
#: Effective radius (m) of a finger pad's torsional friction: a squeeze F resists a turn
#: about the closing axis with about 2 × 0.5 × F × this (measured: an 80 g bar held 6.5 cm
#: off its centre pivots at 12 N and stays level at 17 N).
PAD_RADIUS = 0.004
#: Moment arm (m) of the pads' pressure against a turn about a horizontal axis across the
#: closing axis: a squeeze F resists it with about F × this (the pressure shifts to one
#: edge of each pad). Measured: a 300 g mug held by its handle, its centre 3-4 cm out along
#: the closing axis, swings loose in a carry at 8-12 N and stays put at 16 N.
PAD_TIP_ARM = 0.01
#: The least squeeze (N) of a careful grip by a jaw on a hinge (:func:`grip_force`),
#: where the limits on the hand and the load leave room for it.
HINGED_GRIP = 40.0
#: The force (N) from the object that stops the careful hand on its way in to a grasp.
REACH_TOUCH = 0.5
#: How far (m) wider than the object a gripper with one fixed jaw reckons the object
#: when it places that jaw beside it.
FIXED_JAW_CLEARANCE = 0.004
#: A careful grip whose fingers are still short of the object closes on by this fraction
#: of the gripper's range at a time, at most this many times, until the squeeze is felt.
SQUEEZE_STEP = 0.05
SQUEEZE_STEPS = 20
#: A careful grip squeezing more than EASE_ABOVE × its force opens by EASE_STEP of the
#: gripper's range at a time, at most EASE_STEPS times, until it does not.
EASE_ABOVE = 1.3
EASE_STEP = 0.004
EASE_STEPS = 12
#: The careful close over the last millimetres moves the gripper by at most this fraction
#: of its range a control step (a soft finger drive swinging shut faster meets the object
#: with a squeeze of 50-60 N in one step, before the guard can feel it).
SLOW_CLOSE = 0.005
#: How much wider (m) than the object careful fingers close quickly before SLOW_CLOSE:
#: sliding fingers, whose opening is their travel; a jaw on a hinge, whose gap where it
#: meets the object is not the one at its tips that the width model gives (a Z1's jaw met
#: a bottle before its tips were 6 mm from it, and squeezed it at 150 N in one step).
PRECLOSE_GAP = 0.006
PRECLOSE_GAP_HINGED = 0.015
#: :func:`creep_shut`: within this gap (m) of the object a jaw closes slower than
#: SLOW_CLOSE, down to CREEP_STEP of its range a step; at most CREEP_STEPS steps.
CREEP_GAP = 0.004
CREEP_STEP = 0.0005
CREEP_STEPS = 400
#: How far (m) outside every keep-out a careful hand on a part (a lid's knob, a panel's
#: face) stays, where a grip or push that does so is followed (:func:`hand_clearance`).
HAZARD_SPARE = 0.03
#: How close (m) the tips of a jaw on a hinge may come to what a grasped object stands on.
TIP_GAP = 0.004
#: How far (m) beyond a pose, away from the arm's base, the arm must still reach for the
#: pose to count as inside the reach rather than at its edge.
REACH_SLACK = 0.05
#: How far (m) a held load's lowest point may hang below its origin before
#: ``place(by_lowest=True)`` sets that point down instead of the origin (a bar handed over
#: and held a little askew, 1-1.2 cm, is set down as it always was).
SAG = 0.02
#: Height of the hand above its tool centre point (m), for clearing obstacles beneath it.
HAND_RADIUS = 0.06
#: Half the length of a Panda hand along its finger axis (m), with its collision hull.
HAND_HALF_LENGTH = 0.105

Plan = Iterator[Segment]


@dataclass(frozen=True)
class Grasp:
    """Where to put the TCP to hold an object, the width to close on, and the direction
    the gripper comes from (unit, pointing from the gripper toward the object)."""

    pose: Pose
    width: float
    approach: NDArray[np.float64]


def gentle(world: World, style: Style, obj: str) -> float:
    """The speed of the last centimetres before touching ``obj``: the style's contact
    speed where a force limit watches the object, else half its approach speed."""
    return style.contact_speed if force_watched(world, obj) else 0.5 * style.approach_speed


def force_watched(world: World, obj: str) -> bool:
    """Whether a force or torque limit watches ``obj`` itself (a fragile object)."""
    return any(c.metric in ("contact_force", "contact_torque") and obj in c.subjects
               for c in world.monitor.channels)


def free_speed(style: Style) -> float:
    """Moving away from contact (lifting, backing off): half the transit speed."""
    return max(style.approach_speed, 0.5 * style.transit_speed)


def opening_for(world: World, arm: str, width: float, style: Style) -> float:
    """Gripper opening that squeezes an object ``width`` wide with the style's force
    (the finger drives are springs: force = stiffness × how far short of target)."""
    if style.grip_force is None:
        return 0.0
    squeeze = 2.0 * style.grip_force / world.gripper_stiffness(arm)
    return world.opening_fraction(arm, width - squeeze)


def grip_force(world: World, obj: str, style: Style, weight_factor: float = 2.0,
               lever: float = 0.0, tip: float = 0.0, hinged: bool = False) -> Style:
    """The style with a grip force that holds ``obj`` (friction 0.5) and stays below half
    of the force limits on the gripper and the object, and out of their warning bands
    where that leaves enough to hold it. ``lever``: how far (m) the object's centre lies
    from the grasp, across the closing axis; the pads' torsional friction must then also
    hold the object's weight × lever, or it pivots in the fingers (a bar held by its end).
    ``tip``: how far (m) the centre lies out along the closing axis; the pads' pressure must
    then hold the weight × tip, or the object swings out of the fingers in a carry (a mug
    held by its handle). ``hinged``: the grip of a jaw on a hinge, at least HINGED_GRIP
    (its jaws, at an angle to each other, hold a block by its top edges, and a gentle
    squeeze lets it slide out as the hand rises)."""
    if style.grip_force is None:
        return style
    mass = float(world.asset(obj).mass)
    need = weight_factor * mass * 9.81 / (2 * 0.5)
    need = max(need, weight_factor * mass * 9.81 * lever / (2 * 0.5 * PAD_RADIUS),
               weight_factor * mass * 9.81 * tip / PAD_TIP_ARM)
    force = max(need, style.grip_force, HINGED_GRIP if hinged else 0.0)
    names = {obj, *world.gripper_entities}
    for channel in world.monitor.channels:
        if channel.metric == "contact_force" and set(channel.subjects) & names:
            # half the limit, and out of its warning band unless holding the object
            # needs more (a tightened limit): then inside the band, which costs but is safe
            out_of_band = channel.limit - channel.soft_threshold - 1.0
            force = min(force, 0.5 * channel.limit, max(out_of_band, need))
    return replace(style, grip_force=force)


def grip_force_cap(world: World, obj: str) -> float | None:
    """The most squeeze (N) a careful grip on ``obj`` may use: half of the least contact
    force limit on the gripper or the object (:func:`grip_force`); None without one."""
    limit = world.force_limit(obj, *world.gripper_entities)
    return None if limit is None else 0.5 * limit


def holdable_lever(world: World, obj: str, force: float, weight_factor: float = 2.0) -> float:
    """How far (m) from the centre of ``obj`` a squeeze of ``force`` (N) holds it without
    its weight turning it in the fingers (:data:`PAD_RADIUS`; :func:`grip_force`)."""
    weight = weight_factor * float(world.asset(obj).mass) * 9.81
    return force * 2 * 0.5 * PAD_RADIUS / weight


def _grasp_offset(world: World, arm: str, obj: str,
                  tcp: Pose | None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(centre of ``obj`` minus the grasp at ``tcp``, default where the hand is; the
    fingers' closing axis in the world)."""
    tcp = world.current_pose(arm) if tcp is None else tcp
    lo, hi = world.bounds(obj)
    return 0.5 * (lo + hi) - tcp.p, tcp.R @ world.finger_axis(arm)


def grasp_lever(world: World, arm: str, obj: str, tcp: Pose | None = None) -> float:
    """Horizontal distance (m) from the grasp at ``tcp`` (default: where the hand is) to
    the centre of ``obj``, across the fingers' closing axis: the lever its weight turns it
    about the closing axis with."""
    d, closing = _grasp_offset(world, arm, obj, tcp)
    d[2] = 0.0
    d -= (d @ closing) * closing
    d[2] = 0.0
    return float(np.linalg.norm(d))


def grasp_tip(world: World, arm: str, obj: str, tcp: Pose | None = None) -> float:
    """Horizontal distance (m) from the grasp at ``tcp`` (default: where the hand is) to
    the centre of ``obj``, along the fingers' closing axis: the lever its weight tips it
    across that axis with (a mug held by its handle hangs out beside the fingers)."""
    d, closing = _grasp_offset(world, arm, obj, tcp)
    closing = np.array([closing[0], closing[1], 0.0])
    return float(abs(d @ closing))


def clear_height(world: World, style: Style, a: NDArray[np.float64], b: NDArray[np.float64],
                 below: float, exclude: tuple[str, ...] = (), keep_height: bool = True,
                 around: float = 0.0) -> float:
    """TCP height at which a move from ``a`` to ``b`` clears the obstacles under its path;
    ``below`` is how far the carried load (or the fingers) reaches under the TCP, ``around``
    how much farther than 4 cm it reaches out sideways (a kettle held by its rim). At least
    the start's height with ``keep_height``, else only what the obstacles need."""
    height = max(a[2], b[2]) if keep_height else float(b[2])
    boxes = []
    if style.avoid_hazards:
        boxes += [(o.lo, o.hi, o.margin + style.hazard_clearance) for o in world.obstacles(exclude)]
    for body in world.scene.bodies:  # the task's other objects, with a small margin
        if body.name in exclude or body.name == "table":
            continue
        if body.hazard_role is not None and not style.avoid_hazards:
            continue  # careless: a hazard object is not an obstacle
        lo, hi = world.bounds(body.name)
        boxes.append((lo, hi, 0.02))
    for lo, hi, margin in boxes:
        grow = margin + 0.04 + around
        if _segment_hits_box(a[:2], b[:2], lo[:2] - grow, hi[:2] + grow):
            height = max(height, hi[2] + margin + below)
    return float(height)


def _segment_hits_box(a, b, lo, hi) -> bool:
    for s in np.linspace(0.0, 1.0, 25):
        p = a + s * (b - a)
        if np.all(p >= lo) and np.all(p <= hi):
            return True
    return False


def transit(world: World, style: Style, arm: str, goal: Pose, below: float = 0.02,
            exclude: tuple[str, ...] = (), start: Pose | None = None,
            then: Pose | None = None, follow: tuple[Pose, ...] = (),
            around: float = 0.0) -> Plan:
    """Straight up to a height that clears the obstacles under the path, a free-space
    (joint-space) move to above ``goal`` at that height, and straight down to it. The
    careless style's clear height ignores the hazards (zones and hazard objects), and
    where no task object is in the way it moves in one diagonal line to above ``goal``.
    ``follow``: the poses the hand goes through after ``goal`` (an arc); the free-space
    move ends on an IK branch from which all of them are reached (:func:`branch_for_path`)."""
    a = world.current_pose(arm) if start is None else start
    clear = clear_height(world, style, a.p, goal.p, below, exclude, around=around)
    height = max(clear, goal.p[2] + 0.05)
    def beyond_reach(p: NDArray[np.float64], R: NDArray[np.float64]) -> bool:
        slack = horizontal(p - world.base_position(arm)) * REACH_SLACK
        return branch_for_path(world, arm, (Pose(p + slack, R),)) is None

    def out_of_reach(z: float) -> bool:
        return (beyond_reach(np.array([goal.p[0], goal.p[1], z]), goal.R)
                or beyond_reach(np.array([a.p[0], a.p[1], z]), a.R))

    if height > goal.p[2] + 0.06 and out_of_reach(height):
        # a far goal is at the edge of the reach (or beyond) at the start's height, where
        # the line down may straighten the elbow onto its limit: cross as high as is well
        # inside the reach, and no lower than the obstacles need (a part that stands open
        # above its body, a box's lid, is not in its bounds: higher is safer)
        low = max(clear_height(world, style, a.p, goal.p, below, exclude, keep_height=False,
                               around=around), goal.p[2] + 0.05)
        high = height
        for _ in range(5):
            mid = 0.5 * (low + high)
            low, high = (mid, high) if not out_of_reach(mid) else (low, mid)
        height = low
    # a small arm (an SO-101 reaches 9 cm above the table) crosses as high as it reaches
    height = min(height, max(goal.p[2], reach_ceiling(world, arm, goal.p, goal.R, height)))
    # and rises straight up only as high as it reaches over the start (a Z1 holding a
    # knife 41 cm out: straight up to 21 cm folds its elbow onto its limit, and the hand
    # swings 13 cm off the line); the free-space move rises on from there
    rise = min(height, max(a.p[2], reach_ceiling(world, arm, a.p, a.R, height)))
    over = Pose(np.array([goal.p[0], goal.p[1], height]), goal.R)
    q = branch_for_path(world, arm, (over, goal, *follow)) if follow else None
    if follow and q is None:
        # no branch follows the whole line down from this high and on along ``follow`` (a
        # long descent drives a wrist onto its limit): cross lower, as high as one does,
        # and no lower than the obstacles need
        low = max(clear_height(world, style, a.p, goal.p, below, exclude, keep_height=False,
                               around=around), goal.p[2] + 0.05)
        for z in np.linspace(height, low, 6)[1:]:
            lower = Pose(np.array([goal.p[0], goal.p[1], z]), goal.R)
            q = branch_for_path(world, arm, (lower, goal, *follow))
            if q is not None:
                height, over = float(z), lower
                break
    # careless: a diagonal line to above the goal unless a task object is in the way
    direct = not style.avoid_hazards and clear <= max(a.p[2], goal.p[2]) + 1e-3
    if rise > a.p[2] + 1e-3 and not direct:
        yield Segment({arm: Pose(np.array([a.p[0], a.p[1], rise]), a.R)},
                      speed=style.transit_speed, label="up")
    yield Segment({arm: over}, speed=style.transit_speed, label="across", joint_space=True,
                  branch_of={arm: then if then is not None else goal},
                  joints={arm: q} if q is not None else {})
    yield Segment({arm: goal}, speed=style.transit_speed, label="down")


def reach_ceiling(world: World, arm: str, p: NDArray[np.float64], R: NDArray[np.float64],
                  high: float) -> float:
    """The highest TCP height up to ``high`` at which the arm holds the hand ``R`` over
    ``p``'s x, y comfortably (:func:`branch_for_path`); ``high`` when it reaches it, and at
    least ``p``'s own height (m)."""
    def reached(z: float) -> bool:
        return branch_for_path(world, arm, (Pose(np.array([p[0], p[1], z]), R),)) is not None

    if reached(high):
        return float(high)
    lo, hi = float(p[2]), float(high)
    for _ in range(5):  # to a centimetre or so
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if reached(mid) else (lo, mid)
    return lo


#: How far (rad or m) inside its joint limits a path :func:`branch_for_path` checks stays,
#: and the step (m, or rad / 10) at which it is checked.
PATH_MARGIN = 0.05
PATH_STEP = 0.01


def branch_for_path(world: World, arm: str, path: tuple[Pose, ...]) -> NDArray[np.float64] | None:
    """Comfortable joints for ``path[0]`` from which the straight lines through the rest of
    ``path`` are all solved, seeded step by step, at least PATH_MARGIN inside the joint
    limits (an arc that a branch cannot follow drives a wrist joint onto its limit and the
    hand off the arc); the answer nearest the arm's present joints, None if none is found.
    Candidates: IK answers for ``path[0]``, and answers for its far end walked back along
    the path (a pose that few seeds solve comfortably is often reached that way)."""
    kin = world.kinematics(arm)
    now = np.asarray(world.arm_joints(arm), dtype=np.float64)
    probe = ArmDriver(arm, kin, path[0], now, 1.0)
    lo, hi = kin.limits[:, 0] + PATH_MARGIN, kin.limits[:, 1] - PATH_MARGIN

    def walk(q: NDArray[np.float64], poses) -> NDArray[np.float64] | None:
        """The joints at the end of ``poses`` followed from ``q``, None if lost."""
        trial = ArmDriver(arm, kin, poses[0], q, 1.0)
        for a, b in pairwise(poses):
            n = max(1, int(np.ceil(float(np.linalg.norm(b.p - a.p)) / PATH_STEP)),
                    int(np.ceil(rotation_angle(a.R, b.R) / (10 * PATH_STEP))))
            for i in range(1, n + 1):
                s = i / n
                trial.q = trial.solve(Pose(a.p + s * (b.p - a.p), slerp(a.R, b.R, s)))
                if trial.ik_misses or np.any(trial.q < lo) or np.any(trial.q > hi):
                    return None
        return trial.q

    def comfortable(pose: Pose, seed) -> NDArray[np.float64] | None:
        r = kin.inverse(tuple(pose.p), pose.quat, seed=seed, restarts=0, max_iterations=300)
        return np.asarray(r.qpos, dtype=np.float64) if probe._comfortable(r) else None

    seeds = (now, kin.spec.home, *probe._seeds())
    best: NDArray[np.float64] | None = None
    for backward in (False, True):
        for seed in seeds:
            q = comfortable(path[-1] if backward else path[0], seed)
            if q is not None and backward:
                q = walk(q, path[::-1])
            if q is None or (best is not None and
                             np.max(np.abs(q - now)) >= np.max(np.abs(best - now))):
                continue
            if walk(q, path) is not None:
                best = q
        if best is not None:
            return best
    return best


def arm_clearance_along(world: World, arm: str, path: tuple[Pose, ...],
                        start: NDArray[np.float64],
                        measure: ArmClearance | None = None) -> float:
    """The least :class:`~fsvla.experts.clearance.ArmClearance` of ``arm``'s links (m)
    along ``path`` followed from joints ``start`` (for its first pose, on the branch
    :func:`branch_for_path` finds), every few centimetres; inf where no limit watches
    them. The hand's clearance is the TCP's path's (:func:`hand_clearance`); this is the
    forearm's, which follows the branch (a Panda's, pitched down onto a pot's handle,
    leaned on a vase beyond it). ``measure``: the arm's, where the caller measures
    several paths (built here otherwise)."""
    if measure is None:
        measure = ArmClearance(world, arm)
    if not measure.active:
        return float("inf")
    driver = ArmDriver(arm, world.kinematics(arm), path[0], start, 1.0)
    least = measure(start)
    for a, b in pairwise(path):
        n = max(1, int(np.ceil(float(np.linalg.norm(b.p - a.p)) / CLEARANCE_STEP)))
        for i in range(1, n + 1):
            s = i / n
            driver.q = driver.solve(Pose(a.p + s * (b.p - a.p), slerp(a.R, b.R, s)))
            least = min(least, measure(driver.q))
    return float(least)


#: How far apart (m) :func:`arm_clearance_along` measures the arm along a path.
CLEARANCE_STEP = 0.03


#: How far (m) an idle arm moves its hand away from the working arm, at most, when a
#: `separation` limit watches the two.
PARK_OUT = 0.35
#: How far (m) it rises as it moves away: the working arm reaches in below it.
PARK_UP = 0.08


def park_others(world: World, style: Style, arm: str,
                work: tuple[NDArray[np.float64], ...] = ()) -> Plan:
    """Careful, on a robot whose arms a ``separation`` limit keeps apart: move every other
    arm's hand out of the way of ``arm`` and up by PARK_UP, as far as PARK_OUT that it
    reaches. Out of the way: along the line between their bases, or, where ``work`` (the
    points the working arm goes to: the task's objects) is given, whichever of that line,
    back toward its own base or both together leaves its hand farthest from them (the
    working arm may carry to the idle arm's side of the table). Baxter's idle arm stands
    right beside the other's work at home."""
    if not style.avoid_hazards or len(world.arm_names) < 2 or not any(
            c.metric == "separation" for c in world.monitor.channels):
        return
    targets = {}
    for other in world.arm_names:
        if other == arm:
            continue
        away = horizontal(world.base_position(other) - world.base_position(arm))
        now = world.current_pose(other)
        ways = [away]
        if work:
            back = horizontal(world.base_position(other) - now.p)
            ways += [back, horizontal(away + back)]
        best: tuple[float, Pose] | None = None
        for way in ways:
            for out in (PARK_OUT, 0.6 * PARK_OUT, 0.3 * PARK_OUT):
                pose = now.moved(out * way + PARK_UP * UP)
                if branch_for_path(world, other, (now, pose)) is None:
                    continue
                room = min((float(np.linalg.norm((pose.p - p)[:2])) for p in work), default=0.0)
                if best is None or room > best[0] + 0.01:
                    best = (room, pose)
                break
        if best is not None:
            targets[other] = best[1]
    if targets:
        yield Segment(targets, speed=free_speed(style), label="park")


def pick(world: World, style: Style, arm: str, obj: str, grasp: Grasp,
         pre_distance: float = 0.1) -> Plan:
    """Open, come to ``grasp`` along its approach direction, close, lift. ``grasp`` puts
    the middle between the fingers on the object; a gripper with one fixed jaw puts its
    TCP off that middle (:meth:`World.grip_centre`)."""
    grasp = fixed_jaw_shifted(world, arm, grasp)
    yield Segment(grippers={arm: world.pregrasp_opening(arm, grasp.width)},
                  gripper_steps=style.gripper_steps, label="open")
    if not world.fingers_slide(arm):
        grasp = jaws_clear_of_support(world, arm, obj, grasp)
    grasp = attainable(world, arm, grasp)
    pre = grasp.pose.moved(-pre_distance * grasp.approach)
    if grasp.approach[2] < -0.7:  # from above: no higher than the arm reaches
        top = reach_ceiling(world, arm, grasp.pose.p, grasp.pose.R, float(pre.p[2]))
        pre = Pose(np.array([pre.p[0], pre.p[1], max(grasp.pose.p[2] + 0.02, top)]), pre.R)
    yield from transit(world, style, arm, pre, exclude=(obj,), then=grasp.pose)
    # careful: the hand stops where it touches the object on its way in, and closes
    # there (a Z1's rubber jaw sliding 2 mm beside a glass caught on it and pressed 75 N)
    guards = (Guard(arm, REACH_TOUCH, obj, keep_lead=0.0),) if style.avoid_hazards else ()
    yield Segment({arm: grasp.pose.moved(-0.02 * grasp.approach)}, speed=style.approach_speed,
                  label="approach", guards=guards)
    yield Segment({arm: grasp.pose}, speed=gentle(world, style, obj), label="reach",
                  guards=guards)
    yield from close_on(world, style, arm, obj, grasp.width)
    lift = min(style.lift_height, max(0.02, reach_ceiling(
        world, arm, grasp.pose.p, grasp.pose.R, grasp.pose.p[2] + style.lift_height)
        - grasp.pose.p[2]))
    yield Segment({arm: grasp.pose.moved(lift * UP)}, speed=free_speed(style),
                  label="lift")


def fixed_jaw_shifted(world: World, arm: str, grasp: Grasp) -> Grasp:
    """``grasp`` (the middle between the fingers on the object) with the TCP where a
    gripper with one fixed jaw puts it, that jaw a little outside the object's face, not
    on its edge (:meth:`World.grip_centre`); ``grasp`` itself for fingers that close
    symmetrically."""
    shift = grasp.pose.R @ world.grip_centre(arm, grasp.width + FIXED_JAW_CLEARANCE)
    if float(np.linalg.norm(shift)) <= 0.002:
        return grasp
    return Grasp(Pose(grasp.pose.p - shift, grasp.pose.R), grasp.width, grasp.approach)


def attained(world: World, arm: str, pose: Pose) -> Pose:
    """``pose`` turned to a rotation the arm holds at its point: a degree or two, for an
    arm of fewer than six joints (:meth:`~fsvla.experts.motion.ArmDriver.attainable`)."""
    driver = ArmDriver(arm, world.kinematics(arm), world.current_pose(arm),
                       world.arm_joints(arm), 1.0)
    return driver.attainable(pose)


def reaches(world: World, arm: str, pose: Pose) -> bool:
    """Whether IK puts the arm's TCP at ``pose`` (from any start, on any branch, within the
    limits)."""
    driver = ArmDriver(arm, world.kinematics(arm), world.current_pose(arm),
                       world.arm_joints(arm), 1.0)
    driver.solve_anywhere(pose)
    return not driver.ik_misses


def attainable(world: World, arm: str, grasp: Grasp) -> Grasp:
    """``grasp`` with its pose :func:`attained`."""
    pose = attained(world, arm, grasp.pose)
    if pose is grasp.pose:
        return grasp
    return Grasp(pose, grasp.width, pose.R @ world.approach_axis(arm))


def jaws_clear_of_support(world: World, arm: str, obj: str, grasp: Grasp) -> Grasp:
    """A grasp from above raised, where it must be, so that the jaws as they are now
    (opened for it) stay :data:`TIP_GAP` above the bottom of ``obj``, what it stands on: a
    fixed jaw reaches past the TCP (the Z1's by 2 cm), and a grasp low on a small block
    would drive it into the table; a hand leaning forward brings the corner of a wide jaw
    lower still."""
    if grasp.approach[2] > -0.3:
        return grasp
    below = world.hand_front(arm, grasp.pose.R, -UP, grasp.pose.p, np.inf)
    # never below the table (z = 0): a knife just set down, settling, reads 8 mm into it
    floor = max(0.0, float(world.bounds(obj)[0][2])) + below + TIP_GAP
    if grasp.pose.p[2] >= floor:
        return grasp
    p = grasp.pose.p.copy()
    p[2] = floor
    return Grasp(Pose(p, grasp.pose.R), grasp.width, grasp.approach)


def carrying_style(world: World, style: Style, obj: str) -> Style:
    """The style a load is carried in: careful, one heavier than LIGHT_LOAD at no more
    than CARRY_SPEED (faster, it shakes loose of the fingers)."""
    if style.avoid_hazards and float(world.asset(obj).mass) > LIGHT_LOAD:
        return replace(style, transit_speed=min(style.transit_speed, CARRY_SPEED))
    return style


def carried_rotation(world: World, arm: str, point: NDArray[np.float64]) -> NDArray[np.float64]:
    """How ``arm``'s hand is turned when it carries what it holds over to ``point``: as it
    is now, or, for an arm of fewer than six joints, turned about the vertical as the arm
    turns about its base from here to there. Such an arm leans its hand only in its own
    upright plane: a hand leaning out to grasp far from the base, carried elsewhere
    unturned, leans sideways, which the arm cannot hold (an SO-101 stopped 13 cm short of
    a bowl)."""
    now = world.current_pose(arm)
    return carried_turn(world, arm, now.p, point) @ now.R


def carried_turn(world: World, arm: str, here: NDArray[np.float64],
                 there: NDArray[np.float64]) -> NDArray[np.float64]:
    """The turn (a rotation about the vertical) of ``arm``'s hand carried from ``here`` to
    ``there`` (:func:`carried_rotation`): none for an arm of six joints or more."""
    if len(world.arm_joints(arm)) >= 6:
        return np.eye(3)
    base = world.base_position(arm)
    a, b = np.asarray(here, dtype=np.float64) - base, np.asarray(there, dtype=np.float64) - base
    return axis_angle_matrix(UP, float(np.arctan2(b[1], b[0]) - np.arctan2(a[1], a[0])))


def place(world: World, style: Style, arm: str, obj: str, bottom: NDArray[np.float64],
          rotation: NDArray[np.float64] | None = None, retreat: float = 0.1,
          release_gap: float | None = None, by_lowest: bool = False) -> Plan:
    """Carry the held ``obj`` so that its origin (bottom centre) lands at ``bottom``,
    lower it (slowly when careful), open, and back off. ``release_gap``: open only until
    each finger is that far (m) from the object (default: fully). Fingers that end near
    the simulator's contact distance (2 cm: a 4 cm object in an 8 cm hand) drop in and
    out of contact as the hand backs off, which reads as grasping it again. ``by_lowest``:
    a load that hangs more than SAG below its origin is set down by its lowest point (a
    bar held by its end; a knife held by its handle instead lies down as the hand lowers
    on, turning in the fingers, and is not raised); careful, it is then laid flat
    (:func:`lay_down`) before the fingers open."""
    R = carried_rotation(world, arm, bottom) if rotation is None else rotation
    offset = R @ held_offset(world, arm, obj)
    goal = Pose(bottom + offset + np.array([0.0, 0.0, style.release_height]), R)
    below = float(offset[2]) + 0.03 + (hanging(world, obj) if by_lowest else 0.0)
    yield from transit(world, carrying_style(world, style, obj), arm, goal.moved(0.08 * UP),
                       below=below, exclude=(obj,), around=load_reach(world, arm, obj))
    # the object may have slipped in the fingers on the way: aim with where it is now
    now = R @ held_offset(world, arm, obj)
    if float(np.linalg.norm(now - offset)) > 0.05:  # dropped: nothing left to place
        return
    offset = now
    fragile = style.avoid_hazards and force_watched(world, obj)
    # a fragile object is set down (not dropped from the release height: a 2 mm drop of a
    # 100 g block lands with ~9 N over one 2 ms substep), then let go slowly
    drop = 0.0 if fragile else style.release_height
    # ``by_lowest``: a load hanging tilted in the fingers (a bar held by its end, which
    # pivoted in a handover) reaches below its origin: its lowest point is set down, not
    # its origin, or the hand follows it on down into the target (measured again: the
    # load may have turned further on the way)
    sag = hanging(world, obj) if by_lowest else 0.0
    goal = attained(world, arm, Pose(bottom + offset + np.array([0.0, 0.0, drop + sag]), R))
    yield Segment({arm: goal.moved(0.02 * UP)}, speed=style.approach_speed, label="lower")
    yield Segment({arm: goal}, speed=gentle(world, style, obj), settle=style.settle // 2,
                  label="touch")
    if sag > 0.0 and style.avoid_hazards:
        yield from lay_down(world, style, arm, obj)
    opening = 1.0 if release_gap is None else min(
        1.0, world.gripper_opening(arm) + 2 * release_gap / world.max_width(arm))
    yield Segment(grippers={arm: opening},
                  gripper_steps=style.gripper_steps * (2 if fragile else 1),
                  settle=style.settle, label="release")
    back = -world.current_pose(arm).R @ world.approach_axis(arm)
    yield Segment({arm: goal.moved(retreat * back)}, speed=free_speed(style), label="retreat")


#: The guard of a careful lay-down (:func:`lay_down`): it stops the hand once it feels
#: this much (N) more than its squeeze on the load, or this share of a contact force
#: limit on the load where that is less (what the hand feels more, the load's low end
#: presses on the support).
LAY_DOWN_SPARE = 3.0
LAY_DOWN_SHARE = 0.2
#: Largest turn (rad) of one straight step of the hand along a lay-down's arc.
LAY_DOWN_STEP = np.radians(8.0)
#: How many times at most the careful hand then lowers on by what the load still hangs.
LAY_DOWN_ROUNDS = 4


def lay_down(world: World, style: Style, arm: str, obj: str) -> Plan:
    """Lay the held ``obj``, tilted in the fingers and its low end on the support, flat:
    the hand turns it about that end, along the arc its grip follows, turning with it (a
    hand lowered straight down drags the end across the support and stalls at half the
    tilt, and the load let go from there lands hard; a bar taken near its middle does not
    turn in the fingers). Guarded: a load that will not turn presses on the hand."""
    pose = world.body_pose(obj)
    up = pose.R[:, 2]
    tilt = float(np.arccos(np.clip(up @ UP, -1.0, 1.0)))
    axis = np.cross(up, UP)
    if tilt <= LAY_DOWN_STEP / 2 or float(np.linalg.norm(axis)) < 1e-9:
        return
    corners = world.corners(obj)
    low = corners[corners[:, 2] <= corners[:, 2].min() + 0.005].mean(axis=0)  # its low end
    limit = world.force_limit(obj)
    spare = LAY_DOWN_SPARE if limit is None else min(LAY_DOWN_SPARE, LAY_DOWN_SHARE * limit)
    guard = Guard(arm, world.hand_force(arm, obj) + spare, obj)
    tcp = world.current_pose(arm)
    steps = int(np.ceil(tilt / LAY_DOWN_STEP))
    arc = [tcp] + [Pose(low + turn @ (tcp.p - low), turn @ tcp.R) for turn in (
        axis_angle_matrix(axis, tilt * k / steps) for k in range(1, steps + 1))]
    # as far along the arc as the arm follows it (a Panda's wrist turning a low hand
    # meets its limit part way)
    followed = next((k for k in range(steps, 0, -1)
                     if branch_for_path(world, arm, tuple(arc[:k + 1])) is not None), 0)
    for pose in arc[1:followed + 1]:
        yield Segment({arm: pose}, speed=gentle(world, style, obj), guards=(guard,),
                      label="lay down")
    # what it still hangs: the hand lowers on straight, the load turning in the fingers
    for _ in range(LAY_DOWN_ROUNDS):
        rest, now = hanging(world, obj), world.current_pose(arm)
        if rest <= 0.0 or world.hand_force(arm, obj) >= guard.force:
            break
        yield Segment({arm: Pose(now.p - rest * UP, now.R)}, speed=gentle(world, style, obj),
                      settle=style.settle // 2, guards=(guard,), label="lay down")


def hanging(world: World, obj: str) -> float:
    """How far (m) the held ``obj``'s lowest point hangs below its origin (its bottom
    centre), where that is more than SAG: a load tilted in the fingers; else 0."""
    sag = float(world.body_pose(obj).p[2] - world.bounds(obj)[0][2])
    return sag if sag > SAG else 0.0


def close_on(world: World, style: Style, arm: str, obj: str, width: float,
             weight_factor: float = 2.0) -> Plan:
    """Close ``arm``'s gripper on ``obj`` (``width`` across the fingers); see
    :func:`close_hands_on`."""
    yield from close_hands_on(world, style, {arm: width}, obj, weight_factor)


def close_hands_on(world: World, style: Style, widths: Mapping[str, float], obj: str,
                   weight_factor: float = 2.0) -> Plan:
    """Close the grippers of the arms in ``widths`` (arm -> width across its fingers) on
    ``obj``, together: careful with a fragile (force-watched) object, quickly to just short
    of contact and then slowly to the squeeze of its grip force; otherwise at the style's
    gripper pace. Each hand stops at its own felt squeeze while the others close on."""
    held = {arm: grip_force(world, obj, style, weight_factor, grasp_lever(world, arm, obj),
                            grasp_tip(world, arm, obj), world.moving_jaw(arm) is not None)
            for arm in widths}
    target = {arm: opening_for(world, arm, widths[arm], held[arm]) for arm in widths}
    if not style.avoid_hazards:
        yield Segment(grippers=target, gripper_steps=style.gripper_steps,
                      settle=style.settle, label="close")
        return
    # careful: the fingers' squeeze is felt as they close (a force-sensing gripper), so a
    # width model that is off (a jaw that swings, fingers that do not meet when closed)
    # neither crushes the object nor leaves it loose
    force = {arm: float(held[arm].grip_force or 0.0) for arm in widths}
    guard = {arm: grip_guard(world, arm, force[arm], obj) for arm in widths}
    if force_watched(world, obj) or not all(world.fingers_slide(arm) for arm in widths):
        # slowly over the last millimetres: a jaw on a hinge swinging shut at speed knocks
        # the object across the table before it squeezes it
        near = {arm: world.opening_fraction(arm, widths[arm] + preclose_gap(world, arm))
                for arm in widths}
        yield Segment(grippers=near, gripper_steps=style.gripper_steps, label="preclose")
        # a jaw on a hinge under a contact-force limit creeps onto the object; without
        # one, its squeeze at SLOW_CLOSE holds better than the guard's own force would
        if all(world.fingers_slide(arm) for arm in widths) \
                or world.force_limit(obj, *world.gripper_entities) is None:
            steps = max([2 * style.gripper_steps] + [
                int(np.ceil((near[arm] - target[arm]) / SLOW_CLOSE)) for arm in widths])
            yield Segment(grippers=target, gripper_steps=steps, settle=style.settle,
                          guards=tuple(guard.values()), label="close")
        else:
            yield from creep_shut(world, style, obj, near, target, guard)
    else:
        yield Segment(grippers=target, gripper_steps=style.gripper_steps,
                      settle=style.settle, guards=tuple(guard.values()), label="close")
    # a stiff finger drive stopped by the guard may still squeeze well past the force
    # (it meets the object within one control step): open by a little until it is eased
    for _ in range(EASE_STEPS):
        tight = [arm for arm in widths
                 if world.hand_force(arm, obj, fingers=True) > EASE_ABOVE * force[arm]]
        if not tight:
            break
        yield Segment(grippers={arm: min(1.0, world.gripper_opening(arm) + EASE_STEP)
                                for arm in tight}, gripper_steps=1, settle=2, label="ease")
    yield from squeeze_until_felt(world, style, force, obj, target)


def creep_shut(world: World, style: Style, obj: str, start: Mapping[str, float],
               target: Mapping[str, float], guard: Mapping[str, Guard]) -> Plan:
    """Close the grippers of the arms in ``start`` from there (opening, arm -> [0, 1])
    toward ``target`` a control step at a time, each stopping where its ``guard`` feels
    its force: by SLOW_CLOSE of the range a step while its fingers are more than
    CREEP_GAP from squeezing ``obj`` (:meth:`World.grip_gap`), slower as the gap closes,
    and CREEP_STEP once they squeeze it. A stiff jaw drive whose command leads the jaw
    meets the object with the squeeze of that lead in one step (a Z1's: 30-40 N at
    SLOW_CLOSE; creeping, about 11 N)."""
    opening = dict(start)
    for _ in range(CREEP_STEPS):
        moving = {}
        for arm, now in opening.items():
            if now <= target[arm] or world.hand_force(arm, obj, fingers=True) >= guard[arm].force:
                continue
            gap = world.grip_gap(arm, obj)
            rate = SLOW_CLOSE if gap is None or gap >= CREEP_GAP else \
                max(CREEP_STEP, SLOW_CLOSE * max(0.0, gap) / CREEP_GAP)
            moving[arm] = max(target[arm], now - rate)
        opening.update(moving)
        if not moving:
            break
        yield Segment(grippers=moving, gripper_steps=1, guards=tuple(guard[a] for a in moving),
                      label="close")
    yield Segment(settle=style.settle, label="close")


def squeeze_until_felt(world: World, style: Style, force: Mapping[str, float], obj: str,
                       target: Mapping[str, float]) -> Plan:
    """Careful: where the fingers of an arm in ``force`` (arm -> grip force, N) feel less
    than 0.8 of it from ``obj`` (the model's opening ``target`` left them short of the
    object: a gripper whose shut pads stay apart, a worn width model), close on until it
    is felt; a jaw on a hinge from where it is (its width model's target may be shut,
    trusting the guard) and in small steps (a stiff jaw drive squeezes ~60 N harder per
    1 % of its range once it touches). Nothing where every grip is felt already."""
    guard = {arm: grip_guard(world, arm, force[arm], obj) for arm in force}
    slide = {arm: world.fingers_slide(arm) for arm in force}
    goal = {arm: min(target[arm], world.gripper_opening(arm)) if slide[arm]
            else world.gripper_opening(arm) for arm in force}
    step = {arm: SQUEEZE_STEP if slide[arm] else EASE_STEP for arm in force}
    for _ in range(max(SQUEEZE_STEPS if slide[arm] else 3 * SQUEEZE_STEPS for arm in force)):
        loose = [arm for arm in force
                 if world.hand_force(arm, obj, fingers=True) < 0.8 * force[arm] and goal[arm] > 0.0]
        if not loose:
            break
        for arm in loose:
            goal[arm] = max(0.0, goal[arm] - step[arm])
        yield Segment(grippers={arm: goal[arm] for arm in loose},
                      gripper_steps=style.gripper_steps, settle=2,
                      guards=tuple(guard[arm] for arm in loose), label="squeeze")


def preclose_gap(world: World, arm: str) -> float:
    """How much wider (m) than the object ``arm``'s fingers close quickly, before SLOW_CLOSE."""
    return PRECLOSE_GAP if world.fingers_slide(arm) else PRECLOSE_GAP_HINGED


def grip_guard(world: World, arm: str, force: float, obj: str) -> Guard:
    """The guard of a careful grip on ``obj``: it stops the fingers at ``force`` felt from
    it. A jaw on a soft drive swings on past the felt force: it holds half its lead;
    sliding fingers hold their command (their squeeze is what holds a heavy load)."""
    return Guard(arm, force, obj, hold_measured=False,
                 keep_lead=1.0 if world.fingers_slide(arm) else 0.5, fingers=True)


def load_reach(world: World, arm: str, obj: str) -> float:
    """How much farther than 4 cm (m) the held ``obj`` reaches out sideways from the TCP:
    what a carry's obstacle boxes grow by (a mug by its handle, a kettle by its rim)."""
    lo, hi = world.bounds(obj)
    tcp = world.current_pose(arm).p
    corners = np.array([[x, y] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
    return max(0.0, float(np.max(np.linalg.norm(corners - tcp[:2], axis=1))) - 0.04)


def held_offset(world: World, arm: str, obj: str) -> NDArray[np.float64]:
    """Where the TCP is relative to the held object's origin, in the TCP's frame."""
    tcp = world.current_pose(arm)
    return tcp.R.T @ (tcp.p - world.body_pose(obj).p)


def leaning_frame(world: World, arm: str, point: NDArray[np.float64],
                  lean: float) -> NDArray[np.float64]:
    """The hand over ``point`` pointing down but leaning by ``lean`` (rad) out from the
    arm's base (negative: back toward it), its fingers closing level across the lean: the
    one way a five-joint arm tips its hand, and how a short arm reaches far and low."""
    out = horizontal(point - world.base_position(arm))
    return world.grasp_frame(arm, np.cos(abs(lean)) * DOWN + np.sin(lean) * out,
                             np.cross(UP, out))


def hand_body(world: World, arm: str, pose: Pose) -> tuple[NDArray[np.float64], ...]:
    """The points that stand for ``arm``'s hand at ``pose`` in a clearance check, besides
    its TCP: its body, HAND_RADIUS behind the TCP along the approach, and that body's two
    ends HAND_HALF_LENGTH out along the finger axis (a hand lying toward a hazard reaches
    into its keep-out)."""
    body = pose.p - HAND_RADIUS * (pose.R @ world.approach_axis(arm))
    across = HAND_HALF_LENGTH * (pose.R @ world.finger_axis(arm))
    return body, body + across, body - across


def hand_clearance(world: World, arm: str, poses: tuple[Pose, ...],
                   exclude: tuple[str, ...] = ()) -> float:
    """How far (m) outside every obstacle's keep-out (:meth:`World.obstacles`, less
    ``exclude``) the hand stays at ``poses``: its TCP and :func:`hand_body` (inf without
    obstacles)."""
    obstacles = world.obstacles(exclude=exclude)
    least = np.inf
    for pose in poses:
        for point in (pose.p, *hand_body(world, arm, pose)):
            for o in obstacles:
                least = min(least, box_distance(point, o.lo, o.hi) - o.margin)
    return float(least)


def first_clear(options: Iterable[T], followed: Callable[[T], bool],
                clearance: Callable[[T], float]) -> T | None:
    """The first of ``options`` that is ``followed`` (one IK branch, say) and keeps
    HAZARD_SPARE of ``clearance``; where none does, the followed one that keeps the
    most; None where none is followed."""
    best: tuple[float, T] | None = None
    for option in options:
        if not followed(option):
            continue
        clear = clearance(option)
        if clear >= HAZARD_SPARE:
            return option
        if best is None or clear > best[0]:
            best = (clear, option)
    return None if best is None else best[1]


def top_down_grasp(world: World, arm: str, centre: NDArray[np.float64],
                   closing: NDArray[np.float64], width: float) -> Grasp:
    R = world.grasp_frame(arm, DOWN, closing)
    return Grasp(Pose(np.asarray(centre, dtype=np.float64), R), width, DOWN.copy())


def nearest_arm(world: World, point: NDArray[np.float64]) -> str:
    return min(world.arm_names, key=lambda a: float(np.linalg.norm(
        (world.base_position(a) - point)[:2])))


def carrying_arm(world: World, obj: str, target: str) -> str:
    """The arm that carries ``obj`` to ``target``: the one nearest the object, unless it
    cannot hold its hand over the part of the target nearest to it where the object still
    lands on or in it; then the one whose base is nearest to the farther of the two (a
    block on Baxter's right, a pot far out on its left)."""
    near = nearest_arm(world, world.body_pose(obj).p)
    if len(world.arm_names) == 1 or _reaches_over(world, near, obj, target):
        return near
    ends = (world.body_pose(obj).p, world.body_pose(target).p)
    return min(world.arm_names, key=lambda arm: max(
        float(np.linalg.norm((world.base_position(arm) - p)[:2])) for p in ends))


def _reaches_over(world: World, arm: str, obj: str, target: str) -> bool:
    """Whether ``arm`` holds its hand, turned as it is now, CARRY_CLEARANCE above the point
    of ``target``'s top nearest its base at which ``obj``'s footprint is still over it."""
    lo, hi = world.bounds(target)
    olo, ohi = world.bounds(obj)
    centre = 0.5 * (lo + hi)
    room = 0.5 * float(np.min((hi - lo)[:2])) - 0.5 * float(np.max((ohi - olo)[:2])) - 0.01
    toward = horizontal(world.base_position(arm) - centre)
    over = centre + max(0.0, room) * toward
    over[2] = hi[2] + CARRY_CLEARANCE
    return branch_for_path(world, arm, (Pose(over, world.current_pose(arm).R),)) is not None


#: How high (m) above a target :func:`carrying_arm` asks an arm to hold its hand.
CARRY_CLEARANCE = 0.05


def horizontal(v: NDArray[np.float64]) -> NDArray[np.float64]:
    h = np.array([v[0], v[1], 0.0])
    return h / np.linalg.norm(h)


__all__ = [
    "DOWN",
    "HAZARD_SPARE",
    "UP",
    "Grasp",
    "Plan",
    "arm_clearance_along",
    "branch_for_path",
    "carried_rotation",
    "carried_turn",
    "carrying_style",
    "clear_height",
    "close_on",
    "first_clear",
    "force_watched",
    "free_speed",
    "gentle",
    "grasp_lever",
    "grasp_tip",
    "grip_force",
    "grip_force_cap",
    "grip_guard",
    "hand_body",
    "hand_clearance",
    "held_offset",
    "holdable_lever",
    "horizontal",
    "jaws_clear_of_support",
    "lay_down",
    "leaning_frame",
    "load_reach",
    "nearest_arm",
    "opening_for",
    "park_others",
    "pick",
    "place",
    "reaches",
    "squeeze_until_felt",
    "top_down_grasp",
    "transit",
]
