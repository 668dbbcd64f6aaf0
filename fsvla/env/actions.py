"""Action formats of the fsvla environment, and their validation.

An action is one flat ``float32`` vector made of one block per arm, in the embodiment's
arm order (``EmbodimentSpec.arm_names``):

- ``joint_pos``: ``[q_1 … q_n, g]`` — absolute arm joint positions (rad or m, the URDF's
  joint order of the arm spec) and the gripper opening ``g`` in [0, 1] (0 closed, 1 open,
  linear in between). This is the format VLAs for bimanual arms emit (ALOHA-style: 7 + 7
  for two 6-DoF arms, 8 + 8 for two pandas).
- ``ee_pose``: ``[x, y, z, qw, qx, qy, qz, g]`` — the tool centre point's target pose in
  the world (table) frame, quaternion scalar first, and the gripper opening. The
  quaternion must be unit to within 1e-2 (it is then normalised); the environment
  solves inverse kinematics and drives the joints there.

Nothing is clipped, padded or guessed: an action of the wrong shape, with a NaN or an
infinity, or outside its bounds raises :class:`InvalidActionError`, which names every
offending component.
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


class ControlMode(str, Enum):
    JOINT_POS = "joint_pos"
    EE_POSE = "ee_pose"


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
    """One arm's decoded command: joint targets or a TCP pose target, and a gripper opening."""

    arm: str
    joint_targets: NDArray[np.float64] | None
    tcp_position: NDArray[np.float64] | None
    tcp_quaternion: NDArray[np.float64] | None
    gripper: float


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
            if self.mode is ControlMode.JOINT_POS:
                labels += [f"{arm.name}.{joint}" for joint in arm.joints]
                low += [_finite(v, -np.pi) for v in arm.lower]
                high += [_finite(v, np.pi) for v in arm.upper]
            else:
                labels += [f"{arm.name}.{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
                unit = 1.0 + QUATERNION_TOLERANCE
                low += [-EE_POSITION_BOUND] * 3 + [-unit] * 4
                high += [EE_POSITION_BOUND] * 3 + [unit] * 4
            labels.append(f"{arm.name}.gripper")
            low.append(0.0)
            high.append(1.0)
        self.labels = tuple(labels)
        self.low = np.asarray(low, dtype=np.float32)
        self.high = np.asarray(high, dtype=np.float32)

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
        for arm in self.arms:
            if self.mode is ControlMode.JOINT_POS:
                end = start + len(arm.joints)
                commands.append(ArmCommand(arm.name, vector[start:end].copy(), None, None,
                                           float(vector[end])))
                start = end + 1
            else:
                quaternion = vector[start + 3:start + 7]
                norm = float(np.linalg.norm(quaternion))
                if abs(norm - 1.0) > QUATERNION_TOLERANCE:
                    problems.append(f"{arm.name}'s target quaternion has length {norm:.4g}, "
                                    f"not 1 (within {QUATERNION_TOLERANCE})")
                    norm = norm or 1.0
                commands.append(ArmCommand(arm.name, None, vector[start:start + 3].copy(),
                                           quaternion / norm, float(vector[start + 7])))
                start += 8
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


def _finite(value: float, fallback: float) -> float:
    return float(value) if np.isfinite(value) else fallback


__all__ = ["ActionCodec", "ArmCommand", "ArmLayout", "ControlMode", "InvalidActionError"]
