"""FCL geometry of the monitored frames, with an AABB broad phase.

Every frame (a rigid body, an articulated body's link, a robot link, a zone) owns FCL
pieces built by ``fsvla.compiler.collision.pieces_of`` from compiler ``Shape`` models:
bodies and zones from the SceneSpec, robot links from the shapes the simulator gives
(``MonitoredScene.frame_shapes``). Each step :meth:`SceneGeometry.set_poses` moves the world
axis-aligned bounds of every piece, and of every frame (the box around its pieces), in
one compiled pass (``fsvla.monitor.kernels``); FCL transforms are set lazily, only for
pieces an exact query touches. :meth:`SceneGeometry.prefetch` gives each distance query
of a step the gap between its groups' nearest frames, in one call; a query already that
far answers with it. Otherwise :meth:`SceneGeometry.distance` visits the piece pairs of
two groups in order of a lower bound of their signed distance and stops once that bound
exceeds the best exact distance found, so the minimum is exact while far pairs cost
nothing. A pair's bound is the larger of its boxes' gap (where they are apart) and the
bound *carried* from the group's last exact pass: the exact distance found then, less
how far each of the two pieces can have moved since (``kernels.carry_bounds``); a pair
neither of whose pieces moved keeps its exact distance. While a carried object passes a
protected one a step moves it a centimetre, so slanted pieces whose boxes overlap but
which were centimetres apart need no new FCL query. Given ``exact_below`` the search
also stops once the bounds reach that value: the answer is then a lower bound no
smaller than ``exact_below`` (channels pass their limit plus soft threshold plus
``EXACT_BAND``, so states and costs stay exact). Results are memoised until a frame of
either group moves by more than ``POSE_TOLERANCE``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.geometry import shape_aabb, shape_to_trimesh
from fsvla.compiler.assets.model import (
    Shape,
)
from fsvla.compiler.collision import CollisionPiece, pieces_of, signed_distance
from fsvla.compiler.pose import pose_matrix

from . import kernels
from .state import Matrix4

#: Distances are capped here (m): a group with no geometry, or nothing in range.
MAX_DISTANCE = 10.0
#: A frame is re-posed only when an entry of its 4x4 pose changed by more than this
#: (10 µm, ~1e-5 rad): PhysX jitters resting bodies by about 1e-6.
POSE_TOLERANCE = 1e-5
#: An exact FCL distance carried as a bound loses this much (m): FCL finds distances to 1e-6.
CARRY_SLACK = 1e-5
_POINT_SECTIONS = 12  # rim points of a round shape for footprint / lowest-point queries

def _local_points(shape: Shape, base_dir: Path | None) -> NDArray[np.float64]:
    if shape.type == "convex_mesh" and shape.mesh.type == "file":
        from fsvla.compiler.collision import shape_vertices

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
        self._centres: list[NDArray[np.float64]] = []
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
        self._pairs: dict[tuple[frozenset[str], frozenset[str]], tuple] = {}
        # per query: lower bounds of its piece pairs' distances, which are exact, the poses they
        # hold at, and the buffer their order is sorted into (kernels.carry_bounds)
        self._carried: dict[tuple[frozenset[str], frozenset[str]],
                            tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64], NDArray[np.int64]]] = {}
        self._batches: dict[tuple, tuple] = {}
        self._bound_rows: dict[frozenset[str], NDArray[np.int64]] = {}  # frame-bound rows of a group
        self._prefetched: dict[tuple[frozenset[str], frozenset[str]], tuple[int, float]] = {}
        self._moves_made = 0  # times set_poses moved a frame: the prefetch is current while equal
        self._prefetched_at = -1
        self._prefetched_for: tuple | None = None
        self._moves: dict[tuple[str, ...], tuple[list[int], NDArray[np.int64]]] = {}
        self._group_frames: dict[frozenset[str], NDArray[np.int64]] = {}
        self._frame_points: dict[str, NDArray[np.float64]] = {}
        self._frozen = False
        #: Instants a control step's motion is sampled at (the physics substeps; 1: its end only).
        self.sweep_samples = 1
        self.step = 0  # control steps begun (:meth:`begin_step`)
        self._start: NDArray[np.float64] | None = None  # every frame's pose where the step began

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
            self._centres.append((lo + hi) / 2.0)
            self._halves.append((hi - lo) / 2.0)
            self._points.append(points)
            self._placed.append(-1)
        self._frozen = False

    def _freeze(self) -> None:
        kernels.warm_up()
        if hasattr(self, "_pose_array"):  # frames added after queries keep the others' poses
            for i, pose in enumerate(self._pose_array):
                self._poses[i] = pose
        self._c = np.array(self._centres, dtype=np.float64).reshape(-1, 3)
        self._h = np.array(self._halves, dtype=np.float64).reshape(-1, 3)
        self._radius = np.sqrt((self._h ** 2).sum(axis=1))  # a piece lies within this of its box's centre
        self._pf = np.array(self._piece_frame, dtype=np.int64)
        self._pose_array = np.array(self._poses, dtype=np.float64).reshape(-1, 4, 4)
        self._plo, self._phi = np.zeros_like(self._c), np.zeros_like(self._c)
        self._locals = np.array([p.local for p in self._pieces], dtype=np.float64).reshape(-1, 4, 4)
        self._rotations, self._translations = np.zeros((len(self._pieces), 3, 3)), np.zeros((len(self._pieces), 3))
        self._groups.clear()
        self._moves.clear()
        self._group_frames.clear()
        self._memo.clear()
        self._carried.clear()
        self._pairs.clear()
        self._batches.clear()
        self._prefetched.clear()
        self._prefetched_for = None
        self._bound_rows.clear()
        self._stamp = np.array(self._stamp, dtype=np.int64)
        # the frames with pieces, in frame order, are the rows of the frame bounds
        counts = np.bincount(self._pf, minlength=len(self.frames))
        self._gap_rows = {f: r for r, f in enumerate(f for f, n in zip(self.frames, counts.tolist()) if n)}
        row_of_frame = np.cumsum(counts > 0) - 1
        self._piece_row = row_of_frame[self._pf].astype(np.int64)
        self._flo = np.zeros((len(self._gap_rows), 3))
        self._fhi = np.zeros((len(self._gap_rows), 3))
        self._frame_points = {f: np.concatenate([self._points[i] for i in idx]) for f, idx in self._frame_pieces.items()
                              if idx}
        self._update_bounds()
        self._moves_made += 1  # every bound may have changed
        # how far each frame's geometry reaches from the frame's origin, and where a step began
        self._reach = np.zeros(len(self.frames))
        np.maximum.at(self._reach, self._pf, np.sqrt((self._c ** 2).sum(axis=1)) + self._radius)
        self._start_buffer, self._start = np.empty_like(self._pose_array), None
        self._frozen = True

    def has(self, frame: str) -> bool:
        return bool(self._frame_pieces.get(frame))

    def frame_pieces(self, frame: str) -> list[CollisionPiece]:
        """The frame's FCL pieces (their transforms are placed lazily: call ``place``)."""
        return [self._pieces[i] for i in self._frame_pieces.get(frame, ())]

    # --- moving ---------------------------------------------------------------------------

    def set_poses(self, poses: Mapping[str, Matrix4]) -> None:
        """Move the frames in ``poses`` (others keep their pose). A frame whose matrix
        changed by at most ``POSE_TOLERANCE`` in every entry keeps its pose, so resting
        bodies keep their FCL transforms and memoised distances."""
        if not self._frozen:
            self._freeze()
        names = getattr(poses, "names", None) or tuple(poses)
        plan = self._moves.get(names)
        if plan is None:
            keep = [i for i, f in enumerate(names) if f in self._frame_index]
            frames = np.array([self._frame_index[names[i]] for i in keep], dtype=np.int64)
            plan = self._moves[names] = (None if len(keep) == len(names) else np.array(keep, dtype=np.int64), frames)
        keep, frames = plan
        if len(frames) == 0:
            return
        stack = getattr(poses, "stack", None)
        if stack is None:
            values = list(poses.values())
            stack = np.array(values if keep is None else [values[i] for i in keep], dtype=np.float64)
        elif keep is not None:
            stack = stack[keep]
        if kernels.move_frames(stack, frames, self._pose_array, self._stamp, POSE_TOLERANCE, self._pf, self._c,
                               self._h, self._piece_row, self._plo, self._phi, self._flo, self._fhi):
            self._moves_made += 1  # and the bounds are updated

    def _update_bounds(self) -> None:
        """Every piece's and every frame's world bounds (one pass over all pieces is cheaper
        than picking the moved ones; the others get the same numbers again)."""
        if len(self._pf):
            kernels.update_bounds(self._pose_array, self._pf, self._c, self._h, self._piece_row,
                                  self._plo, self._phi, self._flo, self._fhi)

    def begin_step(self, fresh: bool = False) -> None:
        """Mark the start of a control step: the poses held now are where its motion begins
        (``fresh``: nowhere, as at reset). :func:`fsvla.monitor.sweep.swept_distance` reads
        them as :attr:`step_start`."""
        if not self._frozen:
            self._freeze()
        self.step += 1
        if fresh:
            self._start = None
        else:
            np.copyto(self._start_buffer, self._pose_array)
            self._start = self._start_buffer

    @property
    def step_start(self) -> NDArray[np.float64] | None:
        """Every frame's pose where the current control step began (None at reset)."""
        return self._start

    @property
    def poses_array(self) -> NDArray[np.float64]:
        """Every frame's pose now, as rows (:meth:`frame_rows`) of one array."""
        if not self._frozen:
            self._freeze()
        return self._pose_array

    @property
    def reach(self) -> NDArray[np.float64]:
        """Per frame: how far its geometry reaches from its origin (0 with no geometry)."""
        if not self._frozen:
            self._freeze()
        return self._reach

    def pose(self, frame: str) -> Matrix4:
        if not self._frozen:
            self._freeze()
        return self._pose_array[self._frame_index[frame]]

    def _fcl(self, piece: int) -> CollisionPiece:
        frame = self._piece_frame[piece]
        found = self._pieces[piece]
        if self._placed[piece] != self._stamp[frame]:
            # rows of contiguous buffers: FCL takes them as they are (a Transform built from
            # slices of the pose costs twice as much, and this runs for every query)
            rotation, translation = self._rotations[piece], self._translations[piece]
            kernels.place_piece(self._pose_array, frame, self._locals[piece], rotation, translation)
            found.obj.setRotation(rotation)
            found.obj.setTranslation(translation)
            self._placed[piece] = self._stamp[frame]
        return found

    # --- queries --------------------------------------------------------------------------

    def version(self, frames: frozenset[str]) -> int:
        """A number that grows whenever a frame of the group moves."""
        return kernels.stamp_total(self._stamp, self.frame_rows(frames))

    def frame_rows(self, frames: frozenset[str]) -> NDArray[np.int64]:
        """The group's frames as rows of the pose array (:attr:`step_start`, :attr:`reach`)."""
        index = self._group_frames.get(frames)
        if index is None:
            index = self._group_frames[frames] = np.array(
                [self._frame_index[f] for f in frames if f in self._frame_index], dtype=np.int64)
        return index

    def _group(self, frames: frozenset[str]) -> NDArray[np.int64]:
        found = self._groups.get(frames)
        if found is None:
            found = np.array(sorted(i for f in frames for i in self._frame_pieces.get(f, ())), dtype=np.int64)
            self._groups[frames] = found
        return found

    def _pair(self, a: frozenset[str], b: frozenset[str]) -> tuple[NDArray[np.int64], NDArray[np.int64],
                                                                  NDArray[np.int64], NDArray[np.bool_]]:
        """(a's pieces, b's pieces, the frames of both for the version, same-frame piece pairs)."""
        key = (a, b)
        found = self._pairs.get(key)
        if found is None:
            ia, ib = self._group(a), self._group(b)
            frames = np.array([self._frame_index[f] for f in a if f in self._frame_index]
                              + [self._frame_index[f] for f in b if f in self._frame_index], dtype=np.int64)
            pf = np.asarray(self._piece_frame, dtype=np.int64)
            same = (pf[ia][:, None] == pf[ib][None, :]).ravel()
            found = self._pairs[key] = (ia, ib, frames, same)
        return found

    def prefetch(self, queries: tuple[tuple[frozenset[str], frozenset[str]], ...]) -> None:
        """Frame-level bounds of many :meth:`distance` queries in one vectorised pass: for
        each, the smallest gap between the world bounds of a frame of one group and a frame
        of the other (a lower bound of the distance, and of every piece-pair bound).
        :meth:`distance` answers with it, without a piece-level pass, when it is already at
        least ``exact_below``."""
        if not self._frozen:
            self._freeze()
        plan = self._batches.get(queries)
        if plan is None:
            plan = self._batches[queries] = self._batch_plan(queries)
        keys, frames, frame_starts, rows_a, rows_b, starts = plan
        if not keys:
            return
        if self._prefetched_at == self._moves_made and self._prefetched_for is queries:
            return  # nothing moved since these were fetched
        nearest, versions = np.empty(len(keys)), np.empty(len(keys), dtype=np.int64)
        kernels.nearest_per_query(self._flo, self._fhi, rows_a, rows_b, starts, nearest, self._stamp, frames,
                                  frame_starts, versions)
        self._prefetched = dict(zip(keys, zip(versions.tolist(), nearest.tolist())))
        self._prefetched_at, self._prefetched_for = self._moves_made, queries

    @property
    def moves(self) -> int:
        """How many times :meth:`set_poses` moved a frame: while it is unchanged, nothing moved."""
        return self._moves_made

    @property
    def boxes(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """World bounds (lower, upper) of the frames (rows of :meth:`frame_indices`), then of
        the pieces (as :meth:`pieces` numbers them); updated in place as frames move."""
        if not self._frozen:
            self._freeze()
        return self._flo, self._fhi, self._plo, self._phi

    def frame_indices(self, frames: Iterable[str]) -> NDArray[np.int64]:
        """Rows of the frame bounds for those of ``frames`` that have pieces (sorted)."""
        if not self._frozen:
            self._freeze()
        rows = self._gap_rows
        return np.array(sorted(rows[f] for f in frames if f in rows), dtype=np.int64)

    def _batch_plan(self, queries: tuple[tuple[frozenset[str], frozenset[str]], ...]) -> tuple:
        keys, frames, frame_starts, rows_a, rows_b, starts = [], [], [], [], [], []
        rows, count = self._gap_rows, 0
        for a, b in dict.fromkeys(queries):
            ia, ib, fr, _ = self._pair(a, b)
            if len(ia) == 0 or len(ib) == 0:
                continue
            fa = sorted({rows[self.frames[self._piece_frame[i]]] for i in ia})
            fb = sorted({rows[self.frames[self._piece_frame[i]]] for i in ib})
            keys.append((a, b))
            frame_starts.append(count)
            count += len(fr)
            frames.append(fr)
            starts.append(len(rows_a))
            rows_a += [x for x in fa for _ in fb]
            rows_b += [y for _ in fa for y in fb]
        if not keys:
            return ((), None, None, None, None, None)
        return (tuple(keys), np.concatenate(frames), *(np.array(v, dtype=np.int64)
                                                       for v in (frame_starts, rows_a, rows_b, starts)))

    def distance(self, a: frozenset[str], b: frozenset[str], exact_below: float = MAX_DISTANCE) -> float:
        """Smallest signed distance between the pieces of two frame groups (negative when
        they overlap: the deepest penetration); MAX_DISTANCE when either has no geometry.

        The result is exact when it is below ``exact_below``; otherwise it is a lower bound
        of the distance that is itself at least ``exact_below`` (the search stops once every
        remaining pair's bounds are that far apart)."""
        if not self._frozen:
            self._freeze()
        key = (a, b)
        found = self._prefetched.get(key)
        fresh = found is not None and self._prefetched_at == self._moves_made  # nothing moved since
        if fresh and found[1] >= exact_below:  # far at the frame level already
            return found[1]
        ia, ib, frames, _ = self._pair(a, b)
        version = found[0] if fresh else kernels.stamp_total(self._stamp, frames)  # as the prefetch sums them
        cached = self._memo.get(key)
        if cached is not None and cached[2] == version and (cached[0] < cached[1] or cached[1] >= exact_below):
            return cached[0]
        if len(ia) == 0 or len(ib) == 0:
            return MAX_DISTANCE
        lower, known, order, n, beyond = self._carry(key, ia, ib, exact_below)
        if n == 0:  # every pair is far: the bounds answer
            beyond = min(beyond, MAX_DISTANCE)
            self._memo[key] = (beyond, exact_below, version)
            return beyond
        best = MAX_DISTANCE
        nb = len(ib)
        for flat in order[:n].tolist():  # the pairs whose bounds are below exact_below, nearest first
            bound = float(lower[flat])
            if bound >= best:  # this pair and the rest are at least that far
                break
            if not known[flat]:
                bound = signed_distance(self._fcl(ia[flat // nb]).obj, self._fcl(ib[flat % nb]).obj)
                lower[flat], known[flat] = bound, True
            best = min(best, bound)
        else:  # the pairs left are at least as far as the nearest of their bounds
            best = min(best, beyond)
        self._memo[key] = (best, exact_below, version)
        return best

    def _carry(self, key: tuple[frozenset[str], frozenset[str]], ia: NDArray[np.int64], ib: NDArray[np.int64],
               below: float) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int64], int, float]:
        """Lower bounds of the signed distance of every piece pair of a query (a * b, row-major)
        and whether each is exact: what the last exact pass found, less how far the pieces
        moved since (``kernels.carry_bounds``), or their boxes' gap where that is larger.
        Then the pairs whose bound is below ``below``, nearest first (``order[:n]``), and the
        smallest bound of the others."""
        carried = self._carried.get(key)
        if carried is None:
            same = self._pair(*key)[3]  # pieces of one frame in both groups are never compared
            carried = self._carried[key] = (np.where(same, np.inf, -np.inf), same.copy(), self._pose_array.copy(),
                                            np.zeros(len(same), dtype=np.int64))
        lower, known, ref, order = carried
        n, beyond = kernels.carry_bounds(self._pose_array, ref, self._pf, self._c, self._radius, self._plo,
                                         self._phi, ia, ib, lower, known, CARRY_SLACK, below, order)
        return lower, known, order, n, beyond

    def within_step(self, a: frozenset[str], b: frozenset[str], first: float,
                    before: float | None = None) -> StepSampler:
        """The distance of two groups inside the current control step (from :meth:`begin_step`
        to now), at the instants from ``first`` to ``1 - first`` of it (``before``: their
        distance where it began, if known): see :class:`StepSampler`."""
        if not self._frozen:
            self._freeze()
        return StepSampler(self, a, b, first, -np.inf if before is None else before)

    def pieces(self, frames: frozenset[str]) -> NDArray[np.int64]:
        """Indices of the frames' pieces (sorted), as the rows/columns of :meth:`near`."""
        return self._group(frames)

    def local_points(self, frame: str) -> NDArray[np.float64] | None:
        """Sample points of the frame's geometry in its own coordinates (the vertices of its
        pieces, the rims of round shapes), or None for a frame without geometry."""
        if not self._frozen:
            self._freeze()
        return self._frame_points.get(frame)

    def bounds(self, frames: frozenset[str]) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """World axis-aligned bounds (lower, upper) of the frames' pieces, or None: taken
        from the frame bounds :meth:`set_poses` keeps (a frame's box holds its pieces')."""
        if not self._frozen:
            self._freeze()
        rows = self._bound_rows.get(frames)
        if rows is None:
            rows = self._bound_rows[frames] = self.frame_indices(frames)
        if len(rows) == 1:
            r = rows[0]
            return self._flo[r].copy(), self._fhi[r].copy()
        if len(rows) == 0:
            return None
        return self._flo[rows].min(axis=0), self._fhi[rows].max(axis=0)



class StepSampler:
    """Two groups' distance inside a control step, every frame moving along the straight
    interpolation of its poses at the step's two ends (``kernels.interpolate_frames``).

    Each piece pair has a bound over the whole step (:attr:`floor` is the smallest): from
    its bound at the step's start (its boxes' gap there, or the groups' distance there) and
    at its end (the one :meth:`distance` carries), each less how far its pieces can travel
    from there (``kernels.step_bounds``).
    Calling it with ``(s, exact_below)`` gives the distance at the fraction ``s`` of the
    step, exact below ``exact_below``, else a lower bound at least that large: only pairs
    whose step bound is below ``exact_below`` are looked at, nearest bound first, and FCL
    measures those whose bound at ``s`` (their boxes' gap there, and their end bound less
    the travel left) is still below. Nothing is memoised; the FCL transforms it sets are
    set again when next needed."""

    def __init__(self, geo: SceneGeometry, a: frozenset[str], b: frozenset[str], first: float, before: float):
        self._geo = geo
        start = geo._start if geo._start is not None else geo._pose_array
        self._start, self._end = start, geo._pose_array
        ia, ib, _, _ = geo._pair(a, b)
        self._ia, self._ib = ia, ib
        self._at_end = geo._carry((a, b), ia, ib, -np.inf)[0].copy()
        self._travel_a = kernels.piece_travel(start, self._end, geo._pf, geo._c, geo._radius, ia)
        self._travel_b = kernels.piece_travel(start, self._end, geo._pf, geo._c, geo._radius, ib)
        self._step, self._at_start = np.empty(len(ia) * len(ib)), np.empty(len(ia) * len(ib))
        kernels.step_bounds(start, geo._pf, geo._c, geo._h, ia, ib, self._at_end, self._travel_a, self._travel_b,
                            first, before, self._step, self._at_start)
        self.floor = float(self._step.min()) if len(self._step) else MAX_DISTANCE
        self._frames = np.union1d(geo._pf[ia], geo._pf[ib])
        self._poses = self._end.copy()

    def floors(self, s: NDArray[np.float64], below: float) -> NDArray[np.float64]:
        """A lower bound of the distance at each instant ``s``, from the pairs whose step
        bound is below ``below`` (the others' are at least ``below``): each pair's bound at
        the step's start and end, less how far it can travel from there to the instant."""
        pairs = np.flatnonzero(self._step < below)
        if len(pairs) == 0:
            return np.full(len(s), max(self.floor, below))
        nb = len(self._ib)
        travel = (self._travel_a[pairs // nb] + self._travel_b[pairs % nb])[:, None]
        lower = np.maximum(self._at_start[pairs, None] - travel * s, self._at_end[pairs, None] - travel * (1.0 - s))
        return np.minimum(lower.min(axis=0), below)

    def __call__(self, s: float, exact_below: float) -> float:
        geo, ia, ib = self._geo, self._ia, self._ib
        pairs = np.flatnonzero(self._step < exact_below)
        if len(pairs) == 0:  # no pair comes that close at any instant
            return self.floor
        kernels.interpolate_frames(self._start, self._end, self._frames, s, self._poses)
        bounds = np.empty(len(pairs))
        kernels.instant_bounds(self._poses, geo._pf, geo._c, geo._h, ia, ib, pairs, self._at_end, self._travel_a,
                               self._travel_b, 1.0 - s, bounds)
        rest = float(self._step[self._step >= exact_below].min(initial=MAX_DISTANCE))  # the pairs left out
        best, placed, nb = MAX_DISTANCE, set(), len(ib)
        for n in np.argsort(bounds, kind="stable").tolist():
            if bounds[n] >= min(best, exact_below):
                return min(best, float(bounds[n]), rest)
            k = int(pairs[n])
            pa, pb = int(ia[k // nb]), int(ib[k % nb])
            for p in (pa, pb):
                if p not in placed:
                    self._place(p)
                    placed.add(p)
            best = min(best, signed_distance(geo._pieces[pa].obj, geo._pieces[pb].obj))
        return min(best, rest)

    def _place(self, p: int) -> None:
        geo = self._geo
        kernels.place_piece(self._poses, geo._pf[p], geo._locals[p], geo._rotations[p], geo._translations[p])
        obj = geo._pieces[p].obj
        obj.setRotation(geo._rotations[p])
        obj.setTranslation(geo._translations[p])
        geo._placed[p] = -1  # placed at its frame's pose again when next used

__all__ = ["MAX_DISTANCE", "POSE_TOLERANCE", "SceneGeometry", "StepSampler"]
