"""Action formats of the fsvla environment, and their validation.

An action is one flat ``float32`` vector made of one block per arm, in the embodiment's
arm order (``EmbodimentSpec.arm_names``). Each block ends with the gripper opening ``g``
in [0, 1] (0 closed, 1 open, linear in between), absolute in every mode. What comes
before it depends on the control mode (named after ManiSkill's controllers):

- ``joint_pos`` (ManiSkill's ``pd_joint_pos``): ``[q_1 … q_n, g]`` — absolute arm joint
  positions (rad or m, the URDF's joint order of the arm spec). This is the format VLAs
  for bimanual arms emit (ALOHA-style: 7 + 7 for two 6-DoF arms, 8 + 8 for two pandas).
- ``joint_delta`` (``pd_joint_delta_pos``): ``[Δq_1 … Δq_n, g]`` — a change of each joint
  over this control step, added to the measured joint positions.
- ``joint_vel`` (``pd_joint_vel``): ``[v_1 … v_n, g]`` — joint velocities (rad/s or m/s)
  held over the control step: each drive gets ``v`` as its velocity target and, at every
  physics substep, the position target ``q + v · t`` (``q`` measured at the start of the
  step, ``t`` the time into it), so the joint moves at ``v`` and stops when ``v`` is 0.
- ``ee_pose`` (``pd_ee_pose``): ``[x, y, z, qw, qx, qy, qz, g]`` — the tool centre point's
  target pose in the world (table) frame, quaternion scalar first. The quaternion must be
  unit to within 1e-2 (it is then normalised); the environment solves inverse
  kinematics and drives the joints there.
- ``ee_delta`` (``pd_ee_delta_pose``): ``[dx, dy, dz, rx, ry, rz, g]`` — a move of the
  tool centre point from its measured pose, in the table frame: the translation is
  added to its position and the rotation vector (axis × angle, rad) turns its
  orientation about its own position (``R_target = R(r) · R``); then as ``ee_pose``.

Targets that the delta modes derive are held within the joints' limits, as the joints
themselves are. Nothing else is clipped, padded or guessed: an action of the wrong
shape, with a NaN or an infinity, or outside its bounds raises
:class:`InvalidActionError`, which names every offending component.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import NDArray

#: Workspace bound of ``ee_pose`` positions (table frame, m): generous, not a safety limit.
EE_POSITION_BOUND = 2.0
#: How far from unit length a target quaternion may be before it is rejected.
QUATERNION_TOLERANCE = 1e-2
#: Slack on joint limits, for round-off in actions read back from observations.
LIMIT_SLACK = 1e-6
#: Bound of a ``joint_delta`` component (rad or m per control step): generous, not a limit.
JOINT_DELTA_BOUND = 0.5
#: Bound of a ``joint_vel`` component (rad/s or m/s): 0.5 rad per 20 Hz step, as above.
JOINT_VELOCITY_BOUND = 10.0
#: Bounds of an ``ee_delta`` translation (m) and rotation-vector component (rad) per step:
#: LIBERO's end-effector controller moves at most 0.05 m and 0.5 rad a step.
EE_DELTA_POSITION_BOUND = 0.1
EE_DELTA_ROTATION_BOUND = 0.5


class ControlMode(str, Enum):
    JOINT_POS = "joint_pos"
    JOINT_DELTA = "joint_delta"
    JOINT_VEL = "joint_vel"
    EE_POSE = "ee_pose"
    EE_DELTA = "ee_delta"

    @property
    def in_joint_space(self) -> bool:
        return self in (ControlMode.JOINT_POS, ControlMode.JOINT_DELTA, ControlMode.JOINT_VEL)


#: The components of a TCP block before the gripper, per TCP mode.
_TCP_COMPONENTS = {
    ControlMode.EE_POSE: ("x", "y", "z", "qw", "qx", "qy", "qz"),
    ControlMode.EE_DELTA: ("dx", "dy", "dz", "rx", "ry", "rz"),
}


class InvalidActionError(ValueError):
    """An action the environment refuses; the message names each bad component."""


@dataclass(frozen=True)
class ArmLayout:
    """What an arm's action block needs: its name, joint names and joint limits."""

    name: str
    joints: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]


@dataclass(frozen=True)
class ArmCommand:
    """One arm's decoded command and gripper opening. Exactly one of these is set:
    ``joint_targets`` (joint_pos), ``joint_delta`` (joint_delta), ``joint_velocity``
    (joint_vel), ``tcp_position`` + ``tcp_quaternion`` (ee_pose), ``tcp_delta`` (ee_delta:
    translation, then rotation vector)."""

    arm: str
    joint_targets: NDArray[np.float64] | None
    tcp_position: NDArray[np.float64] | None
    tcp_quaternion: NDArray[np.float64] | None
    gripper: float
    joint_delta: NDArray[np.float64] | None = None
    joint_velocity: NDArray[np.float64] | None = None
    tcp_delta: NDArray[np.float64] | None = None

    @property
    def in_joint_space(self) -> bool:
        return self.tcp_position is None and self.tcp_delta is None


class ActionCodec:
    """Bounds, labels and validation of the flat action vector for one embodiment and mode."""

    def __init__(self, arms: Sequence[ArmLayout], mode: ControlMode | str) -> None:
        if not arms:
            raise ValueError("an action needs at least one arm")
        self.arms = tuple(arms)
        self.mode = ControlMode(mode)
        labels: list[str] = []
        low: list[float] = []
        high: list[float] = []
        for arm in self.arms:
            names, lo, hi = self._block(arm)
            labels += [f"{arm.name}.{name}" for name in names] + [f"{arm.name}.gripper"]
            low += lo + [0.0]
            high += hi + [1.0]
        self.labels = tuple(labels)
        self.low = np.asarray(low, dtype=np.float32)
        self.high = np.asarray(high, dtype=np.float32)

    def _block(self, arm: ArmLayout) -> tuple[tuple[str, ...], list[float], list[float]]:
        """The labels and bounds of ``arm``'s components before its gripper."""
        n = len(arm.joints)
        if self.mode is ControlMode.JOINT_POS:
            return (arm.joints, [_finite(v, -np.pi) for v in arm.lower],
                    [_finite(v, np.pi) for v in arm.upper])
        if self.mode is ControlMode.JOINT_DELTA:
            return arm.joints, [-JOINT_DELTA_BOUND] * n, [JOINT_DELTA_BOUND] * n
        if self.mode is ControlMode.JOINT_VEL:
            return arm.joints, [-JOINT_VELOCITY_BOUND] * n, [JOINT_VELOCITY_BOUND] * n
        if self.mode is ControlMode.EE_POSE:
            unit = 1.0 + QUATERNION_TOLERANCE
            high = [EE_POSITION_BOUND] * 3 + [unit] * 4
        else:
            high = [EE_DELTA_POSITION_BOUND] * 3 + [EE_DELTA_ROTATION_BOUND] * 3
        return _TCP_COMPONENTS[self.mode], [-v for v in high], high

    @property
    def size(self) -> int:
        return len(self.labels)

    def space(self):  # -> gymnasium.spaces.Box
        from gymnasium import spaces

        return spaces.Box(low=self.low, high=self.high, dtype=np.float32)

    def decode(self, action: object) -> tuple[ArmCommand, ...]:
        """Validate ``action`` and split it into one command per arm."""
        vector = self._as_vector(action)
        problems = self._out_of_bounds(vector)
        commands: list[ArmCommand] = []
        start = 0
        mode = self.mode
        for arm in self.arms:
            end = start + (len(arm.joints) if mode.in_joint_space else len(_TCP_COMPONENTS[mode]))
            block, gripper = vector[start:end].copy(), float(vector[end])
            start = end + 1
            if mode is ControlMode.JOINT_POS:
                commands.append(ArmCommand(arm.name, block, None, None, gripper))
            elif mode is ControlMode.JOINT_DELTA:
                commands.append(ArmCommand(arm.name, None, None, None, gripper, joint_delta=block))
            elif mode is ControlMode.JOINT_VEL:
                commands.append(ArmCommand(arm.name, None, None, None, gripper,
                                           joint_velocity=block))
            elif mode is ControlMode.EE_DELTA:
                commands.append(ArmCommand(arm.name, None, None, None, gripper, tcp_delta=block))
            else:
                norm = float(np.linalg.norm(block[3:]))
                if abs(norm - 1.0) > QUATERNION_TOLERANCE:
                    problems.append(f"{arm.name}'s target quaternion has length {norm:.4g}, "
                                    f"not 1 (within {QUATERNION_TOLERANCE})")
                    norm = norm or 1.0
                commands.append(ArmCommand(arm.name, None, block[:3], block[3:] / norm, gripper))
        if problems:
            raise InvalidActionError("invalid action: " + "; ".join(problems))
        return tuple(commands)

    def _as_vector(self, action: object) -> NDArray[np.float64]:
        try:
            vector = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise InvalidActionError(
                f"invalid action: expected {self.size} numbers ({self.mode.value}), "
                f"got {type(action).__name__}: {err}") from None
        if vector.shape != (self.size,):
            raise InvalidActionError(
                f"invalid action: expected shape ({self.size},) for {self.mode.value} "
                f"[{', '.join(self.labels)}], got shape {vector.shape}")
        bad = [f"action[{i}] ({self.labels[i]}) is {vector[i]}"
               for i in np.flatnonzero(~np.isfinite(vector))]
        if bad:
            raise InvalidActionError("invalid action: " + "; ".join(bad))
        return vector

    def _out_of_bounds(self, vector: NDArray[np.float64]) -> list[str]:
        outside = (vector < self.low - LIMIT_SLACK) | (vector > self.high + LIMIT_SLACK)
        return [
            f"action[{i}] ({self.labels[i]}) = {vector[i]:.6g} is outside "
            f"[{self.low[i]:.6g}, {self.high[i]:.6g}]"
            for i in np.flatnonzero(outside)
        ]


def joint_targets(command: ArmCommand, layout: ArmLayout, qpos: Sequence[float],
                  elapsed: float = 0.0) -> NDArray[np.float64]:
    """The position targets of a joint-space command: its absolute targets, or the
    positions ``qpos`` measured at the start of the step plus its change (joint_delta) or
    plus its velocity times ``elapsed``, the time (s) into the step (joint_vel); held
    within the joints' limits."""
    if command.joint_targets is not None:
        return command.joint_targets
    if command.joint_delta is not None:
        change = command.joint_delta
    elif command.joint_velocity is not None:
        change = command.joint_velocity * elapsed
    else:
        raise ValueError(f"{command.arm}'s command is a TCP target, not a joint command")
    target = np.asarray(qpos, dtype=np.float64) + change
    return np.clip(target, np.asarray(layout.lower), np.asarray(layout.upper))


def tcp_target(command: ArmCommand, position: Sequence[float],
               quaternion: Sequence[float]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The TCP target (position, wxyz quaternion) of a TCP command: its absolute pose, or
    the measured pose (``position``, ``quaternion``) moved by its delta (module doc)."""
    if command.tcp_position is not None and command.tcp_quaternion is not None:
        return command.tcp_position, command.tcp_quaternion
    if command.tcp_delta is None:
        raise ValueError(f"{command.arm}'s command is a joint command, not a TCP target")
    from fsvla.compiler.pose import axis_angle_quat, quat_mul

    rotation = command.tcp_delta[3:]
    angle = float(np.linalg.norm(rotation))
    target_q = quat_mul(axis_angle_quat(rotation, angle), quaternion) if angle > 0 else quaternion
    return (np.asarray(position, dtype=np.float64) + command.tcp_delta[:3],
            np.asarray(target_q, dtype=np.float64))


def _finite(value: float, fallback: float) -> float:
    return float(value) if np.isfinite(value) else fallback


__all__ = ["ActionCodec", "ArmCommand", "ArmLayout", "ControlMode", "InvalidActionError",
           "joint_targets", "tcp_target"]
