"""Forward and inverse kinematics of a loaded arm's tool centre point (TCP) and links.

Uses the Pinocchio model SAPIEN builds from an articulation (``create_pinocchio_model``,
damped least-squares CLIK). Poses are in the table (world) frame; quaternions wxyz.
:class:`ArmKinematics` is the SAPIEN back-end's :class:`fsvla.world.ArmModel`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import (
    AXES,
    Quat,
    Vec3,
    matrix_to_quat,
    point_axis,
    quat_to_matrix,
    rotation_angle,
    transform_points,
)
from fsvla.embodiments.spec import ArmSpec
from fsvla.world import IKResult, pad_gap

from .robot import LoadedArm


def _primitive_corners(shape: Any) -> NDArray[np.float64] | None:
    """The 8 corners of a box, sphere, capsule or cylinder collision shape's bounding box
    in its own frame (SAPIEN's capsules and cylinders lie along x); None for others."""
    if hasattr(shape, "half_size"):
        half = np.asarray(shape.half_size, dtype=np.float64)
    elif hasattr(shape, "half_length"):
        r = float(shape.radius)
        half = np.array([float(shape.half_length) + r, r, r])
    elif hasattr(shape, "radius"):
        half = np.full(3, float(shape.radius))
    else:
        return None
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    return signs * half


class ArmKinematics:
    """FK/IK of one arm; other joints of its articulation stay where they are."""

    def __init__(self, arm: LoadedArm) -> None:
        import sapien

        self._sapien = sapien
        self.arm = arm
        self._model = arm.articulation.create_pinocchio_model()
        self._mask = np.zeros(arm.articulation.dof, dtype=np.int32)
        self._mask[list(arm.joint_indices)] = 1
        self._tcp = sapien.Pose(list(arm.spec.tcp_offset))
        joints = arm.articulation.active_joints
        self.limits = np.array([joints[i].limit[0] for i in arm.joint_indices], dtype=np.float64)

    @property
    def spec(self) -> ArmSpec:
        return self.arm.spec

    @property
    def link_names(self) -> tuple[str, ...]:
        """Every link of the arm's articulation, in its order (the index of a link)."""
        return tuple(link.name for link in self.arm.articulation.get_links())

    def link_poses(self, arm_q: Sequence[float],
                   links: Sequence[int]) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """World positions (n, 3) and quaternions (n, 4) of ``links`` at arm joints ``arm_q``."""
        self._model.compute_forward_kinematics(self._full(arm_q))
        root = self.arm.articulation.get_root_pose()
        poses = [root * self._model.get_link_pose(i) for i in links]
        return (np.array([pose.p for pose in poses]).reshape(-1, 3),
                np.array([pose.q for pose in poses]).reshape(-1, 4))

    def finger_points(self, fraction: float) -> NDArray[np.float64]:
        """World positions (n, 3), one per finger link, of the points that lie on the TCP
        when the gripper is closed, with the gripper open by ``fraction`` and the arm where
        it is: their largest distance is the opening at the TCP (``fsvla validate``'s
        measure), the first two's difference the direction the fingers close along."""
        tcp, closed = self._fingers_at(0.0)
        held = [pose.inv() * tcp for pose in closed]  # the TCP in each finger's frame
        _, opened = self._fingers_at(fraction)
        return np.array([(pose * point).p for pose, point in zip(opened, held)],
                        dtype=np.float64)

    def shut_gap(self, depth: float) -> float:
        """How far apart (m) the fingers' collision hulls stay across their closing axis
        with the gripper shut (the arm as it is), measured on what of them lies within
        ``depth`` behind the TCP, the pads: Baxter's fingertips stop apart; a Panda's
        fingers and a hinged jaw meet (0)."""
        points = self.finger_points(1.0)
        if len(points) < 2 or np.linalg.norm(points[0] - points[1]) < 1e-6:
            return 0.0
        across = (points[0] - points[1]) / np.linalg.norm(points[0] - points[1])
        tcp, closed = self._fingers_at(0.0)
        back = -(quat_to_matrix(tcp.q) @ np.asarray(AXES[self.arm.spec.approach_axis], dtype=np.float64))
        links = self.arm.articulation.get_links()
        hulls = []
        for finger, pose in zip(self.arm.finger_links, closed):
            local = self.link_vertices(next(i for i, lk in enumerate(links) if lk.name == finger.name))
            if local is not None:
                hulls.append(transform_points(local, pose.p, pose.q))
        return pad_gap(hulls, np.asarray(tcp.p, dtype=np.float64), across, back, depth)

    def _fingers_at(self, fraction: float) -> tuple[Any, list[Any]]:
        """The world TCP pose and each finger link's, the gripper open by ``fraction``."""
        links = self.arm.articulation.get_links()
        indices = [next(i for i, lk in enumerate(links) if lk.name == f.name)
                   for f in self.arm.finger_links]
        root = self.arm.articulation.get_root_pose()
        gripper = self.arm.spec.gripper
        full = self._full(None)
        for index, lo, hi in zip(self.arm.gripper_indices, gripper.closed, gripper.open):
            full[index] = lo + fraction * (hi - lo)
        self._model.compute_forward_kinematics(full)
        tcp = root * self._model.get_link_pose(self.arm.ee_link_index) * self._tcp
        return tcp, [root * self._model.get_link_pose(i) for i in indices]

    def link_vertices(self, link: int) -> NDArray[np.float64] | None:
        """The vertices of a link's convex collision pieces, in the link's frame."""
        parts = []
        for shape in self.arm.articulation.get_links()[link].collision_shapes:
            if hasattr(shape, "get_vertices"):
                v = np.asarray(shape.get_vertices(), dtype=np.float64) * np.asarray(shape.scale)
            else:  # a primitive: the corners of its box (an over-estimate, like the hulls)
                v = _primitive_corners(shape)
                if v is None:
                    continue
            pose = shape.local_pose
            parts.append(transform_points(v, pose.p, pose.q))
        return np.concatenate(parts) if parts else None

    def _full(self, arm_q: Sequence[float] | None) -> NDArray[np.float64]:
        full = np.asarray(self.arm.articulation.get_qpos(), dtype=np.float64).copy()
        if arm_q is not None:
            full[list(self.arm.joint_indices)] = arm_q
        return full

    def tcp_pose(self, arm_q: Sequence[float] | None = None) -> Any:
        """World TCP pose for arm joints ``arm_q`` (default: the current ones)."""
        self._model.compute_forward_kinematics(self._full(arm_q))
        link = self._model.get_link_pose(self.arm.ee_link_index)
        return self.arm.articulation.get_root_pose() * link * self._tcp

    def top_down(self, arm_q: Sequence[float] | None = None) -> Quat:
        """TCP orientation with the approach axis pointing straight down, keeping the
        heading the TCP has at ``arm_q`` (default: home)."""
        q = self.arm.spec.home if arm_q is None else arm_q
        rotation = quat_to_matrix(self.tcp_pose(q).q)
        return matrix_to_quat(point_axis(rotation, self.arm.spec.approach_axis, (0.0, 0.0, -1.0)))

    def inverse(
        self,
        position: Vec3,
        orientation: Quat,
        seed: Sequence[float] | None = None,
        restarts: int = 8,
        max_iterations: int = 500,
    ) -> IKResult:
        """Arm joints putting the TCP at ``position`` with ``orientation`` (world frame).

        The solver (CLIK) ignores joint limits, so it starts from ``seed`` (default: home)
        and, while its answer is outside the limits or off target by more than 1 mm or
        0.01 rad, from up to ``restarts`` more seeds drawn (seeded, reproducibly)
        within the limits. Returns the first good answer, else the closest one.
        """
        rng = np.random.default_rng(0)
        finite = np.where(np.isfinite(self.limits), self.limits, np.array([-np.pi, np.pi]))
        start = np.asarray(self.arm.spec.home if seed is None else seed, dtype=np.float64)
        best: IKResult | None = None
        for attempt in range(restarts + 1):
            if attempt:
                start = rng.uniform(finite[:, 0], finite[:, 1])
            result = self._solve_once(position, orientation, start, max_iterations)
            if result.ok(position_tol=1e-3, rotation_tol=1e-2):
                return result
            if best is None or _rank(result) < _rank(best):
                best = result
        assert best is not None
        return best

    def _solve_once(
        self, position: Vec3, orientation: Quat, start: NDArray[np.float64], max_iterations: int
    ) -> IKResult:
        sapien = self._sapien
        target = sapien.Pose(list(position), list(orientation))
        link_target = self.arm.articulation.get_root_pose().inv() * target * self._tcp.inv()
        full, converged, _ = self._model.compute_inverse_kinematics(
            self.arm.ee_link_index,
            link_target,
            initial_qpos=self._full(start),
            active_qmask=self._mask,
            max_iterations=max_iterations,
        )
        arm_q = np.asarray(full, dtype=np.float64)[list(self.arm.joint_indices)]
        reached = self.tcp_pose(arm_q)
        position_error = float(np.linalg.norm(np.asarray(reached.p) - np.asarray(position)))
        rotation_error = rotation_angle(quat_to_matrix(reached.q), quat_to_matrix(orientation))
        within = bool(
            np.all(arm_q >= self.limits[:, 0] - 1e-6) and np.all(arm_q <= self.limits[:, 1] + 1e-6)
        )
        return IKResult(arm_q, bool(converged), position_error, rotation_error, within)


def _rank(result: IKResult) -> tuple[bool, float]:
    return (not result.within_limits, result.position_error + 0.1 * result.rotation_error)


__all__ = ["ArmKinematics", "IKResult"]
