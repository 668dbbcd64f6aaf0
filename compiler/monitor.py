"""MonitorSpec: what the safety monitor measures, as versioned plain data, and its lowering.

A :class:`MonitorSpec` is the monitor's half of a compiled scenario (the SceneSpec is the
simulator's half). It is lowered from a scenario *and* the scene of the same layout
(:func:`lower_monitor`): lower it from a variant's scenario and scene, not from L0, since a
``tighten`` rule changes a limit and a ``couple`` rule sets a requirement's ``within``.
Nothing here imports a simulator; the runtime (``fsvla.monitor``) builds FCL geometry and
reads SAPIEN state from it.

Every name a channel or condition uses is resolved once, into an :class:`Entity`:

- a **body** of the scene (rigid: one frame; articulated: one frame per link);
- a **zone**: its monitored ``region``, or for a corridor its ``walls`` (the hazard);
- a **robot** link group, from the embodiment (``robot``: every link of every robot;
  ``gripper`` / ``<arm>_gripper``: the links under the lowest common ancestor of an arm's
  finger links and end-effector link, e.g. the Panda's hand, fingers and TCP;
  ``arm`` / ``<arm>_arm``: the links under the arm's base link).

Link groups are read from the robots' URDF trees (``example-robot-data``), so the spec
lists link names explicitly. Channels follow ``LimitSpec`` one for one, in the
scenario's order; requirements become finite-state channels after them (see
``docs/monitor.md`` for each metric's margin).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from functools import lru_cache
from typing import Annotated, Any, Literal

from fsvla.dsl.catalog import robot_parts
from fsvla.dsl.models import (
    ChannelFamily,
    Condition,
    Scenario,
    Shaping,
    SourceRef,
    predicates_in,
    versioned_json_schema,
)
from pydantic import BaseModel, ConfigDict, Field

from fsvla.embodiments.spec import ArmSpec, EmbodimentSpec, RobotSpec

from .scene import SceneSpec

MONITOR_SCHEMA_VERSION = "1.0"

#: Soft threshold of every temporal channel on the FSM's margin scale [-1, 1] (see
#: ``fsvla.monitor.temporal``): +1 satisfied or pending, 1 - elapsed/within while a
#: coupling window runs, -1 a violation.
TEMPORAL_SOFT_THRESHOLD = 0.5


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RobotLink(_Model):
    robot: str  # a robot of the embodiment (one articulation)
    link: str


class BodyEntity(_Model):
    kind: Literal["body"] = "body"
    name: str
    articulated: bool
    links: tuple[str, ...] = ()  # articulated bodies: the links with geometry frames
    parts: tuple[tuple[str, str, str], ...] = ()  # articulated: (part, link, joint)
    support: str  # the body it stands on ("world" for the table)


class ZoneEntity(_Model):
    kind: Literal["zone"] = "zone"
    name: str
    zone_kind: str
    geometry: Literal["region", "walls"]  # a corridor's hazard is its walls


class RobotEntity(_Model):
    kind: Literal["robot"] = "robot"
    name: str  # robot, gripper, arm, left_arm, right_gripper, ...
    links: tuple[RobotLink, ...]
    reference_link: RobotLink | None = None  # the point `aligned` uses (an ee_link)


Entity = Annotated[BodyEntity | ZoneEntity | RobotEntity, Field(discriminator="kind")]


class ArmLinks(_Model):
    """An arm's links, for predicates that name an arm (``grasped(pot, left)``)."""

    name: str
    robot: str
    ee_link: str
    finger_links: tuple[str, ...]
    gripper_links: tuple[str, ...]
    links: tuple[str, ...]


Metric = Literal["contact_force", "contact_torque", "clearance", "separation", "edge_clearance",
                 "displacement", "tilt", "zone_distance", "untouched", "do_not_disturb"]
METRIC_NAMES: tuple[str, ...] = Metric.__args__  # type: ignore[attr-defined]


class ChannelSpec(_Model):
    """One dual-threshold channel: margin q (larger is safer), hard limit at q = 0,
    warning band [0, soft_threshold), soft cost shaped by ``shaping``, weighted by ``weight``."""

    name: str
    origin: Literal["constrain", "watch", "hazard"]
    family: ChannelFamily
    metric: Metric
    subjects: tuple[str, ...]  # entity names
    reference: str | None = None  # entity name
    support: str | None = None  # edge_clearance: the body whose top edge is the fence
    pairs: tuple[tuple[str, str], ...] = ()  # (subject, reference) entity pairs measured
    comparison: Literal["<=", ">="]
    limit: float  # SI
    unit: str
    soft_threshold: float = Field(gt=0)
    shaping: Shaping = "linear"
    weight: float = Field(1.0, ge=0)
    source: SourceRef


class RequirementSpec(_Model):
    """A temporal channel: ``first`` must have held (within ``within`` s) before each time
    ``then`` starts to hold. The margin scale is fixed (see TEMPORAL_SOFT_THRESHOLD)."""

    name: str  # the channel's name (the requirement's, made unique among channels)
    requirement: str
    first: Condition
    then: Condition
    within: float | None = None
    soft_threshold: float = TEMPORAL_SOFT_THRESHOLD
    shaping: Shaping = "linear"
    weight: float = Field(1.0, ge=0)
    source: SourceRef


class SuccessSpec(_Model):
    condition: Condition
    hold: float = 0.0  # s


class MonitorSpec(_Model):
    schema_version: Literal["1.0"] = MONITOR_SCHEMA_VERSION
    scenario: str
    suite: str
    source_digest: str
    level: str
    seed: int
    timestep: float  # s per physics substep
    substeps: int  # physics substeps per control step
    control_dt: float  # s per control step
    entities: tuple[Entity, ...]
    arms: tuple[ArmLinks, ...]
    channels: tuple[ChannelSpec, ...]
    requirements: tuple[RequirementSpec, ...] = ()
    success: SuccessSpec

    @property
    def channel_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.channels) + tuple(r.name for r in self.requirements)

    def entity(self, name: str) -> BodyEntity | ZoneEntity | RobotEntity:
        found = next((e for e in self.entities if e.name == name), None)
        if found is None:
            raise KeyError(f"monitor spec has no entity {name!r} (entities: "
                           f"{', '.join(e.name for e in self.entities)})")
        return found

    def arm(self, name: str) -> ArmLinks:
        found = next((a for a in self.arms if a.name == name), None)
        if found is None:
            raise KeyError(f"monitor spec has no arm {name!r} (arms: "
                           f"{', '.join(a.name for a in self.arms)})")
        return found


def monitor_json_schema() -> dict[str, Any]:
    """The JSON Schema of a MonitorSpec, tagged with its version."""
    return versioned_json_schema(MonitorSpec, f"urn:fsvla:schema:monitor:{MONITOR_SCHEMA_VERSION}",
                                 "fsvla monitor")


def monitor_json_schema_text() -> str:
    return json.dumps(monitor_json_schema(), indent=2, sort_keys=True)


class MonitorLoweringError(ValueError):
    """A name the monitor cannot resolve; ``source`` is where it was written."""

    def __init__(self, message: str, source: SourceRef):
        self.message, self.source = message, source
        super().__init__(f"{source.file}:{source.line}:{source.column}: {message}")


# --- robot link groups ------------------------------------------------------------------


@lru_cache(maxsize=16)
def _urdf_parents(urdf: str) -> tuple[tuple[str, ...], tuple[tuple[str, str, str], ...],
                                      frozenset[str]]:
    """(link names in file order, (child, parent, joint type) triples, the links with
    collision geometry) of a URDF file."""
    from fsvla.embodiments.assets import resolve_asset

    root = ET.parse(resolve_asset(urdf)).getroot()
    links = tuple(link.get("name", "") for link in root.findall("link"))
    joints = tuple((j.find("child").get("link", ""), j.find("parent").get("link", ""),  # type: ignore[union-attr]
                    j.get("type", "")) for j in root.findall("joint"))
    solid = frozenset(link.get("name", "") for link in root.findall("link")
                      if link.find("collision") is not None)
    return links, joints, solid


class _Tree:
    """A robot's link tree (from its URDF)."""

    def __init__(self, robot: RobotSpec):
        links, joints, solid = _urdf_parents(robot.urdf)
        self.links = links
        self.parent = {child: parent for child, parent, _type in joints}
        self.fixed = {child for child, _parent, kind in joints if kind == "fixed"}
        self.solid = solid

    def rigid_top(self, link: str) -> str:
        """The highest solid link fixed to ``link`` below the last moving joint above it:
        its parent, while both are fixed to theirs and the parent has collision geometry
        (Baxter's `left_hand_link` holds the gripper's base; the wrist link it is fixed to
        turns on the last joint, and is the arm's; a Panda's `panda_link8` is a frame)."""
        while (link in self.fixed and self.parent[link] in self.fixed
               and self.parent[link] in self.solid):
            link = self.parent[link]
        return link

    def ancestors(self, link: str) -> list[str]:
        chain = [link]
        while chain[-1] in self.parent:
            chain.append(self.parent[chain[-1]])
        return chain

    def subtree(self, top: str) -> tuple[str, ...]:
        return tuple(link for link in self.links if top in self.ancestors(link))

    def common_ancestor(self, links: tuple[str, ...]) -> str:
        chains = [self.ancestors(link) for link in links]
        return next(a for a in chains[0] if all(a in c for c in chains[1:]))


def _arm_links(robot: RobotSpec, arm: ArmSpec, tree: _Tree) -> ArmLinks:
    # the hand: what is rigidly fixed to the fingers' and the TCP's common link, up to
    # the last moving joint (a hand's flange and mount bump into things as its fingers do)
    hand = tree.rigid_top(tree.common_ancestor((*arm.gripper.finger_links, arm.ee_link)))
    return ArmLinks(name=arm.name, robot=robot.name, ee_link=arm.ee_link,
                    finger_links=arm.gripper.finger_links, gripper_links=tree.subtree(hand),
                    links=tree.subtree(arm.base_link))


def lower_arms(embodiment: EmbodimentSpec) -> tuple[ArmLinks, ...]:
    """Every arm's links, from its robot's URDF tree."""
    arms = []
    for robot in embodiment.robots:
        tree = _Tree(robot)
        arms.extend(_arm_links(robot, arm, tree) for arm in robot.arms)
    return tuple(arms)


def _robot_entities(embodiment: EmbodimentSpec, arms: tuple[ArmLinks, ...]) -> dict[str, RobotEntity]:
    def refs(arm: ArmLinks, names: tuple[str, ...]) -> tuple[RobotLink, ...]:
        return tuple(RobotLink(robot=arm.robot, link=n) for n in names)

    every = tuple(RobotLink(robot=r.name, link=link) for r in embodiment.robots for link in _Tree(r).links)
    groups = {"robot": RobotEntity(name="robot", links=every),
              "gripper": RobotEntity(name="gripper", links=sum((refs(a, a.gripper_links) for a in arms), ()),
                                     reference_link=RobotLink(robot=arms[0].robot, link=arms[0].ee_link)
                                     if len(arms) == 1 else None)}
    for arm in arms:
        tcp = RobotLink(robot=arm.robot, link=arm.ee_link)
        prefix = "" if arm.name == "arm" else f"{arm.name}_"
        groups[f"{prefix}arm"] = RobotEntity(name=f"{prefix}arm", links=refs(arm, arm.links), reference_link=tcp)
        if prefix:
            groups[f"{prefix}gripper"] = RobotEntity(name=f"{prefix}gripper", links=refs(arm, arm.gripper_links),
                                                     reference_link=tcp)
    return groups


# --- lowering ---------------------------------------------------------------------------


def lower_monitor(scenario: Scenario, scene: SceneSpec) -> MonitorSpec:
    """Lower the limits, requirements and success condition of ``scenario`` to a MonitorSpec
    for ``scene`` (the scene of the same layout). Raises :class:`MonitorLoweringError`."""
    arms = lower_arms(scene.embodiment)
    robot = _robot_entities(scene.embodiment, arms)
    known = set(robot_parts(scenario.arms))
    bodies = {b.name: b for b in scene.bodies}
    zones = {z.name: z for z in scene.zones}
    arm_names = {a.name for a in arms}
    entities: dict[str, BodyEntity | ZoneEntity | RobotEntity] = {}

    def resolve(name: str, source: SourceRef) -> str:
        if name in entities:
            return name
        if name in bodies:
            b = bodies[name]
            if b.asset.asset_type == "articulated":
                entities[name] = BodyEntity(
                    name=name, articulated=True, links=tuple(link.name for link in b.asset.links),
                    parts=tuple((p.name, p.link, p.joint) for p in b.asset.parts), support=b.support)
            else:
                entities[name] = BodyEntity(name=name, articulated=False, support=b.support)
        elif name in zones:
            z = zones[name]
            entities[name] = ZoneEntity(name=name, zone_kind=z.kind,
                                        geometry="walls" if z.kind == "corridor" else "region")
        elif name in robot and name in known:
            entities[name] = robot[name]
        else:
            raise MonitorLoweringError(f"the monitor cannot resolve {name!r}: not a body, zone or robot "
                                       f"part of scene {scene.scenario!r}", source)
        return name

    channels = []
    for limit in scenario.limits:
        subjects = tuple(resolve(s, limit.source) for s in limit.subjects)
        reference = resolve(limit.reference, limit.source) if limit.reference else None
        support = None
        if limit.metric == "edge_clearance":
            first = entities[subjects[0]]
            support = first.support if isinstance(first, BodyEntity) and first.support in bodies else "table"
            resolve(support, limit.source)
        pairs = tuple((s, reference) for s in subjects) if reference else ()
        channels.append(ChannelSpec(
            name=limit.name, origin=limit.origin, family=limit.family, metric=limit.metric,
            subjects=subjects, reference=reference, support=support, pairs=pairs,
            comparison=limit.comparison, limit=limit.limit, unit=limit.unit,
            soft_threshold=limit.soft_threshold, shaping=limit.shaping, weight=limit.weight,
            source=limit.source))

    def resolve_condition(condition: Condition, source: SourceRef) -> None:
        for predicate, arg in ((p.name, a) for p in predicates_in(condition) for a in p.args):
            if predicate == "grasped" and arg in arm_names and arg not in bodies:
                continue
            resolve(arg, source)

    taken = {c.name for c in channels}
    requirements = []
    for req in scenario.requirements:
        resolve_condition(req.first, req.source)
        resolve_condition(req.then, req.source)
        name = req.name if req.name not in taken else f"{req.name} (require)"
        taken.add(name)
        requirements.append(RequirementSpec(name=name, requirement=req.name, first=req.first, then=req.then,
                                            within=req.within, weight=req.weight, source=req.source))
    resolve_condition(scenario.success.condition, scenario.source)

    return MonitorSpec(
        scenario=scenario.name, suite=scenario.suite, source_digest=scenario.source_digest,
        level=scene.level, seed=scene.seed, timestep=scene.physics.timestep,
        substeps=scene.physics.substeps, control_dt=scene.physics.control_dt,
        entities=tuple(entities.values()), arms=arms, channels=tuple(channels),
        requirements=tuple(requirements),
        success=SuccessSpec(condition=scenario.success.condition, hold=scenario.success.hold))


__all__ = [
    "METRIC_NAMES",
    "MONITOR_SCHEMA_VERSION",
    "TEMPORAL_SOFT_THRESHOLD",
    "ArmLinks",
    "BodyEntity",
    "ChannelSpec",
    "Entity",
    "MonitorLoweringError",
    "MonitorSpec",
    "RequirementSpec",
    "RobotEntity",
    "RobotLink",
    "SuccessSpec",
    "ZoneEntity",
    "lower_arms",
    "lower_monitor",
    "monitor_json_schema",
    "monitor_json_schema_text",
]
