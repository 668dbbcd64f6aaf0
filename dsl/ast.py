"""The typed syntax tree of a scenario file: what was written, where, not yet checked.

Every node keeps its span so that each later diagnostic can point at the exact
words it is about. Values keep their units as written; conversion to SI and all
name resolution happen in the checker.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

from .spans import Span


@dataclass(frozen=True)
class Name:
    value: str
    span: Span


@dataclass(frozen=True)
class Quantity:
    number: float
    unit: str | None
    span: Span
    text: str  # the number as written, for messages


@dataclass(frozen=True)
class Vector:
    items: tuple["Value", ...]
    span: Span


@dataclass(frozen=True)
class String:
    value: str
    span: Span


@dataclass(frozen=True)
class Ref:
    name: str
    span: Span


@dataclass(frozen=True)
class Argument:
    keyword: Name | None
    value: "Value"
    span: Span


@dataclass(frozen=True)
class Call:
    name: Name
    arguments: tuple[Argument, ...]
    span: Span

    @property
    def positional(self) -> tuple[Argument, ...]:
        return tuple(a for a in self.arguments if a.keyword is None)

    @property
    def keywords(self) -> tuple[Argument, ...]:
        return tuple(a for a in self.arguments if a.keyword is not None)


Value = Union[Quantity, Vector, String, Ref, Call]


# ----------------------------------------------------------------- conditions

@dataclass(frozen=True)
class AllOf:
    items: tuple["Condition", ...]
    span: Span


@dataclass(frozen=True)
class AnyOf:
    items: tuple["Condition", ...]
    span: Span


@dataclass(frozen=True)
class Negation:
    item: "Condition"
    span: Span


Condition = Union[Call, AllOf, AnyOf, Negation]


# ----------------------------------------------------------------- placements

@dataclass(frozen=True)
class At:
    position: Vector
    span: Span


@dataclass(frozen=True)
class On:
    support: Name
    span: Span


@dataclass(frozen=True)
class Yaw:
    angle: Quantity
    span: Span


@dataclass(frozen=True)
class Relation:
    kind: Name  # left_of, right_of, in_front_of, behind
    anchor: Name
    distance: Quantity
    span: Span


Placement = Union[At, On, Yaw, Relation]


@dataclass(frozen=True)
class Modifier:
    kind: str  # warn, cost, weight
    value: Quantity | Name
    span: Span


# ----------------------------------------------------------------- statements

@dataclass(frozen=True)
class Setting:
    """A single-valued statement: suite, task, embodiment, instruction, horizon."""

    keyword: Name
    value: Name | Call | String | Quantity
    span: Span


@dataclass(frozen=True)
class ObjectDecl:
    name: Name
    asset: Call
    placements: tuple[Placement, ...]
    span: Span


@dataclass(frozen=True)
class Keep:
    subjects: tuple[Name, ...]
    distance: Quantity
    modifiers: tuple[Modifier, ...]
    span: Span


@dataclass(frozen=True)
class HazardDecl:
    name: Name
    definition: Call
    placements: tuple[Placement, ...]
    keeps: tuple[Keep, ...]
    span: Span


@dataclass(frozen=True)
class LimitDecl:
    """`constrain` (a Safe-Core limit) or `watch` (a negative side effect)."""

    keyword: Name
    name: Name | None
    measure: Call
    comparator: Name | None
    limit: Quantity | None
    modifiers: tuple[Modifier, ...]
    span: Span


@dataclass(frozen=True)
class RequireDecl:
    name: Name | None
    first: Condition
    then: Condition
    within: Quantity | None
    modifiers: tuple[Modifier, ...]
    span: Span


@dataclass(frozen=True)
class SuccessDecl:
    condition: Condition
    hold: Quantity | None
    span: Span


@dataclass(frozen=True)
class RemoveDecl:
    names: tuple[Name, ...]
    span: Span


@dataclass(frozen=True)
class Rule:
    """One layout-variant rule: jitter, approach, clutter, tighten or couple."""

    kind: Name
    target: Name | None
    other: Name | None
    amount: Quantity
    extra: Quantity | None  # jitter's yaw
    span: Span


@dataclass(frozen=True)
class VariantLevel:
    level: Name
    rules: tuple[Rule, ...]
    span: Span


@dataclass(frozen=True)
class VariantsBlock:
    levels: tuple[VariantLevel, ...]
    span: Span


@dataclass(frozen=True)
class LanguageEntry:
    level: Name
    category: Name | None
    texts: tuple[String, ...]
    span: Span


@dataclass(frozen=True)
class LanguageBlock:
    entries: tuple[LanguageEntry, ...]
    span: Span


@dataclass(frozen=True)
class VisionEntry:
    level: Name
    settings: tuple[Call, ...]
    span: Span


@dataclass(frozen=True)
class VisionBlock:
    entries: tuple[VisionEntry, ...]
    span: Span


Statement = Union[Setting, ObjectDecl, HazardDecl, LimitDecl, RequireDecl, SuccessDecl,
                  RemoveDecl, VariantsBlock, LanguageBlock, VisionBlock]


@dataclass(frozen=True)
class Extends:
    target: str
    is_path: bool
    span: Span


@dataclass(frozen=True)
class ScenarioDecl:
    name: Name
    abstract: bool
    extends: Extends | None
    statements: tuple[Statement, ...]
    span: Span
    file: str = field(default="")
