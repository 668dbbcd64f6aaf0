"""lift: pick the object and hold it up."""

from __future__ import annotations

from .. import grasps
from ..motion import Segment
from ..skills import UP, Plan, nearest_arm, pick
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
    yield Segment({arm: pose.moved(height * UP)}, speed=style.approach_speed, settle=40,
                  label="hold")


#: How much higher (m) than the success asks the object is lifted.
LIFT_SPARE = 0.04


__all__ = ["LIFT_SPARE", "plan_lift"]
