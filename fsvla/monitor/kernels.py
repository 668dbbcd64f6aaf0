"""Compiled inner loops of the monitor's broad phase.

A control step re-poses a few dozen frames, re-bounds a few hundred pieces and compares
a few hundred box pairs: in numpy that is some forty calls on tiny arrays, each costing
more in dispatch than in arithmetic. These loops do the same work in one compiled call
each (numba, cached on disk after the first compilation).

Boxes are axis-aligned and given by their lower and upper corners, rows of ``lo`` and
``hi``. The *gap* of two boxes on an axis is ``max(lo_b - hi_a, lo_a - hi_b)``: negative
where they overlap on that axis. Their *distance* is the length of the positive gaps, a
lower bound of the distance between anything inside them.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit
from numpy.typing import NDArray


@njit(cache=True, nogil=True)
def apply_poses(stack: NDArray, frames: NDArray[np.int64], poses: NDArray[np.float64],
                stamp: NDArray[np.int64], tolerance: float) -> int:
    """Copy ``stack[k]`` into ``poses[frames[k]]`` where an entry differs by more than
    ``tolerance``, bumping that frame's stamp; the number of frames moved."""
    moved = 0
    for k in range(frames.shape[0]):
        f = frames[k]
        changed = False
        for i in range(3):
            for j in range(4):
                if abs(stack[k, i, j] - poses[f, i, j]) > tolerance:
                    changed = True
        if changed:
            for i in range(4):
                for j in range(4):
                    poses[f, i, j] = stack[k, i, j]
            stamp[f] += 1
            moved += 1
    return moved


@njit(cache=True, nogil=True)
def update_bounds(poses: NDArray[np.float64], piece_frame: NDArray[np.int64],
                  centre: NDArray[np.float64], half: NDArray[np.float64],
                  piece_row: NDArray[np.int64], plo: NDArray[np.float64], phi: NDArray[np.float64],
                  flo: NDArray[np.float64], fhi: NDArray[np.float64]) -> None:
    """World bounds of every piece (its local box ``centre`` ± ``half`` under its frame's
    pose) into ``plo``/``phi``, and of every frame (the box around its pieces) into rows
    ``piece_row`` of ``flo``/``fhi``."""
    flo[:] = np.inf
    fhi[:] = -np.inf
    for p in range(piece_frame.shape[0]):
        f = piece_frame[p]
        r = piece_row[p]
        for i in range(3):
            c = poses[f, i, 3]
            h = 0.0
            for j in range(3):
                m = poses[f, i, j]
                c += m * centre[p, j]
                h += abs(m) * half[p, j]
            lo, hi = c - h, c + h
            plo[p, i], phi[p, i] = lo, hi
            flo[r, i] = min(flo[r, i], lo)
            fhi[r, i] = max(fhi[r, i], hi)


@njit(cache=True, nogil=True)
def move_frames(stack: NDArray, frames: NDArray[np.int64], poses: NDArray[np.float64],
                stamp: NDArray[np.int64], tolerance: float, piece_frame: NDArray[np.int64],
                centre: NDArray[np.float64], half: NDArray[np.float64], piece_row: NDArray[np.int64],
                plo: NDArray[np.float64], phi: NDArray[np.float64], flo: NDArray[np.float64],
                fhi: NDArray[np.float64]) -> int:
    """:func:`apply_poses`, then, if a frame moved, :func:`update_bounds`: one call a step."""
    moved = apply_poses(stack, frames, poses, stamp, tolerance)
    if moved and piece_frame.shape[0]:
        update_bounds(poses, piece_frame, centre, half, piece_row, plo, phi, flo, fhi)
    return moved


@njit(cache=True, nogil=True)
def place_piece(poses: NDArray[np.float64], frame: int, local: NDArray[np.float64],
                rotation: NDArray[np.float64], translation: NDArray[np.float64]) -> None:
    """A piece's world transform ``poses[frame] @ local`` (summed in matmul's order), as
    the contiguous rotation and translation FCL takes without copying."""
    for i in range(3):
        for j in range(4):
            total = 0.0
            for k in range(4):
                total += poses[frame, i, k] * local[k, j]
            if j < 3:
                rotation[i, j] = total
            else:
                translation[i] = total


@njit(cache=True, nogil=True, inline="always")
def _distance(lo: NDArray[np.float64], hi: NDArray[np.float64], a: int, b: int) -> float:
    total = 0.0
    for i in range(3):
        g = max(lo[b, i] - hi[a, i], lo[a, i] - hi[b, i])
        if g > 0.0:
            total += g * g
    return math.sqrt(total)


@njit(cache=True, nogil=True, inline="always")
def _within(lo: NDArray[np.float64], hi: NDArray[np.float64], a: int, b: int, gap: float) -> bool:
    for i in range(3):
        if max(lo[b, i] - hi[a, i], lo[a, i] - hi[b, i]) >= gap:
            return False
    return True


@njit(cache=True, nogil=True)
def nearest_per_query(lo: NDArray[np.float64], hi: NDArray[np.float64], a: NDArray[np.int64],
                      b: NDArray[np.int64], starts: NDArray[np.int64], out: NDArray[np.float64],
                      stamp: NDArray[np.int64], frames: NDArray[np.int64], frame_starts: NDArray[np.int64],
                      versions: NDArray[np.int64]) -> None:
    """``out[q]``: the smallest distance of the box pairs ``(a[k], b[k])`` for k from
    ``starts[q]`` up to the next query's start (or the end); ``versions[q]``: the sum of
    ``stamp`` over ``frames`` from ``frame_starts[q]`` up to the next query's."""
    n = starts.shape[0]
    for q in range(n):
        end = starts[q + 1] if q + 1 < n else a.shape[0]
        best = np.inf
        for k in range(starts[q], end):
            best = min(best, _distance(lo, hi, a[k], b[k]))
        out[q] = best
        end = frame_starts[q + 1] if q + 1 < n else frames.shape[0]
        total = 0
        for k in range(frame_starts[q], end):
            total += stamp[frames[k]]
        versions[q] = total


@njit(cache=True, nogil=True, inline="always")
def _moved(now: NDArray[np.float64], then: NDArray[np.float64], centre: NDArray[np.float64],
           radius: float) -> float:
    """How far any point within ``radius`` of ``centre`` (frame coordinates) can have moved
    when its frame went from pose ``then`` to pose ``now``: the centre's displacement plus
    ``radius`` times the spectral norm of the rotation's change, ``2 sin(θ/2)``, which is
    ``sqrt(Σ ΔR_ij² / 2)`` for two rotations."""
    shift = 0.0
    turn = 0.0
    for i in range(3):
        d = now[i, 3] - then[i, 3]
        for j in range(3):
            r = now[i, j] - then[i, j]
            d += r * centre[j]
            turn += r * r
        shift += d * d
    return math.sqrt(shift) + radius * math.sqrt(0.5 * turn)


@njit(cache=True, nogil=True)
def _pieces_moved(poses: NDArray[np.float64], ref: NDArray[np.float64], piece_frame: NDArray[np.int64],
                  centre: NDArray[np.float64], radius: NDArray[np.float64],
                  pieces: NDArray[np.int64]) -> NDArray[np.float64]:
    """:func:`_moved` of each of ``pieces`` between its frame's poses in ``ref`` and ``poses``."""
    out = np.empty(pieces.shape[0])
    for i in range(pieces.shape[0]):
        p = pieces[i]
        out[i] = _moved(poses[piece_frame[p]], ref[piece_frame[p]], centre[p], radius[p])
    return out


@njit(cache=True, nogil=True)
def carry_bounds(poses: NDArray[np.float64], ref: NDArray[np.float64], piece_frame: NDArray[np.int64],
                 centre: NDArray[np.float64], radius: NDArray[np.float64], lo: NDArray[np.float64],
                 hi: NDArray[np.float64], a: NDArray[np.int64], b: NDArray[np.int64],
                 lower: NDArray[np.float64], known: NDArray[np.bool_], slack: float, below: float,
                 order: NDArray[np.int64]) -> tuple[int, float]:
    """Bring the lower bounds ``lower[i * len(b) + j]`` of the signed distances of pieces
    ``a[i]`` and ``b[j]`` from frame poses ``ref`` to ``poses``, then set ``ref`` to them.

    A pair whose distance is ``known`` exactly keeps it while neither piece moved. Else a
    distance cannot have shrunk by more than how far the two pieces moved (signed distance
    is 1-Lipschitz in the motion of either set, penetrations included); an exact value
    becoming a bound also loses ``slack`` (FCL's own tolerance). Where two pieces' boxes
    are apart, their gap is a bound too: the larger one is kept.

    Returns ``(n, beyond)``: ``order[:n]`` are the pairs whose bound is below ``below``,
    nearest first, and ``beyond`` the smallest bound of the others (infinity if none)."""
    na, nb = a.shape[0], b.shape[0]
    moved_a = _pieces_moved(poses, ref, piece_frame, centre, radius, a)
    moved_b = _pieces_moved(poses, ref, piece_frame, centre, radius, b)
    n, beyond = 0, np.inf
    for i in range(na):
        for j in range(nb):
            k = i * nb + j
            moved = moved_a[i] + moved_b[j]
            if moved > 0.0 or not known[k]:
                carried = lower[k] - moved
                if known[k]:
                    carried -= slack
                    known[k] = False
                gap = _distance(lo, hi, a[i], b[j])
                lower[k] = max(gap, carried) if gap > 0.0 else carried
            if lower[k] < below:
                order[n] = k
                n += 1
            else:
                beyond = min(beyond, lower[k])
    ref[:] = poses
    if n > 1:
        near = order[:n].copy()
        order[:n] = near[np.argsort(lower[near], kind="mergesort")]
    return n, beyond


@njit(cache=True, nogil=True)
def any_within(lo: NDArray[np.float64], hi: NDArray[np.float64], a: NDArray[np.int64],
               b: NDArray[np.int64], gap: float) -> bool:
    """Whether a box of ``a`` and one of ``b`` have every axis' gap below ``gap``."""
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            if _within(lo, hi, a[i], b[j], gap):
                return True
    return False


@njit(cache=True, nogil=True)
def _any_column(lo: NDArray[np.float64], hi: NDArray[np.float64], rows: NDArray[np.int64],
                cols: NDArray[np.int64], wanted: NDArray[np.bool_], gap: float) -> bool:
    """Whether a box of ``rows`` is within ``gap`` of a box ``cols[j]`` with ``wanted[j]``."""
    for j in range(cols.shape[0]):
        if wanted[j]:
            for i in range(rows.shape[0]):
                if _within(lo, hi, rows[i], cols[j], gap):
                    return True
    return False


@njit(cache=True, nogil=True)
def contact_gate(flo: NDArray[np.float64], fhi: NDArray[np.float64], plo: NDArray[np.float64],
                 phi: NDArray[np.float64], frame_rows: NDArray[np.int64], frame_cols: NDArray[np.int64],
                 frame_scan_rows: NDArray[np.int64], frame_scan_cols: NDArray[np.bool_],
                 frame_last_cols: NDArray[np.bool_], all_cols: NDArray[np.int64],
                 piece_rows: NDArray[np.int64], piece_cols: NDArray[np.int64],
                 piece_scan_rows: NDArray[np.int64], piece_scan_cols: NDArray[np.bool_],
                 piece_last_cols: NDArray[np.bool_], check_scan: bool, check_last: bool, gap: float) -> int:
    """The contact gate's verdict in one pass (bit 1: scan; bit 2: read the last substep).

    A scan may find something when a robot frame of ``frame_rows`` is within ``gap`` of a
    body frame the scan watches (``frame_cols`` where ``frame_scan_cols``), or a robot frame
    whose every contact counts (``frame_scan_rows``) is near any body (``all_cols``); the
    last-substep reading likewise for ``frame_last_cols``. Frame boxes hold their pieces'
    boxes, so only where a frame pair is near are pieces compared, the same way."""
    scan = check_scan and (_any_column(flo, fhi, frame_rows, frame_cols, frame_scan_cols, gap)
                           or any_within(flo, fhi, frame_scan_rows, all_cols, gap))
    last = check_last and _any_column(flo, fhi, frame_rows, frame_cols, frame_last_cols, gap)
    if scan:
        scan = (any_within(plo, phi, piece_scan_rows, piece_cols, gap)
                or _any_column(plo, phi, piece_rows, piece_cols, piece_scan_cols, gap))
    if last:
        last = _any_column(plo, phi, piece_rows, piece_cols, piece_last_cols, gap)
    return int(scan) | 2 * int(last)


@njit(cache=True, nogil=True)
def inside_margin(points: NDArray[np.float64], frame: NDArray[np.float64], support: NDArray[np.float64],
                  x0: float, y0: float, x1: float, y1: float) -> float:
    """The smallest distance, in the xy-plane of the ``support`` pose's frame, from a point
    of ``points`` (in the coordinates of the ``frame`` pose) to the edges of the rectangle
    [x0, x1] × [y0, y1] there: negative for a point outside it; infinity for no points."""
    best = np.inf
    for k in range(points.shape[0]):
        px, py, pz = points[k, 0], points[k, 1], points[k, 2]
        dx = frame[0, 0] * px + frame[0, 1] * py + frame[0, 2] * pz + frame[0, 3] - support[0, 3]
        dy = frame[1, 0] * px + frame[1, 1] * py + frame[1, 2] * pz + frame[1, 3] - support[1, 3]
        dz = frame[2, 0] * px + frame[2, 1] * py + frame[2, 2] * pz + frame[2, 3] - support[2, 3]
        x = dx * support[0, 0] + dy * support[1, 0] + dz * support[2, 0]
        y = dx * support[0, 1] + dy * support[1, 1] + dz * support[2, 1]
        best = min(best, x - x0, x1 - x, y - y0, y1 - y)
    return best


@njit(cache=True, nogil=True)
def stamp_total(stamp: NDArray[np.int64], frames: NDArray[np.int64]) -> int:
    """The sum of the frames' move stamps: it grows whenever one of them moves (numpy's
    fancy index and sum cost four times this call)."""
    total = 0
    for f in frames:
        total += stamp[f]
    return total


@functools.cache
def warm_up() -> None:
    """Load every kernel now (from numba's disk cache, compiling on a first run), so that
    the first control step that needs one does not pay for it: a cold load costs ms."""
    poses, boxes, rows = np.tile(np.eye(4), (2, 1, 1)), np.zeros((2, 3)), np.zeros(2, dtype=np.int64)
    flags, values = np.zeros(2, dtype=np.bool_), np.zeros(2)
    for stack in (poses.astype(np.float32), poses.copy()):  # SAPIEN's float32 poses, hand-made float64 ones
        move_frames(stack, rows, poses.copy(), rows.copy(), 1e-5, rows, boxes, boxes, rows, boxes.copy(),
                    boxes.copy(), boxes.copy(), boxes.copy())
    update_bounds(poses, rows, boxes, boxes, rows, boxes.copy(), boxes.copy(), boxes.copy(), boxes.copy())
    nearest_per_query(boxes, boxes, rows, rows, rows[:1], values[:1].copy(), rows, rows, rows[:1], rows[:1].copy())
    carry_bounds(poses, poses.copy(), rows, boxes, values, boxes, boxes, rows, rows, np.zeros(4),
                 np.zeros(4, dtype=np.bool_), 1e-5, 1.0, np.zeros(4, dtype=np.int64))
    contact_gate(boxes, boxes, boxes, boxes, rows, rows, rows, flags, flags, rows, rows, rows, rows, flags, flags,
                 True, True, 0.1)
    inside_margin(boxes, poses[0], poses[1], 0.0, 0.0, 1.0, 1.0)
    place_piece(poses, 0, poses[1], np.zeros((3, 3)), np.zeros(3))
    stamp_total(rows, rows)


__all__ = ["any_within", "apply_poses", "carry_bounds", "contact_gate", "inside_margin", "move_frames", "nearest_per_query", "place_piece",
           "stamp_total", "update_bounds", "warm_up"]
