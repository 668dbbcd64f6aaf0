"""press: press the object from above with closed fingers."""

from __future__ import annotations

import numpy as np

from ..motion import Pose, Segment
from ..skills import DOWN, UP, Plan, nearest_arm, transit
from ..style import Style
from ..world import World
from .common import retreat_home


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
    yield from retreat_home(world, style, arm)


__all__ = ["plan_press"]
