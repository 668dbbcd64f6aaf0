"""The task library: one scripted plan per base task of ``fsvla.dsl.catalog.TASKS``.

A plan is a generator of motion segments (``fsvla.experts.motion.Segment``) over the
experts' privileged :class:`~fsvla.experts.world.World`; the :class:`~fsvla.experts.style.Style`
decides how carefully it is executed. ``TASK_PLANS`` maps each base task to its plan and
the scene it needs (the roles it binds); the success predicate is the scenario's own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix
from fsvla.dsl.models import predicates_in

from . import grasps
from .motion import Pose, Segment
from .skills import (
    DOWN,
    UP,
    Plan,
    branch_for_path,
    clear_height,
    free_speed,
    grasp_lever,
    grip_force,
    held_offset,
    horizontal,
    nearest_arm,
    opening_for,
    pick,
    place,
    top_down_grasp,
    transit,
)

#: Half the length of a Panda hand along its finger axis (m), with its collision hull.
HAND_HALF_LENGTH = 0.105
#: Half the thickness of a Panda hand across its finger axis (m).
HAND_HALF_WIDTH = 0.032
#: Height of the hand's lowest point above its TCP (m), pointing down.
HAND_BOTTOM = 0.037
#: How far a drawer's handle stands proud of its front (m).
HANDLE_DEPTH = 0.02
from .style import Style
from .world import World


@dataclass(frozen=True)
class TaskPlan:
    """A base task: the roles it needs, what the scene must offer, and its plan."""

    name: str
    roles: tuple[str, ...]
    needs: str  # the scene requirements, in words
    plan: Callable[[World, Style, dict[str, str]], Plan]


# ---------------------------------------------------------------------- helpers
def required_fraction(world: World, body: str) -> float:
    """The largest ``opened(body, fraction=f)`` any requirement or the success asks for."""
    found = [0.0]
    for req in world.monitor.requirements:
        for cond in (req.first, req.then):
            found += [float(p.params.get("fraction", 0.5)) for p in predicates_in(cond)
                      if p.name == "opened" and p.args[0] == body]
    return max(found)


def _place_point(world: World, style: Style, obj: str, target: str,
                 arm: str | None = None) -> np.ndarray:
    """Where on ``target``'s top the object's bottom centre goes: the footprint's centre,
    or (careful) the footprint point farthest from the hazards; with ``arm`` (holding
    ``obj``), careful, only among the points where the hand it holds the object with
    stays comfortably inside the arm's joint limits (a shelf at the edge of the reach:
    an arm stretched onto its elbow limit sags and presses the object into the shelf),
    the carry there ending inside the arm's reach (:func:`_reaches_place`); failing that,
    among those reached from 8 cm above."""
    asset = world.asset(target)
    pose = world.body_pose(target)
    (x0, y0), (x1, y1) = asset.footprint.min_xy, asset.footprint.max_xy
    lo, hi = world.bounds(obj)
    r = 0.5 * max(hi[0] - lo[0], hi[1] - lo[1]) + 0.015
    top = world.top(target)
    candidates = [np.array([(x0 + x1) / 2, (y0 + y1) / 2])]
    if style.avoid_hazards:
        xs = np.linspace(x0 + r, x1 - r, 5) if x1 - x0 > 2 * r else [(x0 + x1) / 2]
        ys = np.linspace(y0 + r, y1 - r, 5) if y1 - y0 > 2 * r else [(y0 + y1) / 2]
        candidates += [np.array([x, y]) for x in xs for y in ys]
    obstacles = world.obstacles(exclude=(obj, target))

    def score(c: np.ndarray) -> float:
        p = pose.R[:2, :2] @ c + pose.p[:2]
        d = [float(np.linalg.norm(np.maximum(0, np.maximum(o.lo[:2] - p, p - o.hi[:2]))))
             - o.margin for o in obstacles]
        return min(min(d, default=1.0), 0.04) - 0.05 * float(np.linalg.norm(c - candidates[0]))

    best = max(candidates, key=score) if style.avoid_hazards else candidates[0]
    if style.avoid_hazards and arm is not None:
        ranked = sorted(candidates, key=score, reverse=True)

        def bottom(c: np.ndarray) -> np.ndarray:
            return np.array([*(pose.R[:2, :2] @ c + pose.p[:2]), top])

        best = next((c for c in ranked if _reaches_place(world, style, arm, obj, bottom(c))),
                    None)
        if best is None:  # none the carry comes down onto surely: one it reaches at all
            best = next((c for c in ranked if _reaches_from_above(world, arm, obj, bottom(c))),
                        ranked[0])
    xy = pose.R[:2, :2] @ best + pose.p[:2]
    return np.array([xy[0], xy[1], top])


def _set_down_pose(world: World, arm: str, obj: str, bottom: np.ndarray) -> Pose:
    """The TCP pose that sets the held ``obj`` down at ``bottom``, the hand as it is now."""
    tcp = world.current_pose(arm)
    return Pose(bottom + tcp.R @ held_offset(world, arm, obj), tcp.R)


def _reaches_from_above(world: World, arm: str, obj: str, bottom: np.ndarray) -> bool:
    """Whether the hand holding ``obj`` as it does now can come straight down from 8 cm
    above onto the pose that sets it down at ``bottom``, inside the arm's joint limits
    (:func:`branch_for_path`)."""
    goal = _set_down_pose(world, arm, obj, bottom)
    return branch_for_path(world, arm, (goal.moved(0.08 * UP), goal)) is not None


def _reaches_place(world: World, style: Style, arm: str, obj: str, bottom: np.ndarray) -> bool:
    """Whether the hand holding ``obj`` as it does now comes straight down onto the pose
    that sets it down at ``bottom`` (:func:`_reaches_from_above`), and the carry that
    brings it there, at :func:`transit`'s clear height above that pose, ends inside the
    arm's reach (:func:`_within_reach`). Far from the base, a carry over a tall hazard
    otherwise ends with the arm at full stretch, and the line down from there may
    straighten the elbow onto its limit and set the object short of its place."""
    if not _reaches_from_above(world, arm, obj, bottom):
        return False
    tcp = world.current_pose(arm)
    goal = _set_down_pose(world, arm, obj, bottom)
    above = goal.moved(0.08 * UP)
    below = float(goal.p[2] - bottom[2]) + 0.03  # how far the load hangs under the TCP
    height = max(clear_height(world, style, tcp.p, above.p, below, (obj,)), above.p[2] + 0.05)
    return _within_reach(world, arm, Pose(np.array([above.p[0], above.p[1], height]), above.R))


#: How far (m) beyond a carry's end, away from the arm's base, the arm must still reach.
REACH_SLACK = 0.05


def _within_reach(world: World, arm: str, pose: Pose) -> bool:
    """Whether ``pose`` lies REACH_SLACK inside the arm's reach: the same hand REACH_SLACK
    farther from the base is still solved comfortably. At full stretch (a Panda's elbow at
    -0.47 rad, its two offset links in line) a line that brings the hand nearer has two
    answers, the elbow bending, or straightening onto its -0.07 limit, and which one the
    driver takes depends on the last digits of its joints."""
    out = horizontal(pose.p - world.base_position(arm))
    return branch_for_path(world, arm, (Pose(pose.p + REACH_SLACK * out, pose.R),)) is not None


def _retreat_home(world: World, style: Style, arm: str) -> Plan:
    pose = world.current_pose(arm)
    yield Segment({arm: pose.moved(0.08 * UP)}, speed=free_speed(style), label="clear")


# ---------------------------------------------------------------------- single-arm tasks
def plan_pick_place(world: World, style: Style, roles: dict[str, str]) -> Plan:
    obj, target = roles["object"], roles["target"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    yield from place(world, style, arm, obj, _place_point(world, style, obj, target, arm))
    yield from _retreat_home(world, style, arm)


def plan_lift(world: World, style: Style, roles: dict[str, str], by: float = 0.15) -> Plan:
    obj = roles["object"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    pose = world.current_pose(arm)
    yield Segment({arm: pose.moved(by * UP)}, speed=style.approach_speed, settle=40, label="hold")


def plan_push(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Push ``object`` over the table to ``target``'s centre with closed fingers."""
    obj, target = roles["object"], roles["target"]
    start, goal = world.body_pose(obj).p, world.body_pose(target).p
    arm = nearest_arm(world, start)
    direction = horizontal(goal - start)
    lo, hi = world.bounds(obj)
    reach = 0.5 * float(np.abs(direction[:2]) @ (hi - lo)[:2]) + 0.02
    height = lo[2] + 0.4 * (hi[2] - lo[2])
    R = world.grasp_frame(arm, DOWN, np.cross(UP, direction))
    behind = Pose(np.array([start[0], start[1], height]) - reach * direction, R)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="close")
    yield from transit(world, style, arm, behind.moved(0.08 * UP), exclude=(obj,))
    yield Segment({arm: behind}, speed=style.approach_speed, label="down")
    travel = float(np.linalg.norm((goal - start)[:2]))
    yield Segment({arm: behind.moved(travel * direction)}, speed=style.contact_speed * 3,
                  settle=style.settle, label="push")
    yield from _retreat_home(world, style, arm)


def _part_handle(world: World, body: str):
    """The handle of a body's first part: (world centre, opening direction, travel)."""
    part, joint = world.part(body)
    link = world.link_pose(body, part.link)
    handle = world.shape(body, "handle", link=part.link)
    centre = link.R @ np.asarray(handle.pose.position) + link.p
    body_pose = world.body_pose(body)
    direction = body_pose.R @ np.asarray(joint.axis, dtype=np.float64)
    return centre, direction / np.linalg.norm(direction), joint.upper - joint.lower, handle


def push_part_closed(world: World, style: Style, body: str) -> Plan:
    """Close a sliding part by pushing its front with the closed fingers, pointing down,
    below the handle (pulling the handle back from far out is beyond a Panda's reach)."""
    centre, opening, travel, handle = _part_handle(world, body)
    part, _joint = world.part(body)
    link = world.link_pose(body, part.link)
    arm = nearest_arm(world, centre)
    R = world.grasp_frame(arm, DOWN, np.cross(UP, opening))
    height = 0.5 * (link.p[2] + centre[2] - float(handle.half_size[2]))
    # the hand is HAND_HALF_WIDTH thick about the TCP across its fingers: it comes down
    # well in front of the handle (HANDLE_DEPTH proud of the front; a hand that grazes it
    # on the way down knocks the drawer in and then hits it at full push speed), comes up
    # to the handle slowly, and pushes from rest
    standoff = HAND_HALF_WIDTH + HANDLE_DEPTH + 0.035
    start = np.array([link.p[0], link.p[1], height]) + opening * standoff
    tcp = Pose(start, R)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="fist")
    yield from transit(world, style, arm, tcp, exclude=(body,))
    link = world.link_pose(body, part.link)  # where the front is now
    gap = float(opening @ (tcp.p - link.p)) - HAND_HALF_WIDTH - HANDLE_DEPTH
    near = tcp.moved(-(gap - 0.006) * opening)
    yield Segment({arm: near}, speed=max(2 * style.contact_speed, 0.5 * style.approach_speed),
                  label="to part")
    touch = near.moved(-0.008 * opening)
    yield Segment({arm: touch}, speed=style.contact_speed, settle=style.settle,
                  label="touch part")
    push = world.open_fraction(body) * travel - 0.002  # stop at the end of travel
    goal = touch.moved(-push * opening)
    # slowly: a rigid hand on a free-sliding drawer chatters, ~60 N spikes at 6 cm/s
    yield Segment({arm: goal}, speed=2 * style.contact_speed, settle=style.settle,
                  label="push part")
    for _ in range(3):  # the wrist, thicker than the hand, may meet the front first
        left = world.open_fraction(body) * travel
        if left < 0.02 * travel:
            break
        goal = goal.moved(-(left - 0.002) * opening)
        yield Segment({arm: goal}, speed=2 * style.contact_speed, settle=style.settle,
                      label="push part")
    back = world.current_pose(arm)
    yield Segment({arm: back.moved(0.04 * opening)}, speed=free_speed(style), label="back")
    yield Segment({arm: back.moved(0.04 * opening + 0.1 * UP)}, speed=free_speed(style),
                  label="up")


def plan_move_part(world: World, style: Style, body: str, fraction: float) -> Plan:
    """Pull a sliding part's handle until it is open by ``fraction`` (closing: push)."""
    if fraction < world.open_fraction(body):
        yield from push_part_closed(world, style, body)
        return
    centre, opening, travel, handle = _part_handle(world, body)
    part, _joint = world.part(body)
    arm = nearest_arm(world, centre)
    approach = -opening
    delta = (fraction - world.open_fraction(body)) * travel
    start = centre - approach * (float(handle.half_size[0]) - 0.004)
    R = _pull_frame(world, arm, approach, start, delta * opening)
    tcp = Pose(start, R)
    yield Segment(grippers={arm: 1.0}, gripper_steps=style.gripper_steps, label="open")
    # the IK branch that can still reach the handle where the pull ends
    yield from transit(world, style, arm, tcp.moved(-0.1 * approach), exclude=(body,),
                       then=tcp.moved(delta * opening))
    yield Segment({arm: tcp}, speed=style.approach_speed, label="to handle")
    width = 2 * float(handle.half_size[2])
    yield Segment(grippers={arm: opening_for(world, arm, width, style)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="grip handle")
    yield Segment({arm: tcp.moved(delta * opening)}, speed=max(style.contact_speed * 4, 0.06),
                  settle=style.settle, label="slide part")
    yield Segment(grippers={arm: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="let go")
    # slide off the end of the handle (backing away may be out of reach, and rising
    # would lift the handle), then back off and up
    part_link = world.link_pose(body, part.link)
    half = np.asarray(handle.half_size, dtype=np.float64)
    along = part_link.R[:, int(np.argmax(half[:2]))]
    if along @ (world.base_position(arm) - centre) < 0:
        along = -along
    off = world.current_pose(arm).moved((float(half.max()) + 0.035) * along)
    yield Segment({arm: off}, speed=free_speed(style), label="slide off")
    yield Segment({arm: off.moved(-0.03 * approach + 0.1 * UP)}, speed=free_speed(style),
                  label="up")


def _pull_frame(world: World, arm: str, approach: np.ndarray, start: np.ndarray,
                pull: np.ndarray) -> np.ndarray:
    """The upright hand (fingers closing vertically) on a handle at ``start``, of the two
    that differ by a half turn about the approach, from which the arm can follow the pull
    by ``pull`` (m, world) on one IK branch; the one nearer the hand's present turn first.
    Low and close to a Panda's base, one of them has no comfortable answer at all."""
    from .motion import ArmDriver

    R0 = world.grasp_frame(arm, approach, UP)
    loaded = world.robot.arm(arm)
    for R in (R0, axis_angle_matrix(approach, np.pi) @ R0):
        driver = ArmDriver(arm, world.kinematics(arm), world.current_pose(arm), loaded.qpos(), 1.0)
        tcp = Pose(start, R)
        if driver.branch_that_tracks(tcp, tcp.moved(pull)) is not None:
            return R
    return R0


def plan_open(world: World, style: Style, roles: dict[str, str]) -> Plan:
    yield from plan_move_part(world, style, roles["object"], max(0.8, required_fraction(
        world, roles["object"]) + 0.15))


def plan_close(world: World, style: Style, roles: dict[str, str]) -> Plan:
    yield from plan_move_part(world, style, roles["object"], 0.0)


def _open_front_box(world: World, body: str, fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """The xy box the part's front sweeps when it opens to ``fraction`` (across: the
    body's width), grown by a hand's length."""
    centre, opening, travel, _ = _part_handle(world, body)
    lo, hi = world.bounds(body)
    reach = centre + opening * (fraction - world.open_fraction(body)) * travel
    along = np.abs(opening[:2]) >= 0.5  # the axis the part slides along
    box_lo = np.where(along, np.minimum(centre[:2], reach[:2]), lo[:2])
    box_hi = np.where(along, np.maximum(centre[:2], reach[:2]), hi[:2])
    return box_lo - HAND_HALF_LENGTH - 0.03, box_hi + HAND_HALF_LENGTH + 0.03


def _blocked_by_open_part(world: World, body: str, obj: str, fraction: float) -> bool:
    """Whether grasping ``obj`` would put the hand where the opened part will be."""
    lo, hi = _open_front_box(world, body, fraction)
    p = world.body_pose(obj).p[:2]
    return bool(np.all(p >= lo) and np.all(p <= hi))


def _stage(world: World, style: Style, obj: str, body: str) -> Plan:
    """Move ``obj`` out of the way of ``body``'s part before it opens (careful only):
    sideways, beside the body, turned so that the hand that takes it again lies along the
    part's front rather than across it."""
    pose = world.body_pose(obj)
    _, opening, _, _ = _part_handle(world, body)
    lo, hi = world.bounds(body)
    side = np.cross(UP, opening)
    centre = 0.5 * (lo + hi)
    sign = 1.0 if (pose.p - centre) @ side >= 0 else -1.0
    half = 0.5 * float(np.abs(side[:2]) @ (hi - lo)[:2])
    spot = pose.p + side * (sign * (half + 0.09) - (pose.p - centre) @ side)
    arm = nearest_arm(world, pose.p)
    yield from pick(world, style, arm, obj, grasps.choose(world, style, arm, obj))
    R = world.grasp_frame(arm, DOWN, side)
    yield from place(world, style, arm, obj, np.array([spot[0], spot[1], pose.p[2]]), rotation=R)


def plan_insert(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Open the container's part (careful: past every fraction a requirement asks for;
    careless: just far enough), put the object in, let go, close the part."""
    obj, target = roles["object"], roles["target"]
    asset = world.asset(target)
    if not getattr(asset, "parts", None):
        yield from plan_pick_place(world, style, roles)
        return
    if world.part(target)[1].type == "revolute" and world.part(target)[0].name == "lid":
        yield from _insert_under_lid(world, style, obj, target)
        return
    need = required_fraction(world, target)
    # careful: past the largest fraction a requirement asks for, but short of the end of
    # travel (a Panda pulling the handle that far folds onto its own base)
    fraction = min(0.85, need + 0.07) if style.honour_preconditions else max(0.3, need - 0.2)
    if style.avoid_hazards and _blocked_by_open_part(world, target, obj, fraction):
        yield from _stage(world, style, obj, target)
    yield from plan_move_part(world, style, target, fraction)
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    _, opening, _, _ = _part_handle(world, target)
    part, _joint = world.part(target)
    link = world.link_pose(target, part.link)
    shapes = next(lk for lk in asset.links if lk.name == part.link).collision
    floor = next(s for s in shapes if s.name == "floor")
    front = next(s for s in shapes if s.name == "front")
    floor_top = link.p[2] + floor.pose.position[2] + floor.half_size[2]
    # Lay the object across the drawer, fingers closing along the drawer's travel. The
    # hand is longer along its finger axis (2 × HAND_HALF_LENGTH) than a drawer's travel,
    # so it lets go above the cabinet's top and the object drops into the open mouth.
    R = world.grasp_frame(arm, DOWN, opening)
    inner = link.p + link.R @ np.array([front.pose.position[0] + front.half_size[0], 0.0, 0.0])
    lo, hi = world.bounds(target)
    mouth = float(opening @ inner) - max(float(opening @ lo), float(opening @ hi))  # open length
    tcp_x = inner - opening * 0.5 * mouth
    offset = R @ held_offset(world, arm, obj)
    clear = world.bounds(target)[1][2] + (HAND_BOTTOM + 0.015) - offset[2]
    bottom = np.array([tcp_x[0] - offset[0], link.p[1], max(floor_top + 0.003, clear)])
    if abs(opening[0]) < abs(opening[1]):  # a drawer that slides along y
        bottom = np.array([link.p[0], tcp_x[1] - offset[1], bottom[2]])
    yield from place(world, style, arm, obj, bottom, rotation=R, retreat=0.08)
    yield from plan_move_part(world, style, target, 0.0)


#: Lid angle (rad) the careful expert lifts a lid to: past vertical, so that it falls
#: open onto its stop instead of shut when the hand leaves it.
LID_PAST_VERTICAL = np.deg2rad(95.0)


def lift_lid(world: World, style: Style, body: str, angle: float) -> Plan:
    """Lift a hinged lid by its knob from below: the closed fingers come horizontally
    under the knob's overhang (the hand upright, the fingers closing across the lid: a
    Panda cannot point a flat hand forward that low), then follow the knob's arc about the
    hinge, the hand turning with the lid, up to ``angle`` (rad); the hand then backs away
    (a lid left short of vertical falls shut). The hand is 21 cm tall that way: the knob
    must stand 11 cm or more above the table."""
    part, joint = world.part(body)
    link = world.link_pose(body, part.link)
    knob = world.shape(body, "knob", link=part.link)
    axis = world.body_pose(body).R @ np.asarray(joint.axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    span = joint.upper - joint.lower
    now = world.open_fraction(body) * span
    closed = axis_angle_matrix(axis, -now) @ link.R  # the lid frame when shut
    c, half = np.asarray(knob.pose.position), np.asarray(knob.half_size)
    # under the knob's front edge (the fingertips reach ~1 cm past the TCP), the closed
    # fingers' half thickness and a little more below it
    local = np.array([c[0] - half[0] - 0.002, c[1], c[2] - half[2] - 0.016])
    toward_hinge = -np.sign(c[0]) * np.array([1.0, 0.0, 0.0])  # the knob is at -x

    def pose_at(theta: float, near: np.ndarray | None = None) -> Pose:
        R = axis_angle_matrix(axis, theta) @ closed
        approach = R @ toward_hinge
        return Pose(link.p + R @ local, world.grasp_frame(arm, approach, R[:, 2], near=near))

    arm = nearest_arm(world, link.p + closed @ local)
    start = pose_at(now)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="fist")
    back_off = -0.06 * (start.R @ world.approach_axis(arm))
    arc: tuple[Pose, ...] = ()
    if style.avoid_hazards:
        # on an IK branch that follows the whole arc (others drive a wrist joint onto its
        # limit half way up: the hand leaves the arc and jams against the lid), the hand
        # turned either way about its approach (a fist is symmetric), each pose of the
        # arc the turn nearest the one before
        flipped = start.R @ axis_angle_matrix(world.approach_axis(arm), np.pi)
        options = [_chained(pose_at, now, angle, R0) for R0 in (start.R, flipped)]
        arc = next((a for a in options if branch_for_path(
            world, arm, (a[0].moved(back_off), *a)) is not None), options[0])
        start = arc[0]
    yield from transit(world, style, arm, start.moved(back_off), exclude=(body,), then=start,
                       follow=arc)
    yield Segment({arm: start}, speed=style.approach_speed * 0.5, label="under knob")
    speed = max(style.contact_speed * 4, 0.06) if style.avoid_hazards else style.approach_speed
    if style.avoid_hazards:
        # one smooth arc, one control step per segment (each segment eases in and out: a
        # chain of 8° chords stops and starts the hand under the lid, which rises off the
        # fingers and lands back on them, 30-60 N spikes)
        last = [start.R]

        def chained_at(theta: float) -> Pose:
            pose = pose_at(theta, last[0])
            last[0] = pose.R
            return pose

        yield from _smooth_arc(world, style, arm, chained_at, now, angle, speed, "lift lid")
    else:
        steps = max(2, int(np.ceil((angle - now) / np.deg2rad(8.0))))
        for theta in np.linspace(now, angle, steps + 1)[1:]:
            yield Segment({arm: pose_at(float(theta))}, speed=speed, label="lift lid")
    yield Segment({}, settle=style.settle, label="hold lid")
    end = world.current_pose(arm)
    back = -(end.R @ world.approach_axis(arm))
    yield Segment({arm: end.moved(0.06 * back)}, speed=free_speed(style), label="leave lid")
    yield Segment({arm: end.moved(0.06 * back + 0.08 * UP)}, speed=free_speed(style),
                  label="up", settle=20)


def _chained(pose_at: Callable[..., Pose], start: float, end: float, near: np.ndarray,
             n: int = 12) -> tuple[Pose, ...]:
    """``pose_at(theta, near)`` at ``n`` angles from ``start`` to ``end``, each turned the
    way nearest the pose before (the first: nearest ``near``)."""
    poses = []
    for theta in np.linspace(start, end, n):
        poses.append(pose_at(float(theta), near))
        near = poses[-1].R
    return tuple(poses)


def _smooth_arc(world: World, style: Style, arm: str, pose_at: Callable[[float], Pose],
                start: float, end: float, speed: float, label: str) -> Plan:
    """Follow ``pose_at(theta)`` from ``start`` to ``end`` without stopping: one segment per
    control step, the parameter eased in and out over the whole arc, the peak TCP speed
    ``speed`` and the peak turn rate within the style's angular speed."""
    thetas = np.linspace(start, end, 50)
    points = np.array([pose_at(float(t)).p for t in thetas])
    length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
    duration = 1.5 * max(length / speed, abs(end - start) / (0.8 * style.angular_speed))
    n = max(2, int(np.ceil(duration / world.dt)))
    for i in range(1, n + 1):
        s = i / n
        theta = start + (end - start) * s * s * (3.0 - 2.0 * s)
        yield Segment({arm: pose_at(float(theta))}, speed=2.0 * speed, label=label)


def _insert_under_lid(world: World, style: Style, obj: str, target: str) -> Plan:
    """A lidded container: lift the lid (careful: past vertical, where it stays open;
    careless: only as far as asked less 0.2, and it falls shut), then pick the object and
    set it on the container's floor, the hand's long axis along the container's longer
    side (a Panda hand is 21 cm long)."""
    _part, joint = world.part(target)
    span = joint.upper - joint.lower
    need = required_fraction(world, target)
    if style.honour_preconditions:
        angle = max(LID_PAST_VERTICAL, (need + 0.07) * span)
    else:
        angle = max(0.3, need - 0.2) * span
    yield from lift_lid(world, style, target, min(angle, 0.95 * span))
    arm = nearest_arm(world, world.body_pose(obj).p)
    yield from pick(world, style, arm, obj, grasps.choose(world, style, arm, obj))
    body = world.asset(target).links[0].name
    floor = world.shape(target, "bottom", link=body)
    root = world.body_pose(target)
    centre = root.R @ np.asarray(floor.pose.position) + root.p
    bottom = np.array([centre[0], centre[1], centre[2] + float(floor.half_size[2])])
    lo, hi = world.bounds(target)
    longer = root.R[:, 0] if hi[0] - lo[0] >= hi[1] - lo[1] else root.R[:, 1]
    R = world.grasp_frame(arm, DOWN, longer)
    if not style.honour_preconditions:  # careless: onto the top, let go from above
        bottom[2] = float(hi[2])
    yield from place(world, style, arm, obj, bottom, rotation=R, retreat=0.1)
    yield from _retreat_home(world, style, arm)


def plan_pour(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Lift the object, hold it over the target, tilt it by 100°, tilt it back, put it down."""
    obj, target = roles["object"], roles["target"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    start = world.body_pose(obj).p.copy()
    yield from pick(world, style, arm, obj, grasp)
    over = world.body_pose(target).p + np.array([0.0, 0.0, world.bounds(target)[1][2] + 0.12])
    tcp = world.current_pose(arm)
    yield from transit(world, style, arm, Pose(over, tcp.R), below=0.15, exclude=(obj, target))
    axis = horizontal(world.base_position(arm) - over)
    tilt = axis_angle_matrix(axis, np.deg2rad(100))
    yield Segment({arm: Pose(over, tilt @ tcp.R)}, speed=style.approach_speed, settle=20,
                  label="pour")
    yield Segment({arm: Pose(over, tcp.R)}, speed=style.approach_speed, label="unpour")
    yield from place(world, style, arm, obj, start)


def plan_press(world: World, style: Style, roles: dict[str, str]) -> Plan:
    obj = roles["object"]
    lo, hi = world.bounds(obj)
    top = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.005])
    arm = nearest_arm(world, top)
    R = world.grasp_frame(arm, DOWN, np.array([0.0, 1.0, 0.0]))
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="close")
    yield from transit(world, style, arm, Pose(top + 0.08 * UP, R), exclude=(obj,))
    yield Segment({arm: Pose(top, R)}, speed=style.approach_speed, label="touch")
    yield Segment({arm: Pose(top - np.array([0.0, 0.0, 0.01]), R)}, speed=style.contact_speed,
                  settle=20, label="press")
    yield from _retreat_home(world, style, arm)


# ---------------------------------------------------------------------- bimanual tasks
def plan_bimanual_lift(world: World, style: Style, roles: dict[str, str], by: float = 0.15) -> Plan:
    """Each arm takes the side handle nearer to it. Careful: both close, then lift in step
    (``require grasped(pot, left) and grasped(pot, right) before lifted(pot)``). Careless:
    each arm lifts as soon as it holds (:func:`_lift_as_each_holds`)."""
    obj = roles["object"]
    handles = {arm: _nearer_handle(world, arm, obj) for arm in world.arm_names}
    yield Segment(grippers={a: 1.0 for a in handles}, gripper_steps=style.gripper_steps,
                  label="open")
    if not style.honour_preconditions:
        yield from _lift_as_each_holds(world, style, obj, handles, by)
        return
    chosen = {arm: grasps.reach_handle(world, arm, obj, h, lift=by) for arm, h in handles.items()}
    for arm, g in chosen.items():  # one arm after the other to the pre-grasp, on the
        # IK branch from which the lines down and on to the handle are followed
        yield from transit(world, style, arm, g.pose.moved(-0.1 * g.approach), exclude=(obj,),
                           then=g.pose, follow=(g.pose,))
    yield Segment({a: g.pose for a, g in chosen.items()}, speed=style.approach_speed,
                  label="reach handles")
    held = grip_force(world, obj, style, weight_factor=1.5)
    yield Segment(grippers={a: opening_for(world, a, g.width, held) for a, g in chosen.items()},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="close")
    speed = style.approach_speed * (0.6 if style.avoid_hazards else 1.0)
    yield Segment({a: g.pose.moved(by * UP) for a, g in chosen.items()}, speed=speed,
                  settle=60, label="lift")


def _nearer_handle(world: World, arm: str, obj: str) -> str:
    """The name of ``obj``'s side handle nearer to the base of ``arm``."""
    handles = [s.name for s in world.asset(obj).collision if s.name.startswith("handle")]
    return min(handles, key=lambda h: float(np.linalg.norm(
        world.to_world(obj, world.shape(obj, h).pose.position) - world.base_position(arm))))


def _lift_as_each_holds(world: World, style: Style, obj: str, handles: dict[str, str],
                        by: float) -> Plan:
    """Careless: each arm in turn comes to its handle, closes and lifts at once, without
    waiting for the other hand (it skips the task's ``require grasped(.., left) and
    grasped(.., right) before lifted(..)``). A pot lifted by one handle tips over in the
    fingers; the next arm goes for its handle where the tipped pot now holds it (up beside
    the first hand), closes and lifts: the pot is wrenched between the two hands."""
    held = grip_force(world, obj, style, weight_factor=1.5)
    for arm, handle in handles.items():
        g = grasps.reach_handle(world, arm, obj, handle, lift=by)  # the handle as it is now
        yield from transit(world, style, arm, g.pose.moved(-0.1 * g.approach), exclude=(obj,),
                           then=g.pose, follow=(g.pose,))
        yield Segment({arm: g.pose}, speed=style.approach_speed, label="reach handle")
        yield Segment(grippers={arm: opening_for(world, arm, g.width, held)},
                      gripper_steps=style.gripper_steps, settle=style.settle, label="close")
        yield Segment({arm: g.pose.moved(by * UP)}, speed=style.approach_speed, settle=20,
                      label="lift")


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
    mid = 0.5 * (world.base_position(giver) + world.base_position(taker))
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    centre = np.array([mid[0], mid[1], height])
    tcp = world.current_pose(giver)
    offset = tcp.p - 0.5 * (world.bounds(obj)[0] + world.bounds(obj)[1])
    giver_goal = Pose(centre + np.array([0.0, 0.0, max(offset[2], 0.3 * size[2] / 2 + 0.008)]),
                      tcp.R)
    yield from transit(world, style, giver, giver_goal, below=0.05, exclude=(obj,))
    towards = horizontal(centre - world.base_position(taker))
    closing = tcp.R @ world.finger_axis(giver)
    R = world.grasp_frame(taker, towards, closing)
    take = Pose(centre - np.array([0.0, 0.0, 0.3 * size[2]]) - towards * 0.004, R)
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    yield from transit(world, style, taker, take.moved(-0.12 * towards), below=0.05, exclude=(obj,))
    yield Segment({taker: take}, speed=style.approach_speed, label="to block")
    held = grip_force(world, obj, style)
    width = float(abs(closing @ size))
    yield Segment(grippers={taker: opening_for(world, taker, width, held)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="take")
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    yield Segment({giver: back.moved(0.1 * UP)}, speed=style.approach_speed, label="giver up")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    if support is not None:
        spot = _place_point(world, style, obj, support)
    else:
        spot = np.array([centre[0], centre[1], 0.0])
    yield from place(world, style, taker, obj, spot)
    yield from _retreat_home(world, style, taker)


#: An object at least this long (m) is handed over by its two ends, both hands from
#: above (two Panda hands side by side need 2 × HAND_HALF_WIDTH and a margin).
LONG_ENOUGH = 0.15
#: How far from an end (m) each hand holds a long object.
END_GRASP = 0.025


def _handover_by_the_ends(world: World, style: Style, obj: str, giver: str, taker: str) -> Plan:
    """A long object: the giver takes the end nearer to it from above, brings the object
    over the middle (its long axis from arm to arm), the taker takes the other end from
    above, the giver lets go and backs off, the taker puts it on the support. A Panda can
    hold out a top-down hand there; a hand pointing sideways at the object it cannot."""
    shape = world.asset(obj).collision[0]
    half = np.asarray(shape.half_size, dtype=np.float64)
    pose = world.body_pose(obj)
    axis = int(np.argmax(half[:2]))
    along, across = pose.R[:, axis], pose.R[:, 1 - axis]
    centre = world.to_world(obj, shape.pose.position)
    reach = float(half[axis]) - END_GRASP
    side = 1.0 if along @ (world.base_position(giver) - centre) >= 0 else -1.0
    lift = np.array([0.0, 0.0, 0.3 * half[2]])
    width = 2 * float(half[1 - axis])
    grasp = top_down_grasp(world, giver, centre + side * reach * along + lift, across, width)
    yield from pick(world, style, giver, obj, grasp)
    mid = 0.5 * (world.base_position(giver) + world.base_position(taker))
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    held = world.current_pose(giver)
    now = world.to_world(obj, shape.pose.position)
    goal = Pose(np.array([mid[0], mid[1], height]) + (held.p - now), held.R)
    yield from transit(world, style, giver, goal, below=0.05, exclude=(obj,))
    now = world.to_world(obj, shape.pose.position)
    along = world.body_pose(obj).R[:, axis]
    across = world.body_pose(obj).R[:, 1 - axis]
    side = 1.0 if along @ (world.base_position(taker) - now) >= 0 else -1.0
    take = top_down_grasp(world, taker, now + side * reach * along + lift, across, width)
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    yield from transit(world, style, taker, take.pose.moved(0.1 * UP), exclude=(obj,),
                       then=take.pose)
    yield Segment({taker: take.pose.moved(0.02 * UP)}, speed=style.approach_speed, label="to end")
    yield Segment({taker: take.pose}, speed=0.5 * style.approach_speed, label="to end")
    # the taker ends up holding the object alone, by its end: firm enough not to pivot
    gripped = grip_force(world, obj, style, lever=grasp_lever(world, taker, obj, take.pose))
    yield Segment(grippers={taker: opening_for(world, taker, width, gripped)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="take")
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    home = horizontal(world.base_position(giver) - back.p)
    yield Segment({giver: back.moved(0.08 * UP)}, speed=style.approach_speed, label="giver up")
    yield Segment({giver: back.moved(0.08 * UP + 0.12 * home)}, speed=free_speed(style),
                  label="giver back")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    spot = (_place_point(world, style, obj, support) if support is not None
            else np.array([mid[0], mid[1], 0.0]))
    # let go with the fingers 1 cm clear: no contact flicker that reads as a new grasp
    yield from place(world, style, taker, obj, spot, release_gap=0.01)
    yield from _retreat_home(world, style, taker)


TASK_PLANS: dict[str, TaskPlan] = {t.name: t for t in (
    TaskPlan("pick_place", ("object", "target"), "a graspable object; a target with a top",
             plan_pick_place),
    TaskPlan("stack", ("object", "target"), "a graspable object; a target with a flat top",
             plan_pick_place),
    TaskPlan("lift", ("object",), "a graspable object", plan_lift),
    TaskPlan("push", ("object", "target"), "an object that slides; a target location",
             plan_push),
    TaskPlan("open", ("object",), "an articulated body whose part has a `handle`", plan_open),
    TaskPlan("close", ("object",), "an articulated body whose part has a `handle`", plan_close),
    TaskPlan("insert", ("object", "target"),
             "a graspable object; a container (a drawer_cabinet: opened first)", plan_insert),
    TaskPlan("pour", ("object", "target"), "a graspable container; a target below it",
             plan_pour),
    TaskPlan("press", ("object",), "an object to press from above", plan_press),
    TaskPlan("bimanual_lift", ("object",), "two arms; an object with `handle_*` shapes",
             plan_bimanual_lift),
    TaskPlan("handover", ("object",), "two arms; a graspable object; optionally a support",
             plan_handover),
)}

__all__ = ["TASK_PLANS", "TaskPlan", "required_fraction"]
