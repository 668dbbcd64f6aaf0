"""insert: open the container (a drawer, or a lid), put the object in, close it."""

from __future__ import annotations

import numpy as np

from .. import grasps
from ..skills import (
    DOWN,
    UP,
    Plan,
    carrying_arm,
    held_offset,
    nearest_arm,
    park_others,
    pick,
    place,
)
from ..style import Style
from ..world import World
from .cavity import place_in_cavity
from .common import HAND_BOTTOM, HAND_HALF_LENGTH, required_fraction, retreat_home
from .hinge import knob_pinch_fits, swing_lid
from .lid import LID_PAST_VERTICAL, lift_lid
from .open_close import part_handle, plan_move_part
from .pick_place import plan_pick_place


def _open_front_box(world: World, body: str, fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """The xy box the part's front sweeps when it opens to ``fraction`` (across: the
    body's width), grown by a hand's length."""
    centre, opening, travel, _ = part_handle(world, body)
    lo, hi = world.bounds(body)
    reach = centre + opening * (fraction - world.open_fraction(body)) * travel
    along = np.abs(opening[:2]) >= 0.5  # the axis the part slides along
    box_lo = np.where(along, np.minimum(centre[:2], reach[:2]), lo[:2])
    box_hi = np.where(along, np.maximum(centre[:2], reach[:2]), hi[:2])
    return box_lo - HAND_HALF_LENGTH - 0.03, box_hi + HAND_HALF_LENGTH + 0.03


def _blocked_by_open_part(world: World, body: str, obj: str, fraction: float) -> bool:
    """Whether grasping ``obj`` would put the hand where the opened part will be."""
    lo, hi = _open_front_box(world, body, fraction)
    p = world.body_pose(obj).p[:2]
    return bool(np.all(p >= lo) and np.all(p <= hi))


def _stage(world: World, style: Style, obj: str, body: str) -> Plan:
    """Move ``obj`` out of the way of ``body``'s part before it opens (careful only):
    sideways, beside the body, turned so that the hand that takes it again lies along the
    part's front rather than across it."""
    pose = world.body_pose(obj)
    _, opening, _, _ = part_handle(world, body)
    lo, hi = world.bounds(body)
    side = np.cross(UP, opening)
    centre = 0.5 * (lo + hi)
    sign = 1.0 if (pose.p - centre) @ side >= 0 else -1.0
    half = 0.5 * float(np.abs(side[:2]) @ (hi - lo)[:2])
    spot = pose.p + side * (sign * (half + 0.09) - (pose.p - centre) @ side)
    arm = nearest_arm(world, pose.p)
    yield from pick(world, style, arm, obj, grasps.choose(world, style, arm, obj))
    R = world.grasp_frame(arm, DOWN, side)
    yield from place(world, style, arm, obj, np.array([spot[0], spot[1], pose.p[2]]), rotation=R)


def plan_insert(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Open the container's part (careful: past every fraction a requirement asks for;
    careless: just far enough), put the object in, let go, close the part."""
    obj, target = roles["object"], roles["target"]
    asset = world.asset(target)
    if not getattr(asset, "parts", None):
        if getattr(asset, "cavity", None) is not None:  # a pot, a bowl, a mug: into it
            yield from _insert_into_cavity(world, style, obj, target)
        else:
            yield from plan_pick_place(world, style, roles)
        return
    part, joint = world.part(target)
    if joint.type == "revolute" and part.name == "lid":
        yield from _insert_under_lid(world, style, obj, target)
        return
    if joint.type != "prismatic":
        raise NotImplementedError(
            f"the experts cannot yet insert into `{target}` through its {joint.type} "
            f"`{part.name}` (a hinged door): they open drawers and lift lids")
    need = required_fraction(world, target)
    # careful: past the largest fraction a requirement asks for, but short of the end of
    # travel (a Panda pulling the handle that far folds onto its own base)
    fraction = min(0.85, need + 0.07) if style.honour_preconditions else max(0.3, need - 0.2)
    if style.avoid_hazards and _blocked_by_open_part(world, target, obj, fraction):
        yield from _stage(world, style, obj, target)
    yield from plan_move_part(world, style, target, fraction)
    arm = carrying_arm(world, obj, target)
    grasp = grasps.choose(world, style, arm, obj)
    yield from pick(world, style, arm, obj, grasp)
    _, opening, _, _ = part_handle(world, target)
    part, _joint = world.part(target)
    link = world.link_pose(target, part.link)
    shapes = next(lk for lk in asset.links if lk.name == part.link).collision
    floor = next(s for s in shapes if s.name == "floor")
    front = next(s for s in shapes if s.name == "front")
    floor_top = link.p[2] + floor.pose.position[2] + floor.half_size[2]
    # Lay the object across the drawer, fingers closing along the drawer's travel. The
    # hand is longer along its finger axis (2 × HAND_HALF_LENGTH) than a drawer's travel,
    # so it lets go above the cabinet's top and the object drops into the open mouth.
    R = world.grasp_frame(arm, DOWN, opening)
    inner = link.p + link.R @ np.array([front.pose.position[0] + front.half_size[0], 0.0, 0.0])
    lo, hi = world.bounds(target)
    mouth = float(opening @ inner) - max(float(opening @ lo), float(opening @ hi))  # open length
    tcp_x = inner - opening * 0.5 * mouth
    offset = R @ held_offset(world, arm, obj)
    clear = world.bounds(target)[1][2] + (HAND_BOTTOM + 0.015) - offset[2]
    bottom = np.array([tcp_x[0] - offset[0], link.p[1], max(floor_top + 0.003, clear)])
    if abs(opening[0]) < abs(opening[1]):  # a drawer that slides along y
        bottom = np.array([link.p[0], tcp_x[1] - offset[1], bottom[2]])
    yield from place(world, style, arm, obj, bottom, rotation=R, retreat=0.08)
    yield from plan_move_part(world, style, target, 0.0)


def _insert_into_cavity(world: World, style: Style, obj: str, target: str) -> Plan:
    """An open container: pick the object and put it in the container's cavity (``inside``
    tests the cavity). Careful: let go as low as the hand stays clear of the container
    (:func:`~.cavity.place_in_cavity`: a Panda hand is wider than a pot's mouth); careless:
    set down on the cavity's floor, the hand landing on the rim where it is too wide."""
    arm = carrying_arm(world, obj, target)
    yield from pick(world, style, arm, obj, grasps.choose(world, style, arm, obj))
    if style.avoid_hazards:  # the hand stays clear of the rim; the object drops the rest
        yield from place_in_cavity(world, style, arm, obj, target)
        return
    # careless: onto the floor, the hand down into the mouth whatever it meets
    cavity = world.asset(target).cavity
    centre = world.to_world(target, cavity.pose.position)
    floor = float(centre[2]) - float(getattr(cavity, "half_length", 0.0))
    yield from place(world, style, arm, obj, np.array([centre[0], centre[1], floor]))
    yield from retreat_home(world, style, arm)


def _insert_under_lid(world: World, style: Style, obj: str, target: str) -> Plan:
    """A lidded container: lift the lid (careful: past vertical, where it stays open;
    careless: only as far as asked less 0.2, and it falls shut), then pick the object.
    Careful: let it go over the floor as low as the hand stays clear of the walls and the
    lid (:func:`~.cavity.place_in_cavity`); careless: from the height of the box's top,
    the hand's long axis along the box's longer side (a Panda hand is 21 cm long)."""
    _part, joint = world.part(target)
    span = joint.upper - joint.lower
    need = required_fraction(world, target)
    if style.honour_preconditions:
        angle = max(LID_PAST_VERTICAL, (need + 0.07) * span)
    else:
        angle = max(0.3, need - 0.2) * span
    angle = min(angle, 0.95 * span)
    if _knob_height(world, target) < KNOB_LIFTED_FROM_BELOW and knob_pinch_fits(world, target):
        # too low for the hand upright under the knob (it meets the table): pinched by its
        # ends, as `open` does, and past upright (held short of it, it would keep the hand);
        # fingers too thick to hold the knob's ends lift it from below instead, as `open`'s
        yield from swing_lid(world, style, target, angle,
                             missed=lambda: lift_lid(world, style, target, angle))
    else:
        yield from lift_lid(world, style, target, angle)
    arm = carrying_arm(world, obj, target)
    # the arm that lifted the lid stands over the box the other carries to: out of its way
    yield from park_others(world, style, arm, (world.body_pose(obj).p, world.body_pose(target).p))
    yield from pick(world, style, arm, obj, grasps.choose(world, style, arm, obj))
    if style.avoid_hazards:  # as into an open container (:func:`_insert_into_cavity`)
        # careful: let go as low as the hand stays clear of the walls and of the lid
        # standing open over them (a Panda hand is longer than most boxes are wide)
        yield from place_in_cavity(world, style, arm, obj, target)
        yield from retreat_home(world, style, arm)
        return
    # careless: over the middle of the floor, let go from the height of the box's top
    body = world.asset(target).links[0].name
    floor = world.shape(target, "bottom", link=body)
    root = world.body_pose(target)
    centre = root.R @ np.asarray(floor.pose.position) + root.p
    lo, hi = world.bounds(target)
    longer = root.R[:, 0] if hi[0] - lo[0] >= hi[1] - lo[1] else root.R[:, 1]
    R = world.grasp_frame(arm, DOWN, longer)
    yield from place(world, style, arm, obj, np.array([centre[0], centre[1], float(hi[2])]),
                     rotation=R, retreat=0.1)
    yield from retreat_home(world, style, arm)


#: The least height (m) of a lid's knob above the table at which the hand lifts it from
#: below (:func:`~.lid.lift_lid`: the upright Panda hand under it is 21 cm tall); a lower
#: one is pinched by its ends (:func:`~.hinge.swing_lid`).
KNOB_LIFTED_FROM_BELOW = 0.11


def _knob_height(world: World, body: str) -> float:
    """How high (m) above the table the bottom of a lid's knob is now."""
    part, _joint = world.part(body)
    knob = world.shape(body, "knob", link=part.link)
    link = world.link_pose(body, part.link)
    centre = link.p + link.R @ np.asarray(knob.pose.position, dtype=np.float64)
    return float(centre[2] - np.abs(link.R[2, :]) @ np.asarray(knob.half_size, dtype=np.float64))


__all__ = ["plan_insert"]
