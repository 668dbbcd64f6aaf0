"""Motion primitives of the scripted experts: Cartesian straight-line segments of the tool
centre point (TCP), turned into joint targets by inverse kinematics, one per control step.

A :class:`Segment` moves some arms' TCPs along straight lines (positions linear,
orientations slerped) at a speed limit, and sets their grippers. :class:`ArmDriver`
keeps each arm's last commanded pose and joints, so that consecutive segments join
without jumps and every IK solve is seeded by the previous step's answer (no wrist
flips). The planner is IK on waypoints, not a sampling planner: the task plans place
their waypoints (approach heights, via points over hazards) so that the straight
segments between them are collision-free; see ``docs/experts.md``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from fsvla.embodiments.frames import matrix_to_quat, quat_to_matrix

#: Largest joint step (rad) between two IK solves of one segment before it is split.
MAX_JOINT_STEP = 0.12
#: How far inside its joint limits (rad or m) a free-space move's goal configuration stays.
LIMIT_MARGIN = 0.15


@dataclass(frozen=True)
class Pose:
    """A TCP pose in the world (table) frame: position (m) and rotation matrix."""

    p: NDArray[np.float64]
    R: NDArray[np.float64]

    @classmethod
    def of(cls, p: Sequence[float], R: NDArray[np.float64]) -> Pose:
        return cls(np.asarray(p, dtype=np.float64), np.asarray(R, dtype=np.float64))

    def moved(self, dp: Sequence[float]) -> Pose:
        return Pose(self.p + np.asarray(dp, dtype=np.float64), self.R)

    @property
    def quat(self) -> tuple[float, float, float, float]:
        return matrix_to_quat(self.R)


@dataclass
class Segment:
    """Move the named arms to ``targets`` in a straight line at ``speed`` (m/s), then set
    their grippers (``grippers``, opening in [0, 1]) over ``gripper_steps`` steps, then
    wait ``settle`` steps. Arms not named hold their pose; ``grippers`` may name arms
    that do not move."""

    targets: dict[str, Pose] = field(default_factory=dict)
    speed: float = 0.1
    grippers: dict[str, float] = field(default_factory=dict)
    gripper_steps: int = 0
    settle: int = 0
    label: str = ""
    joint_space: bool = False  # free-space move: interpolate joints to the IK of the target
    branch_of: dict[str, Pose] = field(default_factory=dict)  # joint_space: end on the IK
    # branch that also reaches these poses (the grasp below a hover point)


def slerp(R0: NDArray[np.float64], R1: NDArray[np.float64], s: float) -> NDArray[np.float64]:
    """Rotation a fraction ``s`` of the way from ``R0`` to ``R1`` (about one axis)."""
    rel = R0.T @ R1
    angle = float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))
    if angle < 1e-9:
        return R1.copy()
    axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    if np.linalg.norm(axis) < 1e-9:  # a half turn: any axis perpendicular works
        w, v = np.linalg.eigh(rel + rel.T)
        axis = v[:, np.argmax(w)]
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    a = s * angle
    return R0 @ (np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k)


def rotation_angle(R0: NDArray[np.float64], R1: NDArray[np.float64]) -> float:
    return float(np.arccos(np.clip((np.trace(R0.T @ R1) - 1.0) / 2.0, -1.0, 1.0)))


class ArmDriver:
    """One arm's commanded state (TCP pose, joints, gripper) and its IK."""

    def __init__(self, name: str, kinematics, pose: Pose, qpos: NDArray[np.float64],
                 gripper: float) -> None:
        self.name = name
        self.kin = kinematics
        self.pose = pose
        self.q = np.asarray(qpos, dtype=np.float64)
        self.gripper = float(gripper)
        self.ik_misses = 0

    def solve_anywhere(self, pose: Pose, branch_of: Pose | None = None) -> NDArray[np.float64]:
        """Joints for ``pose`` on any IK branch (the seeded one when it is within the
        limits, else the nearest of several restarts): the end of a joint-space move.
        With ``branch_of``, on the branch of that pose's comfortable answer."""
        if branch_of is not None:
            q_branch = self.solve_anywhere(branch_of)
            result = self.kin.inverse(tuple(pose.p), pose.quat, seed=q_branch, restarts=0,
                                      max_iterations=300)
            if self._comfortable(result):
                return np.asarray(result.qpos, dtype=np.float64)
        result = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=0,
                                  max_iterations=300)
        if not self._comfortable(result):
            best = None
            for seed in (self.q, self.kin.arm.spec.home, *self._seeds()):
                r = self.kin.inverse(tuple(pose.p), pose.quat, seed=seed, restarts=0)
                if self._comfortable(r) and (
                        best is None or _jump(r, self.q) < _jump(best, self.q)):
                    best = r
            if best is None:
                self.ik_misses += 1
            else:
                result = best
        return np.clip(result.qpos, self.kin.limits[:, 0], self.kin.limits[:, 1])

    def _comfortable(self, result) -> bool:
        """An exact answer at least LIMIT_MARGIN inside every joint limit (a Panda whose
        elbow is folded to its limit hits its own shoulder)."""
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        return bool(result.ok(position_tol=2e-3, rotation_tol=2e-2)
                    and np.all(result.qpos >= lo) and np.all(result.qpos <= hi))

    def _seeds(self) -> list[NDArray[np.float64]]:
        rng = np.random.default_rng(0)
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        home = np.asarray(self.kin.arm.spec.home, dtype=np.float64)
        return [np.clip(home + rng.normal(0.0, 0.6, home.shape), lo, hi) for _ in range(16)]

    def solve(self, pose: Pose) -> NDArray[np.float64]:
        """Joints for ``pose``, seeded by the last command; the closest answer if none is
        exact (counted in ``ik_misses``)."""
        result = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=0,
                                  max_iterations=200)
        if not result.ok(position_tol=2e-3, rotation_tol=2e-2):
            retry = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=6)
            # along a straight segment, never jump to another IK branch
            if _jump(retry, self.q) < MAX_JOINT_STEP and _rank(retry, self.q) < _rank(result, self.q):
                result = retry
            if not result.ok(position_tol=5e-3, rotation_tol=5e-2):
                self.ik_misses += 1
        return np.clip(result.qpos, self.kin.limits[:, 0], self.kin.limits[:, 1])


def _jump(result, seed: NDArray[np.float64]) -> float:
    return float(np.max(np.abs(result.qpos - seed)))


def _rank(result, seed: NDArray[np.float64]) -> tuple[bool, float]:
    jump = float(np.max(np.abs(result.qpos - seed)))
    return (not result.ok(position_tol=5e-3, rotation_tol=5e-2),
            result.position_error + 0.1 * result.rotation_error + 0.01 * jump)


@dataclass(frozen=True)
class Step:
    """One control step's command for every arm: joints, TCP pose and gripper."""

    q: dict[str, NDArray[np.float64]]
    pose: dict[str, Pose]
    gripper: dict[str, float]
    label: str = ""


def expand(segment: Segment, drivers: Mapping[str, ArmDriver], dt: float,
           angular_speed: float) -> list[Step]:
    """The per-step commands of ``segment``; updates the drivers' commanded state."""
    steps: list[Step] = []
    n = 1
    for name, target in segment.targets.items():
        d = drivers[name]
        dist = float(np.linalg.norm(target.p - d.pose.p))
        turn = rotation_angle(d.pose.R, target.R)
        n = max(n, int(np.ceil(dist / max(segment.speed * dt, 1e-6))),
                int(np.ceil(turn / max(angular_speed * dt, 1e-6))))
    if segment.targets and segment.joint_space and _straight_line_ok(segment, drivers, dt,
                                                                     angular_speed):
        segment = Segment(segment.targets, segment.speed, segment.grippers,
                          segment.gripper_steps, segment.settle, segment.label)
    if segment.targets and segment.joint_space:
        q0 = {name: drivers[name].q.copy() for name in segment.targets}
        q1 = {name: drivers[name].solve_anywhere(t, segment.branch_of.get(name))
              for name, t in segment.targets.items()}
        joint_speed = angular_speed
        n = max(n, max(int(np.ceil(float(np.max(np.abs(q1[k] - q0[k]))) / (joint_speed * dt)))
                       for k in q0))
        for i in range(1, n + 1):
            s = _ease(i / n)
            for name in segment.targets:
                d = drivers[name]
                d.q = q0[name] + s * (q1[name] - q0[name])
                tcp = d.kin.tcp_pose(d.q)
                d.pose = Pose.of(tcp.p, quat_to_matrix(tcp.q))
            steps.append(_snapshot(drivers, segment.label))
    elif segment.targets:
        starts = {name: drivers[name].pose for name in segment.targets}
        for i in range(1, n + 1):
            s = _ease(i / n)
            for name, target in segment.targets.items():
                a = starts[name]
                pose = Pose(a.p + s * (target.p - a.p), slerp(a.R, target.R, s))
                d = drivers[name]
                q = d.solve(pose)
                d.pose, d.q = pose, q
            steps.append(_snapshot(drivers, segment.label))
    if segment.grippers:
        k = max(1, segment.gripper_steps)
        starts_g = {name: drivers[name].gripper for name in segment.grippers}
        for i in range(1, k + 1):
            for name, g in segment.grippers.items():
                drivers[name].gripper = starts_g[name] + (g - starts_g[name]) * i / k
            steps.append(_snapshot(drivers, segment.label))
    for _ in range(segment.settle):
        steps.append(_snapshot(drivers, segment.label))
    return steps


def _straight_line_ok(segment: Segment, drivers: Mapping[str, ArmDriver], dt: float,
                      angular_speed: float) -> bool:
    """Whether a free-space segment can be a Cartesian straight line on the current IK
    branch (every step solved, comfortably inside the limits at its end)."""
    import copy

    trial = {name: copy.copy(d) for name, d in drivers.items()}
    for d in trial.values():
        d.ik_misses = 0
    straight = Segment(segment.targets, segment.speed, label=segment.label)
    expand(straight, trial, dt, angular_speed)
    for name in segment.targets:
        d = trial[name]
        lo = d.kin.limits[:, 0] + LIMIT_MARGIN
        hi = d.kin.limits[:, 1] - LIMIT_MARGIN
        if d.ik_misses or np.any(d.q < lo) or np.any(d.q > hi):
            return False
        branch = segment.branch_of.get(name)
        if branch is not None:  # the straight line must also leave the goal reachable
            probe = copy.copy(d)
            probe.ik_misses = 0
            probe.solve(branch)
            if probe.ik_misses:
                return False
    return True


def _ease(s: float) -> float:
    """Smooth start and stop (cubic ease in/out) along a segment."""
    return s * s * (3.0 - 2.0 * s)


def _snapshot(drivers: Mapping[str, ArmDriver], label: str) -> Step:
    return Step(q={n: d.q.copy() for n, d in drivers.items()},
                pose={n: d.pose for n, d in drivers.items()},
                gripper={n: d.gripper for n, d in drivers.items()}, label=label)


def current_pose(arm) -> Pose:
    pose = arm.tcp_pose()
    return Pose.of(pose.p, quat_to_matrix(pose.q))


__all__ = ["ArmDriver", "Pose", "Segment", "Step", "current_pose", "expand", "rotation_angle",
           "slerp"]
