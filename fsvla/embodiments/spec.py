"""The embodiment spec: a robot set-up described as plain, validated data.

An embodiment is one or more *robots* (one URDF articulation each, fixed at a mount
pose on the table) carrying one or more *arms* (a joint chain with an end-effector and
a gripper), plus named *cameras*. A single-arm embodiment has one arm called ``arm``;
a bimanual one has ``left`` and ``right`` arms, from two URDFs (``dual_panda``) or from
one URDF with two arms (``baxter``).

Frames: the world is the table frame (origin at the centre of the table top, +x forward
away from the main robot, +y left, +z up; metres, radians). Quaternions are (w, x, y, z).
Joint positions are in the URDF's units (radians for revolute, metres for prismatic).
See ``docs/embodiments.md``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from fsvla.compiler.pose import Quat, Vec3, look_at_quat

Axis = Literal["+x", "-x", "+y", "-y", "+z", "-z"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def _unique(names: list[str], what: str) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise ValueError(f"{what} `{name}` is listed twice")
        seen.add(name)


class DriveSpec(_Strict):
    """PD joint-position drive: torque = stiffness * (target - q) - damping * dq, clipped."""

    stiffness: float = Field(gt=0, description="N·m/rad (revolute) or N/m (prismatic)")
    damping: float = Field(ge=0, description="N·m·s/rad or N·s/m")
    force_limit: float = Field(gt=0, description="N·m or N")


class MountSpec(_Strict):
    """Where a robot's root link sits in the table frame."""

    position: Vec3 = (0.0, 0.0, 0.0)
    yaw: float = Field(0.0, description="rotation about +z, radians")


class WorkspaceSpec(_Strict):
    """An axis-aligned box in the table frame that the arm's tool centre point must
    reach with the gripper pointing down (checked by the embodiment tests)."""

    center: Vec3
    size: Vec3

    @field_validator("size")
    @classmethod
    def _positive(cls, size: Vec3) -> Vec3:
        if min(size) < 0:
            raise ValueError(f"workspace size must be non-negative, got {size}")
        return size


class GripperSpec(_Strict):
    joints: tuple[str, ...] = Field(min_length=1)
    open: tuple[float, ...]
    closed: tuple[float, ...]
    finger_links: tuple[str, ...] = Field(min_length=1)
    home: Literal["open", "closed"] = "open"
    drive: DriveSpec = DriveSpec(stiffness=1e3, damping=1e2, force_limit=100.0)
    pad_friction: float | None = Field(
        None, ge=0.0, le=2.0,
        description="static friction of the finger links' collision shapes (rubber pads: "
                    "about 1); unset, the simulator's default material (0.3)")

    @model_validator(mode="after")
    def _lengths(self) -> GripperSpec:
        _unique(list(self.joints), "gripper joint")
        n = len(self.joints)
        for field in ("open", "closed"):
            got = len(getattr(self, field))
            if got != n:
                raise ValueError(f"gripper `{field}` has {got} values for {n} joints {self.joints}")
        return self

    def targets(self, open: bool) -> tuple[float, ...]:
        return self.open if open else self.closed


class ArmSpec(_Strict):
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    base_link: str
    joints: tuple[str, ...] = Field(min_length=1, description="arm joints, base to tip")
    home: tuple[float, ...] = Field(description="arm joint positions at home, same order")
    ee_link: str
    tcp_offset: Vec3 = Field((0.0, 0.0, 0.0), description="tool centre point in ee_link frame")
    approach_axis: Axis = Field("+z", description="ee_link axis pointing out of the gripper")
    gripper: GripperSpec
    drive: DriveSpec = DriveSpec(stiffness=1e4, damping=1e3, force_limit=500.0)
    workspace: WorkspaceSpec

    @model_validator(mode="after")
    def _home_matches(self) -> ArmSpec:
        _unique(list(self.joints) + list(self.gripper.joints), "joint")
        if len(self.home) != len(self.joints):
            raise ValueError(
                f"arm `{self.name}`: `home` has {len(self.home)} values for "
                f"{len(self.joints)} joints {self.joints}"
            )
        return self


class RobotSpec(_Strict):
    """One URDF articulation: its file, where it is mounted, and the arms it carries."""

    name: str
    urdf: str = Field(description="absolute, or relative to example-robot-data's robots/")
    srdf: str | None = None
    mount: MountSpec = MountSpec()
    arms: tuple[ArmSpec, ...] = Field(min_length=1)
    hold: dict[str, float] = Field(
        default_factory=dict,
        description="positions for the robot's other joints (head, torso); unlisted ones hold 0",
    )
    hold_drive: DriveSpec = DriveSpec(stiffness=1e4, damping=1e3, force_limit=1000.0)
    collision_pieces: dict[str, str] = Field(
        default_factory=dict,
        description="collision mesh file name (as the URDF names it, without folders) -> a "
        "folder of its convex pieces (*.obj), relative to the embodiment's file: the loader "
        "takes one convex hull per collision mesh, which fills a gripper's jaws in",
    )
    self_collisions: bool = Field(
        True,
        description="simulate contacts between this robot's own links (but the pairs its "
        "SRDF disables); a URDF whose collision shapes overlap at rest in pairs its SRDF does "
        "not disable (baxter) needs false",
    )

    @model_validator(mode="after")
    def _hold_disjoint(self) -> RobotSpec:
        arm_joints = {j for arm in self.arms for j in (*arm.joints, *arm.gripper.joints)}
        clash = sorted(arm_joints & set(self.hold))
        if clash:
            raise ValueError(f"robot `{self.name}`: arm joints {clash} cannot also be in `hold`")
        return self


class CameraSpec(_Strict):
    """A camera fixed in the world (``parent = "world"``) or riding on an arm's
    end-effector link (``parent = <arm name>``; pose given in that link's frame).
    Orientation is either ``look_at`` (+ ``up``) or ``quat`` (wxyz); a SAPIEN camera
    looks along its local +x with +z up."""

    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    parent: str = "world"
    position: Vec3
    look_at: Vec3 | None = None
    up: Vec3 = (0.0, 0.0, 1.0)
    quat: Quat | None = None
    fovy: float = Field(1.0, gt=0, lt=3.14, description="vertical field of view, radians")
    width: int = Field(320, gt=0)
    height: int = Field(240, gt=0)
    near: float = Field(0.01, gt=0)
    far: float = Field(10.0, gt=0)

    @model_validator(mode="after")
    def _one_orientation(self) -> CameraSpec:
        if (self.look_at is None) == (self.quat is None):
            raise ValueError(f"camera `{self.name}`: give exactly one of `look_at` or `quat`")
        if self.look_at is not None:
            look_at_quat(self.position, self.look_at, self.up)  # raises on degenerate input
        if self.far <= self.near:
            raise ValueError(
                f"camera `{self.name}`: far ({self.far}) must exceed near ({self.near})"
            )
        return self

    def orientation(self) -> Quat:
        """wxyz orientation in the parent frame."""
        if self.quat is not None:
            return self.quat
        assert self.look_at is not None
        return look_at_quat(self.position, self.look_at, self.up)


class EmbodimentSpec(_Strict):
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    description: str = ""
    robots: tuple[RobotSpec, ...] = Field(min_length=1)
    cameras: tuple[CameraSpec, ...] = ()

    @model_validator(mode="after")
    def _names(self) -> EmbodimentSpec:
        _unique([r.name for r in self.robots], "robot")
        arm_names = [a.name for r in self.robots for a in r.arms]
        _unique(arm_names, "arm")
        _unique([c.name for c in self.cameras], "camera")
        for cam in self.cameras:
            if cam.parent != "world" and cam.parent not in arm_names:
                raise ValueError(
                    f"camera `{cam.name}`: parent `{cam.parent}` is neither `world` "
                    f"nor an arm ({', '.join(arm_names)})"
                )
        return self

    @property
    def arms(self) -> tuple[ArmSpec, ...]:
        return tuple(a for r in self.robots for a in r.arms)

    @property
    def arm_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.arms)

    def arm(self, name: str) -> ArmSpec:
        for arm in self.arms:
            if arm.name == name:
                return arm
        raise KeyError(f"embodiment `{self.name}` has no arm `{name}`; arms: {self.arm_names}")

    def robot_of(self, arm_name: str) -> RobotSpec:
        for robot in self.robots:
            if any(a.name == arm_name for a in robot.arms):
                return robot
        raise KeyError(f"embodiment `{self.name}` has no arm `{arm_name}`")


__all__ = [
    "ArmSpec", "Axis", "CameraSpec", "DriveSpec", "EmbodimentSpec", "GripperSpec", "MountSpec",
    "RobotSpec", "WorkspaceSpec",
]
