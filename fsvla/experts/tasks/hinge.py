"""Swinging a hinged part (a box's lid, a microwave's door) open or shut by holding it
where a hand can: the hand's path is the held point's arc about the joint's axis (from
the joint's origin and axis in the world), followed in one smooth sweep.

- A **lid** is pinched by its knob's two ends, the fingers closing along the hinge axis,
  the hand pointing down: the knob turns between the pads (their grip about the closing
  axis is weak), so the hand keeps its turn while the knob follows its arc. The same
  grip lifts a shut lid (past upright: it then falls open onto its stop) and brings one
  standing open back down (past upright it must be pulled, then lowered: let go above its
  seat, it slams shut). It needs no room below the knob: a low box's lid too. Where the
  arm holds no one turn of the hand along the whole arc (a small arm far out, a Panda
  pulling a lid from past upright to shut), the hand turns on the knob as it goes: the
  pads hold the knob's ends, about which it turns freely.
- A **door** on a vertical hinge is pinched by its handle across the handle's width, the
  hand pitched down toward the door (a flat hand pointing forward is out of a Panda's
  comfortable reach low down), and the hand turns with the door about the hinge.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix

from ..motion import Pose, Segment
from ..skills import (
    DOWN,
    FIXED_JAW_CLEARANCE,
    SLOW_CLOSE,
    SQUEEZE_STEPS,
    UP,
    Plan,
    attained,
    branch_for_path,
    first_clear,
    free_speed,
    grip_guard,
    hand_clearance,
    nearest_arm,
    opening_for,
    reaches,
    transit,
)
from ..style import Style
from ..world import World
from .lid import smooth_arc

#: How far (m) a pinch keeps its fingers' inner edge out from the face the knob or handle
#: stands on (the fingers are thicker than a knob stands proud).
FACE_CLEARANCE = 0.004
#: Pitches (deg) of the hand on a door's handle, from pointing down; the careful expert
#: takes the first whose whole arc one IK branch follows.
DOOR_PITCHES = (45.0, 60.0, 30.0, 75.0, 15.0, 0.0)
#: Turns (deg) of the hand on a lid's knob, about the hinge, from the one that points it
#: down half way along the arc; the careful expert takes the first one IK follows.
LID_TURNS = (0.0, -15.0, 15.0, -30.0, 30.0, -45.0, 45.0)
#: How far (m) the fingers reach back from the TCP toward the palm, for the clearance of
#: their inner corners from the lid's edge (a Panda's: 4.5 cm).
PALM_REACH = 0.045
#: How many poses along a knob's arc are checked for one IK branch that follows them.
ARC_POSES = 12
#: The least force (N) a careful pinch must feel from the part to have it in hand.
FELT = 0.5
#: How much wider (m) than the held knob the gripper must open.
PINCH_SPARE = 0.012


@dataclass(frozen=True)
class Hinge:
    """A revolute part now: a point on its axis, the axis (world, unit; opening turns the
    part positively about it), the part's frame when shut, the angle now and its range."""

    point: NDArray[np.float64]
    axis: NDArray[np.float64]
    closed: NDArray[np.float64]
    now: float
    span: float

    def turn(self, theta: float) -> NDArray[np.float64]:
        """The rotation taking the part from where it is now to the angle ``theta``."""
        return axis_angle_matrix(self.axis, theta - self.now)

    def at(self, local: NDArray[np.float64], theta: float) -> NDArray[np.float64]:
        """Where the point ``local`` (the part's link frame) is at the angle ``theta``."""
        return self.point + axis_angle_matrix(self.axis, theta) @ self.closed @ local


def hinge(world: World, body: str) -> Hinge:
    part, joint = world.part(body)
    link = world.link_pose(body, part.link)
    axis = world.body_pose(body).R @ np.asarray(joint.axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    span = float(joint.upper - joint.lower)
    now = world.open_fraction(body) * span
    # the child link's frame is the joint's frame (URDF): its origin lies on the axis
    return Hinge(link.p, axis, axis_angle_matrix(axis, -now) @ link.R, now, span)


def has_shape(world: World, body: str, link: str, shape: str) -> bool:
    return any(lk.name == link and any(s.name == shape for s in lk.collision)
               for lk in world.asset(body).links)


def knob_pinch_fits(world: World, body: str) -> bool:
    """Whether a lid's knob is narrow enough along the hinge for the nearest arm's gripper
    to pinch it by its ends."""
    part, _joint = world.part(body)
    if not has_shape(world, body, part.link, "knob"):
        return False
    knob = world.shape(body, "knob", link=part.link)
    h = hinge(world, body)
    width = _extent_along(knob, h.closed.T @ h.axis)
    arm = nearest_arm(world, h.at(np.asarray(knob.pose.position, dtype=np.float64), h.now))
    return width + PINCH_SPARE <= world.max_width(arm)


def _extent_along(shape, direction: NDArray[np.float64]) -> float:
    """A box shape's full extent (m) along ``direction`` (its link's frame)."""
    return float(2.0 * np.abs(np.asarray(shape.half_size)) @ np.abs(direction))


@dataclass(frozen=True)
class Knob:
    """A lid's knob, in the lid's link frame: its box shape and centre, and the lid's
    axes: along the hinge, the lid's thin axis (up when shut), and out from the hinge
    toward the knob (which stands proud of the lid's far edge)."""

    shape: object
    centre: NDArray[np.float64]
    along: NDArray[np.float64]
    normal: NDArray[np.float64]
    outward: NDArray[np.float64]

    def extent(self, direction: NDArray[np.float64]) -> float:
        """The knob's full extent (m) along ``direction`` (the lid's frame)."""
        return _extent_along(self.shape, direction)


def knob_of(world: World, body: str, h: Hinge) -> Knob:
    """``body``'s lid knob and the lid's axes (:class:`Knob`), its hinge ``h``."""
    part, _joint = world.part(body)
    knob = world.shape(body, "knob", link=part.link)
    panel = world.shape(body, "panel", link=part.link)
    along = h.closed.T @ h.axis
    normal_axis = int(np.argmin(np.abs(np.asarray(panel.half_size))))
    normal = np.eye(3)[normal_axis]
    if h.closed[:, normal_axis] @ UP < 0:
        normal = -normal
    c = np.asarray(knob.pose.position, dtype=np.float64)
    outward = c - normal * (c @ normal) - along * (c @ along)
    outward /= max(np.linalg.norm(outward), 1e-9)
    return Knob(knob, c, along, normal, outward)


@dataclass(frozen=True)
class LidGrip:
    """How a hand holds a lid's knob along its arc: the arm, the knob's width between the
    fingers, the TCP pose beyond the knob it comes in from, the TCP pose at each lid angle,
    and that pose at a dozen angles of the arc."""

    arm: str
    width: float
    back: Pose
    pose_at: Callable[[float], Pose]
    arc: tuple[Pose, ...]


def _lid_grip(world: World, style: Style, body: str, start: float, angle: float,
              turning: bool = False) -> LidGrip | None:
    """How the hand holds the knob to carry the lid from ``start`` to ``angle`` (rad).
    Careful: the first fixed turn on the lid whose whole arc one IK branch follows; with
    ``turning``, instead a turn that changes along the arc (:func:`_turning_grip`); None
    if none is found. Careless: the first fixed turn."""
    h = hinge(world, body)
    now = start
    knob = knob_of(world, body, h)
    c, normal, outward = knob.centre, knob.normal, knob.outward
    width = knob.extent(knob.along)
    root = c - outward * 0.5 * knob.extent(outward)  # the lid's edge
    arm = nearest_arm(world, h.at(c, now))
    tip, thick = world.finger_box(arm)
    centre = world.grip_centre(arm, width + FIXED_JAW_CLEARANCE)

    few_joints = len(world.arm_joints(arm)) < 6

    def held(theta: float, R: NDArray[np.float64], out: NDArray[np.float64]) -> Pose:
        """The TCP holding the knob at ``theta`` with the hand's turn ``R`` on the shut
        lid, ``out`` the point held (lid frame), turned the degree or two an arm of five
        joints needs to hold it (the pinch of the knob's ends does not mind)."""
        return attained(world, arm, lid_pose(h, R, out, centre, theta))

    def turn(psi: float, flip: bool) -> NDArray[np.float64]:
        """The hand's turn on the shut lid (world) whose palm lies ``psi`` (rad) from the
        lid's normal toward outward."""
        palm = np.cos(psi) * normal + np.sin(psi) * outward  # lid frame, TCP → palm
        R = world.grasp_frame(arm, h.closed @ -palm, h.axis,
                              near=world.grasp_frame(arm, DOWN, h.axis))
        return R @ axis_angle_matrix(world.approach_axis(arm), np.pi) if flip else R

    def inner(psi: float) -> float:
        """How far out from the lid's edge the TCP holds the knob at the turn ``psi``, for
        the fingers' inner corners to stay clear of the edge."""
        across = np.cos(psi) * outward - np.sin(psi) * normal
        reach = max(tip * np.sin(psi) + thick * abs(np.cos(psi)),
                    -PALM_REACH * np.sin(psi) + thick * abs(np.cos(psi)))
        return max(reach, thick * abs(across @ outward)) + FACE_CLEARANCE

    def upright(psi: float, theta: float) -> bool:
        """Whether the palm is at or above the knob's level at the turn ``psi`` and the lid
        angle ``theta`` (below it, the hand would come up through the box)."""
        palm = np.cos(psi) * normal + np.sin(psi) * outward
        return float(axis_angle_matrix(h.axis, theta) @ h.closed @ palm @ UP) >= -1e-9

    def fixed(R: NDArray[np.float64], local: NDArray[np.float64]) -> Callable[[float], Pose]:
        return lambda t: held(t, R, local)

    # the hand comes to the knob from beyond its tip, along the lid: the fingers slide
    # down past the knob's ends, with nothing of the lid in their way
    beyond = 0.06 * (axis_angle_matrix(h.axis, now) @ h.closed @ outward)

    def approach(pose_at: Callable[[float], Pose],
                 ends: tuple[Pose, Pose] | None = None) -> tuple[Pose, tuple[Pose, ...]]:
        """The pose beyond the knob the hand comes in from, and the arc: ARC_POSES poses
        from ``now`` to ``angle`` (``ends``: its first and last, where already made)."""
        first, last = ends if ends is not None else (pose_at(now), pose_at(angle))
        inside = tuple(pose_at(float(t)) for t in np.linspace(now, angle, ARC_POSES)[1:-1])
        return attained(world, arm, first.moved(beyond)), (first, *inside, last)

    followed: dict[Callable[[float], Pose], tuple[Pose, tuple[Pose, ...]]] = {}

    def follows(pose_at: Callable[[float], Pose]) -> bool:
        # for an arm of five joints the ends first, each on its own: most grips miss one,
        # and each pose of the arc costs it a search (:func:`held`)
        ends = (pose_at(now), pose_at(angle))
        if few_joints and not all(reaches(world, arm, end) for end in ends):
            return False
        back, arc = approach(pose_at, ends)
        if branch_for_path(world, arm, (back, *arc)) is None:
            return False
        followed[pose_at] = (back, arc)  # the grip made of it need not search them again
        return True

    mid = 0.5 * (now + angle)
    psis = [float(np.clip(mid + np.deg2rad(d), -0.3, np.pi / 2)) for d in LID_TURNS]
    options = [fixed(turn(p, f), root + outward * inner(p)) for p in psis for f in (False, True)]
    pose_at: Callable[[float], Pose] | None = options[0]
    if style.avoid_hazards:
        def clearance(option: Callable[[float], Pose]) -> float:
            back, arc = followed[option]
            return hand_clearance(world, arm, (back, *arc), (body,))

        # the first fixed turn that keeps the hand clear of the keep-outs (a hand pointing
        # at the knob across the box reaches back toward what stands behind it)
        pose_at = None if turning else first_clear(options, follows, clearance)
        if turning:
            pose_at = _turning_grip(world, arm, now, angle, turn, inner, upright, follows,
                                    lambda R, out, t: held(t, R, root + outward * out))
        if pose_at is None:
            return None
    back, arc = followed[pose_at] if pose_at in followed else approach(pose_at)
    return LidGrip(arm, width, back, pose_at, arc)


#: The hand's turns on a lid (deg, from the lid's normal toward the knob's side) a turning
#: grip is drawn from, and the lid angles at which each is first checked.
TURNING_PSIS = tuple(range(-30, 181, 15))
TURNING_CHECKS = 7
#: How many turning grips whose sampled poses IK reaches are checked along the whole arc.
TURNING_TRIES = 6


def _turning_grip(world: World, arm: str, now: float, angle: float,
                  turn: Callable[[float, bool], NDArray[np.float64]],
                  inner: Callable[[float], float],
                  upright: Callable[[float, float], bool],
                  follows: Callable[[Callable[[float], Pose]], bool],
                  pose: Callable[[NDArray[np.float64], float, float], Pose],
                  ) -> Callable[[float], Pose] | None:
    """A grip whose turn on the lid changes evenly along the arc, from ``psi_a`` at
    ``now`` to ``psi_b`` at ``angle``: where no fixed turn is reached along the whole arc
    (a small arm holds its hand at few turns in the world, and a long arc turns the lid
    through all of them). The fingers pinch the knob's ends, so the knob turns between the
    pads about the hinge's direction as the hand turns. The TCP holds the knob as far out
    as the largest turn's fingers need. The hand never points up (its palm never lower than
    the knob, where the box is). The least turning in the fingers first; None if none of
    the TURNING_TRIES best is followed by one IK branch. ``pose(R, out, theta)``: the TCP
    with the hand's turn ``R`` on the shut lid, holding the knob ``out`` (m) beyond the
    lid's edge, the lid at ``theta``."""
    psis = np.deg2rad(TURNING_PSIS)
    thetas = np.linspace(now, angle, TURNING_CHECKS)
    reached: dict[tuple[int, bool, int], bool] = {}

    def at(psi_a: float, psi_b: float, flip: bool) -> Callable[[float], Pose]:
        out = max(inner(p) for p in (psi_a, psi_b, *psis)
                  if min(psi_a, psi_b) <= p <= max(psi_a, psi_b))
        first = turn(psi_a, flip) @ world.finger_axis(arm)

        def pose_at(theta: float) -> Pose:
            R = turn(psi_on(psi_a, psi_b, theta), flip)
            # the same finger on the same end of the knob all along: `turn` takes the
            # side nearer a hand pointing down, which changes along a long arc (the hand
            # then rolled half a turn on the knob it pinched, and the lid stayed put)
            if (R @ world.finger_axis(arm)) @ first < 0.0:
                R = R @ axis_angle_matrix(world.approach_axis(arm), np.pi)
            return pose(R, out, theta)
        return pose_at

    def psi_on(psi_a: float, psi_b: float, theta: float) -> float:
        s = 0.0 if angle == now else (theta - now) / (angle - now)
        return psi_a + s * (psi_b - psi_a)

    def ok(psi_a: float, psi_b: float, flip: bool) -> bool:
        """Whether IK reaches the grip at each checked angle (the turn rounded to 5 deg,
        held as far out as its own fingers need: a quick first sieve)."""
        for i, theta in enumerate(thetas):
            psi = psi_on(psi_a, psi_b, float(theta))
            if not upright(psi, float(theta)):
                return False
            key = (round(float(np.degrees(psi)) / 5.0), flip, i)
            if key not in reached:
                near = np.deg2rad(5.0 * key[0])
                tcp = pose(turn(near, flip), inner(near), float(theta))
                reached[key] = branch_for_path(world, arm, (tcp,)) is not None
            if not reached[key]:
                return False
        return True

    pairs = sorted(((float(a), float(b), flip) for a in psis for b in psis for flip in (False, True)
                    if upright(a, now) and upright(b, angle)),
                   key=lambda x: (abs(x[0] - x[1]), x[2]))
    tried = 0
    for psi_a, psi_b, flip in pairs:
        if tried >= TURNING_TRIES:
            break
        if not ok(psi_a, psi_b, flip):
            continue
        tried += 1
        pose_at = at(psi_a, psi_b, flip)
        if follows(pose_at):
            return pose_at
    return None


def swing_lid(world: World, style: Style, body: str, angle: float,
              least: float | None = None, missed: Callable[[], Plan] | None = None,
              unreachable: Callable[[], Plan] | None = None) -> Plan:
    """Pinch a lid's knob by its ends (the fingers closing along the hinge) and carry it
    along its arc to ``angle`` (rad), the hand turning with the lid; let go and rise.
    The hand's turn on the lid is the one that keeps it nearest pointing down over the
    whole arc (tilted toward the robot at one end, away at the other), its fingers clear
    of the lid's edge behind the knob. Opening: past upright, the lid falls open onto its
    stop. Closing: pulled over upright and lowered onto its seat, not dropped.
    Opening where no IK branch follows the arc to ``angle``: carried as far as one does,
    but at least to ``least`` (rad), and held there, since it would fall shut. Where no
    fixed turn on the lid is followed even that far, the hand turns on the knob along the
    arc (:func:`_turning_grip`). A careful pinch that feels nothing from the knob (fingers
    thicker than it stands out) lets go and runs ``missed`` instead, or says so; one that
    finds no grip IK follows runs ``unreachable`` instead, or says so."""
    now = hinge(world, body).now
    grip, held = None, False
    for turning in (False, True):  # a grip that turns on the knob only where no fixed one holds
        grip = _lid_grip(world, style, body, now, angle, turning)
        if grip is None and least is not None and now < least < angle:
            for lower in np.linspace(angle, least, 5)[1:]:
                grip = _lid_grip(world, style, body, now, float(lower), turning)
                if grip is not None:
                    angle, held = float(lower), True
                    break
        if grip is not None:
            break
    if grip is None and unreachable is not None:
        yield from unreachable()
        return
    if grip is None:
        raise NotImplementedError(_out_of_reach(nearest_arm(world, world.body_pose(body).p),
                                                body, "knob", now, angle))
    arm, width, back, arc = grip.arm, grip.width, grip.back, grip.arc
    start = arc[0]
    opening = 1.0 if world.fingers_slide(arm) else world.pregrasp_opening(arm, width)
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps, label="open")
    yield from transit(world, style, arm, back, exclude=(body,), then=start, follow=arc)
    yield Segment({arm: start}, speed=0.5 * style.approach_speed, label="to knob")
    yield from pinch(world, style, arm, body, width, *knob_pinch(world, style, arm, body))
    if style.avoid_hazards and world.hand_force(arm, body, fingers=True) < FELT:
        if missed is not None:
            yield from let_go(world, style, arm, opening, 0.05)
            yield from missed()
            return
        raise NotImplementedError(
            f"the careful expert's fingers closed on nothing at `{body}`'s knob: the pinch "
            f"that keeps `{arm}`'s fingers clear of the lid's edge holds the knob beyond "
            f"its end (the fingers are thicker than the knob stands out)")
    yield from sweep(world, style, arm, grip.pose_at, now, angle, "swing lid")
    if held:  # short of upright: let go and it falls shut
        yield Segment({}, settle=round(world.scenario.horizon / world.dt), label="hold lid open")
        return
    yield Segment({}, settle=style.settle, label="hold lid")
    yield from let_go(world, style, arm, opening, 0.05)


#: Angles (deg) at which the careful expert lets a lid rest between two grips on its way
#: down, where no one grip follows the whole arc (a Panda holds the knob of a lid standing
#: past upright from behind it, and the shut lid's from in front): the first one where the
#: hinge's friction holds the lid with half of it to spare.
LID_RESTS = (85.0, 80.0, 75.0, 70.0)


def lower_lid(world: World, style: Style, body: str, angle: float,
              instead: Callable[[], Plan] | None = None) -> Plan:
    """Bring a lid down to ``angle`` (rad) by its knob (:func:`swing_lid`); careful, where
    no one grip follows the whole arc, in two: down to where the lid rests on its own
    (LID_RESTS), let go, and again from there with the grip that follows the rest; where
    no grip is followed at all, or the pinch feels nothing, ``instead`` (or say so)."""
    h = hinge(world, body)
    if style.avoid_hazards and _lid_grip(world, style, body, h.now, angle) is None:
        for rest in np.deg2rad(LID_RESTS):
            if (angle < rest < h.now and _rests(world, body, float(rest))
                    and _lid_grip(world, style, body, h.now, float(rest)) is not None
                    and _lid_grip(world, style, body, float(rest), angle) is not None):
                yield from swing_lid(world, style, body, float(rest))
                yield from swing_lid(world, style, body, angle)
                return
    yield from swing_lid(world, style, body, angle, missed=instead, unreachable=instead)


def _rests(world: World, body: str, theta: float) -> bool:
    """Whether the lid stays at ``theta`` (rad) let go: its weight's torque about the hinge
    at most half the joint's friction (the URDF's ``dynamics friction``)."""
    part, joint = world.part(body)
    asset = world.asset(body)
    if joint.friction <= 0.0:
        return False
    link = next(lk for lk in asset.links if lk.name == part.link)
    panel = world.shape(body, "panel", link=part.link)
    h = hinge(world, body)
    r = np.asarray(panel.pose.position, dtype=np.float64)
    r = r - (r @ (h.closed.T @ h.axis)) * (h.closed.T @ h.axis)
    torque = link.mass * 9.81 * float(np.linalg.norm(r)) * max(0.0, float(np.cos(theta)))
    return torque <= 0.5 * joint.friction


def lid_pose(h: Hinge, R_shut: NDArray[np.float64], local: NDArray[np.float64],
              centre: NDArray[np.float64], theta: float) -> Pose:
    """The TCP holding the lid's point ``local`` at the angle ``theta``, the hand turned
    with the lid from ``R_shut`` (its turn when the lid is shut)."""
    turn = axis_angle_matrix(h.axis, theta)
    R = turn @ R_shut
    return Pose(h.at(local, theta) - R @ centre, R)



def let_go(world: World, style: Style, arm: str, opening: float, back: float) -> Plan:
    """Open to ``opening``, back the hand off ``back`` (m) along its approach, and rise."""
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps,
                  settle=style.settle, label="let go")
    end = world.current_pose(arm)
    away = -(end.R @ world.approach_axis(arm))
    yield Segment({arm: end.moved(back * away)}, speed=free_speed(style), label="back")
    yield Segment({arm: end.moved(back * away + 0.08 * UP)}, speed=free_speed(style),
                  label="up", settle=20)


#: The careful squeeze (N) on a door's handle that the door is swung by: the pads hold
#: the handle by friction along the pull (at the style's 8 N a Panda's fingers slid off a
#: microwave's handle as the door passed 55°, and it stopped there).
DOOR_PINCH = 24.0


def swing_door(world: World, style: Style, body: str, angle: float) -> Plan:
    """Pinch a door's handle across its width, the hand pitched down toward the door, and
    turn the door with it about its hinge to ``angle`` (rad); let go and back away."""
    part, _joint = world.part(body)
    handle = world.shape(body, "handle", link=part.link)
    panel = world.shape(body, "panel", link=part.link)
    h = hinge(world, body)
    c = np.asarray(handle.pose.position, dtype=np.float64)
    half = np.abs(np.asarray(handle.half_size, dtype=np.float64))
    p_half = np.abs(np.asarray(panel.half_size, dtype=np.float64))
    normal_axis = int(np.argmin(p_half))  # the panel's thin axis: the handle stands on it
    long_axis = int(np.argmax(half))
    closing_axis = ({0, 1, 2} - {normal_axis, long_axis}).pop()
    outward = np.zeros(3)
    outward[normal_axis] = np.sign(c[normal_axis] - np.asarray(panel.pose.position)[normal_axis])
    width = float(2 * half[closing_axis])
    local = c + outward * FACE_CLEARANCE
    arm = nearest_arm(world, h.at(local, h.now))
    current = axis_angle_matrix(h.axis, h.now) @ h.closed  # the door's frame now
    n_now = current @ outward  # world, the door's outward normal now
    closing_now = current[:, closing_axis]

    def frame(pitch: float) -> NDArray[np.float64]:
        a = np.deg2rad(pitch)
        approach = np.cos(a) * -n_now + np.sin(a) * DOWN
        return world.grasp_frame(arm, approach, closing_now)

    def pose_at(R: NDArray[np.float64]) -> Callable[[float], Pose]:
        centre = world.grip_centre(arm, width + FIXED_JAW_CLEARANCE)
        p0 = h.at(local, h.now) - R @ centre

        def at(theta: float) -> Pose:
            turn = h.turn(theta)
            return Pose(h.point + turn @ (p0 - h.point), turn @ R)
        return at

    options = [frame(p) for p in DOOR_PITCHES]
    R = options[0]
    if style.avoid_hazards:
        for candidate in options:
            at = pose_at(candidate)
            arc = tuple(at(float(t)) for t in np.linspace(h.now, angle, 12))
            back = arc[0].moved(-0.06 * (candidate @ world.approach_axis(arm)))
            if branch_for_path(world, arm, (back, *arc)) is not None:
                R = candidate
                break
        else:
            raise NotImplementedError(_out_of_reach(arm, body, "handle", h.now, angle))
    at = pose_at(R)
    start = at(h.now)
    approach = R @ world.approach_axis(arm)
    back = start.moved(-0.06 * approach)
    arc = tuple(at(float(t)) for t in np.linspace(h.now, angle, 12))
    opening = 1.0 if world.fingers_slide(arm) else world.pregrasp_opening(arm, width)
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps, label="open")
    yield from transit(world, style, arm, back, exclude=(body,), then=start, follow=arc)
    yield Segment({arm: start}, speed=0.5 * style.approach_speed, label="to handle")
    yield from pinch(world, style, arm, body, width, DOOR_PINCH)
    yield from sweep(world, style, arm, at, h.now, angle, "swing door")
    yield Segment({}, settle=style.settle, label="hold door")
    yield from let_go(world, style, arm, opening, 0.06)


#: The squeeze (N) a careful pinch of a knob by a jaw on a hinge wants (the style's 8 N
#: let an SO-101's knob slip out of its jaws as the lid's weight came onto them, the lid
#: 8 deg up), and the share of it at which the pinch closes no further: the swinging jaw
#: alone presses the knob against the hinge, and closing on from there (or pinching at 16
#: N or more) brings the fixed jaw onto the knob with a jump of 60-110 N.
KNOB_SQUEEZE = 12.0
KNOB_FELT = 0.5
#: Where no `contact_force` limit watches the hand or the lid, the squeeze (N) a careful
#: pinch of a knob by a jaw on a hinge closes on until it feels all of: the fixed jaw
#: comes onto the knob too (the swinging jaw alone at 12 N let an SO-101's knob slip out
#: as the lid came up, 6-10 deg open, on most of its lids).
KNOB_FIRM = 30.0
#: The share of its squeeze at which a careful pinch otherwise closes no further.
PINCH_FELT = 0.8


def knob_pinch(world: World, style: Style, arm: str,
               body: str | None = None) -> tuple[float | None, float]:
    """The squeeze (N) a careful pinch of a knob by ``arm`` wants and the share of it felt
    at which it closes no further: for a jaw on a hinge, KNOB_FIRM all felt where no
    contact-force limit watches the hand or ``body`` (when given), else KNOB_SQUEEZE and
    KNOB_FELT; for other grippers the style's grip force (None) and PINCH_FELT."""
    if style.grip_force is None or world.moving_jaw(arm) is None:
        return None, PINCH_FELT
    if body is not None and world.force_allowance(body, *world.gripper_entities) is None:
        return max(style.grip_force, KNOB_FIRM), 1.0
    return max(style.grip_force, KNOB_SQUEEZE), KNOB_FELT


def pinch_force(world: World, style: Style, body: str, wanted: float | None = None) -> float:
    """The careful squeeze on a part of ``body``: ``wanted`` (default: the style's grip
    force), at most half of a contact-force limit on the hand or the body and out of its
    warning band, at least 2 N."""
    force = float(style.grip_force or 0.0) if wanted is None else wanted
    allowed = world.force_allowance(body, *world.gripper_entities)
    return max(force if allowed is None else min(force, allowed), 2.0)


def pinch(world: World, style: Style, arm: str, body: str, width: float,
          wanted: float | None = None, felt: float = PINCH_FELT) -> Plan:
    """Close the fingers on a part ``width`` across: careful, quickly to just short of it,
    then slowly with the hand's force guarded at :func:`pinch_force` (of ``wanted``),
    closing on by small steps until ``felt`` of it is felt; careless, shut at once."""
    force = pinch_force(world, style, body, wanted)
    target = opening_for(world, arm, width, replace(style, grip_force=force)
                         if style.grip_force is not None else style)
    if not style.avoid_hazards:
        yield Segment(grippers={arm: target}, gripper_steps=style.gripper_steps,
                      settle=style.settle, label="pinch")
        return
    guard = grip_guard(world, arm, force, body)
    near = world.opening_fraction(arm, width + 0.006)
    yield Segment(grippers={arm: near}, gripper_steps=style.gripper_steps, label="preclose")
    steps = max(2 * style.gripper_steps, int(np.ceil((near - target) / SLOW_CLOSE)))
    yield Segment(grippers={arm: target}, gripper_steps=steps, settle=style.settle,
                  guards=(guard,), label="pinch")
    yield from squeeze_on(world, style, arm, body, force, felt=felt)


def squeeze_on(world: World, style: Style, arm: str, body: str, force: float,
               step: float = 2 * SLOW_CLOSE, felt: float = PINCH_FELT) -> Plan:
    """Careful: close on by ``step`` of the gripper's range at a time, guarded, until the
    hand feels ``felt`` of ``force`` from ``body`` (fingers that stop short of each other
    when closed, as Baxter's, leave a handle loose at the width model's opening)."""
    if not style.avoid_hazards:
        return
    guard = grip_guard(world, arm, force, body)
    goal = world.gripper_opening(arm)
    for _ in range(SQUEEZE_STEPS):
        if world.hand_force(arm, body, fingers=True) >= felt * force or goal <= 0.0:
            break
        goal = max(0.0, goal - step)
        yield Segment(grippers={arm: goal}, gripper_steps=2, settle=2, guards=(guard,),
                      label="squeeze")


def _out_of_reach(arm: str, body: str, held: str, start: float, end: float) -> str:
    """Why the careful expert does not swing a part: no IK branch follows the arc (an arm
    driven along it anyway leaves the arc and flails through the scene)."""
    return (f"the careful expert cannot swing `{body}` by its {held} from "
            f"{np.degrees(start):.0f}° to {np.degrees(end):.0f}°: no IK branch of `{arm}` "
            f"follows the {held}'s arc within the joint limits (out of the arm's reach)")


def sweep(world: World, style: Style, arm: str, pose_at: Callable[[float], Pose],
           start: float, end: float, label: str) -> Plan:
    """Careful: one smooth sweep along the arc; careless: 8° chords at approach speed."""
    if style.avoid_hazards:
        yield from smooth_arc(world, style, arm, pose_at, start, end,
                               max(style.contact_speed * 4, 0.06), label)
        return
    steps = max(2, int(np.ceil(abs(end - start) / np.deg2rad(8.0))))
    for theta in np.linspace(start, end, steps + 1)[1:]:
        yield Segment({arm: pose_at(float(theta))}, speed=style.approach_speed, label=label)


__all__ = ["FELT", "Hinge", "Knob", "LidGrip", "hinge", "knob_of", "knob_pinch",
           "knob_pinch_fits", "let_go", "lid_pose", "lower_lid", "pinch", "pinch_force",
           "squeeze_on", "sweep", "swing_door", "swing_lid"]
