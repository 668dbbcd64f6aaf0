"""Swinging a hinged part (a box's lid, a microwave's door) open or shut by holding it
where a hand can: the hand's path is the held point's arc about the joint's axis (from
the joint's origin and axis in the world), followed in one smooth sweep.

- A **lid** is pinched by its knob's two ends, the fingers closing along the hinge axis,
  the hand pointing down: the knob turns between the pads (their grip about the closing
  axis is weak), so the hand keeps its turn while the knob follows its arc. The same
  grip lifts a shut lid (past upright: it then falls open onto its stop) and brings one
  standing open back down (past upright it must be pulled, then lowered: let go above its
  seat, it slams shut). It needs no room below the knob: a low box's lid too.
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
    branch_for_path,
    free_speed,
    grip_guard,
    nearest_arm,
    opening_for,
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


def _lid_grip(world: World, style: Style, body: str, start: float, angle: float):
    """How the hand holds the knob to carry the lid from ``start`` to ``angle`` (rad):
    (hinge, arm, hand turn on the shut lid, held point, grip centre, knob width, the
    approach from beyond the knob, the arc); careful, the first turn whose whole arc one
    IK branch follows, None if none is; careless, the first."""
    part, _joint = world.part(body)
    knob = world.shape(body, "knob", link=part.link)
    h = hinge(world, body)
    now = start
    c = np.asarray(knob.pose.position, dtype=np.float64)
    half = np.abs(np.asarray(knob.half_size, dtype=np.float64))
    along = h.closed.T @ h.axis  # the hinge axis in the lid's frame
    width = _extent_along(knob, along)
    panel = world.shape(body, "panel", link=part.link)
    normal_axis = int(np.argmin(np.abs(np.asarray(panel.half_size))))
    normal = np.eye(3)[normal_axis]  # the lid's thin axis (up when shut)
    if h.closed[:, normal_axis] @ UP < 0:
        normal = -normal
    # the knob stands proud of the lid's far edge, away from the hinge
    outward = c - normal * (c @ normal) - along * (c @ along)
    outward /= max(np.linalg.norm(outward), 1e-9)
    root = c - outward * float(np.abs(half) @ np.abs(outward))  # the lid's edge
    arm = nearest_arm(world, h.at(c, now))
    tip, thick = finger_box(world, arm)
    centre = world.grip_centre(arm, width + FIXED_JAW_CLEARANCE)

    def option(psi: float, flip: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The hand's turn on the lid (its frame when shut, world) whose palm lies ``psi``
        (rad) from the lid's normal toward outward, and the knob point the TCP holds:
        out from the edge so that the fingers' inner corners stay 2 mm clear of it."""
        palm = np.cos(psi) * normal + np.sin(psi) * outward  # lid frame, TCP → palm
        R = world.grasp_frame(arm, h.closed @ -palm, h.axis,
                              near=world.grasp_frame(arm, DOWN, h.axis))
        if flip:
            R = R @ axis_angle_matrix(world.approach_axis(arm), np.pi)
        across = np.cos(psi) * outward - np.sin(psi) * normal
        inner = max(tip * np.sin(psi) + thick * abs(np.cos(psi)),
                    -PALM_REACH * np.sin(psi) + thick * abs(np.cos(psi)))
        inner = max(inner, thick * abs(across @ outward))
        return R, root + outward * (inner + FACE_CLEARANCE)

    def path(R: NDArray[np.float64], local: NDArray[np.float64], n: int = 12) -> tuple[Pose, ...]:
        return tuple(_lid_pose(h, R, local, centre, float(t)) for t in np.linspace(now, angle, n))

    mid = 0.5 * (now + angle)
    psis = [mid + np.deg2rad(d) for d in LID_TURNS]
    options = [option(float(np.clip(p, -0.3, np.pi / 2)), f) for p in psis for f in (False, True)]
    R, local = options[0]
    # the hand comes to the knob from beyond its tip, along the lid: the fingers slide
    # down past the knob's ends, with nothing of the lid in their way
    beyond = 0.06 * (axis_angle_matrix(h.axis, now) @ h.closed @ outward)
    if style.avoid_hazards:
        found = next(((candidate, point) for candidate, point in options
                      if branch_for_path(world, arm, (path(candidate, point)[0].moved(beyond),
                                                      *path(candidate, point))) is not None), None)
        if found is None:
            return None
        R, local = found
    return h, arm, R, local, centre, width, beyond, path(R, local)


def swing_lid(world: World, style: Style, body: str, angle: float,
              least: float | None = None) -> Plan:
    """Pinch a lid's knob by its ends (the fingers closing along the hinge) and carry it
    along its arc to ``angle`` (rad), the hand turning with the lid; let go and rise.
    The hand's turn on the lid is the one that keeps it nearest pointing down over the
    whole arc (tilted toward the robot at one end, away at the other), its fingers clear
    of the lid's edge behind the knob. Opening: past upright, the lid falls open onto its
    stop. Closing: pulled over upright and lowered onto its seat, not dropped.
    Opening where no IK branch follows the arc to ``angle``: carried as far as one does,
    but at least to ``least`` (rad), and held there, since it would fall shut."""
    now = hinge(world, body).now
    grip = _lid_grip(world, style, body, now, angle)
    held = False
    if grip is None and least is not None and now < least < angle:
        for lower in np.linspace(angle, least, 5)[1:]:
            grip = _lid_grip(world, style, body, now, float(lower))
            if grip is not None:
                angle, held = float(lower), True
                break
    if grip is None:
        raise NotImplementedError(_out_of_reach(nearest_arm(world, world.body_pose(body).p),
                                                body, "knob", now, angle))
    h, arm, R, local, centre, width, beyond, arc = grip
    start = _lid_pose(h, R, local, centre, h.now)
    back = start.moved(beyond)
    opening = 1.0 if world.fingers_slide(arm) else world.pregrasp_opening(arm, width)
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps, label="open")
    yield from transit(world, style, arm, back, exclude=(body,), then=start, follow=arc)
    yield Segment({arm: start}, speed=0.5 * style.approach_speed, label="to knob")
    yield from pinch(world, style, arm, body, width)
    yield from _sweep(world, style, arm, lambda t: _lid_pose(h, R, local, centre, t),
                      h.now, angle, "swing lid")
    if held:  # short of upright: let go and it falls shut
        yield Segment({}, settle=round(world.scenario.horizon / world.dt), label="hold lid open")
        return
    yield Segment({}, settle=style.settle, label="hold lid")
    yield from _let_go(world, style, arm, opening, 0.05)


#: Angles (deg) at which the careful expert lets a lid rest between two grips on its way
#: down, where no one grip follows the whole arc (a Panda holds the knob of a lid standing
#: past upright from behind it, and the shut lid's from in front): the first one where the
#: hinge's friction holds the lid with half of it to spare.
LID_RESTS = (85.0, 80.0, 75.0, 70.0)


def lower_lid(world: World, style: Style, body: str, angle: float) -> Plan:
    """Bring a lid down to ``angle`` (rad) by its knob (:func:`swing_lid`); careful, where
    no one grip follows the whole arc, in two: down to where the lid rests on its own
    (LID_RESTS), let go, and again from there with the grip that follows the rest."""
    h = hinge(world, body)
    if style.avoid_hazards and _lid_grip(world, style, body, h.now, angle) is None:
        for rest in np.deg2rad(LID_RESTS):
            if (angle < rest < h.now and _rests(world, body, float(rest))
                    and _lid_grip(world, style, body, h.now, float(rest)) is not None
                    and _lid_grip(world, style, body, float(rest), angle) is not None):
                yield from swing_lid(world, style, body, float(rest))
                yield from swing_lid(world, style, body, angle)
                return
    yield from swing_lid(world, style, body, angle)


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


def _lid_pose(h: Hinge, R_shut: NDArray[np.float64], local: NDArray[np.float64],
              centre: NDArray[np.float64], theta: float) -> Pose:
    """The TCP holding the lid's point ``local`` at the angle ``theta``, the hand turned
    with the lid from ``R_shut`` (its turn when the lid is shut)."""
    turn = axis_angle_matrix(h.axis, theta)
    R = turn @ R_shut
    return Pose(h.at(local, theta) - R @ centre, R)



def _let_go(world: World, style: Style, arm: str, opening: float, back: float) -> Plan:
    """Open to ``opening``, back the hand off ``back`` (m) along its approach, and rise."""
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps,
                  settle=style.settle, label="let go")
    end = world.current_pose(arm)
    away = -(end.R @ world.approach_axis(arm))
    yield Segment({arm: end.moved(back * away)}, speed=free_speed(style), label="back")
    yield Segment({arm: end.moved(back * away + 0.08 * UP)}, speed=free_speed(style),
                  label="up", settle=20)

#: How far back from the TCP (m) the fingers' hulls are measured for their thickness.
NEAR_TIP = 0.02


def finger_box(world: World, arm: str) -> tuple[float, float]:
    """How far (m) the closed fingers reach past the TCP along the approach, and their half
    thickness across both the approach and the closing axis within NEAR_TIP of the TCP
    (from their collision hulls)."""
    tcp = world.current_pose(arm)
    a = world.approach_axis(arm)
    third = np.cross(a, world.finger_axis(arm))
    reach, thick = 0.0, 0.0
    for link in world.arm_spec(arm).gripper.finger_links:
        found = world.link_points(arm, link)
        if found is None:
            continue
        points = (found - tcp.p) @ tcp.R
        reach = max(reach, float(np.max(points @ a)))
        near = points[points @ a >= -NEAR_TIP]  # the pads, not the jaw's body behind them
        if len(near):
            thick = max(thick, float(np.max(np.abs(near @ third))))
    return reach or 0.01, thick or 0.011


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
    yield from pinch(world, style, arm, body, width)
    yield from _sweep(world, style, arm, at, h.now, angle, "swing door")
    yield Segment({}, settle=style.settle, label="hold door")
    yield from _let_go(world, style, arm, opening, 0.06)


def pinch_force(world: World, style: Style, body: str) -> float:
    """The careful squeeze on a part of ``body``: the style's grip force, at most half of a
    contact-force limit on the hand or the body and out of its warning band, at least 2 N."""
    force = float(style.grip_force or 0.0)
    allowed = world.force_allowance("gripper", body, *[f"{a}_gripper" for a in world.arm_names])
    return max(force if allowed is None else min(force, allowed), 2.0)


def pinch(world: World, style: Style, arm: str, body: str, width: float) -> Plan:
    """Close the fingers on a part ``width`` across: careful, quickly to just short of it,
    then slowly with the hand's force guarded at :func:`pinch_force`, closing on by small
    steps until the squeeze is felt; careless, shut at once."""
    force = pinch_force(world, style, body)
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
    yield from squeeze_on(world, style, arm, body, force)


def squeeze_on(world: World, style: Style, arm: str, body: str, force: float,
               step: float = 2 * SLOW_CLOSE) -> Plan:
    """Careful: close on by ``step`` of the gripper's range at a time, guarded, until the
    hand feels 80 % of ``force`` from ``body`` (fingers that stop short of each other when
    closed, as Baxter's, leave a handle loose at the width model's opening)."""
    if not style.avoid_hazards:
        return
    guard = grip_guard(world, arm, force, body)
    goal = world.gripper_opening(arm)
    for _ in range(SQUEEZE_STEPS):
        if world.hand_force(arm, body) >= 0.8 * force or goal <= 0.0:
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


def _sweep(world: World, style: Style, arm: str, pose_at: Callable[[float], Pose],
           start: float, end: float, label: str) -> Plan:
    """Careful: one smooth sweep along the arc; careless: 8° chords at approach speed."""
    if style.avoid_hazards:
        yield from smooth_arc(world, style, arm, pose_at, start, end,
                               max(style.contact_speed * 4, 0.06), label)
        return
    steps = max(2, int(np.ceil(abs(end - start) / np.deg2rad(8.0))))
    for theta in np.linspace(start, end, steps + 1)[1:]:
        yield Segment({arm: pose_at(float(theta))}, speed=style.approach_speed, label=label)


__all__ = ["Hinge", "finger_box", "hinge", "knob_pinch_fits", "lower_lid", "pinch", "pinch_force", "squeeze_on",
           "swing_door", "swing_lid"]
