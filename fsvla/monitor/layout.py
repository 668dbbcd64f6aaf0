"""The static facts the monitor needs about a scene, by entity name.

A :class:`Layout` resolves the entities of a MonitorSpec to frames (see
``fsvla.monitor.state``), and keeps what channels and predicates read about bodies:
root frame, footprint and support height, cavity, articulated parts with their joint
ranges. :func:`build_geometry` turns the SceneSpec's shapes (and the robot links'
shapes, read from SAPIEN or given by hand) into a :class:`SceneGeometry`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import RigidAsset, Shape
from fsvla.compiler.monitor import BodyEntity, MonitorSpec, RobotEntity, ZoneEntity
from fsvla.compiler.pose import pose_matrix
from fsvla.compiler.scene import SceneSpec

from .geometry import SceneGeometry
from .state import Matrix4, link_frame, robot_frame


def zone_frame(name: str) -> str:
    return f"zone:{name}"


@dataclass(frozen=True)
class PartInfo:
    link_frame: str
    joint: str  # "<body>:<joint>", the WorldState.joints key
    lower: float
    upper: float


@dataclass(frozen=True)
class BodyInfo:
    name: str
    root_frame: str
    frames: frozenset[str]
    articulated: bool
    is_static: bool
    footprint: tuple[tuple[float, float], tuple[float, float]]  # body frame (min_xy, max_xy)
    top: float  # height of its support surface (or its top) above its origin
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]]  # body frame (lower, upper)
    centre: NDArray[np.float64]  # body frame: the centre of ``bounds``
    cavity: Shape | None = None
    parts: tuple[PartInfo, ...] = ()
    link_bounds: Mapping[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(default_factory=dict)


@dataclass(frozen=True)
class ArmFrames:
    name: str
    fingers: frozenset[str]
    gripper: frozenset[str]
    ee: str


@dataclass
class Layout:
    entities: dict[str, frozenset[str]]  # entity -> frames
    bodies: dict[str, BodyInfo]  # every scene body, by name
    zones: dict[str, str]  # zone entity -> its static frame
    reference_frames: dict[str, str]  # robot entity -> the frame of its reference point
    arms: dict[str, ArmFrames]
    initial: dict[str, Matrix4] = field(default_factory=dict)  # body -> root pose at reset
    initial_low: dict[str, float] = field(default_factory=dict)  # body -> lowest z at reset

    @cached_property
    def grippers(self) -> frozenset[str]:
        """Every arm's gripper frames (one set, made once: predicates ask every step)."""
        return frozenset().union(*(a.gripper for a in self.arms.values()))

    def frames(self, entity: str) -> frozenset[str]:
        if entity in self.entities:
            return self.entities[entity]
        if entity in self.bodies:
            return self.bodies[entity].frames
        raise KeyError(f"no entity {entity!r}")

    def moving_frames(self) -> frozenset[str]:
        """Frames whose pose the probe must read each step."""
        frames: set[str] = set()
        for entity, fs in self.entities.items():
            if entity not in self.zones:
                frames |= fs
        frames |= set(self.reference_frames.values())
        for arm in self.arms.values():
            frames |= arm.gripper | {arm.ee}
        return frozenset(f for f in frames if not f.startswith("zone:"))


def _aabb(shapes: Sequence[Shape]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    from fsvla.compiler.assets.geometry import shape_aabb

    boxes = [shape_aabb(s) for s in shapes]
    return (np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0))


def _body_info(body) -> BodyInfo:
    asset = body.asset
    lo = np.subtract(asset.bounds.center, asset.bounds.half_extents)
    hi = np.add(asset.bounds.center, asset.bounds.half_extents)
    footprint = (tuple(asset.footprint.min_xy), tuple(asset.footprint.max_xy))
    top = getattr(asset, "support_height", None)
    top = float(hi[2]) if top is None else float(top)
    if isinstance(asset, RigidAsset):
        return BodyInfo(name=body.name, root_frame=body.name, frames=frozenset({body.name}), articulated=False,
                        is_static=body.is_static, footprint=footprint, top=top, bounds=(lo, hi),
                        centre=(lo + hi) / 2.0, cavity=asset.cavity)
    joints = {j.name: j for j in asset.joints}
    parts = tuple(PartInfo(link_frame=link_frame(body.name, p.link), joint=link_frame(body.name, p.joint),
                           lower=joints[p.joint].lower, upper=joints[p.joint].upper) for p in asset.parts)
    link_bounds = {link_frame(body.name, link.name): _aabb(link.collision)
                   for link in asset.links if link.collision}
    return BodyInfo(name=body.name, root_frame=link_frame(body.name, asset.root_link),
                    frames=frozenset(link_frame(body.name, link.name) for link in asset.links),
                    articulated=True, is_static=body.is_static, footprint=footprint, top=top, bounds=(lo, hi),
                    centre=(lo + hi) / 2.0, parts=parts, link_bounds=link_bounds)


def build_layout(spec: MonitorSpec, scene: SceneSpec) -> Layout:
    bodies = {b.name: _body_info(b) for b in scene.bodies}
    entities: dict[str, frozenset[str]] = {}
    zones: dict[str, str] = {}
    refs: dict[str, str] = {}
    for entity in spec.entities:
        if isinstance(entity, BodyEntity):
            entities[entity.name] = bodies[entity.name].frames
        elif isinstance(entity, ZoneEntity):
            zones[entity.name] = zone_frame(entity.name)
            entities[entity.name] = frozenset({zone_frame(entity.name)})
        elif isinstance(entity, RobotEntity):
            entities[entity.name] = frozenset(robot_frame(r.robot, r.link) for r in entity.links)
            if entity.reference_link is not None:
                refs[entity.name] = robot_frame(entity.reference_link.robot, entity.reference_link.link)
    arms = {a.name: ArmFrames(name=a.name, fingers=frozenset(robot_frame(a.robot, f) for f in a.finger_links),
                              gripper=frozenset(robot_frame(a.robot, f) for f in a.gripper_links),
                              ee=robot_frame(a.robot, a.ee_link)) for a in spec.arms}
    return Layout(entities=entities, bodies=bodies, zones=zones, reference_frames=refs, arms=arms)


def build_geometry(scene: SceneSpec, layout: Layout, robot_shapes: Mapping[str, Sequence[Shape]],
                   initial_poses: Mapping[str, Matrix4] | None = None) -> SceneGeometry:
    """FCL geometry of every scene body (per link when articulated), every monitored zone
    (its region, or a corridor's walls) and the robot links in ``robot_shapes``."""
    geometry = SceneGeometry()
    poses = initial_poses or {}
    for body in scene.bodies:
        world = pose_matrix(body.pose)
        if isinstance(body.asset, RigidAsset):
            geometry.add(body.name, body.asset.collision, poses.get(body.name, world))
            continue
        for link in body.asset.links:
            frame = link_frame(body.name, link.name)
            geometry.add(frame, link.collision, poses.get(frame, world))
    for zone in scene.zones:
        if zone.name not in layout.zones:
            continue
        shapes = zone.marker.collision if zone.kind == "corridor" else [zone.region]
        geometry.add(zone_frame(zone.name), shapes, pose_matrix(zone.pose))
    for frame, shapes in robot_shapes.items():
        geometry.add(frame, shapes, poses.get(frame))
    return geometry


__all__ = ["ArmFrames", "BodyInfo", "Layout", "PartInfo", "build_geometry", "build_layout", "zone_frame"]
