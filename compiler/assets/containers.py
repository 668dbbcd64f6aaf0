"""Hollow containers: pot, mug, glass, bowl, vase, kettle.

Each is a thin-walled shell of revolution. Collision: a base disc (cylinder) plus a
ring of ``WALL_SEGMENTS`` wall boxes per profile segment, so objects fit inside;
handles and spouts are boxes and cylinders. Visual: a watertight revolved shell.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from ..pose import axis_angle_quat
from .bodies import BodyBuilder, revolved_shell, wall_ring
from .geometry import shape_to_trimesh
from .materials import ALUMINIUM, CERAMIC, GLASS, PLASTIC, Substance
from .model import CylinderShape, ParamValue, Pose, RigidAsset

Profile = Sequence[tuple[float, float]]  # (outer radius, z), bottom to rim


def _shell(
    kind: str,
    params: Mapping[str, ParamValue],
    substance: Substance,
    profile: Profile,
    wall: float,
    base: float,
) -> BodyBuilder:
    """A builder holding a shell's base disc, wall ring and revolved visual."""
    r_bottom = profile[0][0]
    if min(r for r, _ in profile) <= wall:
        raise ValueError(f"{kind}: wall {wall} m is too thick for radius {r_bottom} m")
    body = BodyBuilder(kind=kind, params=params, substance=substance)
    body.add_collision(
        CylinderShape(
            name="base",
            pose=Pose(position=(0.0, 0.0, base / 2.0)),
            radius=r_bottom,
            half_length=base / 2.0,
        )
    )
    wall_ring(body, "wall", profile, wall, base)
    body.add_visual("shell", revolved_shell(profile, wall, base))
    return body


def _cavity(radius: float, base: float, height: float) -> CylinderShape:
    return CylinderShape(
        name="cavity",
        pose=Pose(position=(0.0, 0.0, (base + height) / 2.0)),
        radius=radius,
        half_length=(height - base) / 2.0,
    )


def _loop_handle(
    body: BodyBuilder,
    side: float,
    attach_r: tuple[float, float],
    z_low: float,
    z_high: float,
    reach: float,
    bar: float,
    width: float,
) -> None:
    """A C-shaped handle of three boxes on the +x (side=1) or -x (side=-1) side."""
    look = PLASTIC.appearance() if body.substance is ALUMINIUM else None
    outer = max(attach_r) + reach
    for name, z, r_attach in (
        ("handle_low", z_low, attach_r[0]),
        ("handle_high", z_high, attach_r[1]),
    ):
        start = r_attach - bar
        body.add_box(
            name,
            (outer - start, width, bar),
            (side * (start + outer) / 2.0, 0.0, z),
            appearance=look,
        )
    body.add_box(
        "handle_grip",
        (bar, width, z_high - z_low + bar),
        (side * (outer - bar / 2.0), 0.0, (z_low + z_high) / 2.0),
        appearance=look,
    )


def build_pot(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h, wall = float(params["radius"]), float(params["height"]), float(params["wall"])
    base = max(wall, 0.004)
    body = _shell("pot", params, ALUMINIUM, [(r, 0.0), (r, h)], wall, base)
    reach, grip = max(0.025, 0.25 * r), min(0.05, 0.8 * r)
    bar = min(0.012, 0.2 * h)
    # the side handles stick out to the robot's left (+y) and right (-y)
    for side, name in ((-1.0, "handle_right"), (1.0, "handle_left")):
        body.add_box(
            name,
            (grip, reach + wall, bar),
            (0.0, side * (r + (reach - wall) / 2.0), h - 1.5 * bar),
            substance=PLASTIC,
        )
    return body.finish(
        friction=params.get("friction"), mass=params.get("mass"), cavity=_cavity(r - wall, base, h)
    )


def build_mug(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h = float(params["radius"]), float(params["height"])
    wall, base = min(0.005, 0.15 * r), min(0.008, 0.15 * h)
    body = _shell("mug", params, CERAMIC, [(r, 0.0), (r, h)], wall, base)
    _loop_handle(
        body,
        1.0,
        (r, r),
        0.3 * h,
        0.8 * h,
        reach=max(0.02, 0.5 * r),
        bar=min(0.01, 0.1 * h),
        width=min(0.014, 0.4 * r),
    )
    return body.finish(
        friction=params.get("friction"), mass=params.get("mass"), cavity=_cavity(r - wall, base, h)
    )


def build_glass(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h = float(params["radius"]), float(params["height"])
    wall, base = min(0.003, 0.1 * r), min(0.01, 0.15 * h)
    profile = [(0.85 * r, 0.0), (r, h)]
    body = _shell("glass", params, GLASS, profile, wall, base)
    return body.finish(
        friction=params.get("friction"),
        mass=params.get("mass"),
        cavity=_cavity(0.85 * r - wall, base, h),
    )


def build_bowl(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h = float(params["radius"]), float(params["height"])
    wall, base = min(0.005, 0.08 * r), min(0.006, 0.15 * h)
    profile = [(0.55 * r, 0.0), (0.85 * r, 0.45 * h), (r, h)]
    body = _shell("bowl", params, CERAMIC, profile, wall, base)
    return body.finish(
        friction=params.get("friction"),
        mass=params.get("mass"),
        cavity=_cavity(0.55 * r - wall, base, h),
    )


def build_vase(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h = float(params["radius"]), float(params["height"])
    wall, base = min(0.005, 0.1 * r), min(0.01, 0.1 * h)
    profile = [(0.65 * r, 0.0), (r, 0.4 * h), (0.55 * r, 0.8 * h), (0.7 * r, h)]
    body = _shell("vase", params, CERAMIC, profile, wall, base)
    return body.finish(
        friction=params.get("friction"),
        mass=params.get("mass"),
        cavity=_cavity(0.55 * r - wall, base, h),
    )


def build_kettle(params: Mapping[str, ParamValue]) -> RigidAsset:
    r, h = float(params["radius"]), float(params["height"])
    wall, base = 0.003, min(0.005, 0.05 * h)
    profile = [(0.9 * r, 0.0), (r, 0.35 * h), (0.75 * r, h)]
    body = _shell("kettle", params, ALUMINIUM, profile, wall, base)

    def radius_at(z: float) -> float:
        return (
            r * (0.9 + 0.1 * z / (0.35 * h))
            if z <= 0.35 * h
            else r * (1.0 - 0.25 * (z - 0.35 * h) / (0.65 * h))
        )

    z_low, z_high = 0.3 * h, 0.85 * h
    _loop_handle(
        body,
        -1.0,
        (radius_at(z_low), radius_at(z_high)),
        z_low,
        z_high,
        reach=max(0.03, 0.4 * r),
        bar=0.012,
        width=0.02,
    )
    _add_spout(
        body,
        start=(radius_at(0.3 * h) - wall, 0.3 * h),
        radius=max(0.008, 0.12 * r),
        length=0.6 * r + 0.2 * h,
    )
    return body.finish(
        friction=params.get("friction"),
        mass=params.get("mass"),
        cavity=_cavity(0.75 * r - wall, base, h),
    )


def _add_spout(body: BodyBuilder, start: tuple[float, float], radius: float, length: float) -> None:
    """A cylinder leaving the +x wall at 45° upward."""
    angle = math.pi / 4.0
    direction = (math.sin(angle), 0.0, math.cos(angle))
    centre = (start[0] + direction[0] * length / 2.0, 0.0, start[1] + direction[2] * length / 2.0)
    spout = CylinderShape(
        name="spout",
        pose=Pose(position=centre, quaternion=axis_angle_quat((0, 1, 0), angle)),
        radius=radius,
        half_length=length / 2.0,
    )
    body.add_collision(spout)
    body.add_visual("spout", shape_to_trimesh(spout))
