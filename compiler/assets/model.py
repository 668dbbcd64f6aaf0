"""Simulator-neutral asset models: what the compiler hands to a simulator back-end.

Every model is plain, JSON-serialisable data (pydantic, ``extra="forbid"``).

Conventions, shared by every asset:

- Units are SI: metres, kilograms, kg/m³, radians.
- A pose is ``position`` (x, y, z) plus ``quaternion`` in **(w, x, y, z)** order
  (scalar first, as SAPIEN's ``sapien.Pose`` takes it). Identity is (1, 0, 0, 0).
- An asset's body frame has z up and its origin at the **centre of the bottom face of
  its bounding box**, so placing an asset "on" a surface at height h means putting its
  origin at z = h. ``size=(a, b)`` / ``size=(a, b, c)`` parameters are extents along
  x, y (and z). The frame is the table's at yaw 0: **+x away from the robot**, **+y to
  the robot's left**. An object with a front (drawer, door, lid knob, outlet) faces
  **-x**, towards the robot; its left is +y, its right -y.
- Cylinders and capsules have their axis along their local z; ``half_length`` is half
  the length of the cylindrical part (a capsule adds a hemisphere of ``radius`` at
  each end).
- Collision geometry of a rigid body is only primitives and convex meshes, never a
  triangle soup, so FCL and PhysX can treat every piece as convex.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, Literal

from fsvla.dsl.models import versioned_json_schema
from pydantic import BaseModel, ConfigDict, Field, NonNegativeFloat, PositiveFloat, model_validator

SCHEMA_VERSION = "1.0"

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # (w, x, y, z)
Rgba = tuple[float, float, float, float]  # linear colour, components in [0, 1]
Triangle = tuple[int, int, int]
ParamValue = float | int | str | bool | tuple[float, ...]

IDENTITY_QUATERNION: Quat = (1.0, 0.0, 0.0, 0.0)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Pose(_Model):
    """A rigid transform: position (x, y, z) and rotation quaternion (w, x, y, z)."""

    position: Vec3 = (0.0, 0.0, 0.0)
    quaternion: Quat = IDENTITY_QUATERNION


# --- meshes -----------------------------------------------------------------------------


class InlineMesh(_Model):
    """Triangles stored in the spec itself."""

    type: Literal["inline"] = "inline"
    vertices: list[Vec3]
    faces: list[Triangle]


class MeshFile(_Model):
    """A mesh file written next to the spec (or a user's file asset).

    Its vertices are multiplied by ``scale`` first; the owning part's pose then places them."""

    type: Literal["file"] = "file"
    path: str
    scale: Vec3 = (1.0, 1.0, 1.0)


MeshSource = Annotated[InlineMesh | MeshFile, Field(discriminator="type")]


# --- collision shapes -------------------------------------------------------------------


class BoxShape(_Model):
    type: Literal["box"] = "box"
    name: str = ""
    pose: Pose = Pose()
    half_size: tuple[PositiveFloat, PositiveFloat, PositiveFloat]


class CylinderShape(_Model):
    """A cylinder with its axis along local z."""

    type: Literal["cylinder"] = "cylinder"
    name: str = ""
    pose: Pose = Pose()
    radius: PositiveFloat
    half_length: PositiveFloat


class CapsuleShape(_Model):
    """A capsule with its axis along local z; ``half_length`` excludes the end caps."""

    type: Literal["capsule"] = "capsule"
    name: str = ""
    pose: Pose = Pose()
    radius: PositiveFloat
    half_length: NonNegativeFloat


class SphereShape(_Model):
    type: Literal["sphere"] = "sphere"
    name: str = ""
    pose: Pose = Pose()
    radius: PositiveFloat


class ConvexMeshShape(_Model):
    """A convex piece: its vertices' convex hull is the collision geometry."""

    type: Literal["convex_mesh"] = "convex_mesh"
    name: str = ""
    pose: Pose = Pose()
    mesh: MeshSource


Shape = Annotated[
    BoxShape | CylinderShape | CapsuleShape | SphereShape | ConvexMeshShape,
    Field(discriminator="type"),
]


# --- appearance and physics material ----------------------------------------------------


class Appearance(_Model):
    """How a visual part looks. ``emission`` is (r, g, b, strength) for glowing parts."""

    base_color: Rgba
    emission: Rgba | None = None
    roughness: float = 0.6
    metallic: float = 0.0


class Material(_Model):
    """Physical material of a body plus its default look.

    ``density`` is the body's effective density (mass / collision volume), so a back-end
    that derives mass from density gets the same mass as ``RigidAsset.mass``.
    """

    static_friction: float = Field(ge=0.0)
    dynamic_friction: float = Field(ge=0.0)
    restitution: float = Field(default=0.1, ge=0.0, le=1.0)
    density: float = Field(gt=0.0)
    base_color: Rgba = (0.7, 0.7, 0.7, 1.0)
    emission: Rgba | None = None
    roughness: float = 0.6
    metallic: float = 0.0


class VisualPart(_Model):
    """A rendered mesh of a body; ``appearance`` None means the body material's look."""

    name: str
    mesh: MeshSource
    pose: Pose = Pose()
    appearance: Appearance | None = None


# --- extents ------------------------------------------------------------------------------


class Bounds(_Model):
    """An axis-aligned box in the body frame."""

    center: Vec3
    half_extents: Vec3


class Footprint(_Model):
    """The 2D rectangle (body frame, x-y) an asset covers; layout feasibility uses it."""

    min_xy: Vec2
    max_xy: Vec2


# --- assets -------------------------------------------------------------------------------


class RigidAsset(_Model):
    """One rigid body: collision pieces, visuals, mass properties, material."""

    schema_version: Literal["1.0"] = SCHEMA_VERSION
    asset_type: Literal["rigid"] = "rigid"
    kind: str
    params: dict[str, ParamValue]
    collision: list[Shape]
    visuals: list[VisualPart]
    mass: float = Field(gt=0.0)
    center_of_mass: Vec3
    inertia: Vec3  # principal moments about the centre of mass, kg·m²
    inertia_frame: Quat = IDENTITY_QUATERNION  # principal axes in the body frame (w, x, y, z)
    material: Material
    is_static: bool
    bounds: Bounds
    footprint: Footprint
    support_height: float | None = None  # height of the surface other objects stand on
    cavity: Shape | None = None  # the open volume of a container ("inside" tests it)

    @model_validator(mode="after")
    def _collision_not_empty(self) -> RigidAsset:
        if not self.collision:
            raise ValueError(f"rigid asset {self.kind!r} has no collision pieces")
        return self


class Link(_Model):
    """A link of an articulated asset and its collision pieces (link frame)."""

    name: str
    collision: list[Shape]
    mass: float = Field(ge=0.0)


class Joint(_Model):
    name: str
    type: Literal["revolute", "prismatic", "continuous", "fixed"]
    parent: str
    child: str
    origin: Pose = Pose()
    axis: Vec3 = (0.0, 0.0, 1.0)
    lower: float = 0.0
    upper: float = 0.0
    friction: float = Field(default=0.0, ge=0.0)  # <dynamics friction>: N·m (revolute) or N


class Part(_Model):
    """A named movable part that predicates such as ``opened(box)`` refer to."""

    name: str
    link: str
    joint: str


def start_positions(joints: Sequence[Joint], moving: Sequence[str],
                    params: Mapping[str, Any]) -> dict[str, float]:
    """Joint name -> the position (rad or m) an articulated body starts at, with the asset's
    ``open`` fraction: each joint of ``moving`` (its parts' joints) that fraction of the way
    from its lower limit to its upper. Empty without ``open`` (or at 0): every joint then
    starts at 0, as do the joints not named here."""
    fraction = float(params.get("open", 0.0) or 0.0)
    if fraction <= 0.0:
        return {}
    return {j.name: j.lower + fraction * (j.upper - j.lower) for j in joints if j.name in moving}


class ArticulatedAsset(_Model):
    """An articulated body described by a URDF (inline text or a file) plus its structure."""

    schema_version: Literal["1.0"] = SCHEMA_VERSION
    asset_type: Literal["articulated"] = "articulated"
    kind: str
    params: dict[str, ParamValue]
    urdf: str | None = None  # the URDF text, when generated from a template
    urdf_path: str | None = None  # an absolute path, when the asset is a user's URDF file
    scale: float = 1.0  # applied to the URDF at load time; links/joints below are scaled
    root_link: str
    links: list[Link]
    joints: list[Joint]
    parts: list[Part]
    fixed_base: bool = True
    material: Material
    bounds: Bounds
    footprint: Footprint

    @model_validator(mode="after")
    def _one_urdf_source(self) -> ArticulatedAsset:
        if (self.urdf is None) == (self.urdf_path is None):
            raise ValueError("an articulated asset needs exactly one of `urdf` and `urdf_path`")
        return self

    def start_positions(self) -> dict[str, float]:
        """The joint positions the body starts at (:func:`start_positions`)."""
        return start_positions(self.joints, [p.joint for p in self.parts], self.params)

    def part(self, name: str) -> Part:
        found = next((p for p in self.parts if p.name == name), None)
        if found is None:
            known = ", ".join(p.name for p in self.parts) or "none"
            raise KeyError(f"asset {self.kind!r} has no part {name!r} (parts: {known})")
        return found


class ZoneAsset(_Model):
    """A hazard region's marker: visuals a camera sees, and (corridor only) static walls."""

    schema_version: Literal["1.0"] = SCHEMA_VERSION
    asset_type: Literal["zone"] = "zone"
    kind: str
    params: dict[str, ParamValue]
    region: Shape  # the monitored region (zone frame: origin on the surface, z up)
    visuals: list[VisualPart]
    collision: list[Shape] = []  # static walls; empty except for corridors
    bounds: Bounds
    footprint: Footprint


Asset = Annotated[RigidAsset | ArticulatedAsset | ZoneAsset, Field(discriminator="asset_type")]


class _AssetDocument(_Model):
    asset: Asset


def json_schema() -> dict[str, Any]:
    """The JSON Schema of an asset (rigid, articulated or zone), tagged with its version."""
    return versioned_json_schema(_AssetDocument, f"urn:fsvla:asset:{SCHEMA_VERSION}", "fsvla asset")


def json_schema_text() -> str:
    return json.dumps(json_schema(), indent=2, sort_keys=True)
