"""Bodies as FCL pieces with cheap bounds: the geometry the feasibility checks measure.

A :class:`Solid` is the collision pieces of one body (or of a zone's region, or of a
corridor's walls), built once with :func:`fsvla.compiler.collision.pieces_of`, plus
each piece's axis-aligned bound in the owner's frame. Moving a solid updates the
pieces' world bounds with numpy only; FCL is asked only about piece pairs whose bounds
come closer than the distance that matters, nearest first, and stops at the first one
that is closer (FCL primitives cost ~3 µs a query; the bounds cost almost nothing).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import fcl
import numpy as np
from fsvla.compiler.assets import ArticulatedAsset, Pose, RigidAsset
from fsvla.compiler.assets.model import CylinderShape, Shape
from numpy.typing import NDArray

from ..collision import (
    CollisionPiece,
    Matrix4,
    fcl_geometry,
    shape_vertices,
    signed_distance,
)
from ..pose import pose_matrix

_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)


@dataclass
class Solid:
    """FCL pieces of one owner, and their world bounds at the owner's current pose."""

    name: str
    pieces: list[CollisionPiece]
    corners: NDArray[np.float64]  # (pieces, 8, 3): each piece's bound's corners, owner frame
    lo: NDArray[np.float64] = field(init=False)  # (pieces, 3) world bounds of each piece
    hi: NDArray[np.float64] = field(init=False)
    box: tuple[NDArray[np.float64], NDArray[np.float64]] = field(init=False)  # the whole solid's
    matrix: Matrix4 = field(init=False)
    _placed: bool = field(init=False, default=False)

    def __post_init__(self) -> None:
        self.move(np.eye(4))

    def move(self, matrix: Matrix4) -> None:
        """Put the owner's frame at ``matrix`` (world)."""
        if self.__dict__.get("matrix") is not None and np.array_equal(matrix, self.matrix):
            return
        self.matrix = matrix
        world = self.corners @ matrix[:3, :3].T + matrix[:3, 3]
        self.lo, self.hi = world.min(axis=1), world.max(axis=1)
        self.box = (self.lo.min(axis=0), self.hi.max(axis=0)) if len(self.lo) else (np.zeros(3), np.zeros(3))
        self._placed = False

    def fcl_pieces(self) -> list[CollisionPiece]:
        if not self._placed:
            for piece in self.pieces:
                piece.place(self.matrix)
            self._placed = True
        return self.pieces


def gap_below(a: Solid, b: Solid, threshold: float) -> float | None:
    """The signed distance between ``a`` and ``b`` if it is below ``threshold``, else None.

    (Not necessarily the smallest distance: the first piece pair found below it.)"""
    if not len(a.pieces) or not len(b.pieces) or _apart(_box_gap(*a.box, *b.box), threshold):
        return None
    sep = np.maximum(0.0, np.maximum(b.lo[None] - a.hi[:, None], a.lo[:, None] - b.hi[None]))
    bound = np.sqrt((sep * sep).sum(axis=-1))
    pairs = np.argwhere((bound < threshold) | (bound <= 0.0))
    if not len(pairs):
        return None
    pairs = pairs[np.argsort(bound[pairs[:, 0], pairs[:, 1]], kind="stable")]
    pa, pb = a.fcl_pieces(), b.fcl_pieces()
    for i, j in pairs:
        distance = signed_distance(pa[i].obj, pb[j].obj)
        if distance < threshold:
            return distance
    return None


def _apart(bound: float, threshold: float) -> bool:
    """Whether a lower ``bound`` (>= 0, 0 when the boxes meet) proves the distance >= threshold."""
    return bound > 0.0 and bound >= threshold


def _box_gap(alo: NDArray, ahi: NDArray, blo: NDArray, bhi: NDArray) -> float:
    sep = np.maximum(0.0, np.maximum(blo - ahi, alo - bhi))
    return float(np.sqrt((sep * sep).sum()))


def solid_of_shapes(name: str, shapes: Sequence[Shape], frame: Matrix4 | None = None) -> Solid:
    """A solid from shapes given in the owner's frame (or in a sub-frame ``frame`` of it)."""
    return _Template.of_shapes([(shapes, frame)]).solid(name)


def solid_of_asset(name: str, asset: RigidAsset | ArticulatedAsset) -> Solid:
    """A body's solid; an articulated body with every joint at zero (drawers shut).

    The FCL geometry of an asset is built once and shared by every solid of it (FCL
    geometries are immutable; each solid has its own objects and transforms)."""
    cached = _TEMPLATES.get(id(asset))
    if cached is None or cached[0] is not asset:
        if len(_TEMPLATES) >= _TEMPLATE_LIMIT:
            _TEMPLATES.clear()
        if isinstance(asset, RigidAsset):
            template = _Template.of_shapes([(asset.collision, None)])
        else:
            frames = link_frames(asset)
            template = _Template.of_shapes([(link.collision, frames[link.name])
                                            for link in asset.links if link.name in frames])
        cached = _TEMPLATES[id(asset)] = (asset, template)
    return cached[1].solid(name)


@dataclass(frozen=True)
class _Template:
    """Shared FCL geometries, their placements in the owner frame, and their bounds' corners."""

    geometries: tuple
    locals: tuple
    corners: NDArray[np.float64]

    @classmethod
    def of_shapes(cls, groups: Sequence[tuple[Sequence[Shape], Matrix4 | None]]) -> _Template:
        geometries, locals_, corners = [], [], []
        for shapes, frame in groups:
            frame = np.eye(4) if frame is None else frame
            for shape in shapes:
                local = frame @ pose_matrix(shape.pose)
                geometries.append(fcl_geometry(shape))
                locals_.append(local)
                corners.append(_local_corners(shape, local))
        stacked = np.stack(corners) if corners else np.zeros((0, 8, 3))
        return cls(tuple(geometries), tuple(locals_), stacked)

    def solid(self, name: str) -> Solid:
        pieces = [CollisionPiece(name, local, fcl.CollisionObject(geometry, fcl.Transform()))
                  for geometry, local in zip(self.geometries, self.locals)]
        return Solid(name, pieces, self.corners)


_TEMPLATES: dict[int, tuple[object, _Template]] = {}
_TEMPLATE_LIMIT = 1024


def link_frames(asset: ArticulatedAsset) -> dict[str, Matrix4]:
    """Each link's frame in the body frame with every joint at zero."""
    frames = {asset.root_link: np.eye(4)}
    pending = list(asset.joints)
    while pending:
        ready = [j for j in pending if j.parent in frames]
        if not ready:
            break
        for joint in ready:
            frames[joint.child] = frames[joint.parent] @ pose_matrix(joint.origin)
            pending.remove(joint)
    return frames


def robot_base(name: str, radius: float, height: float) -> Solid:
    """A stand-in for a robot's base: a vertical cylinder standing on its mount's origin."""
    shape = CylinderShape(name="base", radius=radius, half_length=height / 2.0,
                          pose=Pose(position=(0.0, 0.0, height / 2.0)))
    return solid_of_shapes(name, [shape])


def _local_corners(shape: Shape, local: Matrix4) -> NDArray[np.float64]:
    """The 8 corners of ``shape``'s bound, in the owner frame (``local`` places the shape)."""
    if shape.type == "convex_mesh":
        vertices = shape_vertices(shape)
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    else:
        centre, half = np.zeros(3), np.asarray(_half_extents(shape))
    corners = centre + _SIGNS * half
    return corners @ local[:3, :3].T + local[:3, 3]


def _half_extents(shape: Shape) -> tuple[float, float, float]:
    if shape.type == "box":
        return tuple(shape.half_size)  # type: ignore[return-value]
    if shape.type == "cylinder":
        return (shape.radius, shape.radius, shape.half_length)
    if shape.type == "capsule":
        return (shape.radius, shape.radius, shape.half_length + shape.radius)
    return (shape.radius,) * 3  # sphere


__all__ = ["Solid", "gap_below", "link_frames", "robot_base", "solid_of_asset", "solid_of_shapes"]
