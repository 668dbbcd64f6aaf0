"""push: slide the object over the table to the target with closed fingers."""

from __future__ import annotations

import numpy as np

from ..motion import Pose, Segment
from ..skills import DOWN, UP, Plan, force_watched, horizontal, nearest_arm, transit
from ..style import Style
from ..world import World
from .common import retreat_home


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
    # careful, on an object a force limit watches: at contact speed (a rigid hand pushing
    # at three times that chatters, with one-step spikes of ~60 N)
    speed = style.contact_speed * (1 if style.avoid_hazards and force_watched(world, obj) else 3)
    yield Segment({arm: behind.moved(travel * direction)}, speed=speed,
                  settle=style.settle, label="push")
    yield from retreat_home(world, style, arm)


__all__ = ["plan_push"]
