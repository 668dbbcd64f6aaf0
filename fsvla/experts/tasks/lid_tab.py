"""Pulling a lid that stands past upright back over it by its knob held flat.

A lid's knob is a tab out of its free edge, as thick as the lid. Standing past upright,
the lid leans away from the robot: a push on its face must come from behind it, and a
pinch of the knob's ends (:func:`.hinge.swing_lid`) holds it from behind too, out of
reach of most arms, and wider than Baxter's fingers open. Here the fingers close across
the tab's thickness instead, the hand coming down onto it from beyond its tip, along the
lid: the pads hold the tab flat between them, so the lid does not turn in them, and the
hand turns with it about the hinge as it pulls the lid toward the robot. It pulls as far
down as one IK branch follows the arc; where that is short of shut, it lets go: short of
upright the lid falls shut under its own weight, or rests on its hinge's friction and is
lowered from there as any lid standing open (``then``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix

from ..grasps import fits
from ..motion import Pose, Segment
from ..skills import FIXED_JAW_CLEARANCE, Plan, attained, branch_for_path, nearest_arm, transit
from ..style import Style
from ..world import World
from .hinge import (
    ARC_POSES,
    FELT,
    LidGrip,
    hinge,
    knob_of,
    knob_pinch,
    let_go,
    lid_pose,
    pinch,
    sweep,
)

#: How far (m) in from the tab's tip the TCP holds it.
TAB_DEPTH = 0.008
#: The hand's turns (deg) in the lid's plane, from pointing straight along the lid at the
#: hinge, tried in turn.
TAB_TURNS = (0.0, 30.0, -30.0, 60.0, -60.0)
#: The lid angles (deg) the pull ends at, tried from the lowest: shut first.
PULL_ENDS = (60.0, 70.0, 80.0)
#: How far (m) beyond the tab's tip, along the lid, the hand comes down from.
BEYOND = 0.06


def tab_grip(world: World, style: Style, body: str, end: float) -> LidGrip | None:
    """How a hand holds the knob flat to carry the lid from where it is to ``end`` (rad):
    the first turn of the hand (TAB_TURNS, either way round) whose whole arc, from
    BEYOND the tip on, one IK branch follows; None where none is, or where the tab is
    thinner than the fingers shut or wider than they open."""
    h = hinge(world, body)
    knob = knob_of(world, body, h)
    along, normal, outward = knob.along, knob.normal, knob.outward
    thickness = knob.extent(normal)
    arm = nearest_arm(world, h.at(knob.centre, h.now))
    if world.min_width(arm) > thickness or not fits(world, arm, thickness):
        return None
    held = knob.centre + outward * (0.5 * knob.extent(outward) - TAB_DEPTH)
    centre = world.grip_centre(arm, thickness + FIXED_JAW_CLEARANCE)

    def frame(turn: float, flip: bool) -> NDArray[np.float64]:
        approach = h.closed @ (np.cos(turn) * -outward + np.sin(turn) * along)
        R = world.grasp_frame(arm, approach, h.closed @ normal)
        return R @ axis_angle_matrix(world.approach_axis(arm), np.pi) if flip else R

    def grip(R: NDArray[np.float64]) -> Callable[[float], Pose]:
        return lambda theta: attained(world, arm, lid_pose(h, R, held, centre, theta))

    for turn in np.deg2rad(TAB_TURNS):
        for flip in (False, True):
            pose_at = grip(frame(float(turn), flip))
            arc = tuple(pose_at(float(t)) for t in np.linspace(h.now, end, ARC_POSES))
            back = arc[0].moved(-BEYOND * (arc[0].R @ world.approach_axis(arm)))
            if not style.avoid_hazards or branch_for_path(world, arm, (back, *arc)) is not None:
                return LidGrip(arm, thickness, back, pose_at, arc)
    return None


def pull_over(world: World, style: Style, body: str, angle: float,
              then: Callable[[], Plan], instead: Callable[[], Plan] | None = None) -> Plan:
    """Pull a lid standing past upright toward ``angle`` (rad, shut) by its knob held
    flat (:func:`tab_grip`), as far as an arm follows (PULL_ENDS); let go, and where it
    rests short of ``angle`` on its hinge's friction, ``then``. Where no grip is followed
    past upright, or the pinch feels nothing, ``instead`` (or say so)."""
    h = hinge(world, body)
    grip, end = None, h.now
    for candidate in np.deg2rad(PULL_ENDS):
        end = max(float(candidate), angle)
        if end >= h.now - np.deg2rad(10.0):
            break
        grip = tab_grip(world, style, body, end)
        if grip is not None:
            break
    if grip is None:
        if instead is not None:
            yield from instead()
            return
        raise NotImplementedError(
            f"the careful expert cannot pull `{body}` back over upright from "
            f"{np.degrees(h.now):.0f}°: no IK branch follows its knob's arc, held by its "
            f"ends or flat (out of the arm's reach)")
    arm, start = grip.arm, grip.arc[0]
    opening = 1.0 if world.fingers_slide(arm) else world.pregrasp_opening(arm, grip.width)
    yield Segment(grippers={arm: opening}, gripper_steps=style.gripper_steps, label="open")
    yield from transit(world, style, arm, grip.back, exclude=(body,), then=start,
                       follow=grip.arc)
    yield Segment({arm: start}, speed=0.5 * style.approach_speed, label="onto tab")
    yield from pinch(world, style, arm, body, grip.width, *knob_pinch(world, style, arm))
    if style.avoid_hazards and world.hand_force(arm, body, fingers=True) < FELT:
        yield from let_go(world, style, arm, opening, BEYOND)
        if instead is not None:
            yield from instead()
            return
        raise NotImplementedError(
            f"the careful expert's fingers closed on nothing at `{body}`'s knob held flat")
    yield from sweep(world, style, arm, grip.pose_at, h.now, end, "pull lid over")
    yield Segment({}, settle=style.settle, label="hold lid")
    yield from let_go(world, style, arm, opening, BEYOND)
    if hinge(world, body).now > angle + np.deg2rad(3.0):
        yield from then()


__all__ = ["pull_over", "tab_grip"]
