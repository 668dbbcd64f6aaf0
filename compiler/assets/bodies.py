"""A small accumulator the rigid builders share: pieces in, a `RigidAsset` out.

It also holds the two recurring constructions: a box (collision piece and its
visual) and a thin-walled shell of revolution (a ring of wall boxes per profile
segment, plus a watertight revolved visual).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
import trimesh

from ..pose import axis_angle_quat, pose_matrix, quat_mul
from .geometry import (
    MESH_SECTIONS,
    bounds_of,
    inline_mesh,
    mass_properties,
    shape_aabb,
    shape_to_trimesh,
    union_aabb,
)
from .materials import Substance, physics_material
from .model import (
    IDENTITY_QUATERNION,
    Appearance,
    BoxShape,
    ParamValue,
    Pose,
    Quat,
    RigidAsset,
    Shape,
    VisualPart,
)

WALL_SEGMENTS = 16  # wall boxes around a container; a multiple of 4 keeps the bounds exact


@dataclass
class BodyBuilder:
    """Collects collision pieces (each with its substance) and visual parts of one body."""

    kind: str
    params: Mapping[str, ParamValue]
    substance: Substance
    pieces: list[tuple[Shape, float]] = field(default_factory=list)
    visuals: list[VisualPart] = field(default_factory=list)

    def add_collision(self, shape: Shape, substance: Substance | None = None) -> None:
        self.pieces.append((shape, (substance or self.substance).density))

    def add_visual(
        self, name: str, mesh: trimesh.Trimesh, appearance: Appearance | None = None
    ) -> None:
        self.visuals.append(VisualPart(name=name, mesh=inline_mesh(mesh), appearance=appearance))

    def add_box(
        self,
        name: str,
        size: Sequence[float],
        center: Sequence[float],
        *,
        quaternion: Quat = IDENTITY_QUATERNION,
        substance: Substance | None = None,
        appearance: Appearance | None = None,
        visual: bool = True,
        collide: bool = True,
    ) -> BoxShape:
        """A box given by its full ``size`` and ``center``: a collision piece and/or a visual."""
        shape = BoxShape(
            name=name,
            pose=Pose(position=center, quaternion=quaternion),
            half_size=tuple(float(s) / 2.0 for s in size),
        )
        if collide:
            self.add_collision(shape, substance)
        if visual:
            if appearance is None and substance is not None:
                appearance = substance.appearance()
            self.add_visual(name, shape_to_trimesh(shape), appearance)
        return shape

    def finish(
        self,
        *,
        friction: float | None,
        mass: float | None = None,
        is_static: bool = False,
        support_height: float | None = None,
        cavity: Shape | None = None,
    ) -> RigidAsset:
        """The asset; ``mass`` (kg) rescales every piece's density to reach it."""
        props = mass_properties(self.pieces)
        scale = 1.0 if mass is None else float(mass) / props.mass
        lower, upper = union_aabb(
            [shape_aabb(shape) for shape, _ in self.pieces]
            + [_visual_aabb(part) for part in self.visuals]
        )
        bounds, footprint = bounds_of(lower, upper)
        total_mass = props.mass * scale
        return RigidAsset(
            kind=self.kind,
            params=dict(self.params),
            collision=[shape for shape, _ in self.pieces],
            visuals=self.visuals,
            mass=total_mass,
            center_of_mass=props.center_of_mass,
            inertia=tuple(m * scale for m in props.principal_moments),
            inertia_frame=props.principal_frame,
            material=physics_material(self.substance, friction, total_mass / props.volume),
            is_static=is_static,
            bounds=bounds,
            footprint=footprint,
            support_height=support_height,
            cavity=cavity,
        )


def _visual_aabb(part: VisualPart) -> tuple[np.ndarray, np.ndarray]:
    vertices = np.asarray(part.mesh.vertices)
    matrix = pose_matrix(part.pose)
    placed = vertices @ matrix[:3, :3].T + matrix[:3, 3]
    return placed.min(axis=0), placed.max(axis=0)


# --- shells of revolution -----------------------------------------------------------------


def revolved_shell(
    profile: Sequence[tuple[float, float]], wall: float, base: float, sections: int = MESH_SECTIONS
) -> trimesh.Trimesh:
    """A watertight open-top vessel: the outer ``profile`` (radius, z), bottom to rim,
    offset inward horizontally by ``wall``, with a floor ``base`` thick."""
    outer = [(float(r), float(z)) for r, z in profile]
    inner = [(r - wall, z) for r, z in reversed(outer) if z >= base]
    r_floor = _radius_at(outer, base) - wall
    section = [(0.0, 0.0)] + outer + inner + [(r_floor, base), (0.0, base)]
    return trimesh.creation.revolve(np.asarray(_dedupe(section)), sections=sections)


def revolved_solid(
    profile: Sequence[tuple[float, float]], sections: int = MESH_SECTIONS
) -> trimesh.Trimesh:
    """A watertight solid of revolution under the outer ``profile`` (radius, z)."""
    bottom, top = profile[0][1], profile[-1][1]
    section = [(0.0, bottom)] + [(float(r), float(z)) for r, z in profile] + [(0.0, top)]
    return trimesh.creation.revolve(np.asarray(_dedupe(section)), sections=sections)


def wall_ring(
    builder: BodyBuilder,
    name: str,
    profile: Sequence[tuple[float, float]],
    wall: float,
    base: float,
    segments: int = WALL_SEGMENTS,
) -> None:
    """Collision boxes for the walls above ``base`` of a shell with outer ``profile``.

    Per profile segment, ``segments`` boxes stand around the axis, each tangent to the
    outer surface and tilted with the segment, so objects can be put inside."""
    outer = _clip_profile(profile, base)
    for index, ((r0, z0), (r1, z1)) in enumerate(pairwise(outer)):
        length = math.hypot(r1 - r0, z1 - z0)
        tilt = math.atan2(r1 - r0, z1 - z0)  # outward lean from vertical
        thickness = wall * math.cos(tilt)
        width = 2.0 * max(r0, r1) * math.tan(math.pi / segments)
        # centre of the box in its (radial, z) half-plane: on the wall's mid-surface
        r_mid = (r0 + r1) / 2.0 - thickness / 2.0 * math.cos(tilt)
        z_mid = (z0 + z1) / 2.0 + thickness / 2.0 * math.sin(tilt)
        for k in range(segments):
            phi = 2.0 * math.pi * k / segments
            yaw = axis_angle_quat((0.0, 0.0, 1.0), phi)
            lean = axis_angle_quat((0.0, 1.0, 0.0), tilt)
            builder.add_collision(
                BoxShape(
                    name=f"{name}_{index}_{k}",
                    pose=Pose(
                        position=(r_mid * math.cos(phi), r_mid * math.sin(phi), z_mid),
                        quaternion=quat_mul(yaw, lean),
                    ),
                    half_size=(thickness / 2.0, width / 2.0, length / 2.0),
                )
            )


def _radius_at(profile: Sequence[tuple[float, float]], z: float) -> float:
    zs = [p[1] for p in profile]
    rs = [p[0] for p in profile]
    return float(np.interp(z, zs, rs))


def _clip_profile(
    profile: Sequence[tuple[float, float]], z_min: float
) -> list[tuple[float, float]]:
    kept = [(r, z) for r, z in profile if z > z_min]
    return [(_radius_at(profile, z_min), z_min)] + kept


def _dedupe(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[tuple[float, float]] = []
    for point in points:
        if not out or math.dist(out[-1], point) > 1e-9:
            out.append(point)
    return out
