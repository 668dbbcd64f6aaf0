"""A layout being varied: where each object and zone stands, and the rules that move them.

Positions live in the IR's frames (each support's top surface, see
``fsvla.dsl.models``). A :class:`Draw` holds one sample's offsets on top of the
canonical layout; an entity written ``right_of mug by 14 cm`` keeps that relation, so
it follows its anchor when the anchor moves (then its own jitter applies). World
frames are computed the way ``lower_scene`` places things: an entity on support S at
(x, y) with yaw ψ stands at ``S.xy + R(S.yaw)·(x, y)`` on S's top, yawed ``S.yaw + ψ``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from fsvla.compiler.assets import ArticulatedAsset, RigidAsset, ZoneAsset
from fsvla.dsl.catalog import ASSETS
from fsvla.dsl.models import ObjectSpec, ParamValue, Placement, Scenario, SourceRef, ZoneSpec

from ..assets.registry import merge_params
from ..placement import Rect, support_order
from ..pose import rotate_xy
from ..scene import WORLD, surface_height

#: Distractors for ``clutter``: catalogue kinds with everyday sizes (SI). The blocks are
#: not the default red of a block, so that a distractor is never a copy of "the red block".
CLUTTER_PALETTE: tuple[tuple[str, dict[str, ParamValue]], ...] = (
    ("block", {"size": (0.05, 0.05, 0.05), "color": "yellow"}),
    ("block", {"size": (0.08, 0.04, 0.04), "color": "purple"}),
    ("bottle", {"radius": 0.03, "height": 0.18}),
    ("bowl", {"radius": 0.06, "height": 0.05}),
    ("mug", {"radius": 0.035, "height": 0.09}),
)


def clutter_params(index: int) -> tuple[str, dict[str, ParamValue]]:
    """Palette entry ``index`` with the catalogue's defaults filled in, as the IR holds them."""
    kind, params = CLUTTER_PALETTE[index]
    return kind, merge_params(ASSETS[kind], params)


def rect_of(asset: RigidAsset | ArticulatedAsset | ZoneAsset) -> Rect:
    return Rect(tuple(asset.footprint.min_xy), tuple(asset.footprint.max_xy))  # type: ignore[arg-type]


@dataclass(frozen=True)
class Entity:
    """An object or zone as the canonical layout has it."""

    name: str
    support: str
    xy: tuple[float, float]
    yaw: float
    height: float
    anchor: str | None  # the relation's anchor when it stands on the same support
    footprint: Rect  # own frame
    top: Rect | None  # the surface it offers others (objects only)
    surface: float  # its top's height above its origin (objects only)
    is_zone: bool
    source: SourceRef


@dataclass
class ClutterItem:
    """A distractor added by a ``clutter`` rule."""

    name: str
    palette: int
    support: str
    xy: tuple[float, float]
    yaw: float
    rule: int  # index of the clutter rule that added it
    source: SourceRef  # where that rule was written


@dataclass
class Draw:
    """One sample: offsets on the canonical layout, added clutter, and who moved what."""

    offsets: dict[str, np.ndarray] = field(default_factory=dict)
    turns: dict[str, float] = field(default_factory=dict)
    moved_by: dict[str, set[int]] = field(default_factory=dict)  # entity -> rule indices
    clutter: list[ClutterItem] = field(default_factory=list)

    def shift(self, name: str, delta: np.ndarray, rule: int) -> None:
        self.offsets[name] = self.offsets.get(name, np.zeros(2)) + delta
        self.moved_by.setdefault(name, set()).add(rule)

    def turn(self, name: str, angle: float, rule: int) -> None:
        self.turns[name] = self.turns.get(name, 0.0) + angle
        self.moved_by.setdefault(name, set()).add(rule)


@dataclass(frozen=True)
class Frame:
    """A placed thing in the world: position of its origin, yaw, and its top's height."""

    x: float
    y: float
    z: float
    yaw: float
    top_z: float


class Layout:
    """The canonical layout of a scenario, and the world frames of any draw of it."""

    def __init__(self, scenario: Scenario, assets: dict[str, RigidAsset | ArticulatedAsset],
                 markers: dict[str, ZoneAsset], clutter_assets: dict[int, RigidAsset]):
        self.scenario = scenario
        self.assets, self.markers, self.clutter_assets = assets, markers, clutter_assets
        self.entities: dict[str, Entity] = {}
        for obj in scenario.objects:
            self.entities[obj.name] = self._entity(obj, rect_of(assets[obj.name]), False)
        for zone in scenario.zones:
            self.entities[zone.name] = self._entity(zone, rect_of(markers[zone.name]), True)
        self.order = support_order({o.name: o.placement.support for o in scenario.objects}, (WORLD,))
        table = scenario.object("table")
        self.ground_z = 0.0
        if table is not None and table.placement.support == WORLD:
            self.ground_z = -(surface_height(assets["table"]) + table.placement.height)

    def _entity(self, spec: ObjectSpec | ZoneSpec, footprint: Rect, is_zone: bool) -> Entity:
        p = spec.placement
        anchor = p.relation.anchor if p.relation is not None else None
        other = self._placement(anchor) if anchor else None
        same = other is not None and other.support == p.support
        asset = None if is_zone else self.assets[spec.name]
        return Entity(name=spec.name, support=p.support, xy=tuple(p.position), yaw=p.yaw,
                      height=p.height, anchor=anchor if same else None, footprint=footprint,
                      top=None if asset is None else rect_of(asset),
                      surface=0.0 if asset is None else surface_height(asset),
                      is_zone=is_zone, source=spec.source)

    def _placement(self, name: str) -> Placement | None:
        found = self.scenario.object(name) or next((z for z in self.scenario.zones if z.name == name), None)
        return found.placement if found is not None else None

    # --- positions in support frames -------------------------------------------------------

    def position(self, draw: Draw, name: str) -> tuple[float, float]:
        """Where ``name`` stands on its support in ``draw`` (relations kept)."""
        x, y = self.entities[name].xy
        dx, dy = self._shift(draw, name)
        return (x + dx, y + dy)

    def _shift(self, draw: Draw, name: str) -> tuple[float, float]:
        anchor = self.entities[name].anchor
        dx, dy = self._shift(draw, anchor) if anchor is not None else (0.0, 0.0)
        offset = draw.offsets.get(name)
        if offset is not None:
            dx, dy = dx + float(offset[0]), dy + float(offset[1])
        return (dx, dy)

    def yaw(self, draw: Draw, name: str) -> float:
        return self.entities[name].yaw + draw.turns.get(name, 0.0)

    def movers(self, draw: Draw, name: str) -> set[int]:
        """The rules that moved ``name``, directly, through its anchor or through its support."""
        entity = self.entities.get(name)
        found = set(draw.moved_by.get(name, ()))
        if entity is None:
            return found
        if entity.anchor is not None:
            found |= self.movers(draw, entity.anchor)
        if entity.support in self.entities:
            found |= self.movers(draw, entity.support)
        return found

    # --- world frames ----------------------------------------------------------------------

    def frames(self, draw: Draw) -> dict[str, Frame]:
        """World frames of every object, clutter object and zone in ``draw``."""
        frames = {WORLD: Frame(0.0, 0.0, self.ground_z, 0.0, self.ground_z)}
        for name in self.order:
            e = self.entities[name]
            frames[name] = self._place(frames[e.support], self.position(draw, name), e.height,
                                       self.yaw(draw, name), e.surface)
        for item in draw.clutter:
            frames[item.name] = self._place(frames[item.support], item.xy, 0.0, item.yaw,
                                            surface_height(self.clutter_assets[item.palette]))
        for zone in self.scenario.zones:
            e = self.entities[zone.name]
            frames[zone.name] = self._place(frames[e.support], self.position(draw, zone.name),
                                            e.height, self.yaw(draw, zone.name), 0.0)
        return frames

    @staticmethod
    def _place(support: Frame, xy: tuple[float, float], height: float, yaw: float,
               surface: float) -> Frame:
        dx, dy = rotate_xy(xy, support.yaw)
        z = support.top_z + height
        return Frame(support.x + dx, support.y + dy, z, support.yaw + yaw, z + surface)

    # --- the varied scenario ---------------------------------------------------------------

    def apply(self, draw: Draw, scenario: Scenario) -> Scenario:
        """``scenario`` (limits and requirements already varied) with the draw's placements."""
        objects = [self._moved(o, draw) for o in scenario.objects]
        for item in draw.clutter:
            kind, params = clutter_params(item.palette)
            objects.append(ObjectSpec(
                name=item.name, asset=kind, params=params,
                placement=Placement(support=item.support, position=item.xy, yaw=item.yaw),
                source=item.source))
        zones = tuple(self._moved(z, draw) for z in scenario.zones)
        if not draw.clutter and all(a is b for a, b in zip(objects + list(zones),
                                                          scenario.objects + scenario.zones)):
            return scenario
        return scenario.model_copy(update={"objects": tuple(objects), "zones": zones})

    def _moved(self, spec: ObjectSpec | ZoneSpec, draw: Draw) -> ObjectSpec | ZoneSpec:
        position, yaw = self.position(draw, spec.name), self.yaw(draw, spec.name)
        if position == tuple(spec.placement.position) and yaw == spec.placement.yaw:
            return spec
        placement = spec.placement.model_copy(update={"position": position, "yaw": _wrap(yaw)})
        return spec.model_copy(update={"placement": placement})


def _wrap(angle: float) -> float:
    """``angle`` in [-π, π)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def disc_sample(rng: np.random.Generator, radius: float) -> np.ndarray:
    """A point drawn uniformly in the disc of ``radius`` around the origin."""
    r = radius * math.sqrt(rng.random())
    theta = 2.0 * math.pi * rng.random()
    return np.array([r * math.cos(theta), r * math.sin(theta)])


__all__ = ["CLUTTER_PALETTE", "ClutterItem", "Draw", "Entity", "Frame", "Layout", "clutter_params",
           "disc_sample", "rect_of"]
