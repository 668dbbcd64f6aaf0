"""SceneSpec: the simulator-neutral scene a layout lowers to, and ``lower_scene``.

A :class:`SceneSpec` is plain, versioned, JSON-serialisable data (pydantic,
``extra="forbid"``, frozen) with a JSON Schema (:func:`scene_json_schema`), so a
back-end other than SAPIEN could build the same scene. Nothing here imports a
simulator.

Frames and units (shared with ``fsvla.embodiments`` and ``fsvla.compiler.assets``):

- **World = table frame**: origin at the centre of the table's top surface, +x forward
  (away from the main robot), +y left, +z up; metres, radians, seconds. Robot mounts
  and cameras of the embodiment specs are given in this frame, so the table's body
  origin (the centre of its bottom face, on the floor) is at z = -table height and the
  floor (``ground_z``) is there too. A body standing on the table top has z = 0.
- Poses are ``position`` (x, y, z) plus ``quaternion`` (w, x, y, z).
- An asset's body origin is the centre of the bottom face of its bounding box, so a
  body standing on a surface at height h has its origin at z = h.

Lowering a placement (IR frame: the support's top surface, see ``fsvla.dsl.models``):
an object ``on`` support S at ``position`` (x, y) with ``yaw`` ψ stands at
``S.xy + R(S.yaw)·(x, y)``, ``z = S.z + top(S) + placement.height``, world yaw
``S.yaw + ψ``, where ``top(S)`` is S's ``support_height`` (its bounds' top when it has
none). The support ``world`` is the floor (only the table stands on it). Supports are
resolved in dependency order, so objects on a shelf on the table stack correctly.
Zones are placed the same way.

Physics defaults: gravity (0, 0, -9.81) m/s², physics step 0.002 s (500 Hz), control
rate 20 Hz, i.e. 25 physics substeps per control step (the monitor takes force maxima
over these substeps).

Static checks (:class:`LoweringError`, pointing at the offending ``.fsv`` line): a
footprint that overhangs its support's top by more than half its own size along x or
y (its centre is off the support); two bodies (or a body and a zone's collision walls,
e.g. a corridor's) on the same support whose axis-aligned footprint rectangles (after
yaw, in the support's frame) overlap by more than 1 µm on both axes while their heights
overlap too. Exact collision checks (FCL) belong to variant generation.

Lowering runs in stages (support order, assets, object poses, footprints and overhangs,
zones, overlaps, the embodiment); each returns its results with the problems it found
and goes on, so one :class:`LoweringError` lists every problem of a layout (its
``problems``, in the order they were written), each at its ``.fsv`` file, line and column.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from fsvla.compiler.assets import (
    ArticulatedAsset,
    Pose,
    RigidAsset,
    ZoneAsset,
    build_asset,
    build_zone_marker,
)
from fsvla.compiler.assets.model import Shape
from fsvla.dsl.models import Placement, Scenario, SourceRef, versioned_json_schema
from pydantic import BaseModel, ConfigDict, Field, model_validator

from fsvla.embodiments import EmbodimentSpec, load_embodiment

from .placement import (
    OVERLAP_TOLERANCE,
    CycleError,
    Rect,
    aabb,
    box_corners,
    placed_rect,
    support_order,
)
from .pose import rotate_xy, transform_points, yaw_quat

SCENE_SCHEMA_VERSION = "1.0"

Vec3 = tuple[float, float, float]
Rgb = tuple[float, float, float]
Level = Literal["L0", "L1", "L2"]
HazardRole = Literal["fragile", "protected", "hot", "energized"]
ZoneKind = Literal["heat_zone", "energized_zone", "no_go_zone", "edge_zone", "corridor"]

#: The support name of things standing on the floor (the table).
WORLD = "world"


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Box3(_Model):
    """An axis-aligned box in the world frame."""

    min: Vec3
    max: Vec3


class SceneBody(_Model):
    """One body of the scene: a built asset at a world pose."""

    name: str
    asset: Annotated[RigidAsset | ArticulatedAsset, Field(discriminator="asset_type")]
    pose: Pose  # world pose of the asset's body origin (bottom-face centre)
    is_static: bool  # the body's root is fixed in the world (rigid: static; articulated: fixed base)
    hazard_role: HazardRole | None = None
    support: str  # the body it stands on ("world" = the floor)
    source: SourceRef


class SceneZone(_Model):
    """A hazard zone: its marker (and corridor walls), world pose and monitored region."""

    name: str
    kind: ZoneKind
    marker: ZoneAsset
    pose: Pose  # world pose of the zone frame (origin on the support surface, z up)
    region: Shape  # the monitored volume, in the zone frame (= marker.region)
    region_bounds: Box3  # the region's world axis-aligned bound
    support: str
    source: SourceRef


class RobotMount(_Model):
    """Where a robot of the embodiment is fixed (its root link's world pose)."""

    robot: str
    pose: Pose
    arms: tuple[str, ...]


class SceneCamera(_Model):
    """A camera of the embodiment. ``parent`` "world": ``pose`` is a world pose;
    otherwise ``parent`` is an arm and ``pose`` is in that arm's ``link`` (ee_link) frame.
    The camera looks along its local +x with +z up (SAPIEN's convention)."""

    name: str
    parent: str
    link: str | None = None
    pose: Pose
    fovy: float  # rad, vertical
    width: int
    height: int
    near: float
    far: float


class AmbientLight(_Model):
    type: Literal["ambient"] = "ambient"
    color: Rgb = (0.3, 0.3, 0.3)


class DirectionalLight(_Model):
    type: Literal["directional"] = "directional"
    name: str
    direction: Vec3  # world direction the light travels
    color: Rgb = (1.0, 1.0, 1.0)
    shadow: bool = True


class PointLight(_Model):
    type: Literal["point"] = "point"
    name: str
    position: Vec3
    color: Rgb = (1.0, 1.0, 1.0)
    shadow: bool = False


Light = Annotated[AmbientLight | DirectionalLight | PointLight, Field(discriminator="type")]

DEFAULT_LIGHTS: tuple[AmbientLight | DirectionalLight | PointLight, ...] = (
    AmbientLight(color=(0.3, 0.3, 0.3)),
    # Key light from above, behind and to the left of the main robot.
    DirectionalLight(name="key", direction=(0.5, -0.3, -1.0), color=(1.0, 1.0, 1.0), shadow=True),
)


class PhysicsSpec(_Model):
    """Gravity and time stepping. ``substeps`` physics steps make one control step."""

    gravity: Vec3 = (0.0, 0.0, -9.81)  # m/s²
    timestep: float = Field(0.002, gt=0.0)  # s per physics step (500 Hz)
    control_rate: float = Field(20.0, gt=0.0)  # Hz (policy actions, monitor samples)
    # m: PhysX makes contacts between shapes this close. 4 mm covers a body moving 2 m/s
    # for one 2 ms step; PhysX's 1 cm default had every piece of a glass within 1 cm of a
    # finger or the table in contact, 44 contacts where 9 touch (slower physics, and
    # each one read by the monitor's contact scan).
    contact_offset: float = Field(0.004, gt=0.0)

    @model_validator(mode="after")
    def _whole_substeps(self) -> PhysicsSpec:
        ratio = 1.0 / (self.timestep * self.control_rate)
        if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
            raise ValueError(
                f"a control step (1/{self.control_rate} s) must be a whole number of physics "
                f"steps ({self.timestep} s), got {ratio:.6g}"
            )
        return self

    @property
    def substeps(self) -> int:
        return round(1.0 / (self.timestep * self.control_rate))

    @property
    def control_dt(self) -> float:
        return 1.0 / self.control_rate


class SceneSpec(_Model):
    """A scene: bodies, zones, robots, cameras, lights and physics for one layout."""

    schema_version: Literal["1.0"] = SCENE_SCHEMA_VERSION
    scenario: str
    source_digest: str  # the scenario IR's digest, for provenance and caching
    level: Level
    seed: int
    ground_z: float  # the floor's height in the world (table-top) frame
    bodies: tuple[SceneBody, ...]
    zones: tuple[SceneZone, ...] = ()
    embodiment: EmbodimentSpec
    mounts: tuple[RobotMount, ...]
    cameras: tuple[SceneCamera, ...]
    lights: tuple[Light, ...] = DEFAULT_LIGHTS
    physics: PhysicsSpec = PhysicsSpec()

    def body(self, name: str) -> SceneBody:
        found = next((b for b in self.bodies if b.name == name), None)
        if found is None:
            raise KeyError(f"scene has no body {name!r} (bodies: "
                           f"{', '.join(b.name for b in self.bodies)})")
        return found

    def zone(self, name: str) -> SceneZone:
        found = next((z for z in self.zones if z.name == name), None)
        if found is None:
            raise KeyError(f"scene has no zone {name!r} (zones: "
                           f"{', '.join(z.name for z in self.zones) or 'none'})")
        return found


def scene_json_schema() -> dict[str, Any]:
    """The JSON Schema of a SceneSpec, tagged with its version."""
    return versioned_json_schema(SceneSpec, f"urn:fsvla:schema:scene:{SCENE_SCHEMA_VERSION}", "fsvla scene")


def scene_json_schema_text() -> str:
    return json.dumps(scene_json_schema(), indent=2, sort_keys=True)


@dataclass(frozen=True)
class LoweringProblem:
    """One reason a layout cannot be lowered, at the ``.fsv`` line of the offending thing."""

    message: str
    source: SourceRef
    hint: str | None = None

    def __str__(self) -> str:
        text = f"{self.source.file}:{self.source.line}:{self.source.column}: {self.message}"
        return text + (f" (hint: {self.hint})" if self.hint else "")


class LoweringError(ValueError):
    """A layout that cannot be lowered. ``problems`` holds every problem found, in the order
    they were written; ``message``, ``source`` and ``hint`` are the first one's."""

    def __init__(self, message: str, source: SourceRef, *, hint: str | None = None,
                 problems: Sequence[LoweringProblem] = ()):
        self.message = message
        self.source = source
        self.hint = hint
        self.problems = tuple(problems) or (LoweringProblem(message, source, hint),)
        super().__init__("\n".join(str(problem) for problem in self.problems))

    @classmethod
    def of(cls, problems: Sequence[LoweringProblem]) -> LoweringError:
        ordered = sorted(problems, key=lambda p: (p.source.file, p.source.line, p.source.column))
        first = ordered[0]
        return cls(first.message, first.source, hint=first.hint, problems=ordered)


# --- lowering -----------------------------------------------------------------------------


class _Frame:
    """A placed support: world xy, yaw, surface height, top rectangle (own frame)."""

    __slots__ = ("top", "top_z", "xy", "yaw")

    def __init__(self, xy: tuple[float, float], yaw: float, top_z: float, top: Rect | None):
        self.xy, self.yaw, self.top_z, self.top = xy, yaw, top_z, top


def surface_height(asset: RigidAsset | ArticulatedAsset) -> float:
    """Height of the surface other things stand on above ``asset``'s origin."""
    height = getattr(asset, "support_height", None)
    if height is not None:
        return float(height)
    return float(asset.bounds.center[2] + asset.bounds.half_extents[2])


def _rect_of(asset: RigidAsset | ArticulatedAsset | ZoneAsset) -> Rect:
    return Rect(tuple(asset.footprint.min_xy), tuple(asset.footprint.max_xy))  # type: ignore[arg-type]


def _shape_box(shape: Any) -> tuple[Vec3, Vec3] | None:
    """The axis-aligned bound of a collision shape in its owner's frame (None if unknown)."""
    kind = shape.type
    if kind == "box":
        half = shape.half_size
    elif kind == "cylinder":
        half = (shape.radius, shape.radius, shape.half_length)
    elif kind == "capsule":
        half = (shape.radius, shape.radius, shape.half_length + shape.radius)
    elif kind == "sphere":
        half = (shape.radius,) * 3
    elif kind == "convex_mesh" and shape.mesh.type == "inline":
        return aabb(transform_points(shape.mesh.vertices, shape.pose.position, shape.pose.quaternion))
    else:
        return None
    return aabb(transform_points(box_corners((0.0, 0.0, 0.0), half),
                                 shape.pose.position, shape.pose.quaternion))


def _place(frame: _Frame, position: Sequence[float], height: float, yaw: float) -> tuple[Pose, float]:
    dx, dy = rotate_xy(position, frame.yaw)
    world_yaw = frame.yaw + yaw
    pose = Pose(
        position=(frame.xy[0] + dx, frame.xy[1] + dy, frame.top_z + height),
        quaternion=yaw_quat(world_yaw),
    )
    return pose, world_yaw


def overhang_axis(rect: Rect, top: Rect) -> int | None:
    """The axis (0 = x, 1 = y) along which ``rect`` overhangs ``top`` by more than half its
    own size (its centre is off the support), or None when it rests on ``top``."""
    for axis, (amount, size) in enumerate(zip(rect.overhang(top), rect.size)):
        if amount > 0.5 * size + OVERLAP_TOLERANCE:
            return axis
    return None


class _Footprint:
    """A thing on a support, for the overlap check (support frame)."""

    __slots__ = ("name", "rect", "source", "support", "what", "z")

    def __init__(self, name: str, what: str, rect: Rect, z: tuple[float, float], source: SourceRef,
                 support: str):
        self.name, self.what, self.rect, self.z, self.source = name, what, rect, z, source
        self.support = support


def lower_scene(
    scenario: Scenario,
    *,
    level: Level = "L0",
    seed: int = 0,
    base_dir: Path | None = None,
    allowed_roots: Sequence[Path] = (),
    embodiment: EmbodimentSpec | None = None,
    physics: PhysicsSpec | None = None,
    asset_builder: Callable[..., RigidAsset | ArticulatedAsset] = build_asset,
    marker_builder: Callable[..., ZoneAsset] = build_zone_marker,
) -> SceneSpec:
    """Lower the layout of ``scenario`` (as given: canonical for L0; a variant generator
    passes its re-placed scenario with ``level="L1"``/``"L2"``) to a :class:`SceneSpec`.

    ``base_dir`` defaults to the folder of the ``.fsv`` file that declared each object;
    ``allowed_roots`` bound file assets (see ``build_asset``). ``embodiment`` overrides
    loading ``scenario.embodiment`` by name. ``asset_builder``/``marker_builder`` (same
    signatures as ``build_asset``/``build_zone_marker``) let a caller that lowers many
    layouts of one scenario reuse built assets.

    Each stage returns what it lowered and the problems it found, and goes on past a
    problem; a thing that depends on one that failed (an object on a support that could
    not be placed) is skipped, not reported again. Raises one :class:`LoweringError`
    holding every problem."""
    order, problems = _support_order(scenario)
    assets, found = _build_assets(scenario, base_dir, allowed_roots, asset_builder)
    problems += found
    placed = _place_objects(scenario, order, assets)
    footprints, found = _footprints(scenario, assets, placed)
    problems += found
    zones, walls, found = _lower_zones(scenario, assets, placed, marker_builder)
    problems += found
    problems += _overlaps(footprints + walls)
    spec, found = _embodiment(scenario, embodiment)
    problems += found
    if problems:
        raise LoweringError.of(problems)
    mounts = tuple(
        RobotMount(robot=r.name,
                   pose=Pose(position=tuple(r.mount.position), quaternion=yaw_quat(r.mount.yaw)),
                   arms=tuple(a.name for a in r.arms))
        for r in spec.robots
    )
    ee_links = {a.name: a.ee_link for r in spec.robots for a in r.arms}
    cameras = tuple(
        SceneCamera(name=c.name, parent=c.parent,
                    link=None if c.parent == WORLD else ee_links[c.parent],
                    pose=Pose(position=tuple(c.position), quaternion=tuple(c.orientation())),
                    fovy=c.fovy, width=c.width, height=c.height, near=c.near, far=c.far)
        for c in spec.cameras
    )
    return SceneSpec(
        scenario=scenario.name,
        source_digest=scenario.source_digest,
        level=level,
        seed=seed,
        ground_z=placed.ground_z,
        bodies=_bodies(scenario, assets, placed),
        zones=zones,
        embodiment=spec,
        mounts=mounts,
        cameras=cameras,
        physics=physics if physics is not None else PhysicsSpec(),
    )


# --- stages: each returns its results and the problems it found ---------------------------------


def _support_order(scenario: Scenario) -> tuple[list[str], list[LoweringProblem]]:
    """Objects in an order where every support comes before what stands on it. An object on
    a missing support, on itself or in a support cycle is reported and left out."""
    objects = {o.name: o for o in scenario.objects}
    zone_names = {z.name for z in scenario.zones}
    problems: list[LoweringProblem] = []
    supports: dict[str, str] = {}
    for obj in scenario.objects:
        sup = obj.placement.support
        if sup != WORLD and sup not in objects:
            hint = "zones are not surfaces" if sup in zone_names else None
            problems.append(LoweringProblem(f"object {obj.name!r} stands on {sup!r}, which is not an object",
                                            obj.source, hint))
        elif sup == obj.name:
            problems.append(LoweringProblem(f"object {obj.name!r} stands on itself", obj.source))
        else:
            supports[obj.name] = sup
    while True:
        try:
            return support_order(supports, (WORLD,)), problems
        except CycleError as err:
            problems.append(LoweringProblem(f"objects support each other in a cycle: {' -> '.join(err.cycle)}",
                                            objects[err.cycle[0]].source))
            for name in err.cycle:
                supports.pop(name, None)


def _build_assets(scenario: Scenario, base_dir: Path | None, allowed_roots: Sequence[Path],
                  asset_builder: Callable[..., RigidAsset | ArticulatedAsset],
                  ) -> tuple[dict[str, RigidAsset | ArticulatedAsset], list[LoweringProblem]]:
    """Every object's asset; one that cannot be built is reported and left out."""
    assets: dict[str, RigidAsset | ArticulatedAsset] = {}
    problems: list[LoweringProblem] = []
    for obj in scenario.objects:
        folder = base_dir if base_dir is not None else Path(obj.source.file).parent
        try:
            assets[obj.name] = asset_builder(obj.asset, obj.params, base_dir=folder,
                                             allowed_roots=allowed_roots)
        except (ValueError, OSError) as err:
            problems.append(LoweringProblem(f"object {obj.name!r}: cannot build asset {obj.asset!r}: {err}",
                                            obj.source))
    return assets, problems


class _Placed:
    """The objects placed so far: their world poses and the frames of their tops."""

    __slots__ = ("frames", "ground_z", "poses")

    def __init__(self, ground_z: float):
        self.ground_z = ground_z
        self.frames: dict[str, _Frame] = {WORLD: _Frame((0.0, 0.0), 0.0, ground_z, None)}
        self.poses: dict[str, Pose] = {}


def _place_objects(scenario: Scenario, order: Sequence[str],
                   assets: Mapping[str, RigidAsset | ArticulatedAsset]) -> _Placed:
    """World poses in support order, from the floor (the table stands on it, its top is z = 0).
    An object without an asset, or on a support that was not placed, stays unplaced."""
    objects = {o.name: o for o in scenario.objects}
    table = objects.get("table")
    ground_z = 0.0
    if table is not None and table.placement.support == WORLD and "table" in assets:
        ground_z = -(surface_height(assets["table"]) + table.placement.height)
    placed = _Placed(ground_z)
    for name in order:
        obj = objects[name]
        support = placed.frames.get(obj.placement.support)
        if name not in assets or support is None:
            continue
        pose, world_yaw = _place(support, obj.placement.position, obj.placement.height,
                                 obj.placement.yaw)
        placed.poses[name] = pose
        placed.frames[name] = _Frame((pose.position[0], pose.position[1]), world_yaw,
                                     pose.position[2] + surface_height(assets[name]), _rect_of(assets[name]))
    return placed


def _footprints(scenario: Scenario, assets: Mapping[str, RigidAsset | ArticulatedAsset],
                placed: _Placed) -> tuple[list[_Footprint], list[LoweringProblem]]:
    """The footprint of every placed object, and each one whose centre leaves its support's top."""
    footprints: list[_Footprint] = []
    problems: list[LoweringProblem] = []
    for obj in scenario.objects:
        if obj.name not in placed.poses:
            continue
        asset, p = assets[obj.name], obj.placement
        rect = placed_rect(asset.footprint.min_xy, asset.footprint.max_xy, p.position, p.yaw)
        middle = placed.poses[obj.name].position[2] + asset.bounds.center[2]
        z = (middle - asset.bounds.half_extents[2], middle + asset.bounds.half_extents[2])
        footprints.append(_Footprint(obj.name, "object", rect, z, obj.source, p.support))
        top = placed.frames[p.support].top
        axis = overhang_axis(rect, top) if top is not None else None
        if axis is not None:
            amount, size = rect.overhang(top)[axis], rect.size[axis]
            problems.append(LoweringProblem(
                f"object {obj.name!r} overhangs the top of {p.support!r} by {amount:.4f} m "
                f"along {'xy'[axis]}, more than half its size ({size:.4f} m): its footprint "
                f"{rect} vs the top {top} (in {p.support!r}'s frame)",
                obj.source, "move it onto the support or make the support larger"))
    return footprints, problems


def _lower_zones(scenario: Scenario, assets: Mapping[str, RigidAsset | ArticulatedAsset], placed: _Placed,
                 marker_builder: Callable[..., ZoneAsset],
                 ) -> tuple[tuple[SceneZone, ...], list[_Footprint], list[LoweringProblem]]:
    """Every zone on a placed support, and the footprints of its collision walls (a corridor's)."""
    zones: list[SceneZone] = []
    walls: list[_Footprint] = []
    problems: list[LoweringProblem] = []
    objects = {o.name for o in scenario.objects}
    for zone in scenario.zones:
        p = zone.placement
        if p.support != WORLD and p.support not in objects:
            problems.append(LoweringProblem(f"zone {zone.name!r} lies on {p.support!r}, which is not an object",
                                            zone.source))
            continue
        frame = placed.frames.get(p.support)
        if frame is None:
            continue  # its support could not be placed, which is reported already
        support_size = frame.top.size if p.support in assets else None  # type: ignore[union-attr]
        try:
            marker = marker_builder(zone.kind, zone.params, support_size=support_size)
        except ValueError as err:
            problems.append(LoweringProblem(f"zone {zone.name!r}: cannot build {zone.kind!r}: {err}",
                                            zone.source))
            continue
        pose, _ = _place(frame, p.position, p.height, p.yaw)
        zones.append(SceneZone(name=zone.name, kind=zone.kind, marker=marker, pose=pose,
                               region=marker.region, region_bounds=_region_bounds(marker, pose),
                               support=p.support, source=zone.source))
        walls += _walls(zone.name, marker, pose, p, zone.source)
    return tuple(zones), walls, problems


def _region_bounds(marker: ZoneAsset, pose: Pose) -> Box3:
    """The world axis-aligned bound of a zone's monitored region."""
    region_box = _shape_box(marker.region)
    if region_box is None:
        b = marker.bounds
        region_box = (tuple(c - h for c, h in zip(b.center, b.half_extents)),
                      tuple(c + h for c, h in zip(b.center, b.half_extents)))
    lo, hi = aabb(transform_points(box_corners(
        tuple((a + b) / 2 for a, b in zip(*region_box)),
        tuple((b - a) / 2 for a, b in zip(*region_box))), pose.position, pose.quaternion))
    return Box3(min=lo, max=hi)


def _walls(name: str, marker: ZoneAsset, pose: Pose, p: Placement, source: SourceRef) -> list[_Footprint]:
    """A zone's collision walls (a corridor's), static bodies on its support."""
    walls = []
    for i, wall in enumerate(marker.collision):
        box = _shape_box(wall)
        if box is None:
            continue
        rect = placed_rect(box[0][:2], box[1][:2], p.position, p.yaw)
        z = (pose.position[2] + box[0][2], pose.position[2] + box[1][2])
        walls.append(_Footprint(name, f"wall {wall.name or i}", rect, z, source, p.support))
    return walls


def _overlaps(footprints: Sequence[_Footprint]) -> list[LoweringProblem]:
    """Every pair of things on one support whose footprints and heights overlap, reported at
    the one written second."""
    on_support: dict[str, list[_Footprint]] = {}
    for footprint in footprints:
        on_support.setdefault(footprint.support, []).append(footprint)
    problems = []
    for support, items in on_support.items():
        for i, a in enumerate(items):
            for b in items[i + 1:]:
                if a.name == b.name or min(a.z[1], b.z[1]) - max(a.z[0], b.z[0]) <= OVERLAP_TOLERANCE:
                    continue
                if a.rect.overlaps(b.rect):
                    problems.append(_overlap(support, a, b))
    return problems


def _overlap(support: str, a: _Footprint, b: _Footprint) -> LoweringProblem:
    ox, oy = a.rect.overlap(b.rect)
    what_a = f"{a.what} {a.name!r}" if a.what == "object" else f"{a.name!r} ({a.what})"
    what_b = f"{b.what} {b.name!r}" if b.what == "object" else f"{b.name!r} ({b.what})"
    return LoweringProblem(
        f"{what_b} overlaps {what_a} on {support!r} by {ox:.4f} m x {oy:.4f} m: "
        f"footprints {b.rect} and {a.rect} (in {support!r}'s frame; "
        f"written at {a.source.file}:{a.source.line}:{a.source.column})",
        b.source, "move one of them apart")


def _embodiment(scenario: Scenario, given: EmbodimentSpec | None,
                ) -> tuple[EmbodimentSpec | None, list[LoweringProblem]]:
    if given is not None:
        return given, []
    try:
        return load_embodiment(scenario.embodiment), []
    except (KeyError, OSError, ValueError) as err:  # unknown name, bad file: point at the scenario
        return None, [LoweringProblem(f"cannot load embodiment {scenario.embodiment!r}: {err}",
                                      scenario.source)]


def _bodies(scenario: Scenario, assets: Mapping[str, RigidAsset | ArticulatedAsset],
            placed: _Placed) -> tuple[SceneBody, ...]:
    return tuple(
        SceneBody(
            name=obj.name,
            asset=assets[obj.name],
            pose=placed.poses[obj.name],
            is_static=(assets[obj.name].is_static if isinstance(assets[obj.name], RigidAsset)
                       else assets[obj.name].fixed_base),  # type: ignore[union-attr]
            hazard_role=obj.hazard_role,
            support=obj.placement.support,
            source=obj.source,
        )
        for obj in scenario.objects
    )


__all__ = [
    "DEFAULT_LIGHTS", "SCENE_SCHEMA_VERSION", "AmbientLight", "Box3", "DirectionalLight",
    "Light", "LoweringError", "LoweringProblem", "PhysicsSpec", "PointLight", "RobotMount", "SceneBody",
    "SceneCamera", "SceneSpec", "SceneZone", "lower_scene", "overhang_axis", "scene_json_schema",
    "scene_json_schema_text", "surface_height",
]
