"""handover: one arm picks the object and holds it out, the other takes it and puts it down."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix, quat_to_matrix, rotation_angle

from .. import grasps
from ..motion import Pose, Segment
from ..skills import (
    CARRY_SPEED,
    UP,
    Grasp,
    Plan,
    branch_for_path,
    clear_height,
    free_speed,
    grasp_lever,
    grip_force,
    grip_force_cap,
    holdable_lever,
    horizontal,
    nearest_arm,
    opening_for,
    pick,
    place,
    squeeze_until_felt,
    top_down_grasp,
    transit,
)
from ..style import Style
from ..world import World
from .arm_gap import ArmGap
from .common import place_point, retreat_home

#: An object at least this long (m) is handed over by its two ends, both hands from
#: above (two Panda hands side by side need 2 × HAND_HALF_WIDTH and a margin).
LONG_ENOUGH = 0.15

#: How far from an end (m) each hand holds a long object.
END_GRASP = 0.025


#: How far (m) the hands meet in front of their home positions when the arms reach the
#: same way (side by side, as Baxter's): out where the arms' links stay apart.
MEET_AHEAD = 0.15


def meeting_point(world: World, giver: str, taker: str) -> np.ndarray:
    """Where the hands meet: halfway between the arms' home TCPs, moved out along the way
    both arms reach (arms facing each other reach opposite ways: halfway between them; arms
    side by side behind the table: in front of the robot, where their links stay apart)."""
    homes = [world.home_position(arm) for arm in (giver, taker)]
    ahead = np.mean([horizontal(h - world.base_position(arm))
                     for arm, h in zip((giver, taker), homes)], axis=0)
    return 0.5 * (homes[0] + homes[1]) + MEET_AHEAD * ahead


def plan_handover(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """The arm nearer the object picks it, brings it over the middle of the table; the other
    arm takes it from the side, the first lets go and backs off, the second puts it on the
    scenario's support (the first other object with a top), else back on the table."""
    obj = roles["object"]
    giver = nearest_arm(world, world.body_pose(obj).p)
    taker = next(a for a in world.arm_names if a != giver)
    lo, hi = world.bounds(obj)
    if float(np.max((hi - lo)[:2])) >= LONG_ENOUGH:
        yield from _handover_by_the_ends(world, style, obj, giver, taker)
        return
    grasp = grasps.choose(world, style, giver, obj)
    yield from pick(world, style, giver, obj, grasp)
    lo, hi = world.bounds(obj)
    size = hi - lo
    mid = meeting_point(world, giver, taker)
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    centre = np.array([mid[0], mid[1], height])
    tcp = world.current_pose(giver)
    offset = tcp.p - 0.5 * (world.bounds(obj)[0] + world.bounds(obj)[1])
    giver_goal = Pose(centre + np.array([0.0, 0.0, max(offset[2], 0.3 * size[2] / 2 + 0.008)]),
                      tcp.R)
    yield from transit(world, style, giver, giver_goal, below=0.05, exclude=(obj,))
    towards = horizontal(centre - world.home_position(taker))
    closing = tcp.R @ world.finger_axis(giver)
    R = world.grasp_frame(taker, towards, closing)
    take = Pose(centre - np.array([0.0, 0.0, 0.3 * size[2]]) - towards * 0.004, R)
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    yield from transit(world, style, taker, take.moved(-0.12 * towards), below=0.05, exclude=(obj,))
    yield Segment({taker: take}, speed=style.approach_speed, label="to block")
    held = grip_force(world, obj, style)
    width = float(abs(closing @ size))
    yield from _take(world, style, taker, obj, opening_for(world, taker, width, held), held)
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    yield Segment({giver: back.moved(0.1 * UP)}, speed=style.approach_speed, label="giver up")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    if support is not None:
        spot = place_point(world, style, obj, support)
    else:
        spot = np.array([centre[0], centre[1], 0.0])
    yield from place(world, style, taker, obj, spot)
    yield from retreat_home(world, style, taker)


def _take(world: World, style: Style, taker: str, obj: str, opening: float,
          gripped: Style) -> Plan:
    """The taker closes to ``opening``; careful, it closes on until it feels its grip
    force (``gripped``) before the giver lets go: Baxter's right fingertips stay 6 mm
    apart when shut, and a close to the model's opening left a 2.8 cm bar loose between
    them, to fall when the giver opened."""
    yield Segment(grippers={taker: opening}, gripper_steps=style.gripper_steps,
                  settle=style.settle, label="take")
    if style.avoid_hazards:
        yield from squeeze_until_felt(world, style, {taker: float(gripped.grip_force or 0.0)},
                                      obj, {taker: opening})


def _yaw_between(u: NDArray[np.float64], v: NDArray[np.float64]) -> float:
    """The signed angle (rad) about the vertical from horizontal ``u`` to ``v``."""
    return float(np.arctan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1]))


def _joints_at(world: World, arm: str, q: NDArray[np.float64], pose: Pose) -> NDArray[np.float64]:
    """The joints for ``pose`` on ``q``'s branch (a short line away from ``q``'s pose)."""
    kin = world.kinematics(arm)
    r = kin.inverse(tuple(pose.p), pose.quat, seed=q, restarts=0, max_iterations=300)
    return np.asarray(r.qpos, dtype=np.float64)


@dataclass(frozen=True)
class _Bar:
    """A long object's geometry now: its middle, long and short horizontal axes, half
    sizes (along, across, up), and its own long and up axes (tilted where it has pivoted
    in a hand)."""

    centre: NDArray[np.float64]
    along: NDArray[np.float64]
    across: NDArray[np.float64]
    half: NDArray[np.float64]
    line: NDArray[np.float64]
    up: NDArray[np.float64]

    @classmethod
    def of(cls, world: World, obj: str) -> _Bar:
        shape = world.asset(obj).collision[0]
        half = np.asarray(shape.half_size, dtype=np.float64)
        R = world.body_pose(obj).R @ quat_to_matrix(np.asarray(shape.pose.quaternion))
        axis = int(np.argmax(half[:2]))
        up = R[:, 2] if R[2, 2] >= 0 else -R[:, 2]
        return cls(world.to_world(obj, shape.pose.position), horizontal(R[:, axis]),
                   horizontal(R[:, 1 - axis]), np.array([half[axis], half[1 - axis], half[2]]),
                   R[:, axis].copy(), up.copy())


@dataclass(frozen=True)
class _Exchange:
    """Where a long object changes hands: its middle there, the inset of the giver's hand
    from its end, how far from the middle the taker takes it (careful: as far as the giver,
    or nearer where its squeeze is capped, :func:`_take_offset`; careless: at the middle,
    leaving the arms no room apart),
    how far before its take pose (along the approach) the taker's free-space move
    ends (m), and how far the taker's hand leans away from the giver's (rad)."""

    middle: NDArray[np.float64]
    inset: float
    take_at: float
    above: float
    tilt: float = 0.0


#: Insets (m) of the hands from the object's ends, the first preferred; a smaller one
#: spreads the hands farther apart where a separation limit needs it (a finger pad is
#: about 2 cm wide).
INSETS = (END_GRASP, 0.018)
#: Extra heights (m) of the meeting above the lowest one, and shifts (m) of it ahead of
#: the robot, tried in turn until the arms keep their separation there.
MEET_RAISES = (0.0, 0.06, 0.12)
MEET_SHIFTS = (0.0, 0.06, 0.12)
#: Distances (m) before its take pose from which the taker comes straight in.
ABOVE = (0.1, 0.16, 0.22)
#: Leans (rad) of the taker's hand away from the giver, tried in turn: Baxter's forearms
#: stand 40 cm tall above hands that point down, and two of them side by side touch.
TILTS = (0.0, 0.5, 0.9)
#: Careful: the fastest turn (rad/s) of a hand carrying a long object by its end.
CARRY_TURN = 0.8
#: What an exchange that misses a required alignment of the hands loses in rank (m).
UNALIGNED = 1.0
#: How much clearance (m) beyond a separation limit's warning band the careful arms keep.
GAP_SLACK = 0.01


def _meeting_options(world: World, style: Style, obj: str, giver: str,
                     taker: str) -> list[NDArray[np.float64]]:
    """Where the object's middle may be when it changes hands, the preferred first:
    :func:`meeting_point` at the height that clears the obstacles, then (careful) higher
    and farther ahead of the robot, where the arms' links are farther apart."""
    mid = meeting_point(world, giver, taker)
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    base = np.array([mid[0], mid[1], height])
    if not style.avoid_hazards:
        return [base]
    bases = 0.5 * (world.base_position(giver) + world.base_position(taker))
    ahead = np.array([mid[0] - bases[0], mid[1] - bases[1], 0.0])
    toward = horizontal(world.base_position(taker) - world.base_position(giver))
    ahead -= (ahead @ toward) * toward
    ahead = ahead / np.linalg.norm(ahead) if np.linalg.norm(ahead) > 1e-6 else None
    out = []
    for shift in MEET_SHIFTS:
        if shift and ahead is None:
            continue
        for raise_ in MEET_RAISES:
            out.append(base + raise_ * UP + (shift * ahead if shift else 0.0))
    return out


def _end_options(bar: _Bar, world: World, giver: str, toward: NDArray[np.float64],
                 inset: float = END_GRASP) -> list[float]:
    """The ends (+1: along the long axis, -1: against it) the giver may take: one its
    hand comes straight down onto from 10 cm above first (near its base, a Panda's hand
    cannot: the line down drives its elbow onto a limit), then the one its hand turns
    less to hold the object out toward the taker, then the nearer."""
    lift = np.array([0.0, 0.0, 0.3 * bar.half[2]])

    def key(e: float) -> tuple[bool, float, float]:
        grip = top_down_grasp(world, giver, bar.centre + e * (bar.half[0] - inset) * bar.along
                              + lift, bar.across, 2 * float(bar.half[1])).pose
        down = branch_for_path(world, giver, (grip.moved(0.1 * UP), grip)) is not None
        turn = abs(_yaw_between(-e * bar.along, toward))
        near = float(np.linalg.norm((bar.centre + e * bar.along - world.base_position(giver))[:2]))
        return (not down, round(turn, 3), near)

    return sorted((1.0, -1.0), key=key)


def _giver_at_meeting(world: World, giver: str, grip: Pose, centre: NDArray[np.float64],
                      toward: NDArray[np.float64], middle: NDArray[np.float64]) -> Pose:
    """The giver's TCP pose that holds the object (gripped at ``grip`` while its middle is
    at ``centre``) with its middle at ``middle`` and its long axis along ``toward``: the
    hand turned about the vertical."""
    turn = axis_angle_matrix(UP, _yaw_between(horizontal(centre - grip.p), toward))
    return Pose(middle + turn @ (grip.p - centre), turn @ grip.R)


def _taker_grasp(world: World, taker: str, bar: _Bar, middle: NDArray[np.float64],
                 toward: NDArray[np.float64], out: float, tilt: float = 0.0) -> Grasp:
    """The taker's grasp of the object held out along ``toward`` with its middle at
    ``middle``, ``out`` (m) from the middle toward the taker: from above, the hand leaning
    ``tilt`` (rad) away from the giver about the closing axis (the fingers close across
    the object either way, so the grip holds it alike; the taker's wrist and forearm lean
    away from the giver's)."""
    across = np.cross(bar.up, toward)
    point = middle + out * toward + 0.3 * bar.half[2] * bar.up
    approach = -np.cos(tilt) * bar.up - np.sin(tilt) * toward
    R = world.grasp_frame(taker, approach, across)
    return Grasp(Pose(point, R), 2 * float(bar.half[1]), approach)


def _exchange_margin(world: World, gap: ArmGap, giver: str, taker: str, q_giver,
                     grasp: Grasp, above: float) -> float:
    """The arms' smallest separation margin (:class:`ArmGap`) while the giver holds still
    at ``q_giver`` and the taker comes from where it is to ``above`` before ``grasp`` in
    free space, then straight in onto it, less UNALIGNED where the hands are then farther
    apart than a requirement's ``aligned`` allows; -inf where the taker cannot."""
    over = grasp.pose.moved(-above * grasp.approach)
    q_over = branch_for_path(world, taker, (over, grasp.pose))
    if q_over is None:
        return float("-inf")
    q_now = np.asarray(world.arm_joints(taker), dtype=np.float64)
    q_take = _joints_at(world, taker, q_over, grasp.pose)
    margin = min(gap.along(q_giver, q_giver, q_now, q_over),
                 gap.along(q_giver, q_giver, q_over, q_take, samples=3))
    # a requirement that the hands come together (aligned) before the take: an exchange
    # that leaves them too far apart ranks below every one that does not
    return margin if gap.aligned(q_giver, q_take) else margin - UNALIGNED


#: How much nearer the giver's hand (m) than its usual place the careful taker may take
#: a long object where a requirement asks the hands to come together (:func:`_take_outs`).
TAKE_NEARER = (0.02, 0.04, 0.06)
#: How far apart (m) along the object the careful hands hold it at least while it
#: changes hands (a Panda hand's body is 6 cm thick along it).
HANDS_APART = 0.08
#: How far (rad) from level a long object hangs in the giver's hand for the careful
#: taker to take it by its end whatever its grip holds (:func:`_take_offset`).
HANGS_TILTED = np.radians(15.0)


def _tilt(bar: _Bar) -> float:
    """How far (rad) the bar's long axis is from level."""
    return float(np.arcsin(min(1.0, abs(float(bar.line[2])) / float(np.linalg.norm(bar.line)))))


def _insets(world: World, obj: str, bar: _Bar, giver: str) -> tuple[float, ...]:
    """The careful giver's insets from the object's end, the first preferred: INSETS;
    where no force limit caps the squeeze but the most the giver's sliding fingers squeeze
    (their drive's spring shut on the object's thickness) does not hold the object's
    weight from turning in them held that far out (:func:`~fsvla.experts.skills.
    holdable_lever`), first nearer the middle, HANDS_APART / 2 from it, the taker as far
    on the other side (a 190 g bar held by its end in a Panda hand swung 64 deg down
    before the taker came). Under a force limit the giver keeps the end and the taker
    takes the object nearer the middle (:func:`_take_offset`)."""
    out = float(bar.half[0]) - INSETS[0]
    middle = 0.5 * HANDS_APART
    if out <= middle + 0.01 or not world.fingers_slide(giver) \
            or grip_force_cap(world, obj) is not None:
        return INSETS
    squeeze = world.gripper_stiffness(giver) * float(bar.half[1])
    if holdable_lever(world, obj, squeeze) >= out:
        return INSETS
    return (float(bar.half[0]) - middle, *INSETS)


def _take_offset(world: World, obj: str, bar: _Bar, inset: float) -> float:
    """How far from the middle (m) the careful taker takes a long object the giver holds
    ``inset`` from its other end: as far as the giver, unless a force limit caps its
    squeeze below what holds the object's weight from turning in the fingers that far out
    (:func:`~fsvla.experts.skills.holdable_lever`; a 119 g bar held 5.8 cm out under a
    23 N limit swung out of Baxter's fingers as the giver let go); then nearer the middle,
    keeping the hands HANDS_APART."""
    out = float(bar.half[0]) - inset
    cap = grip_force_cap(world, obj)
    if cap is None:
        return out
    return min(out, max(holdable_lever(world, obj, cap), HANDS_APART - out))


def _plan_exchange(world: World, style: Style, obj: str, giver: str,
                   taker: str) -> tuple[float, _Exchange]:
    """Before the pick: which end the giver takes, and where the hands meet. Careful, with
    a separation limit on the arms, the first option (end, inset, meeting point, approach
    height) at which the arms' links keep the limit and its warning band with GAP_SLACK
    to spare, predicted on the arms' models (else the one that keeps the most); careless,
    the first end and meeting point, and the taker takes the object at its middle, next
    to the giver's hand (no room kept)."""
    bar = _Bar.of(world, obj)
    toward = horizontal(world.base_position(taker) - world.base_position(giver))
    ends = _end_options(bar, world, giver, toward)
    meetings = _meeting_options(world, style, obj, giver, taker)
    if not style.avoid_hazards:  # the taker's point is chosen once the giver holds it out
        return ends[0], _Exchange(meetings[0], INSETS[0], 0.0, ABOVE[0])
    insets = _insets(world, obj, bar, giver)
    take_at = {inset: _take_offset(world, obj, bar, inset) for inset in insets}
    first = (ends[0], _Exchange(meetings[0], insets[0], take_at[insets[0]], ABOVE[0]))
    gap = ArmGap(world, giver, taker)
    if not gap.watched:
        return first
    best, best_margin = first, float("-inf")
    lift = np.array([0.0, 0.0, 0.3 * bar.half[2]])
    for inset in insets:
        for e in ends:
            grip = top_down_grasp(world, giver, bar.centre + e * (bar.half[0] - inset) * bar.along
                                  + lift, bar.across, 2 * float(bar.half[1])).pose
            for middle in meetings:
                held = _giver_at_meeting(world, giver, grip, bar.centre, toward, middle)
                q_giver = branch_for_path(world, giver, (held,))
                if q_giver is None:
                    continue
                for out, tilt in product(_take_outs(bar, inset, take_at[inset], gap), TILTS):
                    grasp = _taker_grasp(world, taker, bar, middle, toward, out, tilt)
                    for above in ABOVE:
                        margin = _exchange_margin(world, gap, giver, taker, q_giver, grasp,
                                                  above)
                        if margin > best_margin:
                            best = (e, _Exchange(middle, inset, out, above, tilt))
                            best_margin = margin
                        if margin >= GAP_SLACK:
                            return best
    return best


def _take_outs(bar: _Bar, inset: float, take_at: float, gap: ArmGap) -> list[float]:
    """Where from the middle (m) the careful taker may take the object: ``take_at``; where
    a requirement asks the hands to come together (``aligned``), also TAKE_NEARER nearer
    the giver's hand in turn, keeping them HANDS_APART (a 20 cm bar taken by both ends
    leaves the hands 15 cm apart)."""
    if not gap.asks_aligned:
        return [take_at]
    least = HANDS_APART - (float(bar.half[0]) - inset)
    return [take_at, *(take_at - d for d in TAKE_NEARER if take_at - d >= least)]


def _handover_by_the_ends(world: World, style: Style, obj: str, giver: str, taker: str) -> Plan:
    """A long object: the giver takes one end from above, brings the object over the
    middle with its long axis from arm to arm (turning its hand about the vertical), the
    taker takes the other end from above (careless: at its middle),
    the giver lets go and backs off, the taker puts it on the support. A Panda can hold
    out a top-down hand there; a hand pointing sideways at the object it cannot. Careful,
    with a separation limit on the arms, the end, the meeting point and the taker's
    approach (its hand leaning away from the giver's where their forearms would meet) are
    chosen so that the arms' links keep the limit and its warning band
    (:func:`_plan_exchange`)."""
    bar = _Bar.of(world, obj)
    toward = horizontal(world.base_position(taker) - world.base_position(giver))
    e, meet = _plan_exchange(world, style, obj, giver, taker)
    reach = float(bar.half[0]) - meet.inset
    lift = np.array([0.0, 0.0, 0.3 * bar.half[2]])
    width = 2 * float(bar.half[1])
    grasp = top_down_grasp(world, giver, bar.centre + e * reach * bar.along + lift, bar.across,
                           width)
    yield from pick(world, style, giver, obj, grasp)
    # carry: up to the meeting height (or what clears the obstacles on the way), across in
    # free space turning the hand, down onto the meeting point
    held = world.current_pose(giver)
    now = _Bar.of(world, obj)
    goal = _giver_at_meeting(world, giver, held, now.centre, toward, meet.middle)
    below = float(held.p[2] - (now.centre[2] - now.half[2])) + 0.03
    height = max(clear_height(world, style, held.p, goal.p, below, (obj,),
                              around=float(now.half[0])), goal.p[2])
    if height > held.p[2] + 1e-3:
        yield Segment({giver: Pose(np.array([held.p[0], held.p[1], height]), held.R)},
                      speed=style.transit_speed, label="up")
    over = Pose(np.array([goal.p[0], goal.p[1], height]), goal.R)
    q = branch_for_path(world, giver, (over, goal))
    # careful: a long object held by its end pivots in the fingers when the hand turns it
    # fast; the turn takes at least its angle / CARRY_TURN
    speed = style.transit_speed
    if style.avoid_hazards:
        turn = rotation_angle(held.R, over.R)
        dist = float(np.linalg.norm(over.p - np.array([held.p[0], held.p[1], height])))
        speed = min(speed, CARRY_SPEED, max(dist, 0.01) * CARRY_TURN / max(turn, 1e-3))
    yield Segment({giver: over}, speed=speed, label="across", joint_space=True,
                  branch_of={giver: goal}, joints={giver: q} if q is not None else {})
    yield Segment({giver: goal}, speed=min(speed, style.approach_speed), label="down")
    # the taker: free space to above the far end, straight down onto it
    # aimed at the object as it is now (it may have pivoted a little in the giver's hand)
    now = _Bar.of(world, obj)
    line = now.line if now.line @ toward >= 0 else -now.line
    take_at = meet.take_at if style.avoid_hazards else 0.0  # careless: the middle
    gap = ArmGap(world, giver, taker)
    if style.avoid_hazards and _tilt(now) > HANGS_TILTED and not gap.asks_aligned:
        # it has turned in the giver's fingers and hangs: taken by its far end as it is, it
        # hangs from the taker's as it did from the giver's (unless the hands must come
        # together: then where the plan put the taker, nearer the giver's hand)
        take_at = float(now.half[0]) - meet.inset
    take = _taker_grasp(world, taker, now, now.centre, line, take_at, meet.tilt)
    above = meet.above
    if style.avoid_hazards and gap.watched:
        q_giver = np.asarray(world.arm_joints(giver), dtype=np.float64)
        margins = {h: _exchange_margin(world, gap, giver, taker, q_giver, take, h)
                   for h in dict.fromkeys((meet.above, *ABOVE))}
        above = next((h for h, m in margins.items() if m >= GAP_SLACK),
                     max(margins, key=margins.__getitem__))
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    over = take.pose.moved(-above * take.approach)
    q = branch_for_path(world, taker, (over, take.pose))
    yield Segment({taker: over}, speed=style.transit_speed, label="across", joint_space=True,
                  branch_of={taker: take.pose}, joints={taker: q} if q is not None else {})
    yield Segment({taker: take.pose.moved(-0.02 * take.approach)}, speed=style.approach_speed,
                  label="to end")
    yield Segment({taker: take.pose}, speed=0.5 * style.approach_speed, label="to end")
    # the taker ends up holding the object alone, by its end: firm enough not to pivot
    gripped = grip_force(world, obj, style, lever=grasp_lever(world, taker, obj, take.pose))
    yield from _take(world, style, taker, obj, opening_for(world, taker, width, gripped),
                     gripped)
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    home = horizontal(world.base_position(giver) - back.p)
    yield Segment({giver: back.moved(0.08 * UP)}, speed=style.approach_speed, label="giver up")
    yield Segment({giver: back.moved(0.08 * UP + 0.12 * home)}, speed=free_speed(style),
                  label="giver back")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    spot = (place_point(world, style, obj, support) if support is not None
            else np.array([meet.middle[0], meet.middle[1], 0.0]))
    # let go with the fingers 1 cm clear: no contact flicker that reads as a new grasp
    yield from place(world, style, taker, obj, spot, release_gap=0.01, by_lowest=True)
    yield from retreat_home(world, style, taker)


__all__ = ["END_GRASP", "LONG_ENOUGH", "plan_handover"]
