"""FCL geometry of the monitored frames, with an AABB broad phase.

Every frame (a rigid body, an articulated body's link, a robot link, a zone) owns FCL
pieces built by ``fsvla.compiler.collision.pieces_of`` from compiler ``Shape`` models:
bodies and zones from the SceneSpec, robot links from their SAPIEN collision shapes
(:func:`shapes_of_sapien`). Each step :meth:`SceneGeometry.set_poses` moves the world
axis-aligned bounds of every piece in one vectorised pass; FCL transforms are set
lazily, only for pieces an exact query touches. :meth:`SceneGeometry.distance` visits
the piece pairs of two groups in order of their bounds' gap and stops once that gap
exceeds the best exact distance found, so the minimum is exact while far pairs cost
nothing. Given ``exact_below`` it also stops once the gap reaches that value: the answer
is then a lower bound no smaller than ``exact_below`` (channels pass their limit plus
soft threshold plus ``EXACT_BAND``, so states and costs stay exact). Results are memoised
until a frame of either group moves by more than ``POSE_TOLERANCE``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.geometry import shape_aabb, shape_to_trimesh
from fsvla.compiler.assets.model import (
    BoxShape,
    CapsuleShape,
    ConvexMeshShape,
    CylinderShape,
    InlineMesh,
    Pose,
    Shape,
    SphereShape,
)
from fsvla.compiler.collision import CollisionPiece, fcl_transform, pieces_of, signed_distance

from .state import Matrix4

#: Distances are capped here (m): a group with no geometry, or nothing in range.
MAX_DISTANCE = 10.0
#: A frame is re-posed only when an entry of its 4x4 pose changed by more than this
#: (10 µm, ~1e-5 rad): PhysX jitters resting bodies by about 1e-6.
POSE_TOLERANCE = 1e-5
_POINT_SECTIONS = 12  # rim points of a round shape for footprint / lowest-point queries

# SAPIEN capsules and cylinders lie along local x; ours (and FCL's) along local z.
_Z_TO_X = (0.7071067811865476, 0.0, 0.7071067811865476, 0.0)


def _quat_mul(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def shapes_of_sapien(component: Any) -> list[Shape]:
    """Compiler shapes for the collision shapes of a SAPIEN rigid component or link."""
    import sapien

    physx = sapien.physx
    shapes: list[Shape] = []
    for sh in component.collision_shapes:
        local = sh.local_pose
        p, q = tuple(float(v) for v in local.p), tuple(float(v) for v in local.q)
        if isinstance(sh, physx.PhysxCollisionShapeBox):
            shapes.append(BoxShape(pose=Pose(position=p, quaternion=q),
                                   half_size=tuple(float(v) for v in sh.half_size)))
        elif isinstance(sh, physx.PhysxCollisionShapeSphere):
            shapes.append(SphereShape(pose=Pose(position=p, quaternion=q), radius=float(sh.radius)))
        elif isinstance(sh, physx.PhysxCollisionShapeCapsule):
            shapes.append(CapsuleShape(pose=Pose(position=p, quaternion=_quat_mul(q, _Z_TO_X)),
                                       radius=float(sh.radius), half_length=float(sh.half_length)))
        elif isinstance(sh, physx.PhysxCollisionShapeCylinder):
            shapes.append(CylinderShape(pose=Pose(position=p, quaternion=_quat_mul(q, _Z_TO_X)),
                                        radius=float(sh.radius), half_length=float(sh.half_length)))
        elif isinstance(sh, physx.PhysxCollisionShapeConvexMesh):
            vertices = np.asarray(sh.vertices, dtype=np.float64) * np.asarray(sh.scale, dtype=np.float64)
            faces = np.asarray(sh.get_triangles(), dtype=np.int64)
            shapes.append(ConvexMeshShape(pose=Pose(position=p, quaternion=q), mesh=InlineMesh(
                vertices=[tuple(v) for v in vertices.tolist()], faces=[tuple(f) for f in faces.tolist()])))
        # planes and triangle meshes are not monitored (the floor; never a robot link)
    return shapes


def _local_points(shape: Shape, base_dir: Path | None) -> NDArray[np.float64]:
    if shape.type == "convex_mesh" and shape.mesh.type == "file":
        from fsvla.compiler.collision import pose_matrix, shape_vertices

        v = shape_vertices(shape, base_dir)
        m = pose_matrix(shape.pose)
        return v @ m[:3, :3].T + m[:3, 3]
    return np.asarray(shape_to_trimesh(shape, sections=_POINT_SECTIONS).vertices, dtype=np.float64)


def _file_aabb(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return points.min(axis=0), points.max(axis=0)


class SceneGeometry:
    """FCL pieces per frame, their world bounds, and distance queries between frame groups."""

    def __init__(self) -> None:
        self._pieces: list[CollisionPiece] = []
        self._piece_frame: list[int] = []
        self._centers: list[NDArray[np.float64]] = []
        self._halves: list[NDArray[np.float64]] = []
        self._points: list[NDArray[np.float64]] = []
        self.frames: list[str] = []
        self._frame_index: dict[str, int] = {}
        self._frame_pieces: dict[str, list[int]] = {}
        self._poses: list[Matrix4] = []
        self._stamp: list[int] | NDArray[np.int64] = []  # per frame: bumped on every move
        self._placed: list[int] = []  # per piece: the frame stamp its FCL transform has
        self._groups: dict[frozenset[str], NDArray[np.int64]] = {}
        self._memo: dict[tuple[frozenset[str], frozenset[str]], tuple[float, float, int]] = {}
        self._moves: dict[tuple[str, ...], tuple[list[int], NDArray[np.int64]]] = {}
        self._group_frames: dict[frozenset[str], NDArray[np.int64]] = {}
        self._point_memo: dict[frozenset[str], tuple[int, NDArray[np.float64]]] = {}
        self._frame_points: dict[str, NDArray[np.float64]] = {}
        self._frozen = False

    # --- building -------------------------------------------------------------------------

    def add(self, frame: str, shapes: Iterable[Shape], pose: Matrix4 | None = None,
            base_dir: Path | None = None) -> None:
        """Add ``shapes`` (in the frame's own coordinates) to ``frame`` at ``pose``."""
        shapes = list(shapes)
        if frame not in self._frame_index:
            self._frame_index[frame] = len(self.frames)
            self.frames.append(frame)
            self._frame_pieces[frame] = []
            self._poses.append(np.eye(4) if pose is None else np.asarray(pose, dtype=np.float64))
            self._stamp = [*list(self._stamp), 0]
        index = self._frame_index[frame]
        if pose is not None:
            self._poses[index] = np.asarray(pose, dtype=np.float64)
        for shape, piece in zip(shapes, pieces_of(frame, shapes, self._poses[index], base_dir)):
            points = _local_points(shape, base_dir)
            if shape.type == "convex_mesh" and shape.mesh.type == "file":
                lo, hi = _file_aabb(points)
            else:
                lo, hi = (np.asarray(v, dtype=np.float64) for v in shape_aabb(shape))
            self._frame_pieces[frame].append(len(self._pieces))
            self._pieces.append(piece)
            self._piece_frame.append(index)
            self._centers.append((lo + hi) / 2.0)
            self._halves.append((hi - lo) / 2.0)
            self._points.append(points)
            self._placed.append(-1)
        self._frozen = False

    def _freeze(self) -> None:
        if hasattr(self, "_pose_array"):  # frames added after queries keep the others' poses
            for i, pose in enumerate(self._pose_array):
                self._poses[i] = pose
        self._c = np.array(self._centers, dtype=np.float64).reshape(-1, 3)
        self._h = np.array(self._halves, dtype=np.float64).reshape(-1, 3)
        self._pf = np.array(self._piece_frame, dtype=np.int64)
        self._pose_array = np.array(self._poses, dtype=np.float64).reshape(-1, 4, 4)
        self._wc = np.zeros_like(self._c)
        self._wh = np.zeros_like(self._h)
        self._groups.clear()
        self._moves.clear()
        self._group_frames.clear()
        self._memo.clear()
        self._point_memo.clear()
        self._stamp = np.array(self._stamp, dtype=np.int64)
        self._frame_points = {f: np.concatenate([self._points[i] for i in idx]) for f, idx in self._frame_pieces.items()
                              if idx}
        self._update_bounds(np.arange(len(self._pieces)))
        self._frozen = True

    def has(self, frame: str) -> bool:
        return bool(self._frame_pieces.get(frame))

    # --- moving ---------------------------------------------------------------------------

    def set_poses(self, poses: Mapping[str, Matrix4]) -> None:
        """Move the frames in ``poses`` (others keep their pose). A frame whose matrix
        changed by at most ``POSE_TOLERANCE`` in every entry keeps its pose, so resting
        bodies keep their FCL transforms and memoised distances."""
        if not self._frozen:
            self._freeze()
        names = tuple(poses)
        plan = self._moves.get(names)
        if plan is None:
            keep = [i for i, f in enumerate(names) if f in self._frame_index]
            plan = self._moves[names] = (keep, np.array([self._frame_index[names[i]] for i in keep], dtype=np.int64))
        keep, frames = plan
        if len(frames) == 0:
            return
        values = list(poses.values())
        new = np.array([values[i] for i in keep], dtype=np.float64)
        moved = np.abs(new - self._pose_array[frames]).reshape(len(frames), 16).max(axis=1) > POSE_TOLERANCE
        if not moved.any():
            return
        frames = frames[moved]
        self._pose_array[frames] = new[moved]
        self._stamp[frames] += 1
        moved_frames = np.zeros(len(self._pose_array), dtype=bool)
        moved_frames[frames] = True
        self._update_bounds(np.flatnonzero(moved_frames[self._pf]))

    def _update_bounds(self, pieces: NDArray[np.int64]) -> None:
        if len(pieces) == 0:
            return
        poses = self._pose_array[self._pf[pieces]]
        rot = poses[:, :3, :3]
        self._wc[pieces] = np.einsum("pij,pj->pi", rot, self._c[pieces]) + poses[:, :3, 3]
        self._wh[pieces] = np.einsum("pij,pj->pi", np.abs(rot), self._h[pieces])

    def pose(self, frame: str) -> Matrix4:
        if not self._frozen:
            self._freeze()
        return self._pose_array[self._frame_index[frame]]

    def _fcl(self, piece: int) -> CollisionPiece:
        frame = self._piece_frame[piece]
        if self._placed[piece] != self._stamp[frame]:
            p = self._pieces[piece]
            p.obj.setTransform(fcl_transform(self._pose_array[frame] @ p.local))
            self._placed[piece] = self._stamp[frame]
        return self._pieces[piece]

    # --- queries --------------------------------------------------------------------------

    def version(self, frames: frozenset[str]) -> int:
        """A number that grows whenever a frame of the group moves."""
        index = self._group_frames.get(frames)
        if index is None:
            index = self._group_frames[frames] = np.array(
                [self._frame_index[f] for f in frames if f in self._frame_index], dtype=np.int64)
        return int(self._stamp[index].sum())

    def _group(self, frames: frozenset[str]) -> NDArray[np.int64]:
        found = self._groups.get(frames)
        if found is None:
            found = np.array(sorted(i for f in frames for i in self._frame_pieces.get(f, ())), dtype=np.int64)
            self._groups[frames] = found
        return found

    def distance(self, a: frozenset[str], b: frozenset[str], exact_below: float = MAX_DISTANCE) -> float:
        """Smallest signed distance between the pieces of two frame groups (negative when
        they overlap: the penetration depth); MAX_DISTANCE when either has no geometry.

        The result is exact when it is below ``exact_below``; otherwise it is a lower bound
        of the distance that is itself at least ``exact_below`` (the search stops once every
        remaining pair's bounds are that far apart)."""
        if not self._frozen:
            self._freeze()
        key = (a, b)
        version = self.version(a) + self.version(b)
        cached = self._memo.get(key)
        if cached is not None and cached[2] == version and (cached[0] < cached[1] or cached[1] >= exact_below):
            return cached[0]
        ia, ib = self._group(a), self._group(b)
        if len(ia) == 0 or len(ib) == 0:
            return MAX_DISTANCE
        gap = np.abs(self._wc[ia][:, None, :] - self._wc[ib][None, :, :])
        gap -= self._wh[ia][:, None, :] + self._wh[ib][None, :, :]
        np.maximum(gap, 0.0, out=gap)
        bound = np.sqrt(np.einsum("abk,abk->ab", gap, gap)).ravel()
        nearest = float(bound.min())
        if nearest >= exact_below:  # every pair is far: the broad phase answers
            self._memo[key] = (nearest, exact_below, version)
            return nearest
        order = np.argsort(bound)
        best = MAX_DISTANCE
        nb = len(ib)
        for flat in order:
            lower = float(bound[flat])
            if lower >= best:
                break
            if lower >= exact_below:
                best = lower
                break
            pa, pb = ia[flat // nb], ib[flat % nb]
            if self._piece_frame[pa] == self._piece_frame[pb]:
                continue
            best = min(best, signed_distance(self._fcl(pa).obj, self._fcl(pb).obj))
        self._memo[key] = (best, exact_below, version)
        return best

    def pieces(self, frames: frozenset[str]) -> NDArray[np.int64]:
        """Indices of the frames' pieces (sorted), as the rows/columns of :meth:`near`."""
        return self._group(frames)

    def near(self, a: frozenset[str], b: frozenset[str], gap: float) -> NDArray[np.bool_]:
        """Piece pairs (rows: ``a``'s pieces, columns: ``b``'s) whose bounds are within ``gap``
        on every axis (broad phase only)."""
        if not self._frozen:
            self._freeze()
        ia, ib = self._group(a), self._group(b)
        d = np.abs(self._wc[ia][:, None, :] - self._wc[ib][None, :, :])
        d -= self._wh[ia][:, None, :] + self._wh[ib][None, :, :]
        return np.all(d < gap, axis=2)

    def points(self, frames: frozenset[str]) -> NDArray[np.float64]:
        """World sample points of the frames' geometry (vertices, rims of round shapes)."""
        if not self._frozen:
            self._freeze()
        version = self.version(frames)
        cached = self._point_memo.get(frames)
        if cached is not None and cached[0] == version:
            return cached[1]
        chunks = []
        for frame in frames:
            index = self._frame_index.get(frame)
            if index is None:
                continue
            pose = self._pose_array[index]
            if frame in self._frame_points:
                chunks.append(self._frame_points[frame] @ pose[:3, :3].T + pose[:3, 3])
        points = np.concatenate(chunks) if chunks else np.zeros((0, 3))
        self._point_memo[frames] = (version, points)
        return points

    def bounds(self, frames: frozenset[str]) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """World axis-aligned bounds (lower, upper) of the frames' pieces, or None."""
        if not self._frozen:
            self._freeze()
        idx = self._group(frames)
        if len(idx) == 0:
            return None
        return (self._wc[idx] - self._wh[idx]).min(axis=0), (self._wc[idx] + self._wh[idx]).max(axis=0)


__all__ = ["MAX_DISTANCE", "POSE_TOLERANCE", "SceneGeometry", "shapes_of_sapien"]
