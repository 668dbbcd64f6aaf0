"""Convex pieces of a mesh, for collision.

A nearly convex mesh (volume over hull volume > ``CONVEX_VOLUME_RATIO``) becomes its
convex hull. Otherwise it is decomposed: with CoACD (``pip install coacd``) when it
is importable, else with :func:`split_decomposition`, a simple fallback that splits
the surface in half along its longest axis, recursively and to a bounded depth, and
takes the convex hull of each piece.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import trimesh
from scipy.spatial import QhullError

CONVEX_VOLUME_RATIO = 0.9
MAX_PIECES = 16
SPLIT_DEPTH = 3  # the fallback makes at most 2**SPLIT_DEPTH pieces
SPLIT_MIN_GAIN = 0.03  # stop splitting when the halves' hulls save less than this fraction

Method = Literal["auto", "coacd", "split"]


def convex_pieces(
    mesh: trimesh.Trimesh, *, method: Method = "auto", max_pieces: int = MAX_PIECES
) -> tuple[list[trimesh.Trimesh], str]:
    """Convex pieces covering ``mesh`` and the method used: "hull", "coacd" or "split"."""
    hull = mesh.convex_hull
    if mesh.is_volume and hull.volume > 0 and mesh.volume / hull.volume > CONVEX_VOLUME_RATIO:
        return [hull], "hull"
    if method in ("auto", "coacd"):
        pieces = coacd_decomposition(mesh, max_pieces)
        if pieces is not None:
            return pieces, "coacd"
        if method == "coacd":
            raise ValueError(
                "convex decomposition with CoACD was asked for, but `coacd` is not installed"
            )
    return split_decomposition(mesh), "split"


def coacd_decomposition(
    mesh: trimesh.Trimesh, max_pieces: int = MAX_PIECES
) -> list[trimesh.Trimesh] | None:
    """CoACD's decomposition (seeded, so reproducible); None when coacd is not installed."""
    try:
        import coacd
    except ImportError:
        return None
    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)),
        threshold=0.05,
        max_convex_hull=max_pieces,
        seed=0,
    )
    pieces = [trimesh.Trimesh(vertices, faces).convex_hull for vertices, faces in parts]
    return [p for p in pieces if p.volume > 0]


def split_decomposition(
    mesh: trimesh.Trimesh, max_depth: int = SPLIT_DEPTH
) -> list[trimesh.Trimesh]:
    """Hulls of the pieces of ``mesh`` cut in half along the longest axis, recursively.

    A piece is not cut further when it is at ``max_depth`` or when cutting it would
    shrink the hull volume by less than ``SPLIT_MIN_GAIN`` (it is nearly convex).
    Pieces are triangle soups clipped by planes, so no piece ever needs capping."""
    pieces: list[trimesh.Trimesh] = []
    _split(np.asarray(mesh.triangles, dtype=float), max_depth, pieces)
    return pieces


def _split(triangles: np.ndarray, depth: int, pieces: list[trimesh.Trimesh]) -> None:
    hull = _hull(triangles)
    if hull is None:
        return
    if depth == 0:
        pieces.append(hull)
        return
    points = triangles.reshape(-1, 3)
    lower, upper = points.min(axis=0), points.max(axis=0)
    axis = int(np.argmax(upper - lower))
    middle = (lower[axis] + upper[axis]) / 2.0
    halves = [clip_triangles(triangles, axis, middle, keep_above=above) for above in (True, False)]
    hulls = [_hull(half) for half in halves]
    if (
        any(h is None for h in hulls)
        or sum(h.volume for h in hulls) >= (1.0 - SPLIT_MIN_GAIN) * hull.volume
    ):
        pieces.append(hull)
        return
    for half in halves:
        _split(half, depth - 1, pieces)


def clip_triangles(
    triangles: np.ndarray, axis: int, value: float, *, keep_above: bool
) -> np.ndarray:
    """The parts of triangles (n, 3, 3) on one side of the plane ``x[axis] = value``."""
    distance = triangles[:, :, axis] - value
    if not keep_above:
        distance = -distance
    inside = distance >= 0.0
    count = inside.sum(axis=1)
    kept = [triangles[count == 3]]
    for n_inside, pick in ((1, np.argmax), (2, np.argmin)):
        mask = count == n_inside
        if not mask.any():
            continue
        # rotate each triangle so that its lone inside (or lone outside) vertex comes first
        first = pick(inside[mask], axis=1)
        order = (first[:, None] + np.arange(3)) % 3
        rows = np.arange(order.shape[0])[:, None]
        tri, dist = triangles[mask][rows, order], distance[mask][rows, order]
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        ab = a + (b - a) * (dist[:, 0] / (dist[:, 0] - dist[:, 1]))[:, None]
        ac = a + (c - a) * (dist[:, 0] / (dist[:, 0] - dist[:, 2]))[:, None]
        if n_inside == 1:
            kept.append(np.stack([a, ab, ac], axis=1))
        else:
            kept.append(np.stack([ab, b, c], axis=1))
            kept.append(np.stack([ab, c, ac], axis=1))
    return np.concatenate(kept, axis=0)


def _hull(triangles: np.ndarray) -> trimesh.Trimesh | None:
    """The convex hull of a triangle soup; None when it has no volume."""
    if len(triangles) == 0:
        return None
    try:
        hull = trimesh.Trimesh(vertices=triangles.reshape(-1, 3)).convex_hull
    except (QhullError, ValueError, IndexError):  # flat or degenerate point sets
        return None
    return hull if hull.volume > 1e-15 else None
