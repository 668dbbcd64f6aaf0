"""Load an embodiment spec into a SAPIEN scene as PD-driven articulations.

Each robot of the spec becomes one articulation with a fixed root at its mount pose.
Every movable joint gets a joint-position drive (arm joints the arm's drive, gripper
joints the gripper's, all others the robot's ``hold_drive``) and starts at home.
Gravity stays on; :meth:`LoadedRobot.compensate_gravity` (call it before each
``scene.step()``) feeds the articulation's passive forces forward, as a torque-controlled
arm's controller does, so the drives only correct errors.
"""

from __future__ import annotations

import difflib
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import yaw_quat
from fsvla.embodiments.assets import resolve_asset
from fsvla.embodiments.spec import ArmSpec, DriveSpec, EmbodimentSpec, MountSpec, RobotSpec

from .urdf import prepare_urdf


def mount_pose(mount: MountSpec) -> Any:
    """The mount as a ``sapien.Pose`` in the table (world) frame."""
    import sapien

    return sapien.Pose(list(mount.position), list(yaw_quat(mount.yaw)))


@dataclass(frozen=True)
class LoadedArm:
    """One arm of a loaded robot; indices are into its articulation's ``qpos``."""

    spec: ArmSpec
    articulation: Any
    joint_indices: tuple[int, ...]
    gripper_indices: tuple[int, ...]
    base_link: Any
    ee_link: Any
    ee_link_index: int
    finger_links: tuple[Any, ...]

    @property
    def name(self) -> str:
        return self.spec.name

    def qpos(self) -> NDArray[np.float64]:
        """Arm joint positions, in the spec's joint order."""
        return np.asarray(self.articulation.get_qpos(), dtype=np.float64)[list(self.joint_indices)]

    def gripper_qpos(self) -> NDArray[np.float64]:
        return np.asarray(self.articulation.get_qpos(), dtype=np.float64)[
            list(self.gripper_indices)
        ]

    def set_joint_targets(self, targets: Sequence[float]) -> None:
        """Drive targets for the arm joints, in the spec's joint order."""
        for joint, target in self._drives(targets, "targets"):
            joint.set_drive_target(target)

    def set_joint_velocity_targets(self, velocities: Sequence[float]) -> None:
        """Drive velocity targets for the arm joints (rad/s or m/s), in the spec's order."""
        for joint, velocity in self._drives(velocities, "velocities"):
            joint.set_drive_velocity_target(velocity)

    def _drives(self, values: Sequence[float], what: str) -> list[tuple[Any, float]]:
        """Each arm joint with its value, once ``values`` has one per joint."""
        if len(values) != len(self.joint_indices):
            raise ValueError(
                f"arm `{self.name}` has {len(self.joint_indices)} joints, got {len(values)} {what}"
            )
        joints = self.articulation.active_joints
        return [(joints[index], float(value)) for index, value in zip(self.joint_indices, values)]

    def set_gripper(self, open: bool) -> None:
        """Drive the gripper's joints to their open or closed positions."""
        joints = self.articulation.active_joints
        for index, target in zip(self.gripper_indices, self.spec.gripper.targets(open)):
            joints[index].set_drive_target(float(target))

    def set_gripper_opening(self, opening: float) -> None:
        """Drive the gripper to ``opening`` in [0, 1]: 0 closed, 1 open, linear between."""
        closed, open_ = self.spec.gripper.closed, self.spec.gripper.open
        joints = self.articulation.active_joints
        for index, lo, hi in zip(self.gripper_indices, closed, open_):
            joints[index].set_drive_target(float(lo + opening * (hi - lo)))

    def gripper_opening(self) -> float:
        """How open the gripper is, in [0, 1] (the mean over its joints, clipped)."""
        closed = np.asarray(self.spec.gripper.closed, dtype=np.float64)
        span = np.asarray(self.spec.gripper.open, dtype=np.float64) - closed
        ratio = (self.gripper_qpos() - closed) / np.where(span == 0.0, 1.0, span)
        return float(np.clip(ratio.mean(), 0.0, 1.0))

    def tcp_pose(self) -> Any:
        """World pose (``sapien.Pose``) of the tool centre point."""
        import sapien

        return self.ee_link.entity_pose * sapien.Pose(list(self.spec.tcp_offset))


@dataclass(frozen=True)
class LoadedRobot:
    """An embodiment in a scene: its articulations (by robot name) and arms (by arm name)."""

    spec: EmbodimentSpec
    articulations: Mapping[str, Any]
    arms: Mapping[str, LoadedArm]

    def arm(self, name: str) -> LoadedArm:
        if name not in self.arms:
            raise KeyError(
                f"embodiment `{self.spec.name}` has no arm `{name}`; arms: {list(self.arms)}"
            )
        return self.arms[name]

    def set_gripper(self, open: bool, arm: str | None = None) -> None:
        """Open or close one arm's gripper, or every gripper when ``arm`` is None."""
        for loaded in [self.arm(arm)] if arm else self.arms.values():
            loaded.set_gripper(open)

    def home_qpos(self, robot: str) -> NDArray[np.float64]:
        """Full home joint vector of one articulation (arms, grippers, held joints)."""
        spec = next(r for r in self.spec.robots if r.name == robot)
        return _home_vector(self.articulations[robot], spec)

    def reset_home(self) -> None:
        """Teleport every articulation to home, at rest, with drive targets at home."""
        for name, articulation in self.articulations.items():
            home = self.home_qpos(name)
            articulation.set_qpos(home.astype(np.float32))
            articulation.set_qvel(np.zeros(articulation.dof, dtype=np.float32))
            for joint, target in zip(articulation.active_joints, home):
                joint.set_drive_target(float(target))

    def compensate_gravity(self) -> None:
        """Apply the passive (gravity, Coriolis) forces as joint feed-forward for the next step."""
        for articulation in self.articulations.values():
            articulation.set_qf(
                articulation.compute_passive_force(gravity=True, coriolis_and_centrifugal=True)
            )


def load_robot(scene: Any, spec: EmbodimentSpec) -> LoadedRobot:
    """Load every robot of ``spec`` into ``scene`` at its mount pose, drives set, at home.

    Visual meshes are loaded only when the scene has a render system.
    """
    keep_visuals = _has_render_system(scene)
    articulations: dict[str, Any] = {}
    arms: dict[str, LoadedArm] = {}
    with tempfile.TemporaryDirectory(prefix="fsvla-urdf-") as tmp:
        for index, robot in enumerate(spec.robots):
            articulation = _load_articulation(scene, robot, Path(tmp), keep_visuals)
            disabled = srdf_disabled_pairs(resolve_asset(robot.srdf)) if robot.srdf else ()
            bits = self_collision_bits([link.name for link in articulation.links], disabled)
            _set_collision_groups(articulation, index, robot.self_collisions, bits)
            articulations[robot.name] = articulation
            for arm in robot.arms:
                arms[arm.name] = _bind_arm(articulation, robot, arm)
            _set_drives(articulation, robot)
            _set_pad_friction(articulation, robot)
    loaded = LoadedRobot(spec=spec, articulations=articulations, arms=arms)
    loaded.reset_home()
    return loaded


def _has_render_system(scene: Any) -> bool:
    try:
        scene.get_system("render")
    except (RuntimeError, KeyError, IndexError):
        return False
    return True


def _load_articulation(scene: Any, robot: RobotSpec, tmp: Path, keep_visuals: bool) -> Any:
    pieces = {name: Path(folder) for name, folder in robot.collision_pieces.items()}
    urdf = prepare_urdf(resolve_asset(robot.urdf), tmp, keep_visuals, pieces)
    srdf = str(resolve_asset(robot.srdf)) if robot.srdf else None
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    builder = loader.load_file_as_articulation_builder(str(urdf), srdf)
    builder.initial_pose = mount_pose(robot.mount)
    articulation = builder.build(fix_root_link=True)
    articulation.name = robot.name
    articulation.set_root_pose(mount_pose(robot.mount))
    return articulation


ROBOT_GROUP_BASE = 0x0F00  # collision group 3 of robot i's shapes: ROBOT_GROUP_BASE + i
NO_SELF_COLLISION_BIT = 1 << 31  # the SRDF's pairs use bits 0-30 of group 2
SRDF_BITS = 31


def srdf_disabled_pairs(path: Path) -> list[tuple[str, str]]:
    """The link pairs an SRDF's ``disable_collisions`` elements name, whatever their reason."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    return [(e.get("link1", ""), e.get("link2", "")) for e in root.iter("disable_collisions")]


def self_collision_bits(links: Sequence[str], disabled: Iterable[tuple[str, str]]) -> dict[str, int]:
    """Collision group-2 bits per link such that two links share a bit exactly when their
    pair is disabled: a greedy cover of the disabled pairs by cliques (sets of links that
    are pairwise disabled), one bit each. SAPIEN's own SRDF handling applies only the
    `Default` pairs: a Panda's hand and link 7 (an `Adjacent` pair two fixed joints apart)
    would press into each other at home, in every physics step."""
    known = set(links)
    allowed = {frozenset(p) for p in disabled if p[0] != p[1] and set(p) <= known}
    cliques: list[set[str]] = []
    for pair in sorted(allowed, key=sorted):
        a, b = sorted(pair)
        for clique in cliques:
            if all(frozenset((x, m)) in allowed for x in (a, b) for m in clique if m != x):
                clique.update((a, b))
                break
        else:
            cliques.append({a, b})
    if len(cliques) > SRDF_BITS:
        raise ValueError(f"the SRDF's disabled pairs need {len(cliques)} collision bits; "
                         f"at most {SRDF_BITS} are available (set self_collisions = false)")
    bits = dict.fromkeys(links, 0)
    for i, clique in enumerate(cliques):
        for link in clique:
            bits[link] |= 1 << i
    return bits


def _set_collision_groups(articulation: Any, index: int, self_collisions: bool,
                          bits: Mapping[str, int]) -> None:
    """Give each robot its own collision group 3, so that the group-2 bits act within one
    robot only (SAPIEN leaves group 3 at 0 for every robot, which would let two pandas'
    fingers pass through each other); set group 2 to the links' SRDF bits, and switch
    the robot's self-collisions off where asked.

    SAPIEN: shapes A and B collide iff ((A.g0 & B.g1) or (A.g1 & B.g0)) and
    not ((A.g2 & B.g2) and (A.g3 & 0xffff) == (B.g3 & 0xffff)).
    """
    for link in articulation.links:
        g2 = bits.get(link.name, 0) | (0 if self_collisions else NO_SELF_COLLISION_BIT)
        for shape in link.collision_shapes:
            g0, g1, _, g3 = shape.get_collision_groups()
            g3 = (g3 & 0xFFFF0000) | (ROBOT_GROUP_BASE + index)
            shape.set_collision_groups([g0, g1, g2, g3])


def _find(kind: str, name: str, available: Sequence[str], robot: RobotSpec) -> int:
    if name in available:
        return list(available).index(name)
    hint = difflib.get_close_matches(name, available, n=1)
    raise ValueError(
        f"robot `{robot.name}` ({robot.urdf}) has no {kind} `{name}`"
        + (f"; did you mean `{hint[0]}`?" if hint else "")
        + f" Its {kind}s: {', '.join(available)}"
    )


def _bind_arm(articulation: Any, robot: RobotSpec, arm: ArmSpec) -> LoadedArm:
    joint_names = [j.name for j in articulation.active_joints]
    links = list(articulation.links)
    link_names = [link.name for link in links]
    ee_index = _find("link", arm.ee_link, link_names, robot)
    return LoadedArm(
        spec=arm,
        articulation=articulation,
        joint_indices=tuple(_find("movable joint", j, joint_names, robot) for j in arm.joints),
        gripper_indices=tuple(
            _find("movable joint", j, joint_names, robot) for j in arm.gripper.joints
        ),
        base_link=links[_find("link", arm.base_link, link_names, robot)],
        ee_link=links[ee_index],
        ee_link_index=ee_index,
        finger_links=tuple(
            links[_find("link", f, link_names, robot)] for f in arm.gripper.finger_links
        ),
    )


def _joint_plan(robot: RobotSpec) -> dict[str, tuple[DriveSpec, float]]:
    """Drive and home target for each joint the spec names."""
    plan: dict[str, tuple[DriveSpec, float]] = {}
    for arm in robot.arms:
        for name, home in zip(arm.joints, arm.home):
            plan[name] = (arm.drive, home)
        gripper = arm.gripper
        for name, home in zip(gripper.joints, gripper.targets(gripper.home == "open")):
            plan[name] = (gripper.drive, home)
    return plan


def _home_vector(articulation: Any, robot: RobotSpec) -> NDArray[np.float64]:
    plan = _joint_plan(robot)
    return np.array(
        [
            plan[j.name][1] if j.name in plan else robot.hold.get(j.name, 0.0)
            for j in articulation.active_joints
        ],
        dtype=np.float64,
    )


def _set_drives(articulation: Any, robot: RobotSpec) -> None:
    joint_names = [j.name for j in articulation.active_joints]
    for name in robot.hold:
        _find("movable joint", name, joint_names, robot)
    plan = _joint_plan(robot)
    for joint in articulation.active_joints:
        drive = plan[joint.name][0] if joint.name in plan else robot.hold_drive
        joint.set_drive_properties(drive.stiffness, drive.damping, drive.force_limit, "force")


#: Dynamic over static friction of the finger pads' material.
PAD_DYNAMIC_RATIO = 0.8


def _set_pad_friction(articulation: Any, robot: RobotSpec) -> None:
    """Give the finger links of each arm whose gripper sets ``pad_friction`` a material of
    that static friction (dynamic PAD_DYNAMIC_RATIO of it, no bounce)."""
    import sapien

    for arm in robot.arms:
        friction = arm.gripper.pad_friction
        if friction is None:
            continue
        pad = sapien.physx.PhysxMaterial(friction, PAD_DYNAMIC_RATIO * friction, 0.0)
        for link in articulation.links:
            if link.name in arm.gripper.finger_links:
                for shape in link.collision_shapes:
                    shape.set_physical_material(pad)


__all__ = ["LoadedArm", "LoadedRobot", "load_robot", "mount_pose"]
