"""lift: pick the object and hold it up."""

from __future__ import annotations

from .. import grasps
from ..motion import Segment
from ..skills import UP, Plan, nearest_arm, pick
from ..style import Style
from ..world import World


def plan_lift(world: World, style: Style, roles: dict[str, str], by: float = 0.15) -> Plan:
    obj = roles["object"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    pose = world.current_pose(arm)
    yield Segment({arm: pose.moved(by * UP)}, speed=style.approach_speed, settle=40, label="hold")


__all__ = ["plan_lift"]
