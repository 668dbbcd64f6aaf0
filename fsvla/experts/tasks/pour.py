"""pour: lift the object over the target, tilt it and back, put it down."""

from __future__ import annotations

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix

from .. import grasps
from ..motion import Pose, Segment
from ..skills import Plan, carrying_arm, horizontal, load_reach, pick, place, transit
from ..style import Style
from ..world import World

#: How high (m) above the target's top the held object's bottom is carried to pour; the
#: careful expert POUR_MARGIN higher (a mug held by its handle hangs turned in the fingers,
#: and its rim swings down onto the target's as it tilts).
POUR_CLEARANCE = 0.04
POUR_MARGIN = 0.02
#: How far (deg) the held object is tipped to pour.
POUR_TILT = 100.0


def plan_pour(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Lift the object, hold it over the target, tilt it by 100°, tilt it back, put it down."""
    obj, target = roles["object"], roles["target"]
    arm = carrying_arm(world, obj, target)
    grasp = grasps.choose(world, style, arm, obj)
    start = world.body_pose(obj).p.copy()
    yield from pick(world, style, arm, obj, grasp)
    # the held object's centre (not the hand) over the target's mouth, and the tilt about
    # that centre: a mug held by its handle swings wide of the target when the hand tilts
    tcp = world.current_pose(arm)
    lo, hi = world.bounds(obj)
    held = tcp.p - 0.5 * (lo + hi)  # the hand from the object's centre
    target_xy = world.body_pose(target).p
    clear = world.bounds(target)[1][2] + POUR_CLEARANCE + (POUR_MARGIN if style.avoid_hazards else 0.0)
    centre = np.array([target_xy[0], target_xy[1], clear + 0.5 * (hi - lo)[2]])
    over = Pose(centre + held, tcp.R)
    yield from transit(world, style, arm, over, below=float(held[2]) + 0.5 * float((hi - lo)[2]),
                       exclude=(obj, target), around=load_reach(world, arm, obj))
    axis = horizontal(world.base_position(arm) - centre)
    tilt = axis_angle_matrix(axis, np.deg2rad(POUR_TILT))
    # tipped, the object lies lower than it stands: its lowest point tipped, not upright,
    # is what clears the target (a 20 cm bottle held so that it stood clear of a mug lay
    # 12 cm above the mug once tipped)
    tipped = np.array([centre[0], centre[1], clear + _tipped_half_height(world, obj, tilt)])
    yield Segment({arm: Pose(tipped + tilt @ held, tilt @ tcp.R)}, speed=style.approach_speed,
                  settle=20, label="pour")
    yield Segment({arm: over}, speed=style.approach_speed, label="unpour")
    yield from place(world, style, arm, obj, start)


def _tipped_half_height(world: World, obj: str, tilt: np.ndarray) -> float:
    """How far (m) below its centre the box around ``obj``'s asset reaches once the object
    is turned by ``tilt`` (world) from where it is now."""
    half = np.asarray(world.asset(obj).bounds.half_extents, dtype=np.float64)
    R = tilt @ world.body_pose(obj).R
    return float(np.abs(R[2, :]) @ half)


__all__ = ["plan_pour"]
