"""Small closed props: block, plate, bottle, tray, cutting board, knife."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from .bodies import BodyBuilder, revolved_solid
from .geometry import inline_mesh, shape_to_trimesh
from .materials import FILLED_BOTTLE, PLATE_CERAMIC, STEEL, WOOD
from .model import ConvexMeshShape, CylinderShape, ParamValue, Pose, RigidAsset

PAINTED_WOOD = replace(WOOD, name="painted_wood", color=(0.80, 0.18, 0.15, 1.0))


def build_block(params: Mapping[str, ParamValue]) -> RigidAsset:
    sx, sy, sz = (float(v) for v in params["size"])
    body = BodyBuilder(kind="block", params=params, substance=PAINTED_WOOD)
    body.add_box("block", (sx, sy, sz), (0.0, 0.0, sz / 2.0))
    return body.finish(friction=params.get("friction"), mass=params.get("mass"), support_height=sz)


def build_plate(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A flat ceramic disc."""
    r, t = float(params["radius"]), float(params["thickness"])
    body = BodyBuilder(kind="plate", params=params, substance=PLATE_CERAMIC)
    disc = CylinderShape(
        name="plate", pose=Pose(position=(0.0, 0.0, t / 2.0)), radius=r, half_length=t / 2.0
    )
    body.add_collision(disc)
    body.add_visual("plate", shape_to_trimesh(disc))
    return body.finish(friction=params.get("friction"), mass=params.get("mass"), support_height=t)


def build_bottle(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A body cylinder, a conical shoulder (one convex piece) and a neck cylinder."""
    r, h = float(params["radius"]), float(params["height"])
    shoulder_low, shoulder_high, neck = 0.6 * h, 0.8 * h, max(0.35 * r, 0.008)
    body = BodyBuilder(kind="bottle", params=params, substance=FILLED_BOTTLE)
    body.add_collision(
        CylinderShape(
            name="body",
            pose=Pose(position=(0.0, 0.0, shoulder_low / 2.0)),
            radius=r,
            half_length=shoulder_low / 2.0,
        )
    )
    shoulder = revolved_solid([(r, shoulder_low), (neck, shoulder_high)], sections=16)
    body.add_collision(ConvexMeshShape(name="shoulder", mesh=inline_mesh(shoulder)))
    body.add_collision(
        CylinderShape(
            name="neck",
            pose=Pose(position=(0.0, 0.0, (shoulder_high + h) / 2.0)),
            radius=neck,
            half_length=(h - shoulder_high) / 2.0,
        )
    )
    profile = [(r, 0.0), (r, shoulder_low), (neck, shoulder_high), (neck, h)]
    body.add_visual("bottle", revolved_solid(profile))
    return body.finish(friction=params.get("friction"), mass=params.get("mass"))


def build_tray(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A flat base with a rim of four boxes; ``height`` is the rim's height."""
    width, depth = (float(v) for v in params["size"])
    height = float(params["height"])
    base, rim = min(0.006, height / 2.0), min(0.008, width / 6.0, depth / 6.0)
    body = BodyBuilder(kind="tray", params=params, substance=WOOD)
    look = WOOD.appearance()
    body.add_box("base", (width, depth, base), (0.0, 0.0, base / 2.0), appearance=look)
    rim_z, rim_h = (base + height) / 2.0, height - base
    # front is -x (towards the robot), back +x, left +y, right -y
    for side, name in ((-1.0, "rim_right"), (1.0, "rim_left")):
        body.add_box(
            name, (width, rim, rim_h), (0.0, side * (depth - rim) / 2.0, rim_z), appearance=look
        )
    for side, name in ((-1.0, "rim_front"), (1.0, "rim_back")):
        body.add_box(
            name,
            (rim, depth - 2 * rim, rim_h),
            (side * (width - rim) / 2.0, 0.0, rim_z),
            appearance=look,
        )
    return body.finish(
        friction=params.get("friction"), mass=params.get("mass"), support_height=base
    )


def build_cutting_board(params: Mapping[str, ParamValue]) -> RigidAsset:
    width, depth = (float(v) for v in params["size"])
    thickness = float(params["thickness"])
    body = BodyBuilder(kind="cutting_board", params=params, substance=WOOD)
    body.add_box(
        "board",
        (width, depth, thickness),
        (0.0, 0.0, thickness / 2.0),
        appearance=WOOD.appearance(),
    )
    return body.finish(
        friction=params.get("friction"), mass=params.get("mass"), support_height=thickness
    )


def build_knife(params: Mapping[str, ParamValue]) -> RigidAsset:
    """A knife lying flat along x: a wooden handle (-x) and a thin steel blade (+x)."""
    length, width = float(params["length"]), float(params["width"])
    handle_len, handle_w, handle_t = 0.4 * length, min(0.8 * width, 0.022), min(0.018, 0.8 * width)
    blade_len, blade_t = length - handle_len, 0.002
    body = BodyBuilder(kind="knife", params=params, substance=STEEL)
    x0 = -length / 2.0
    body.add_box(
        "handle",
        (handle_len, handle_w, handle_t),
        (x0 + handle_len / 2.0, 0.0, handle_t / 2.0),
        substance=WOOD,
    )
    body.add_box(
        "blade",
        (blade_len, width, blade_t),
        (x0 + handle_len + blade_len / 2.0, 0.0, handle_t / 2.0),
        substance=STEEL,
    )
    return body.finish(friction=params.get("friction"), mass=params.get("mass"))
