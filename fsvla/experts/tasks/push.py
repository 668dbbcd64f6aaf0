"""push: slide the object over the table to the target with closed fingers."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..motion import Pose, Segment
from ..skills import (
    DOWN,
    UP,
    Plan,
    branch_for_path,
    force_watched,
    horizontal,
    leaning_frame,
    nearest_arm,
    transit,
)
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
    base = np.array([start[0], start[1], height]) - reach * direction
    travel = float(np.linalg.norm((goal - start)[:2]))
    behind = Pose(base, _push_frame(world, arm, base, direction, travel))
    end = behind.moved(travel * direction)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="close")
    # a hand whose body reaches below its TCP (a Z1's) pushes higher, off the table:
    # measured on the shut hand, along its approach axis
    lowest = lo[2] + world.hand_reach(arm) + TABLE_GAP
    if behind.p[2] < lowest:
        lift = min(lowest, lo[2] + 0.7 * (hi[2] - lo[2])) - behind.p[2]
        behind, end = behind.moved(lift * UP), end.moved(lift * UP)
    yield from transit(world, style, arm, behind.moved(0.08 * UP), exclude=(obj,))
    yield Segment({arm: behind}, speed=style.approach_speed, label="down")
    # careful, on an object a force limit watches: at contact speed (a rigid hand pushing
    # at three times that chatters, with one-step spikes of ~60 N)
    speed = style.contact_speed * (1 if style.avoid_hazards and force_watched(world, obj) else 3)
    yield Segment({arm: end}, speed=speed,
                  settle=style.settle, label="push")
    yield from retreat_home(world, style, arm)


def _push_frame(world: World, arm: str, behind: NDArray[np.float64],
                direction: NDArray[np.float64], travel: float) -> NDArray[np.float64]:
    """The hand's orientation for the push: pointing down, fingers closing across the push,
    where the arm follows the whole push that way, else the first turn about the vertical
    it does, then tipped out from the base (a five-joint arm turns its hand with the
    direction to its base, and a short one reaches far only with its hand tipped out)."""
    across = np.cross(UP, direction)
    frames = [world.grasp_frame(arm, DOWN, np.cos(t) * across + np.sin(t) * direction)
              for t in np.deg2rad([0.0, 45.0, -45.0, 90.0])]
    frames += [leaning_frame(world, arm, behind, float(t))
               for t in np.deg2rad([20.0, 40.0, 60.0, 80.0])]
    path = (behind, behind + travel * direction)
    for R in frames:
        if branch_for_path(world, arm, tuple(Pose(p, R) for p in path)) is not None:
            return R
    return frames[0]


#: How far (m) the lowest point of the pushing hand stays above the table.
TABLE_GAP = 0.008

__all__ = ["plan_push"]
