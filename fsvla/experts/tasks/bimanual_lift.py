"""bimanual_lift: both arms take the object's side handles and lift it together."""

from __future__ import annotations

import numpy as np

from .. import grasps
from ..motion import Segment
from ..skills import UP, Plan, close_hands_on, grip_force, opening_for, transit
from ..style import Style
from ..world import World


def plan_bimanual_lift(world: World, style: Style, roles: dict[str, str], by: float = 0.15) -> Plan:
    """Each arm takes the side handle nearer to it. Careful: both close, then lift in step
    (``require grasped(pot, left) and grasped(pot, right) before lifted(pot)``). Careless:
    each arm lifts as soon as it holds (:func:`_lift_as_each_holds`)."""
    obj = roles["object"]
    handles = {arm: _nearer_handle(world, arm, obj) for arm in world.arm_names}
    yield Segment(grippers={a: 1.0 for a in handles}, gripper_steps=style.gripper_steps,
                  label="open")
    if not style.honour_preconditions:
        yield from _lift_as_each_holds(world, style, obj, handles, by)
        return
    chosen = {arm: grasps.reach_handle(world, arm, obj, h, lift=by,
                                           avoid_hazards=style.avoid_hazards)
              for arm, h in handles.items()}
    for arm, g in chosen.items():  # one arm after the other to the pre-grasp, on the
        # IK branch from which the lines down and on to the handle are followed
        yield from transit(world, style, arm, g.pose.moved(-0.1 * g.approach), exclude=(obj,),
                           then=g.pose, follow=(g.pose, g.pose.moved(by * UP)))
    yield Segment({a: g.pose for a, g in chosen.items()}, speed=style.approach_speed,
                  label="reach handles")
    # both hands close together, each until it feels its squeeze
    yield from close_hands_on(world, style, {a: g.width for a, g in chosen.items()}, obj,
                              weight_factor=1.5)
    speed = style.approach_speed * (0.6 if style.avoid_hazards else 1.0)
    yield Segment({a: g.pose.moved(by * UP) for a, g in chosen.items()}, speed=speed,
                  settle=60, label="lift")


def _nearer_handle(world: World, arm: str, obj: str) -> str:
    """The name of ``obj``'s side handle nearer to the base of ``arm``."""
    handles = [s.name for s in world.asset(obj).collision if s.name.startswith("handle")]
    return min(handles, key=lambda h: float(np.linalg.norm(
        world.to_world(obj, world.shape(obj, h).pose.position) - world.base_position(arm))))


def _lift_as_each_holds(world: World, style: Style, obj: str, handles: dict[str, str],
                        by: float) -> Plan:
    """Careless: each arm in turn comes to its handle, closes and lifts at once, without
    waiting for the other hand (it skips the task's ``require grasped(.., left) and
    grasped(.., right) before lifted(..)``). A pot lifted by one handle tips over in the
    fingers; the next arm goes for its handle where the tipped pot now holds it (up beside
    the first hand), closes and lifts: the pot is wrenched between the two hands."""
    held = grip_force(world, obj, style, weight_factor=1.5)
    for arm, handle in handles.items():
        g = grasps.reach_handle(world, arm, obj, handle, lift=by)  # the handle as it is now
        yield from transit(world, style, arm, g.pose.moved(-0.1 * g.approach), exclude=(obj,),
                           then=g.pose, follow=(g.pose,))
        yield Segment({arm: g.pose}, speed=style.approach_speed, label="reach handle")
        yield Segment(grippers={arm: opening_for(world, arm, g.width, held)},
                      gripper_steps=style.gripper_steps, settle=style.settle, label="close")
        yield Segment({arm: g.pose.moved(by * UP)}, speed=style.approach_speed, settle=20,
                      label="lift")


__all__ = ["plan_bimanual_lift"]
