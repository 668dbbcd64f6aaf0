"""A route over the table around the keep-outs, for an object slid along it.

A push moves the object and the hand behind it along the table: it cannot rise over a
heat zone or a no-go column as a carry does. :func:`detour` finds the shortest route for
the object's centre from where it is to the target that keeps the object and the hand
outside every keep-out (each hazard's box grown by its largest limit plus warning band,
:meth:`World.obstacles`) with the object's half-width or the hand's half-length across
the push, whichever is larger, to spare (less where the object or the target stands
nearer, as long as the object itself keeps clear): straight where the line is clear,
else through points on polygons drawn around the grown boxes (a visibility graph,
shortest first). A keep-out the object would not keep clear of where it or the target
stands is left out (nothing avoids it).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..skills import DOWN
from ..world import World, box_distance, nearest_box_distance

#: What (m) the route keeps beyond the keep-outs, for the hand's path off its command.
SPARE = 0.01
#: How finely (m) a leg of the route is checked against the keep-outs.
CHECK_STEP = 0.005
#: Points on the polygon drawn around each corner of a grown box: this many angles over
#: its quarter turn (the polygon lies outside the rounded box it stands for).
CORNER_POINTS = 3
#: How high (m) above the object's top a keep-out still meets the pushing hand.
HAND_HEIGHT = 0.12


@dataclass
class Detour:
    """The points (world, at the object's height) the object's centre is pushed through
    before the target, in order, and the grown boxes they keep clear of (2-D)."""

    points: list[NDArray[np.float64]]
    boxes: list[tuple[NDArray[np.float64], NDArray[np.float64], float]]

    def clear(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
        """Whether the object's centre goes straight from ``a`` to ``b`` clear of them."""
        return _clear(np.asarray(a[:2]), np.asarray(b[:2]), self.boxes)


def detour(world: World, arm: str, obj: str, target: str) -> Detour:
    """The route for ``obj``'s centre to ``target`` (module doc): no points where the
    straight line keeps clear (or no route does)."""
    start, goal = world.body_pose(obj).p.copy(), world.body_pose(target).p.copy()
    lo, hi = world.bounds(obj)
    half = 0.5 * float(np.linalg.norm((hi - lo)[:2]))  # the object's, across any line
    grow = max(half, _hand_half_length(world, arm)) + SPARE
    least = half + SPARE
    boxes = []
    for o in world.obstacles(exclude=(obj, target)):
        if o.lo[2] > hi[2] + HAND_HEIGHT:
            continue
        # as far out as the object and the target stand, where they stand nearer than
        # the hand would keep; none where the object would not keep clear of it there
        ends = min(box_distance(p[:2], o.lo[:2], o.hi[:2]) for p in (start, goal)) - 1e-3
        keep = min(o.margin + grow, ends)
        if keep < o.margin + least:
            continue  # it already holds the object or the target: nothing avoids it
        boxes.append((o.lo[:2].copy(), o.hi[:2].copy(), keep))
    a, b = start[:2], goal[:2]
    if not boxes or _clear(a, b, boxes):
        return Detour([], boxes)
    nodes = [a, b] + [p for box in boxes for p in _around(*box)
                      if all(box_distance(p, lo2, hi2) >= keep2 for lo2, hi2, keep2 in boxes)]
    path = _shortest(nodes, boxes)
    if path is None:
        return Detour([], boxes)
    return Detour([np.array([nodes[i][0], nodes[i][1], start[2]]) for i in path[1:-1]], boxes)


def _hand_half_length(world: World, arm: str) -> float:
    """How far (m) the hand reaches out from its TCP along its finger axis, pointing down:
    across the push, where the fingers close across it (a Panda hand: 10.5 cm)."""
    R = world.grasp_frame(arm, DOWN, np.array([1.0, 0.0, 0.0]))
    axis = R @ world.finger_axis(arm)
    tcp = np.zeros(3)
    return max(world.hand_front(arm, R, s * axis, tcp, np.inf) for s in (1.0, -1.0))


def _around(lo: NDArray[np.float64], hi: NDArray[np.float64], keep: float
            ) -> list[NDArray[np.float64]]:
    """Points of a polygon around the box ``lo``..``hi`` grown by ``keep`` (2-D): at each
    corner, CORNER_POINTS angles over its quarter turn, far enough out for the polygon's
    edges to clear the rounded corner."""
    out = keep / np.cos(np.pi / (4 * (CORNER_POINTS - 1))) + 1e-3
    points = []
    for corner, start in (((hi[0], hi[1]), 0.0), ((lo[0], hi[1]), 90.0),
                          ((lo[0], lo[1]), 180.0), ((hi[0], lo[1]), 270.0)):
        for angle in np.deg2rad(start + np.linspace(0.0, 90.0, CORNER_POINTS)):
            points.append(np.asarray(corner) + out * np.array([np.cos(angle), np.sin(angle)]))
    return points


def _clear(a: NDArray[np.float64], b: NDArray[np.float64],
           boxes: list[tuple[NDArray[np.float64], NDArray[np.float64], float]]) -> bool:
    """Whether the segment ``a``-``b`` keeps each box's ``keep`` (to CHECK_STEP)."""
    n = max(2, int(np.ceil(float(np.linalg.norm(b - a)) / CHECK_STEP)) + 1)
    points = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
    return all(nearest_box_distance(points, lo, hi) >= keep - 1e-3 for lo, hi, keep in boxes)


def _shortest(nodes: list[NDArray[np.float64]],
              boxes: list[tuple[NDArray[np.float64], NDArray[np.float64], float]]
              ) -> list[int] | None:
    """The shortest path from node 0 to node 1 along segments that keep clear (Dijkstra
    over the visibility graph), as node indices; None where none does."""
    best = {0: 0.0}
    before: dict[int, int] = {}
    queue = [(0.0, 0)]
    done: set[int] = set()
    while queue:
        length, i = heapq.heappop(queue)
        if i in done:
            continue
        done.add(i)
        if i == 1:
            path = [1]
            while path[-1] != 0:
                path.append(before[path[-1]])
            return path[::-1]
        for j in range(len(nodes)):
            if j in done:
                continue
            step = float(np.linalg.norm(nodes[j] - nodes[i]))
            if length + step < best.get(j, np.inf) and _clear(nodes[i], nodes[j], boxes):
                best[j] = length + step
                before[j] = i
                heapq.heappush(queue, (length + step, j))
    return None


__all__ = ["Detour", "detour"]
