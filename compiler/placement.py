"""Plain 2D/3D placement geometry for lowering layouts: rectangles, bounds, support order.

Pure functions over floats and tuples (rotations from :mod:`fsvla.compiler.pose`); no
simulator, no FCL. Frames
follow the IR (``fsvla.dsl.models``): a support's top-surface frame has its origin at
the centre of the surface, +x forward, +y left, +z up; yaw is about +z,
counter-clockwise seen from above. Supports are only ever yawed, never tilted.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from .pose import Vec2, Vec3, rotate_xy

#: Footprints may touch; they overlap only when they share more than this (m) on both axes.
OVERLAP_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Rect:
    """An axis-aligned rectangle in some x-y frame."""

    min_xy: Vec2
    max_xy: Vec2

    @property
    def size(self) -> Vec2:
        return (self.max_xy[0] - self.min_xy[0], self.max_xy[1] - self.min_xy[1])

    def overlap(self, other: Rect) -> Vec2:
        """The extent shared with ``other`` along x and y (<= 0 where they are apart)."""
        return (
            min(self.max_xy[0], other.max_xy[0]) - max(self.min_xy[0], other.min_xy[0]),
            min(self.max_xy[1], other.max_xy[1]) - max(self.min_xy[1], other.min_xy[1]),
        )

    def overlaps(self, other: Rect, tol: float = OVERLAP_TOLERANCE) -> bool:
        ox, oy = self.overlap(other)
        return ox > tol and oy > tol

    def overhang(self, support: Rect) -> Vec2:
        """How far this rectangle sticks out of ``support`` along x and y (>= 0)."""
        return (
            max(0.0, self.max_xy[0] - support.max_xy[0], support.min_xy[0] - self.min_xy[0]),
            max(0.0, self.max_xy[1] - support.max_xy[1], support.min_xy[1] - self.min_xy[1]),
        )

    def __str__(self) -> str:
        return (f"x [{self.min_xy[0]:.4f}, {self.max_xy[0]:.4f}] "
                f"y [{self.min_xy[1]:.4f}, {self.max_xy[1]:.4f}] m")


def placed_rect(min_xy: Sequence[float], max_xy: Sequence[float], position: Sequence[float],
                yaw: float) -> Rect:
    """The axis-aligned bound of a body-frame rectangle after ``yaw`` and a shift to ``position``."""
    corners = [
        rotate_xy((x, y), yaw)
        for x in (min_xy[0], max_xy[0])
        for y in (min_xy[1], max_xy[1])
    ]
    xs = [c[0] + position[0] for c in corners]
    ys = [c[1] + position[1] for c in corners]
    return Rect((min(xs), min(ys)), (max(xs), max(ys)))


def box_corners(center: Sequence[float], half: Sequence[float]) -> list[Vec3]:
    return [
        (center[0] + sx * half[0], center[1] + sy * half[1], center[2] + sz * half[2])
        for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)
    ]


def aabb(points: Iterable[Sequence[float]]) -> tuple[Vec3, Vec3]:
    pts = list(points)
    lo = tuple(min(p[i] for p in pts) for i in range(3))
    hi = tuple(max(p[i] for p in pts) for i in range(3))
    return lo, hi  # type: ignore[return-value]


class CycleError(ValueError):
    def __init__(self, cycle: Sequence[str]):
        self.cycle = tuple(cycle)
        super().__init__("support cycle: " + " -> ".join(cycle))


def support_order(supports: Mapping[str, str], roots: Iterable[str] = ("world",)) -> list[str]:
    """Names of ``supports`` (name -> the name it stands on) so every support comes first.

    Stable: among the ready ones, the given order is kept. Names whose support is neither
    a root nor in the mapping are left to the caller to report (they come last, in order).
    Raises :class:`CycleError` naming the cycle."""
    root_set = set(roots)
    order: list[str] = []
    state: dict[str, int] = {}  # 1 visiting, 2 done

    def visit(name: str, path: list[str]) -> None:
        if state.get(name) == 2:
            return
        if state.get(name) == 1:
            start = path.index(name)
            raise CycleError([*path[start:], name])
        state[name] = 1
        parent = supports[name]
        if parent not in root_set and parent in supports:
            visit(parent, [*path, name])
        state[name] = 2
        order.append(name)

    for name in supports:
        visit(name, [])
    return order
