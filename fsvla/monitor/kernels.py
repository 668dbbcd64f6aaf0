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


@njit(cache=True, nogil=True)
def sweep_speed(start: NDArray[np.float64], poses: NDArray[np.float64], frames: NDArray[np.int64],
                reach: NDArray[np.float64]) -> float:
    """How fast a point of the frames' geometry can move, per unit of a control step, while
    each frame goes from pose ``start`` to pose ``poses`` along the straight interpolation
    (its origin on a line, its rotation about one axis at a constant rate): the largest over
    the frames of the origin's shift plus ``reach`` times the angle turned."""
    best = 0.0
    for f in frames:
        shift = 0.0
        trace = 0.0
        for i in range(3):
            d = poses[f, i, 3] - start[f, i, 3]
            shift += d * d
            for j in range(3):
                trace += start[f, i, j] * poses[f, i, j]  # the trace of start^T poses
        turn = math.acos(min(1.0, max(-1.0, 0.5 * (trace - 1.0))))
        best = max(best, math.sqrt(shift) + reach[f] * turn)
    return best


@njit(cache=True, nogil=True, inline="always")
def _turn(start: NDArray[np.float64], end: NDArray[np.float64], f: int) -> tuple[float, float, float, float]:
    """The axis (x, y, z) and angle of the rotation from frame ``f``'s orientation in
    ``start`` to the one in ``end``, in the frame's starting axes (start^T end)."""
    r = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            total = 0.0
            for k in range(3):
                total += start[f, k, i] * end[f, k, j]
            r[i, j] = total
    angle = math.acos(min(1.0, max(-1.0, 0.5 * (r[0, 0] + r[1, 1] + r[2, 2] - 1.0))))
    x, y, z = r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]  # 2 sin(angle) times the axis
    if angle > math.pi - 1e-3:  # sin(angle) too small to divide by: the axis from the symmetric part
        k = 0 if r[0, 0] >= r[1, 1] and r[0, 0] >= r[2, 2] else (1 if r[1, 1] >= r[2, 2] else 2)
        u = np.empty(3)
        for i in range(3):
            u[i] = r[k, i] + r[i, k] if i != k else 1.0 + 2.0 * r[k, k] - r[0, 0] - r[1, 1] - r[2, 2]
        sign = -1.0 if u[0] * x + u[1] * y + u[2] * z < 0.0 else 1.0
        x, y, z = sign * u[0], sign * u[1], sign * u[2]
    norm = math.sqrt(x * x + y * y + z * z)
    if norm <= 0.0:
        return 1.0, 0.0, 0.0, 0.0
    return x / norm, y / norm, z / norm, angle


@njit(cache=True, nogil=True)
def interpolate_frames(start: NDArray[np.float64], end: NDArray[np.float64], frames: NDArray[np.int64], s: float,
                       out: NDArray[np.float64]) -> None:
    """``out[f]`` for each of ``frames``: its pose the fraction ``s`` of the way from ``start``
    to ``end`` (the origin along the line between them, the orientation turned ``s`` of the
    way about the fixed axis that takes one to the other: ``fsvla.monitor.sweep.interpolate``)."""
    for f in frames:
        x, y, z, angle = _turn(start, end, f)
        c, si = math.cos(s * angle), math.sin(s * angle)
        t = 1.0 - c
        turn = np.array([[c + x * x * t, x * y * t - z * si, x * z * t + y * si],
                         [y * x * t + z * si, c + y * y * t, y * z * t - x * si],
                         [z * x * t - y * si, z * y * t + x * si, c + z * z * t]])
        for i in range(3):
            for j in range(3):
                total = 0.0
                for k in range(3):
                    total += start[f, i, k] * turn[k, j]
                out[f, i, j] = total
            out[f, i, 3] = (1.0 - s) * start[f, i, 3] + s * end[f, i, 3]
            out[f, 3, i] = 0.0
        out[f, 3, 3] = 1.0


@njit(cache=True, nogil=True)
def piece_travel(start: NDArray[np.float64], end: NDArray[np.float64], piece_frame: NDArray[np.int64],
                 centre: NDArray[np.float64], radius: NDArray[np.float64], pieces: NDArray[np.int64]
                 ) -> NDArray[np.float64]:
    """How far a point of each of ``pieces`` can travel over the step's interpolated motion
    (:func:`interpolate_frames`): its frame origin's shift plus the angle turned times the
    piece's reach from that origin (its box centre's distance plus its radius)."""
    out = np.empty(pieces.shape[0])
    for n in range(pieces.shape[0]):
        p = pieces[n]
        f = piece_frame[p]
        shift = 0.0
        for i in range(3):
            d = end[f, i, 3] - start[f, i, 3]
            shift += d * d
        reach = math.sqrt(centre[p, 0] ** 2 + centre[p, 1] ** 2 + centre[p, 2] ** 2) + radius[p]
        out[n] = math.sqrt(shift) + _turn(start, end, f)[3] * reach
    return out


@njit(cache=True, nogil=True, inline="always")
def _piece_boxes(poses: NDArray[np.float64], piece_frame: NDArray[np.int64], centre: NDArray[np.float64],
                 half: NDArray[np.float64], a: NDArray[np.int64], b: NDArray[np.int64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """World boxes (rows: ``a``'s pieces, then ``b``'s) with their frames at ``poses``."""
    na, nb = a.shape[0], b.shape[0]
    lo = np.empty((na + nb, 3))
    hi = np.empty((na + nb, 3))
    for n in range(na + nb):
        p = a[n] if n < na else b[n - na]
        f = piece_frame[p]
        for i in range(3):
            c = poses[f, i, 3]
            h = 0.0
            for j in range(3):
                c += poses[f, i, j] * centre[p, j]
                h += abs(poses[f, i, j]) * half[p, j]
            lo[n, i], hi[n, i] = c - h, c + h
    return lo, hi


@njit(cache=True, nogil=True)
def step_bounds(start: NDArray[np.float64], piece_frame: NDArray[np.int64], centre: NDArray[np.float64],
                half: NDArray[np.float64], a: NDArray[np.int64], b: NDArray[np.int64], at_end: NDArray[np.float64],
                travel_a: NDArray[np.float64], travel_b: NDArray[np.float64], first: float, before: float,
                out: NDArray[np.float64], at_start: NDArray[np.float64]) -> None:
    """``out[i * len(b) + j]``: a lower bound of the signed distance of pieces ``a[i]`` and
    ``b[j]`` at every instant from ``first`` to ``1 - first`` of a step, from their bound at
    its start (``at_start``: the larger of their boxes' gap there, frames at ``start``,
    where apart, and ``before``, the groups' distance there) and their bound ``at_end``,
    each less how far the two can travel between that end of the step and the instant."""
    na, nb = a.shape[0], b.shape[0]
    lo, hi = _piece_boxes(start, piece_frame, centre, half, a, b)
    for i in range(na):
        for j in range(nb):
            k = i * nb + j
            travel = travel_a[i] + travel_b[j]
            end = at_end[k]
            gap = _distance(lo, hi, i, na + j)
            gap = max(gap if gap > 0.0 else -np.inf, before)
            at_start[k] = gap
            if gap == -np.inf:  # nothing known at the start
                out[k] = end - travel * (1.0 - first)
            elif travel <= 0.0:
                out[k] = max(gap, end)
            else:  # the larger of two bounds is smallest where they cross
                s = min(1.0 - first, max(first, (gap - end + travel) / (2.0 * travel)))
                out[k] = max(gap - travel * s, end - travel * (1.0 - s))


@njit(cache=True, nogil=True)
def instant_bounds(poses: NDArray[np.float64], piece_frame: NDArray[np.int64], centre: NDArray[np.float64],
                   half: NDArray[np.float64], a: NDArray[np.int64], b: NDArray[np.int64], pairs: NDArray[np.int64],
                   at_end: NDArray[np.float64], travel_a: NDArray[np.float64], travel_b: NDArray[np.float64],
                   rest: float, out: NDArray[np.float64]) -> None:
    """``out[n]``: a lower bound of the signed distance of the piece pair ``pairs[n]`` (``i *
    len(b) + j``: ``a[i]`` and ``b[j]``) with their frames at ``poses``, the fraction ``1 -
    rest`` of a step that ends with the bounds ``at_end``: the larger of their boxes' gap
    (where they are apart) and ``at_end`` less how far the two can travel in the ``rest``."""
    na, nb = a.shape[0], b.shape[0]
    lo, hi = _piece_boxes(poses, piece_frame, centre, half, a, b)
    for n in range(pairs.shape[0]):
        k = pairs[n]
        i, j = k // nb, k % nb
        gap = _distance(lo, hi, i, na + j)
        carried = at_end[k] - (travel_a[i] + travel_b[j]) * rest
        out[n] = max(gap, carried) if gap > 0.0 else carried


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
    sweep_speed(poses, poses, rows, values)
    interpolate_frames(poses, poses.copy(), rows, 0.5, poses.copy())
    travel = piece_travel(poses, poses, rows, boxes, values, rows)
    step_bounds(poses, rows, boxes, boxes, rows, rows, np.zeros(4), travel, travel, 0.04, -np.inf, np.zeros(4),
                np.zeros(4))
    instant_bounds(poses, rows, boxes, boxes, rows, rows, rows, np.zeros(4), travel, travel, 0.5, np.zeros(2))


__all__ = [
    "any_within",
    "apply_poses",
    "carry_bounds",
    "contact_gate",
    "inside_margin",
    "instant_bounds",
    "interpolate_frames",
    "move_frames",
    "nearest_per_query",
    "piece_travel",
    "place_piece",
    "stamp_total",
    "step_bounds",
    "sweep_speed",
    "update_bounds",
    "warm_up",
]
