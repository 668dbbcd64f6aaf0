"""Geometry of shapes: meshes, bounding boxes and mass properties.

Pure functions over the models of :mod:`.model`; numpy and trimesh only (rotations come
from :mod:`fsvla.compiler.pose`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import trimesh

from ..pose import matrix_to_quat, pose_matrix, quat_to_matrix
from .model import (
    Bounds,
    BoxShape,
    CapsuleShape,
    ConvexMeshShape,
    CylinderShape,
    Footprint,
    InlineMesh,
    MeshFile,
    Quat,
    Shape,
    SphereShape,
    Vec3,
)

MESH_SECTIONS = 32  # facets around a visual cylinder or revolved profile; a multiple of 4


# --- meshes -----------------------------------------------------------------------------


def inline_mesh(mesh: trimesh.Trimesh) -> InlineMesh:
    """A trimesh as inline spec data (plain float and int lists)."""
    return InlineMesh(
        vertices=[tuple(v) for v in mesh.vertices.tolist()],
        faces=[tuple(f) for f in mesh.faces.tolist()],
    )


def load_mesh_source(source: InlineMesh | MeshFile) -> trimesh.Trimesh:
    if isinstance(source, InlineMesh):
        return trimesh.Trimesh(
            np.asarray(source.vertices, dtype=float),
            np.asarray(source.faces, dtype=np.int64),
            process=False,
        )
    mesh = trimesh.load(source.path, force="mesh")
    mesh.apply_scale(np.asarray(source.scale, dtype=float))
    return mesh


def shape_to_trimesh(shape: Shape, sections: int = MESH_SECTIONS) -> trimesh.Trimesh:
    """A triangle mesh of a shape, placed by its pose in the body frame."""
    if isinstance(shape, BoxShape):
        mesh = trimesh.creation.box(extents=2.0 * np.asarray(shape.half_size))
    elif isinstance(shape, CylinderShape):
        mesh = trimesh.creation.cylinder(
            radius=shape.radius, height=2.0 * shape.half_length, sections=sections
        )
    elif isinstance(shape, CapsuleShape):
        mesh = trimesh.creation.capsule(
            height=2.0 * shape.half_length, radius=shape.radius, count=[sections, sections]
        )
    elif isinstance(shape, SphereShape):
        mesh = trimesh.creation.icosphere(subdivisions=3, radius=shape.radius)
    elif isinstance(shape, ConvexMeshShape):
        mesh = load_mesh_source(shape.mesh).convex_hull
    else:  # pragma: no cover - the union is closed
        raise TypeError(f"not a shape: {shape!r}")
    mesh.apply_transform(pose_matrix(shape.pose))
    return mesh


# --- bounding boxes ---------------------------------------------------------------------


def shape_aabb(shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """The exact axis-aligned bounds (lower, upper) of a shape in the body frame."""
    rotation = quat_to_matrix(shape.pose.quaternion)
    centre = np.asarray(shape.pose.position, dtype=float)
    if isinstance(shape, BoxShape):
        half = np.abs(rotation) @ np.asarray(shape.half_size)
    elif isinstance(shape, (CylinderShape, CapsuleShape)):
        axis = rotation[:, 2]
        radial = np.sqrt(np.clip(1.0 - axis**2, 0.0, 1.0))
        if isinstance(shape, CylinderShape):
            half = shape.half_length * np.abs(axis) + shape.radius * radial
        else:
            half = shape.half_length * np.abs(axis) + shape.radius
    elif isinstance(shape, SphereShape):
        half = np.full(3, shape.radius)
    else:
        vertices = shape_to_trimesh(shape).vertices
        return vertices.min(axis=0), vertices.max(axis=0)
    return centre - half, centre + half


def union_aabb(boxes: Iterable[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    lows, highs = zip(*boxes)
    return np.min(lows, axis=0), np.max(highs, axis=0)


def bounds_of(lower: np.ndarray, upper: np.ndarray) -> tuple[Bounds, Footprint]:
    centre = (lower + upper) / 2.0
    half = (upper - lower) / 2.0
    bounds = Bounds(center=_vec3(centre), half_extents=_vec3(half))
    footprint = Footprint(
        min_xy=(float(lower[0]), float(lower[1])), max_xy=(float(upper[0]), float(upper[1]))
    )
    return bounds, footprint


def _vec3(values: np.ndarray) -> Vec3:
    return (float(values[0]), float(values[1]), float(values[2]))


# --- mass properties --------------------------------------------------------------------


@dataclass(frozen=True)
class MassProperties:
    mass: float
    volume: float
    center_of_mass: Vec3
    principal_moments: Vec3
    principal_frame: Quat


def _local_volume_and_inertia(shape: Shape) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid and unit-density inertia tensor about the centroid, shape frame."""
    if isinstance(shape, BoxShape):
        a, b, c = 2.0 * np.asarray(shape.half_size)
        volume = a * b * c
        return (
            volume,
            np.zeros(3),
            volume / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b]),
        )
    if isinstance(shape, CylinderShape):
        r, length = shape.radius, 2.0 * shape.half_length
        volume = np.pi * r * r * length
        side = volume * (3 * r * r + length * length) / 12.0
        return volume, np.zeros(3), np.diag([side, side, volume * r * r / 2.0])
    if isinstance(shape, SphereShape):
        volume = 4.0 / 3.0 * np.pi * shape.radius**3
        return volume, np.zeros(3), np.eye(3) * 0.4 * volume * shape.radius**2
    if isinstance(shape, CapsuleShape):
        r, length = shape.radius, 2.0 * shape.half_length
        v_cyl, v_caps = np.pi * r * r * length, 4.0 / 3.0 * np.pi * r**3
        axial = v_cyl * r * r / 2.0 + v_caps * 0.4 * r * r
        side = v_cyl * (length**2 / 12.0 + r * r / 4.0) + v_caps * (
            0.4 * r * r + length**2 / 4.0 + 3.0 * length * r / 8.0
        )
        return v_cyl + v_caps, np.zeros(3), np.diag([side, side, axial])
    hull = load_mesh_source(shape.mesh).convex_hull
    return float(hull.volume), np.asarray(hull.center_mass), np.asarray(hull.moment_inertia)


def mass_properties(pieces: Sequence[tuple[Shape, float]]) -> MassProperties:
    """Mass, centre of mass and principal inertia of (shape, density) pieces.

    Overlaps between pieces are counted twice; builders keep them small.
    """
    mass, volume, centre, inertia = inertia_tensor(pieces)
    moments, frame = principal_axes(inertia)
    return MassProperties(
        mass=mass,
        volume=volume,
        center_of_mass=_vec3(centre),
        principal_moments=_vec3(np.maximum(moments, 1e-12)),
        principal_frame=frame,
    )


def inertia_tensor(
    pieces: Sequence[tuple[Shape, float]],
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Mass, volume, centre of mass and the 3×3 inertia tensor about it (body axes)."""
    masses, centres, tensors, volume = [], [], [], 0.0
    for shape, density in pieces:
        piece_volume, local_centroid, local_inertia = _local_volume_and_inertia(shape)
        rotation = quat_to_matrix(shape.pose.quaternion)
        masses.append(piece_volume * density)
        centres.append(rotation @ local_centroid + np.asarray(shape.pose.position))
        tensors.append(density * rotation @ local_inertia @ rotation.T)
        volume += piece_volume
    mass = float(sum(masses))
    if mass <= 0.0:
        raise ValueError("an asset's collision pieces have no volume")
    centre = np.sum([m * c for m, c in zip(masses, centres)], axis=0) / mass
    inertia = np.zeros((3, 3))
    for m, c, tensor in zip(masses, centres, tensors):
        d = c - centre
        inertia += tensor + m * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return mass, float(volume), centre, inertia


def principal_axes(inertia: np.ndarray) -> tuple[np.ndarray, Quat]:
    """Principal moments and the rotation to their axes; identity when already diagonal."""
    symmetric = (inertia + inertia.T) / 2.0
    off_diagonal = symmetric - np.diag(np.diag(symmetric))
    if np.abs(off_diagonal).max() <= 1e-9 * max(np.trace(symmetric), 1e-30):
        return np.diag(symmetric).copy(), (1.0, 0.0, 0.0, 0.0)
    moments, axes = np.linalg.eigh(symmetric)
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return moments, matrix_to_quat(axes)
