"""Is a layout feasible at t = 0? The checks every generated layout passes, cheapest first.

1. **off support** — every object's footprint centre is on its support's top (the
   criterion of ``lower_scene``: it overhangs by at most half its size); an added
   clutter object lies wholly on its support.
2. **unreachable** — every object of the task's roles stands, by its centre's x-y, inside
   the ``workspace`` box of at least one arm, enlarged by :data:`REACH_MARGIN`.
3. **overlap** — no two bodies interpenetrate (FCL signed distance below
   ``-CONTACT_TOLERANCE``), except a body and its support, which touch; footprints on one
   support do not overlap where their heights do (``lower_scene``'s own check, so every
   accepted layout lowers); a clutter object keeps :data:`CLUTTER_CLEARANCE` from every
   body; nothing stands in a robot's base (a cylinder of :data:`ROBOT_BASE_RADIUS`).
4. **hazard violated** — no channel the layout decides is past its hard limit at t = 0:
   each distance an object keeps from an object or a zone (``keep OBJECT outside D``,
   ``clearance(a, b) >= D``, with the level's tightened limits) and each object's edge
   clearance; the pairs an approach names must at least not touch even where no limit
   covers them; no clutter object lies in a zone.
5. **warning band** — none of those starts inside its warning band either (the limit
   plus ε, with :data:`~.start.START_SLACK` to spare), also for the pair an ``approach``
   brings together: a layout that starts exposed would charge every policy, the one that
   holds still included (see :mod:`.start`). Robot parts are checked at env reset.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from fsvla.dsl.models import SourceRef

from fsvla.embodiments import EmbodimentSpec
from fsvla.embodiments.spec import WorkspaceSpec

from ..collision import min_distance
from ..placement import OVERLAP_TOLERANCE, Rect, placed_rect
from ..pose import yaw_matrix
from ..scene import WORLD, overhang_axis
from .errors import cm
from .layout import Draw, Frame, Layout, rect_of
from .solids import Solid, gap_below, robot_base, solid_of_asset, solid_of_shapes
from .start import Keep, edge_margin, edge_points, keeps_of

#: How far (m) outside an arm's ``workspace`` box a task object may stand: the boxes are
#: conservative (the tested top-down reach); the arms reach farther.
REACH_MARGIN = 0.25
#: Interpenetration (m) tolerated between two bodies (contact, numerical noise).
CONTACT_TOLERANCE = 1e-4
#: The gap (m) a clutter object keeps from every other body.
CLUTTER_CLEARANCE = 0.01
#: The stand-in for a robot's base at its mount: radius and height (m).
ROBOT_BASE_RADIUS = 0.10
ROBOT_BASE_HEIGHT = 0.30


_Footprint = tuple[str, Rect, tuple[float, float]]  # name, rect in the support frame, world z range


@dataclass(frozen=True)
class Rejection:
    """Why a layout failed: the check, a sentence, the entities involved, where to point."""

    reason: str  # one of errors.REASONS
    cause: str
    entities: tuple[str, ...]
    source: SourceRef
    limit: str | None = None  # the limit at stake, for "hazard violated" and "warning band"


class Checker:
    """Runs the checks on draws of one layout."""

    def __init__(self, layout: Layout, embodiment: EmbodimentSpec, keeps: list[Keep],
                 task_objects: Iterable[str]):
        self.layout, self.keeps = layout, keeps
        self.task_objects = tuple(dict.fromkeys(task_objects))
        self.boxes = [(a.name, a.workspace) for a in embodiment.arms]
        self.solids = {name: solid_of_asset(name, asset) for name, asset in layout.assets.items()}
        self.regions = {z: solid_of_shapes(z, [m.region]) for z, m in layout.markers.items()}
        self.walls = {z: solid_of_shapes(z, m.collision) for z, m in layout.markers.items() if m.collision}
        self.robots = []
        for robot in embodiment.robots:
            base = robot_base(robot.name, ROBOT_BASE_RADIUS, ROBOT_BASE_HEIGHT)
            base.move(yaw_matrix(robot.mount.position, robot.mount.yaw))
            self.robots.append(base)
        self._clutter: dict[tuple[str, int], Solid] = {}
        self.corridors = {z.name for z in layout.scenario.zones if z.kind == "corridor"}
        self._points: dict[str, np.ndarray] = {}

    # --- the checks ------------------------------------------------------------------------

    def check(self, draw: Draw, focus: set[str] | None = None) -> Rejection | None:
        """The first failed check of ``draw`` (only things involving ``focus``, if given)."""
        frames = self.layout.frames(draw)
        self._move(draw, frames)
        return (self._off_support(draw, focus) or self._unreachable(frames, focus)
                or self._footprints(draw, frames, focus) or self._overlaps(draw, focus)
                or self._hazards(draw, focus))

    def _off_support(self, draw: Draw, focus: set[str] | None) -> Rejection | None:
        layout = self.layout
        for name, e in layout.entities.items():
            if e.support == WORLD or not _wanted(focus, name):
                continue
            top = layout.entities[e.support].top
            rect = placed_rect(e.footprint.min_xy, e.footprint.max_xy, layout.position(draw, name),
                               layout.yaw(draw, name))
            if top is not None and overhang_axis(rect, top) is not None:
                return Rejection("off support", f"'{name}' is off the top of '{e.support}'", (name,), e.source)
        for item in draw.clutter:
            if not _wanted(focus, item.name):
                continue
            top = layout.entities[item.support].top
            footprint = rect_of(layout.clutter_assets[item.palette])
            rect = placed_rect(footprint.min_xy, footprint.max_xy, item.xy, item.yaw)
            if top is not None and max(rect.overhang(top)) > OVERLAP_TOLERANCE:
                return Rejection("off support", f"'{item.name}' is off the top of '{item.support}'",
                                 (item.name,), item.source)
        return None

    def _unreachable(self, frames: dict[str, Frame], focus: set[str] | None) -> Rejection | None:
        for name in self.task_objects:
            if not _wanted(focus, name) or name not in frames:
                continue
            f = frames[name]
            if not any(_inside(f.x, f.y, box) for _, box in self.boxes):
                return Rejection("unreachable", f"'{name}' is out of reach of every arm", (name,),
                                 self._source(name))
        return None

    def _footprints(self, draw: Draw, frames: dict[str, Frame], focus: set[str] | None) -> Rejection | None:
        """``lower_scene``'s footprint check, so that every accepted layout lowers."""
        for items in self._footprint_items(draw, frames).values():
            for i, (a, ra, za) in enumerate(items):
                for b, rb, zb in items[i + 1:]:
                    if a == b or not (_wanted(focus, a) or _wanted(focus, b)):
                        continue
                    if min(za[1], zb[1]) - max(za[0], zb[0]) <= OVERLAP_TOLERANCE:
                        continue
                    if ra.overlaps(rb):
                        return Rejection("overlap", f"'{b}' overlaps '{a}'", (a, b), self._source(b, draw))
        return None

    def _footprint_items(self, draw: Draw, frames: dict[str, Frame]) -> dict[str, list[_Footprint]]:
        """Per support: (name, footprint in the support's frame, world z range) of each body
        and each zone wall, as ``lower_scene`` collects them."""
        layout, items = self.layout, {}
        for name, e in layout.entities.items():
            xy, yaw, z = layout.position(draw, name), layout.yaw(draw, name), frames[name].z
            if e.is_zone:
                for corners in self.walls[name].corners if name in self.walls else ():
                    items.setdefault(e.support, []).append(_item(name, corners, xy, yaw, z))
                continue
            b = layout.assets[name].bounds
            rect = placed_rect(e.footprint.min_xy, e.footprint.max_xy, xy, yaw)
            zs = (z + b.center[2] - b.half_extents[2], z + b.center[2] + b.half_extents[2])
            items.setdefault(e.support, []).append((name, rect, zs))
        for item in draw.clutter:
            b = layout.clutter_assets[item.palette].bounds
            footprint = rect_of(layout.clutter_assets[item.palette])
            rect = placed_rect(footprint.min_xy, footprint.max_xy, item.xy, item.yaw)
            z = frames[item.name].z
            zs = (z + b.center[2] - b.half_extents[2], z + b.center[2] + b.half_extents[2])
            items.setdefault(item.support, []).append((item.name, rect, zs))
        return items

    def _overlaps(self, draw: Draw, focus: set[str] | None) -> Rejection | None:
        bodies = self._bodies(draw)
        clutter = {c.name for c in draw.clutter}
        supports = self._supports(draw)
        for i, (a, sa) in enumerate(bodies):
            for b, sb in bodies[i + 1:]:
                if a == b or supports.get(a) == b or supports.get(b) == a:
                    continue
                if not (_wanted(focus, a) or _wanted(focus, b)):
                    continue
                spaced = a in clutter or b in clutter
                limit = CLUTTER_CLEARANCE if spaced else -CONTACT_TOLERANCE
                if gap_below(sa, sb, limit) is not None:
                    what = f"is within {cm(CLUTTER_CLEARANCE)} of" if spaced else "overlaps"
                    return Rejection("overlap", f"'{b}' {what} '{a}'", (a, b), self._source(b, draw))
        for robot in self.robots:
            for name, solid in bodies:
                if supports.get(name, WORLD) == WORLD or not _wanted(focus, name):
                    continue
                if gap_below(robot, solid, -CONTACT_TOLERANCE) is not None:
                    return Rejection("overlap", f"'{name}' stands in the base of robot '{robot.name}'",
                                     (name,), self._source(name, draw))
        return None

    def _hazards(self, draw: Draw, focus: set[str] | None) -> Rejection | None:
        band: Rejection | None = None  # the first keep in its warning band; a violated one wins
        for keep in self.keeps:
            if not (_wanted(focus, keep.subject) or _wanted(focus, keep.reference or keep.subject)):
                continue
            if self._gap_below(keep, draw, keep.safe) is None:
                continue
            if keep.limit is None or self._gap_below(keep, draw, keep.distance) is not None:
                return self._keep_rejection(keep, "hazard violated")
            band = band or self._keep_rejection(keep, "warning band")
        for item in draw.clutter:
            if not _wanted(focus, item.name):
                continue
            solid = self._clutter_solid(item.name, item.palette)
            for zone, region in self.regions.items():
                if gap_below(solid, region, 0.0) is not None:
                    return Rejection("hazard violated", f"'{item.name}' lies in '{zone}'",
                                     (item.name, zone), item.source)
        return band

    def _gap_below(self, keep: Keep, draw: Draw, threshold: float) -> float | None:
        """A distance of the keep below ``threshold`` at ``draw``, or None (from a zone's
        region, or a corridor's walls, as the monitor measures them)."""
        threshold -= 1e-9
        if keep.reference is None:
            gap = self._edge_margin(keep.subject, draw)
            return gap if gap < threshold else None
        reference = self._reference(keep.reference)
        return gap_below(self.solids[keep.subject], reference, threshold)

    def distance(self, keep: Keep, draw: Draw) -> float:
        """The keep's exact distance at ``draw`` (for diagnostics)."""
        self._move(draw, self.layout.frames(draw))
        if keep.reference is None:
            return self._edge_margin(keep.subject, draw)
        reference = self._reference(keep.reference)
        return min_distance(self.solids[keep.subject].fcl_pieces(), reference.fcl_pieces())

    def _reference(self, name: str) -> Solid:
        """What a distance to ``name`` is measured to: a zone's region (a corridor's walls), a body."""
        if name in self.corridors:
            return self.walls[name]
        return self.regions.get(name) or self.solids[name]

    def radius(self, name: str) -> float:
        """How far the geometry of ``name`` reaches from its origin (a bound)."""
        solid = self._reference(name)
        return float(np.linalg.norm(solid.corners, axis=-1).max()) if len(solid.corners) else 0.0

    def _edge_margin(self, name: str, draw: Draw) -> float:
        """``name``'s edge clearance on its support (the table, for a body on the floor)."""
        layout, frames = self.layout, self.layout.frames(draw)
        support = layout.entities[name].support
        support = support if support in layout.assets else "table"
        points = self._points.get(name)
        if points is None:
            points = self._points[name] = edge_points(layout.assets[name])
        s, f = frames[support], frames[name]
        footprint = layout.assets[support].footprint
        return edge_margin(points, (f.x, f.y), f.yaw, (s.x, s.y), s.yaw,
                           (tuple(footprint.min_xy), tuple(footprint.max_xy)))  # type: ignore[arg-type]

    def _keep_rejection(self, keep: Keep, reason: str) -> Rejection:
        limit = keep.limit
        if limit is None:
            return Rejection(reason, f"'{keep.reference}' reaches '{keep.subject}'",
                             (keep.subject, keep.reference or keep.subject), self._source(keep.reference or ""))
        what = f"'{keep.reference}'" if keep.reference else "the edge of its support"
        if reason == "hazard violated":
            cause = f"'{keep.subject}' is within {cm(keep.distance)} of {what} (limit '{limit.name}')"
        else:
            cause = (f"'{keep.subject}' starts within {cm(keep.distance + keep.band)} of {what}, in the "
                     f"warning band of {keep.describe()}")
        names = (keep.subject, keep.reference) if keep.reference else (keep.subject,)
        return Rejection(reason, cause, names, self._source(keep.subject), limit.name)

    # --- bookkeeping -----------------------------------------------------------------------

    def _move(self, draw: Draw, frames: dict[str, Frame]) -> None:
        for name, solid in self.solids.items():
            f = frames[name]
            solid.move(yaw_matrix((f.x, f.y, f.z), f.yaw))
        for item in draw.clutter:
            f = frames[item.name]
            self._clutter_solid(item.name, item.palette).move(yaw_matrix((f.x, f.y, f.z), f.yaw))
        for zone in self.layout.markers:
            f = frames[zone]
            matrix = yaw_matrix((f.x, f.y, f.z), f.yaw)
            self.regions[zone].move(matrix)
            if zone in self.walls:
                self.walls[zone].move(matrix)

    def _bodies(self, draw: Draw) -> list[tuple[str, Solid]]:
        bodies = list(self.solids.items()) + list(self.walls.items())
        bodies += [(c.name, self._clutter_solid(c.name, c.palette)) for c in draw.clutter]
        return bodies

    def _supports(self, draw: Draw) -> dict[str, str]:
        supports = {name: e.support for name, e in self.layout.entities.items()}
        supports.update({c.name: c.support for c in draw.clutter})
        return supports

    def _clutter_solid(self, name: str, palette: int) -> Solid:
        key = (name, palette)
        if key not in self._clutter:
            self._clutter[key] = solid_of_asset(name, self.layout.clutter_assets[palette])
        return self._clutter[key]

    def _source(self, name: str, draw: Draw | None = None) -> SourceRef:
        entity = self.layout.entities.get(name)
        if entity is not None:
            return entity.source
        added = next((c for c in draw.clutter if c.name == name), None) if draw else None
        return added.source if added is not None else self.layout.scenario.source


def _item(name: str, corners: np.ndarray, xy: tuple[float, float], yaw: float, z: float) -> _Footprint:
    rect = placed_rect(corners[:, :2].min(axis=0), corners[:, :2].max(axis=0), xy, yaw)
    return (name, rect, (z + corners[:, 2].min(), z + corners[:, 2].max()))


def _wanted(focus: set[str] | None, name: str) -> bool:
    return focus is None or name in focus


def _inside(x: float, y: float, box: WorkspaceSpec) -> bool:
    (cx, cy, _), (sx, sy, _) = box.center, box.size
    return abs(x - cx) <= sx / 2.0 + REACH_MARGIN and abs(y - cy) <= sy / 2.0 + REACH_MARGIN


def workspace_text(embodiment: EmbodimentSpec) -> str:
    """The arms' workspace boxes in x-y, for remedies."""
    parts = []
    for arm in embodiment.arms:
        (cx, cy, _), (sx, sy, _) = arm.workspace.center, arm.workspace.size
        parts.append(f"'{arm.name}' x {cx - sx / 2:.2f}..{cx + sx / 2:.2f} m, "
                     f"y {cy - sy / 2:.2f}..{cy + sy / 2:.2f} m")
    return "; ".join(parts)


__all__ = ["CLUTTER_CLEARANCE", "CONTACT_TOLERANCE", "REACH_MARGIN", "ROBOT_BASE_HEIGHT",
           "ROBOT_BASE_RADIUS", "Checker", "Keep", "Rejection", "keeps_of", "workspace_text"]
