"""Placement clauses of objects and hazards (``at``, ``on``, ``yaw``, relations such as
``left_of pot by 10 cm``), resolved in dependency order with cycles reported once."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import ast, models
from ..catalog import ASSETS, AssetClass, AssetKind
from ..diagnostics import DiagnosticSink, Related, did_you_mean
from ..spans import Span
from ..units import Dimension
from .objects import Declared
from .scope import Part

RELATION_OFFSETS = {"left_of": (0.0, 1.0), "right_of": (0.0, -1.0),
                    "in_front_of": (-1.0, 0.0), "behind": (1.0, 0.0)}


@dataclass
class _Parts:
    """What one declaration's clauses say about its placement, before relations resolve."""

    support: str
    position: tuple[float, float] = (0.0, 0.0)
    height: float = 0.0
    yaw: float = 0.0
    support_given: bool = False
    relation: models.Relation | None = None


class PlacementChecker(Part):
    def placements(self, declared: list[Declared]) -> dict[str, models.Placement]:
        """The placement of every declaration whose clauses and relations resolve."""
        decls = {d.name: d.decl for d in declared}
        kinds = {d.name: d.kind for d in declared}
        kinds.setdefault("table", ASSETS["table"])
        parts = {d.name: self._parts(d.name, d.decl, kinds, decls) for d in declared}
        resolver = _Resolver(self.sink, parts, decls)
        for name in parts:
            resolver.resolve(name)
        return resolver.resolved

    def _parts(self, name: str, decl: ast.ObjectDecl | ast.HazardDecl, kinds: dict[str, AssetKind],
               decls: dict) -> _Parts:
        parts = _Parts(support="world" if name == "table" else "table")  # a declared table stands on the world
        seen: dict[str, Span] = {}
        is_zone = kinds[name].asset_class is AssetClass.ZONE
        for placement in decl.placements:
            key = "position" if isinstance(placement, (ast.At, ast.Relation)) else type(placement).__name__
            if key in seen:
                self.sink.error("FSV306", f"`{name}` is placed twice", placement.span, "placed again",
                                related=[Related(span=seen[key], message="first placed here")],
                                help="give one `at (x, y)` or one relation such as `left_of pot by 10 cm`")
                continue
            seen[key] = placement.span
            if isinstance(placement, ast.At):
                self._position(parts, placement.position, name, allow_height=is_zone)
            elif isinstance(placement, ast.On):
                self._support(parts, placement, name, kinds)
            elif isinstance(placement, ast.Yaw):
                angle = self.values.quantity(placement.angle, Dimension.ANGLE, "yaw")
                if angle is not None:
                    parts.yaw = math.remainder(angle, 2 * math.pi)
            else:
                parts.relation = self._relation(placement, decls)
        return parts

    def _support(self, parts: _Parts, placement: ast.On, name: str, kinds: dict[str, AssetKind]) -> None:
        support = placement.support.value
        if support == name:
            self.sink.error("FSV306", f"`{name}` cannot stand on itself", placement.support.span, "itself")
        elif support not in kinds:
            self.sink.error("FSV101", f"unknown support `{support}`", placement.support.span,
                            "not declared", help=did_you_mean(support, kinds, "objects"))
        elif not kinds[support].support:
            self.sink.error("FSV111", f"`{support}` is a {kinds[support].name}, which nothing "
                            "can stand on", placement.support.span, "not a support",
                            help="supports are: " + ", ".join(
                                f"`{n}`" for n, k in ASSETS.items() if k.support))
        else:
            parts.support = support
            parts.support_given = True

    def _position(self, parts: _Parts, vector: ast.Vector, name: str, allow_height: bool) -> None:
        arity = len(vector.items)
        if arity not in ((2, 3) if allow_height else (2,)):
            self.sink.error("FSV205", f"the position of `{name}` needs "
                            + ("2 or 3 values" if allow_height else "2 values (x, y)"),
                            vector.span, f"{arity} values",
                            help="positions are (x, y) on the support's top surface, from its centre")
            return
        numbers = [self.values.quantity(item, Dimension.LENGTH, f"the position of `{name}`")
                   if isinstance(item, ast.Quantity) else None for item in vector.items]
        for item in vector.items:
            if not isinstance(item, ast.Quantity):
                self.sink.error("FSV207", "a position is made of lengths", item.span, "not a length")
        if any(n is None for n in numbers):
            return
        parts.position = (numbers[0], numbers[1])
        if arity == 3:
            parts.height = numbers[2]

    def _relation(self, placement: ast.Relation, decls: dict) -> models.Relation | None:
        anchor = placement.anchor.value
        if anchor not in decls and anchor != "table":
            self.sink.error("FSV101", f"unknown name `{anchor}`", placement.anchor.span, "not declared",
                            help=did_you_mean(anchor, list(decls), "objects"))
            return None
        distance = self.values.amount(placement.distance, Dimension.LENGTH, "the distance")
        if distance is None:
            return None
        return models.Relation(kind=placement.kind.value, anchor=anchor, distance=distance)


class _Resolver:
    """Placements in dependency order: a relation's anchor and a support resolve first."""

    def __init__(self, sink: DiagnosticSink, parts: dict[str, _Parts], decls: dict):
        self.sink = sink
        self.parts = parts
        self.decls = decls
        self.resolved: dict[str, models.Placement] = {}
        self.visiting: list[str] = []
        self.in_cycle: set[str] = set()

    def resolve(self, name: str) -> models.Placement | None:
        if name in self.resolved:
            return self.resolved[name]
        if name not in self.parts or name in self.in_cycle:
            return None
        if name in self.visiting:
            cycle = self.visiting[self.visiting.index(name):] + [name]
            self.in_cycle.update(cycle)
            self.sink.error("FSV307", "placement relations form a cycle: " + " -> ".join(cycle),
                            self.decls[name].name.span, "placed relative to itself",
                            help="place one of them with `at (x, y)`")
            return None
        self.visiting.append(name)
        placement = self._place(name)
        self.visiting.pop()
        if placement is not None:
            self.resolved[name] = placement
        return placement

    def _place(self, name: str) -> models.Placement | None:
        parts = self.parts[name]
        position, support = parts.position, parts.support
        if parts.relation is not None:
            anchored = self._anchored(name, parts)
            if anchored is None:
                return None
            position, support = anchored
        if support in self.parts and self.resolve(support) is None:
            return None
        return models.Placement(support=support, position=position, height=parts.height,
                                yaw=parts.yaw, relation=parts.relation)

    def _anchored(self, name: str, parts: _Parts) -> tuple[tuple[float, float], str] | None:
        """(position, support) of a placement relative to its anchor."""
        relation = parts.relation
        anchor = (self.resolve(relation.anchor) if relation.anchor != "table"
                  else models.Placement(support="world"))
        if anchor is None:
            return None
        dx, dy = RELATION_OFFSETS[relation.kind]
        position = (anchor.position[0] + dx * relation.distance, anchor.position[1] + dy * relation.distance)
        anchor_support = "table" if relation.anchor == "table" else anchor.support
        if not parts.support_given:
            return position, anchor_support
        if parts.support != anchor_support and relation.anchor != parts.support:
            self.sink.error("FSV306", f"`{name}` stands on `{parts.support}` but is placed relative to "
                            f"`{relation.anchor}`, which stands on `{anchor_support}`",
                            self.decls[name].name.span, "positions in two different frames",
                            help=f"put both on the same support, or place `{name}` with `at (x, y)`")
            return None
        return position, parts.support
