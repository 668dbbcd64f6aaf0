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
                      b: NDArray[np.int64], starts: NDArray[np.int64], out: NDArray[np.float64]) -> None:
    """``out[q]``: the smallest distance of the box pairs ``(a[k], b[k])`` for k from
    ``starts[q]`` up to the next query's start (or the end)."""
    n = starts.shape[0]
    for q in range(n):
        end = starts[q + 1] if q + 1 < n else a.shape[0]
        best = np.inf
        for k in range(starts[q], end):
            best = min(best, _distance(lo, hi, a[k], b[k]))
        out[q] = best


@njit(cache=True, nogil=True)
def pair_distances(lo: NDArray[np.float64], hi: NDArray[np.float64], a: NDArray[np.int64],
                   b: NDArray[np.int64], out: NDArray[np.float64]) -> None:
    """``out[i * len(b) + j]``: the distance of boxes ``a[i]`` and ``b[j]``."""
    nb = b.shape[0]
    for i in range(a.shape[0]):
        for j in range(nb):
            out[i * nb + j] = _distance(lo, hi, a[i], b[j])


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
def columns_within(lo: NDArray[np.float64], hi: NDArray[np.float64], a: NDArray[np.int64],
                   b: NDArray[np.int64], gap: float) -> NDArray[np.bool_]:
    """Per box of ``b``: whether some box of ``a`` has every axis' gap to it below ``gap``."""
    out = np.zeros(b.shape[0], dtype=np.bool_)
    for j in range(b.shape[0]):
        for i in range(a.shape[0]):
            if _within(lo, hi, a[i], b[j], gap):
                out[j] = True
                break
    return out


@njit(cache=True, nogil=True)
def inside_margin(points: NDArray[np.float64], pose: NDArray[np.float64], x0: float, y0: float,
                  x1: float, y1: float) -> float:
    """The smallest distance, in the xy-plane of ``pose``'s frame, from a point of ``points``
    (world) to the edges of the rectangle [x0, x1] × [y0, y1] there: negative for a point
    outside it; infinity for no points."""
    best = np.inf
    for k in range(points.shape[0]):
        dx, dy, dz = points[k, 0] - pose[0, 3], points[k, 1] - pose[1, 3], points[k, 2] - pose[2, 3]
        x = dx * pose[0, 0] + dy * pose[1, 0] + dz * pose[2, 0]
        y = dx * pose[0, 1] + dy * pose[1, 1] + dz * pose[2, 1]
        best = min(best, x - x0, x1 - x, y - y0, y1 - y)
    return best


__all__ = ["any_within", "apply_poses", "columns_within", "inside_margin", "nearest_per_query", "pair_distances",
           "update_bounds"]
