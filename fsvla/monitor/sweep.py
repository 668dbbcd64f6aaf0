"""Distances over a control step's motion, not only at its end.

The monitor reads poses once per control step (20 Hz), after its physics substeps. A frame
that passes through a thin zone within one step — from one side to the other, or in and
back out — is outside the band at both ends; measured at the ends only, the pass goes
unseen. The force channel takes the maximum over the substeps for the same reason.

:func:`swept_distance` looks inside the step. Each frame is taken to move along the
straight interpolation of its poses at the step's two ends (the origin on a line, the
rotation about one axis at a constant rate: :func:`interpolate`), sampled at the step's
physics substeps. A point then moves at most its frame origin's shift plus its reach from
that origin times the angle turned, per step, so a distance changes by at most the two
sides' travel times the time between two instants. Three bounds follow, cheapest first,
and each ends the search where it shows no instant can come below the threshold at stake:

1. the groups' distances at the step's start and end, less the groups' fastest travel
   (one compiled call per group, :func:`kernels.sweep_speed`): a still or far step stops here;
2. per piece pair, its bound at the start (its boxes' gap, or the groups' distance) and
   at the end (the bound :meth:`SceneGeometry.distance` carries), less the pair's own
   travel (:class:`~fsvla.monitor.geometry.StepSampler`): only pairs that may come near;
3. the instants themselves, lowest bound first: those pairs at the instant's interpolated
   poses (their boxes' gap there, then FCL), each measurement raising its neighbours'
   bounds by the distance found less the travel in between.

What the step reports (``limit`` and ``warn = limit + ε`` in distance):

- a step that ends at or beyond ``warn`` (safe) but came within ``warn`` at a sampled
  instant, or ends at or beyond ``limit`` but came within ``limit``, reports the smallest
  sampled distance: the incursion shows as exposure, or as a violation;
- otherwise the distance at the step's end (a step in the band stays in it, with the cost
  of its end: the depth inside the band is not searched).

The interpolation is the monitor's model of the motion between two reads of the poses,
not the path the physics took.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from . import kernels
from .geometry import SceneGeometry
from .state import Matrix4


def swept_distance(geo: SceneGeometry, a: frozenset[str], b: frozenset[str], end: float,
                   before: float | None, limit: float, warn: float) -> float:
    """The distance of groups ``a`` and ``b`` for the control step begun at the geometry's
    :meth:`~SceneGeometry.begin_step`: ``end`` (their distance now, exact below ``warn``),
    unless a sampled instant of the step came below the threshold ``end`` is beyond
    (``warn``, else ``limit``): then the smallest sampled distance. ``before``: their
    distance where the step began, if known (a lower bound will do)."""
    start, n = geo.step_start, geo.sweep_samples
    target = warn if end >= warn else limit if end >= limit else None
    if start is None or n < 2 or target is None:
        return end
    rows = geo.frame_rows(a), geo.frame_rows(b)
    poses, reach = geo.poses_array, geo.reach
    speed = kernels.sweep_speed(start, poses, rows[0], reach) + kernels.sweep_speed(start, poses, rows[1], reach)
    if _lowest_bound(end, before, speed, 1.0 / n) >= target:
        return end
    at = geo.within_step(a, b, 1.0 / n, before)
    if at.floor >= target:  # no piece pair can come that close within the step
        return end
    s = np.arange(1, n) / n
    lower = np.maximum(end - speed * (1.0 - s), at.floors(s, target))
    if before is not None:
        lower = np.maximum(lower, before - speed * s)
    best = math.inf
    while True:
        k = int(np.argmin(lower))
        if lower[k] >= min(target, best):
            break
        d = at(float(s[k]), min(target, best))
        best = min(best, d)
        np.maximum(lower, d - speed * np.abs(s - s[k]), out=lower)
        lower[k] = math.inf
    return best if best < target else end


def _lowest_bound(end: float, before: float | None, speed: float, first: float) -> float:
    """The smallest bound, over the instants from ``first`` to ``1 - first`` of the step, of
    a distance that changes by at most ``speed`` per step and is ``before`` at 0 (if known)
    and ``end`` at 1."""
    if speed <= 0.0:
        return end
    if before is None:
        return end - speed * (1.0 - first)
    s = min(1.0 - first, max(first, (before - end + speed) / (2.0 * speed)))  # where the two bounds cross
    return max(before - speed * s, end - speed * (1.0 - s))


def turns_of(start: NDArray[np.float64], end: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each frame's turn over the step, as a rotation vector in the frame's starting axes."""
    from scipy.spatial.transform import Rotation

    relative = np.einsum("nji,njk->nik", start[:, :3, :3], end[:, :3, :3])
    return Rotation.from_matrix(relative).as_rotvec()


def interpolate(start: NDArray[np.float64], end: NDArray[np.float64], turns: NDArray[np.float64],
                s: float) -> list[Matrix4]:
    """The frames' poses at the fraction ``s`` of the step: the origin ``s`` of the way along
    the line from ``start`` to ``end``, the rotation ``s`` of the way through ``turns``."""
    from scipy.spatial.transform import Rotation

    out = np.zeros_like(start)
    out[:, :3, :3] = start[:, :3, :3] @ Rotation.from_rotvec(s * turns).as_matrix()
    out[:, :3, 3] = (1.0 - s) * start[:, :3, 3] + s * end[:, :3, 3]
    out[:, 3, 3] = 1.0
    return list(out)


__all__ = ["interpolate", "swept_distance", "turns_of"]
