"""handover: one arm picks the object and holds it out, the other takes it and puts it down."""

from __future__ import annotations

import numpy as np

from .. import grasps
from ..motion import Pose, Segment
from ..skills import (
    UP,
    Plan,
    free_speed,
    grasp_lever,
    grip_force,
    horizontal,
    nearest_arm,
    opening_for,
    pick,
    place,
    top_down_grasp,
    transit,
)
from ..style import Style
from ..world import World
from .common import place_point, retreat_home

#: An object at least this long (m) is handed over by its two ends, both hands from
#: above (two Panda hands side by side need 2 × HAND_HALF_WIDTH and a margin).
LONG_ENOUGH = 0.15

#: How far from an end (m) each hand holds a long object.
END_GRASP = 0.025


#: How far (m) the hands meet in front of their home positions when the arms reach the
#: same way (side by side, as Baxter's): out where the arms' links stay apart.
MEET_AHEAD = 0.15


def meeting_point(world: World, giver: str, taker: str) -> np.ndarray:
    """Where the hands meet: halfway between the arms' home TCPs, moved out along the way
    both arms reach (arms facing each other reach opposite ways: halfway between them; arms
    side by side behind the table: in front of the robot, where their links stay apart)."""
    homes = [world.home_position(arm) for arm in (giver, taker)]
    ahead = np.mean([horizontal(h - world.base_position(arm))
                     for arm, h in zip((giver, taker), homes)], axis=0)
    return 0.5 * (homes[0] + homes[1]) + MEET_AHEAD * ahead


def plan_handover(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """The arm nearer the object picks it, brings it over the middle of the table; the other
    arm takes it from the side, the first lets go and backs off, the second puts it on the
    scenario's support (the first other object with a top), else back on the table."""
    obj = roles["object"]
    giver = nearest_arm(world, world.body_pose(obj).p)
    taker = next(a for a in world.arm_names if a != giver)
    lo, hi = world.bounds(obj)
    if float(np.max((hi - lo)[:2])) >= LONG_ENOUGH:
        yield from _handover_by_the_ends(world, style, obj, giver, taker)
        return
    grasp = grasps.choose(world, style, giver, obj)
    yield from pick(world, style, giver, obj, grasp)
    lo, hi = world.bounds(obj)
    size = hi - lo
    mid = meeting_point(world, giver, taker)
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    centre = np.array([mid[0], mid[1], height])
    tcp = world.current_pose(giver)
    offset = tcp.p - 0.5 * (world.bounds(obj)[0] + world.bounds(obj)[1])
    giver_goal = Pose(centre + np.array([0.0, 0.0, max(offset[2], 0.3 * size[2] / 2 + 0.008)]),
                      tcp.R)
    yield from transit(world, style, giver, giver_goal, below=0.05, exclude=(obj,))
    towards = horizontal(centre - world.home_position(taker))
    closing = tcp.R @ world.finger_axis(giver)
    R = world.grasp_frame(taker, towards, closing)
    take = Pose(centre - np.array([0.0, 0.0, 0.3 * size[2]]) - towards * 0.004, R)
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    yield from transit(world, style, taker, take.moved(-0.12 * towards), below=0.05, exclude=(obj,))
    yield Segment({taker: take}, speed=style.approach_speed, label="to block")
    held = grip_force(world, obj, style)
    width = float(abs(closing @ size))
    yield Segment(grippers={taker: opening_for(world, taker, width, held)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="take")
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    yield Segment({giver: back.moved(0.1 * UP)}, speed=style.approach_speed, label="giver up")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    if support is not None:
        spot = place_point(world, style, obj, support)
    else:
        spot = np.array([centre[0], centre[1], 0.0])
    yield from place(world, style, taker, obj, spot)
    yield from retreat_home(world, style, taker)


def _handover_by_the_ends(world: World, style: Style, obj: str, giver: str, taker: str) -> Plan:
    """A long object: the giver takes the end nearer to it from above, brings the object
    over the middle (its long axis from arm to arm), the taker takes the other end from
    above, the giver lets go and backs off, the taker puts it on the support. A Panda can
    hold out a top-down hand there; a hand pointing sideways at the object it cannot."""
    shape = world.asset(obj).collision[0]
    half = np.asarray(shape.half_size, dtype=np.float64)
    pose = world.body_pose(obj)
    axis = int(np.argmax(half[:2]))
    along, across = pose.R[:, axis], pose.R[:, 1 - axis]
    centre = world.to_world(obj, shape.pose.position)
    reach = float(half[axis]) - END_GRASP
    side = 1.0 if along @ (world.base_position(giver) - centre) >= 0 else -1.0
    lift = np.array([0.0, 0.0, 0.3 * half[2]])
    width = 2 * float(half[1 - axis])
    grasp = top_down_grasp(world, giver, centre + side * reach * along + lift, across, width)
    yield from pick(world, style, giver, obj, grasp)
    mid = meeting_point(world, giver, taker)
    height = max([o.hi[2] + o.margin + style.hazard_clearance for o in world.obstacles((obj,))]
                 + [0.1]) + 0.12
    held = world.current_pose(giver)
    now = world.to_world(obj, shape.pose.position)
    goal = Pose(np.array([mid[0], mid[1], height]) + (held.p - now), held.R)
    yield from transit(world, style, giver, goal, below=0.05, exclude=(obj,))
    now = world.to_world(obj, shape.pose.position)
    along = world.body_pose(obj).R[:, axis]
    across = world.body_pose(obj).R[:, 1 - axis]
    side = 1.0 if along @ (world.base_position(taker) - now) >= 0 else -1.0
    take = top_down_grasp(world, taker, now + side * reach * along + lift, across, width)
    yield Segment(grippers={taker: 1.0}, gripper_steps=style.gripper_steps, label="open taker")
    yield from transit(world, style, taker, take.pose.moved(0.1 * UP), exclude=(obj,),
                       then=take.pose)
    yield Segment({taker: take.pose.moved(0.02 * UP)}, speed=style.approach_speed, label="to end")
    yield Segment({taker: take.pose}, speed=0.5 * style.approach_speed, label="to end")
    # the taker ends up holding the object alone, by its end: firm enough not to pivot
    gripped = grip_force(world, obj, style, lever=grasp_lever(world, taker, obj, take.pose))
    yield Segment(grippers={taker: opening_for(world, taker, width, gripped)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="take")
    yield Segment(grippers={giver: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="give")
    back = world.current_pose(giver)
    home = horizontal(world.base_position(giver) - back.p)
    yield Segment({giver: back.moved(0.08 * UP)}, speed=style.approach_speed, label="giver up")
    yield Segment({giver: back.moved(0.08 * UP + 0.12 * home)}, speed=free_speed(style),
                  label="giver back")
    support = next((b.name for b in world.scene.bodies if b.name not in ("table", obj)
                    and getattr(b.asset, "support_height", None) is not None), None)
    spot = (place_point(world, style, obj, support) if support is not None
            else np.array([mid[0], mid[1], 0.0]))
    # let go with the fingers 1 cm clear: no contact flicker that reads as a new grasp
    yield from place(world, style, taker, obj, spot, release_gap=0.01)
    yield from retreat_home(world, style, taker)


__all__ = ["END_GRASP", "LONG_ENOUGH", "plan_handover"]
