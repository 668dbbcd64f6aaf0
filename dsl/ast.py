"""The typed syntax tree of a scenario file: what was written, where, not yet checked.

Every node keeps its span so that each later diagnostic can point at the exact
words it is about. Values keep their units as written; conversion to SI and all
name resolution happen in the checker.
"""

from __future__ import annotations

from dataclasses import FrozenInstanceError
from typing import ClassVar, Union

from .spans import Span


class Node:
    """An immutable node, compared, hashed and printed by its fields, as a frozen dataclass.

    ``@dataclass(frozen=True)`` generates and compiles six methods for each class; for
    the thirty classes here that was 25 ms at every start of `fsvla check`, a twentieth
    of its budget. A node class (made with :func:`node`) compiles only its ``__init__``,
    and keeps its fields in slots: a parse makes thousands of nodes.
    """

    __slots__ = ()
    _fields: ClassVar[tuple[str, ...]] = ()

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def _values(self) -> tuple:
        return tuple(getattr(self, name) for name in self._fields)

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._fields)
        return f"{self.__class__.__qualname__}({fields})"

    def __setattr__(self, name: str, value: object) -> None:
        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __getstate__(self) -> tuple:
        return self._values()

    def __setstate__(self, state: tuple) -> None:
        for name, value in zip(self._fields, state):
            object.__setattr__(self, name, value)


def node(cls: type) -> type:
    """The node class of ``cls``'s annotated fields (with the defaults its body gives)."""
    fields = tuple(cls.__annotations__)
    defaults = {name: cls.__dict__[name] for name in fields if name in cls.__dict__}
    body = {k: v for k, v in cls.__dict__.items() if k not in defaults and k not in ("__dict__", "__weakref__")}
    made = type(cls.__name__, (Node,), {**body, "__slots__": fields, "_fields": fields})
    made.__qualname__ = cls.__qualname__
    parameters = ", ".join(f"{name}=_defaults[{name!r}]" if name in defaults else name for name in fields)
    setters = "".join(f"    _set_{name}(self, {name})\n" for name in fields)
    namespace = {"_defaults": defaults, **{f"_set_{name}": getattr(made, name).__set__ for name in fields}}
    exec(f"def __init__(self, {parameters}):\n{setters}", namespace)  # noqa: S102 - our own field names
    made.__init__ = namespace["__init__"]
    made.__init__.__qualname__ = f"{cls.__qualname__}.__init__"
    return made


@node
class Name:
    value: str
    span: Span


@node
class Quantity:
    number: float
    unit: str | None
    span: Span
    text: str  # the number as written, for messages


@node
class Vector:
    items: tuple["Value", ...]
    span: Span


@node
class String:
    value: str
    span: Span


@node
class Ref:
    name: str
    span: Span


@node
class Argument:
    keyword: Name | None
    value: "Value"
    span: Span


@node
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

@node
class AllOf:
    items: tuple["Condition", ...]
    span: Span


@node
class AnyOf:
    items: tuple["Condition", ...]
    span: Span


@node
class Negation:
    item: "Condition"
    span: Span


Condition = Union[Call, AllOf, AnyOf, Negation]


# ----------------------------------------------------------------- placements

@node
class At:
    position: Vector
    span: Span


@node
class On:
    support: Name
    span: Span


@node
class Yaw:
    angle: Quantity
    span: Span


@node
class Relation:
    kind: Name  # left_of, right_of, in_front_of, behind
    anchor: Name
    distance: Quantity
    span: Span


Placement = Union[At, On, Yaw, Relation]


@node
class Modifier:
    kind: str  # warn, cost, weight
    value: Quantity | Name
    span: Span


# ----------------------------------------------------------------- statements

@node
class Setting:
    """A single-valued statement: suite, task, embodiment, instruction, horizon."""

    keyword: Name
    value: Name | Call | String | Quantity
    span: Span


@node
class ObjectDecl:
    name: Name
    asset: Call
    placements: tuple[Placement, ...]
    span: Span


@node
class Keep:
    subjects: tuple[Name, ...]
    distance: Quantity
    modifiers: tuple[Modifier, ...]
    span: Span


@node
class HazardDecl:
    name: Name
    definition: Call
    placements: tuple[Placement, ...]
    keeps: tuple[Keep, ...]
    span: Span


@node
class LimitDecl:
    """`constrain` (a Safe-Core limit) or `watch` (a negative side effect)."""

    keyword: Name
    name: Name | None
    measure: Call
    comparator: Name | None
    limit: Quantity | None
    modifiers: tuple[Modifier, ...]
    span: Span


@node
class RequireDecl:
    name: Name | None
    first: Condition
    then: Condition
    within: Quantity | None
    modifiers: tuple[Modifier, ...]
    span: Span


@node
class SuccessDecl:
    condition: Condition
    hold: Quantity | None
    span: Span


@node
class RemoveDecl:
    names: tuple[Name, ...]
    span: Span


@node
class Rule:
    """One layout-variant rule: jitter, approach, clutter, tighten or couple."""

    kind: Name
    target: Name | None
    other: Name | None
    amount: Quantity
    extra: Quantity | None  # jitter's yaw
    span: Span


@node
class VariantLevel:
    level: Name
    rules: tuple[Rule, ...]
    span: Span
    none: Name | None = None  # `L0: none`: the level's rules are none at all


@node
class VariantsBlock:
    levels: tuple[VariantLevel, ...]
    span: Span


@node
class LanguageEntry:
    level: Name
    category: Name | None
    texts: tuple[String, ...]
    span: Span


@node
class LanguageBlock:
    entries: tuple[LanguageEntry, ...]
    span: Span


@node
class VisionEntry:
    level: Name
    settings: tuple[Call, ...]
    span: Span


@node
class VisionBlock:
    entries: tuple[VisionEntry, ...]
    span: Span


Statement = Union[Setting, ObjectDecl, HazardDecl, LimitDecl, RequireDecl, SuccessDecl,
                  RemoveDecl, VariantsBlock, LanguageBlock, VisionBlock]


@node
class Extends:
    target: str
    is_path: bool
    span: Span


@node
class ScenarioDecl:
    name: Name
    abstract: bool
    extends: Extends | None
    statements: tuple[Statement, ...]
    span: Span
    file: str = ""
