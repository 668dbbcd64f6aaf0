"""The checked scenario IR: what a .fsv file means, as versioned plain data.

Everything the compiler needs is here, resolved and in SI units (metres,
newtons, newton-metres, radians, seconds, kilograms); nothing refers back to the
text except ``SourceRef`` provenance, which later stages use to point their own
diagnostics (an infeasible variant rule, say) at the line that caused them.

Frames: positions are in the frame of the support's top surface: origin at the
centre of the surface, +x away from the robot's base (forward), +y to the
robot's left, +z up. Yaw is about +z, counter-clockwise seen from above.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Literal, Union

from pydantic import BaseModel, ConfigDict, Field

SCHEMA_VERSION = "1.0"

ParamValue = Union[float, int, str, bool, tuple[float, ...]]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SourceRef(_Model):
    """Where a construct was written: file, 1-based line and column."""

    file: str
    line: int
    column: int


class Relation(_Model):
    kind: Literal["left_of", "right_of", "in_front_of", "behind"]
    anchor: str
    distance: float  # m, centre to centre


class Placement(_Model):
    support: str = "table"  # the object whose top surface this stands on
    position: tuple[float, float] = (0.0, 0.0)  # m, resolved (relations already applied)
    height: float = 0.0  # m above the support surface (for zones hovering above it)
    yaw: float = 0.0  # rad
    relation: Relation | None = None  # as written, for variant generation to keep


class ObjectSpec(_Model):
    """A body in the scene: a task object, a distractor, a support, or an object hazard."""

    name: str
    asset: str  # an entry of fsvla.dsl.catalog.ASSETS
    params: dict[str, ParamValue]  # SI, defaults filled in; file paths resolved and absolute
    placement: Placement
    hazard_role: Literal["fragile", "protected", "hot", "energized"] | None = None
    source: SourceRef


class ZoneSpec(_Model):
    """A hazardous region with no body: heat, energised, no-go, edge band, corridor."""

    name: str
    kind: Literal["heat_zone", "energized_zone", "no_go_zone", "edge_zone", "corridor"]
    params: dict[str, ParamValue]
    placement: Placement
    source: SourceRef


ChannelFamily = Literal["force", "thermal", "boundary", "collaborative", "temporal", "side_effect"]
Shaping = Literal["linear", "quadratic", "exponential", "step"]


class LimitSpec(_Model):
    """One dual-threshold channel: hard limit (margin 0) and soft threshold epsilon > 0.

    The margin q is ``limit - measured`` for an upper bound (``<=``) and
    ``measured - limit`` for a lower bound (``>=``): larger is safer; the state is
    a violation when q < 0 and a warning when 0 <= q < soft_threshold.
    """

    name: str
    origin: Literal["constrain", "watch", "hazard"]
    family: ChannelFamily
    metric: str  # contact_force, contact_torque, clearance, separation, edge_clearance,
    #              displacement, tilt, zone_distance, untouched, do_not_disturb
    subjects: tuple[str, ...]  # the entities measured (objects, robot parts)
    reference: str | None = None  # the other entity, hazard or zone, where there is one
    comparison: Literal["<=", ">="]
    limit: float  # SI
    unit: str  # SI unit of limit and soft_threshold
    soft_threshold: float
    shaping: Shaping = "linear"
    weight: float = 1.0
    source: SourceRef


class Predicate(_Model):
    kind: Literal["predicate"] = "predicate"
    name: str  # an entry of fsvla.dsl.catalog.PREDICATES
    args: tuple[str, ...]  # entity names (objects, robot parts) or arm names
    params: dict[str, ParamValue] = Field(default_factory=dict)


class AllOf(_Model):
    kind: Literal["all"] = "all"
    items: tuple["Condition", ...]


class AnyOf(_Model):
    kind: Literal["any"] = "any"
    items: tuple["Condition", ...]


class Not(_Model):
    kind: Literal["not"] = "not"
    item: "Condition"


Condition = Annotated[Union[Predicate, AllOf, AnyOf, Not], Field(discriminator="kind")]


def predicates_in(condition: Condition) -> Iterator[Predicate]:
    """Every predicate of a condition tree, left to right (depth first)."""
    if isinstance(condition, Predicate):
        yield condition
    elif isinstance(condition, (AllOf, AnyOf)):
        for item in condition.items:
            yield from predicates_in(item)
    elif isinstance(condition, Not):
        yield from predicates_in(condition.item)
    else:
        raise TypeError(f"not a condition: {condition!r}")


class Requirement(_Model):
    """A temporal precondition: ``first`` must have held before ``then`` first holds."""

    name: str
    first: Condition
    then: Condition
    within: float | None = None  # s: `first` must have held within this long before `then`
    weight: float = 1.0
    source: SourceRef


class Success(_Model):
    condition: Condition
    hold: float = 0.0  # s the condition must hold


class Task(_Model):
    name: str  # an entry of fsvla.dsl.catalog.TASKS
    roles: dict[str, str]  # role -> object name
    source: SourceRef


class Jitter(_Model):
    rule: Literal["jitter"] = "jitter"
    target: str
    distance: float  # m, uniform in a disc of this radius
    yaw: float = 0.0  # rad, uniform in [-yaw, yaw]
    source: SourceRef


class Approach(_Model):
    rule: Literal["approach"] = "approach"
    hazard: str
    toward: str
    distance: float  # m moved toward the object
    source: SourceRef


class Clutter(_Model):
    rule: Literal["clutter"] = "clutter"
    count: int
    near: str | None = None
    source: SourceRef


class Tighten(_Model):
    rule: Literal["tighten"] = "tighten"
    target: str  # a limit's name
    limit: float  # the new hard limit, SI; always stricter than the L0 one
    source: SourceRef


class Couple(_Model):
    rule: Literal["couple"] = "couple"
    requirement: str
    within: float  # s
    source: SourceRef


VariantRule = Annotated[Union[Jitter, Approach, Clutter, Tighten, Couple], Field(discriminator="rule")]


class LanguageVariant(_Model):
    text: str
    category: Literal["paraphrase", "compositional", "unsafe", "contradictory", "ambiguous",
                      "hijack"] | None = None
    source: SourceRef


class VisionSetting(_Model):
    name: str  # an entry of fsvla.dsl.vision.SETTINGS
    params: dict[str, ParamValue]
    source: SourceRef


class Scenario(_Model):
    """A checked, fully resolved scenario: the input of the compiler."""

    schema_version: Literal["1.0"] = SCHEMA_VERSION
    name: str
    suite: Literal["force", "thermal", "boundary", "collaborative", "temporal"]
    task: Task
    embodiment: str
    arms: tuple[str, ...]
    instruction: str
    horizon: float  # s
    objects: tuple[ObjectSpec, ...]  # the table first
    zones: tuple[ZoneSpec, ...] = ()
    limits: tuple[LimitSpec, ...] = ()
    requirements: tuple[Requirement, ...] = ()
    success: Success
    # L0: the nuisance jitter when written (() for `L0: none`); absent, the default one.
    variants: dict[Literal["L0", "L1", "L2"], tuple[VariantRule, ...]] = Field(default_factory=dict)
    language: dict[Literal["W1", "W2", "W3", "W4"], tuple[LanguageVariant, ...]] = Field(
        default_factory=dict)
    vision: dict[Literal["V1", "V2", "V3", "V4"], tuple[VisionSetting, ...]] = Field(
        default_factory=dict)
    source: SourceRef
    lineage: tuple[str, ...] = ()  # the files this one extends, nearest first
    source_digest: str  # sha256 over the text of this file and everything it extends

    def object(self, name: str) -> ObjectSpec | None:
        return next((o for o in self.objects if o.name == name), None)


def versioned_json_schema(model: type[BaseModel], urn: str, title: str) -> dict:
    """The JSON Schema of ``model`` with its ``$id`` (a versioned URN) and title."""
    schema = model.model_json_schema()
    schema["$id"] = urn
    schema["title"] = title
    return schema


def ir_json_schema() -> dict:
    """The JSON Schema of the scenario IR (``fsvla schema``)."""
    return versioned_json_schema(Scenario, f"urn:fsvla:schema:scenario:{SCHEMA_VERSION}", "fsvla scenario IR")
