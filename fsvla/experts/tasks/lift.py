"""lift: pick the object and hold it up."""

from __future__ import annotations

import numpy as np

from .. import grasps
from ..motion import Pose, Segment
from ..skills import (
    HAZARD_SPARE,
    UP,
    Plan,
    hand_clearance,
    horizontal,
    nearest_arm,
    pick,
    reach_ceiling,
    reaches,
)
from ..style import Style
from ..world import World
from .common import required_lift


def plan_lift(world: World, style: Style, roles: dict[str, str], by: float = 0.15) -> Plan:
    obj = roles["object"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    pose = world.current_pose(arm)
    # as high as the success asks and 4 cm more, up to ``by`` (a small arm's reach ends
    # low: a goal beyond it swings the arm sideways and shakes the object out)
    height = min(by, max(required_lift(world, obj) + LIFT_SPARE, LIFT_SPARE))
    yield Segment({arm: hold_pose(world, style, arm, obj, pose, height)},
                  speed=style.approach_speed, settle=40, label="hold")


#: How much higher (m) than the success asks the object is lifted.
LIFT_SPARE = 0.04

#: Where the arm does not reach ``height`` straight above the grasp, :func:`hold_pose`
#: tries points this far (m) from it along the line to the arm's base: nearer the base
#: first (a small arm, its hand leaning out to a block far from it, holds it low there).
HOLD_SHIFTS = (0.02, 0.04, 0.06, 0.08, 0.1, 0.12, -0.02, -0.04, -0.06)

#: How much higher (m) a shifted hold must reach than straight up to be worth the move.
HOLD_GAIN = 0.005


def hold_pose(world: World, style: Style, arm: str, obj: str, pose: Pose, height: float) -> Pose:
    """Where the hand, at ``pose`` with ``obj`` in it, holds it ``height`` higher: straight
    up where the arm reaches that (:func:`reaches`); else the first of HOLD_SHIFTS along
    the line to the arm's base over which it holds the hand that high (:func:`reach_ceiling`),
    or the one over which it holds it highest, HOLD_GAIN above what it holds straight up.
    Careful, a shifted hold keeps the hand HAZARD_SPARE outside every keep-out."""
    up = pose.moved(height * UP)
    if reaches(world, arm, up):
        return up
    goal = float(up.p[2])
    toward = horizontal(world.base_position(arm) - pose.p)
    best, highest = up, reach_ceiling(world, arm, pose.p, pose.R, goal) + HOLD_GAIN
    for shift in HOLD_SHIFTS:
        p = pose.p + shift * toward
        top = reach_ceiling(world, arm, p, pose.R, goal)
        option = Pose(np.array([p[0], p[1], top]), pose.R)
        if top < highest or (style.avoid_hazards and hand_clearance(
                world, arm, (option,), exclude=(obj,)) < HAZARD_SPARE):
            continue
        if top >= goal:
            return option
        best, highest = option, top
    return best


__all__ = ["HOLD_GAIN", "HOLD_SHIFTS", "LIFT_SPARE", "hold_pose", "plan_lift"]
