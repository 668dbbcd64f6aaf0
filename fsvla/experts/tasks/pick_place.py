"""pick_place (and stack): pick the object, set it on the target's top, retreat."""

from __future__ import annotations

from .. import grasps
from ..skills import Plan, carrying_arm, pick, place
from ..style import Style
from ..world import World
from .common import place_point, retreat_home


def plan_pick_place(world: World, style: Style, roles: dict[str, str]) -> Plan:
    obj, target = roles["object"], roles["target"]
    arm = carrying_arm(world, obj, target)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    yield from place(world, style, arm, obj, place_point(world, style, obj, target, arm))
    yield from retreat_home(world, style, arm)


__all__ = ["plan_pick_place"]
