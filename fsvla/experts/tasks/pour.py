"""pour: lift the object over the target, tilt it and back, put it down."""

from __future__ import annotations

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix

from .. import grasps
from ..motion import Pose, Segment
from ..skills import Plan, horizontal, nearest_arm, pick, place, transit
from ..style import Style
from ..world import World


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


__all__ = ["plan_pour"]
