"""FCL geometry for the compiler's shapes: one place that turns a :class:`Shape` into FCL.

Both layout feasibility (``fsvla.compiler.variants``) and the runtime safety monitor
(``fsvla.monitor``) measure distances between the same pieces, so both build their FCL
objects here. Every piece is a primitive or a convex mesh (see
``fsvla.compiler.assets.model``); FCL measures those in microseconds, while a triangle
soup would cost a BVH query per pair.

Conventions: poses are (x, y, z) + (w, x, y, z); FCL cylinders and capsules have their
axis along local z like ours, and FCL's ``length`` is the full length of the
cylindrical part, so ``length = 2 * half_length``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import fcl
import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import Shape
from fsvla.compiler.pose import pose_matrix

Matrix4 = NDArray[np.float64]


def fcl_transform(matrix: Matrix4) -> fcl.Transform:
    return fcl.Transform(np.ascontiguousarray(matrix[:3, :3]), np.ascontiguousarray(matrix[:3, 3]))


def convex_geometry(vertices: NDArray[np.float64]) -> fcl.Convex:
    """An FCL convex from a point set: its convex hull (so any vertex cloud is accepted)."""
    import trimesh  # lazy: only convex pieces need it

    hull = trimesh.convex.convex_hull(np.asarray(vertices, dtype=np.float64))
    faces = np.hstack([np.full((len(hull.faces), 1), 3), hull.faces]).ravel()
    return fcl.Convex(np.asarray(hull.vertices, dtype=np.float64), len(hull.faces), faces)


def shape_vertices(shape: Shape, base_dir: Path | None = None) -> NDArray[np.float64]:
    """The vertices of a convex-mesh shape, in the shape's frame (file meshes scaled)."""
    mesh = shape.mesh  # type: ignore[union-attr]
    if mesh.type == "inline":
        return np.asarray(mesh.vertices, dtype=np.float64)
    import trimesh

    path = Path(mesh.path)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    loaded = trimesh.load(path, force="mesh")
    return np.asarray(loaded.vertices, dtype=np.float64) * np.asarray(mesh.scale)


def fcl_geometry(shape: Shape, base_dir: Path | None = None) -> fcl.CollisionGeometry:
    """The FCL geometry of one collision shape, in the shape's own frame."""
    if shape.type == "box":
        return fcl.Box(*(2.0 * h for h in shape.half_size))
    if shape.type == "cylinder":
        return fcl.Cylinder(shape.radius, 2.0 * shape.half_length)
    if shape.type == "capsule":
        return fcl.Capsule(shape.radius, 2.0 * shape.half_length)
    if shape.type == "sphere":
        return fcl.Sphere(shape.radius)
    if shape.type == "convex_mesh":
        return convex_geometry(shape_vertices(shape, base_dir))
    raise ValueError(f"no FCL geometry for shape type {shape.type!r}")


@dataclass
class CollisionPiece:
    """One FCL object of a body: ``local`` places the piece in its owner's frame."""

    owner: str
    local: Matrix4
    obj: fcl.CollisionObject

    def place(self, owner_pose: Matrix4) -> None:
        """Move the piece to where it is when its owner's frame is at ``owner_pose``."""
        self.obj.setTransform(fcl_transform(owner_pose @ self.local))


def pieces_of(owner: str, shapes: Sequence[Shape], owner_pose: Matrix4 | None = None,
              base_dir: Path | None = None) -> list[CollisionPiece]:
    """FCL pieces for ``shapes`` (in the owner's frame), placed at ``owner_pose``."""
    pose = np.eye(4) if owner_pose is None else owner_pose
    pieces = []
    for shape in shapes:
        local = pose_matrix(shape.pose)
        obj = fcl.CollisionObject(fcl_geometry(shape, base_dir), fcl_transform(pose @ local))
        pieces.append(CollisionPiece(owner, local, obj))
    return pieces


_DISTANCE_REQUEST = fcl.DistanceRequest(enable_signed_distance=True)


def signed_distance(a: fcl.CollisionObject, b: fcl.CollisionObject) -> float:
    """Distance between two pieces; negative (the penetration depth) when they overlap."""
    return float(fcl.distance(a, b, _DISTANCE_REQUEST, fcl.DistanceResult()))


def min_distance(a: Sequence[CollisionPiece], b: Sequence[CollisionPiece]) -> float:
    """The smallest signed distance between any piece of ``a`` and any piece of ``b``."""
    best = float("inf")
    for pa in a:
        for pb in b:
            best = min(best, signed_distance(pa.obj, pb.obj))
    return best


__all__ = [
    "CollisionPiece", "convex_geometry", "fcl_geometry", "fcl_transform", "min_distance",
    "pieces_of", "shape_vertices", "signed_distance",
]
