"""Static fixtures: table, shelf, stove, socket panel. Collision: boxes only.

Frame: +x away from the robot, +y to its left, z up; a front faces -x (the robot).
"""

from __future__ import annotations

from collections.abc import Mapping

from .bodies import BodyBuilder
from .geometry import shape_to_trimesh
from .materials import ENAMEL, HOT_GLOW, LAMINATE, PLASTIC, WOOD
from .model import CylinderShape, ParamValue, Pose, RigidAsset

PLATE_GLOW_RADIUS_FRACTION = 0.35  # heating plate radius / smaller side of the stove


def _legs(
    body: BodyBuilder, width: float, depth: float, height: float, leg: float, inset: float
) -> None:
    for ix, sx in enumerate((-1.0, 1.0)):
        for iy, sy in enumerate((-1.0, 1.0)):
            x = sx * (width / 2.0 - inset - leg / 2.0)
            y = sy * (depth / 2.0 - inset - leg / 2.0)
            body.add_box(f"leg_{ix}{iy}", (leg, leg, height), (x, y, height / 2.0), substance=WOOD)


def build_table(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A table: a top slab on four legs; its origin is on the floor, its top at ``height``."""
    width, depth = (float(v) for v in params["size"])
    height = float(params["height"])
    top = min(0.04, 0.2 * height)
    body = BodyBuilder(kind="table", params=params, substance=LAMINATE)
    body.add_box(
        "top", (width, depth, top), (0.0, 0.0, height - top / 2.0), appearance=LAMINATE.appearance()
    )
    _legs(body, width, depth, height - top, leg=0.05, inset=0.04)
    return body.finish(friction=params.get("friction"), is_static=True, support_height=height)


def build_shelf(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A raised platform: a slab on four legs, or a solid block when low or narrow."""
    width, depth = (float(v) for v in params["size"])
    height = float(params["height"])
    body = BodyBuilder(kind="shelf", params=params, substance=WOOD)
    slab, leg = 0.02, 0.02
    if height < 0.06 or min(width, depth) < 4 * leg:
        body.add_box(
            "block", (width, depth, height), (0.0, 0.0, height / 2.0), appearance=WOOD.appearance()
        )
    else:
        body.add_box(
            "top",
            (width, depth, slab),
            (0.0, 0.0, height - slab / 2.0),
            appearance=WOOD.appearance(),
        )
        _legs(body, width, depth, height - slab, leg=leg, inset=0.0)
    return body.finish(friction=params.get("friction"), is_static=True, support_height=height)


def build_stove(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A low enamel box with a glowing (emissive red-orange) heating plate on top."""
    width, depth = (float(v) for v in params["size"])
    height = float(params["height"])
    body = BodyBuilder(kind="stove", params=params, substance=ENAMEL)
    body.add_box(
        "body", (width, depth, height), (0.0, 0.0, height / 2.0), appearance=ENAMEL.appearance()
    )
    plate_radius = PLATE_GLOW_RADIUS_FRACTION * min(width, depth)
    plate = CylinderShape(
        name="heating_plate",
        pose=Pose(position=(0.0, 0.0, height)),
        radius=plate_radius,
        half_length=0.001,
    )
    glow = ENAMEL.appearance(color=(0.9, 0.25, 0.05, 1.0), emission=HOT_GLOW)
    body.add_visual("heating_plate", shape_to_trimesh(plate), glow)
    return body.finish(friction=params.get("friction"), is_static=True, support_height=height)


def build_socket_panel(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A foot plate with an upright panel at its back (+x); the outlet faces -x (the robot).

    ``size`` is (depth along x, width along y), as for every asset; the panel spans the
    width.
    """
    depth, width = (float(v) for v in params["size"])
    height = float(params["height"])
    foot, thickness = min(0.01, height / 4.0), min(0.02, depth / 2.0)
    body = BodyBuilder(kind="socket_panel", params=params, substance=PLASTIC)
    white = PLASTIC.appearance(color=(0.93, 0.93, 0.9, 1.0))
    body.add_box("foot", (depth, width, foot), (0.0, 0.0, foot / 2.0), appearance=white)
    panel_x = depth / 2.0 - thickness / 2.0
    body.add_box(
        "panel",
        (thickness, width, height - foot),
        (panel_x, 0.0, (height + foot) / 2.0),
        appearance=white,
    )
    # the outlet: a faceplate on the panel's front (-x) face, two slots and an earth hole
    face_w, face_h = 0.7 * width, min(0.6 * (height - foot), 0.9 * width)
    face_z = foot + (height - foot) * 0.55
    front_x = depth / 2.0 - thickness
    body.add_box(
        "faceplate",
        (0.003, face_w, face_h),
        (front_x - 0.0015, 0.0, face_z),
        appearance=PLASTIC.appearance(color=(0.98, 0.98, 0.96, 1.0)),
    )
    dark = PLASTIC.appearance(color=(0.05, 0.05, 0.05, 1.0))
    slot_w, slot_h = 0.08 * face_w, 0.3 * face_h
    for side, name in ((1.0, "slot_left"), (-1.0, "slot_right")):  # left is +y
        body.add_box(
            name,
            (0.001, slot_w, slot_h),
            (front_x - 0.0035, side * 0.2 * face_w, face_z + 0.1 * face_h),
            appearance=dark,
            collide=False,
        )
    body.add_box(
        "earth",
        (0.001, slot_w * 1.5, slot_w * 1.5),
        (front_x - 0.0035, 0.0, face_z - 0.25 * face_h),
        appearance=dark,
        collide=False,
    )
    return body.finish(friction=params.get("friction"), is_static=True)
