"""Two reference policies with no learning in them: ``random`` and ``hold-still``.

They bound a results table from below: a policy that does nothing (``hold-still``) and
one that does anything (``random``) show what the scenario's monitor and success
condition make of no skill at all.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .base import EpisodeInfo


class RandomPolicy:
    """Uniform random actions within the action bounds, seeded per episode."""

    name = "random"

    def __init__(self, seed: int = 0) -> None:
        self._base_seed = seed
        self._rng = np.random.default_rng(seed)
        self._low = self._high = np.zeros(0)

    def reset(self, episode: EpisodeInfo) -> None:
        self._rng = np.random.default_rng([self._base_seed, episode.policy_seed])
        self._low = np.asarray(episode.action.low, dtype=np.float64)
        self._high = np.asarray(episode.action.high, dtype=np.float64)
        if episode.action.control_mode == "ee_pose":
            raise ValueError("the random policy draws joint positions; use control_mode joint_pos")

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        return self._rng.uniform(self._low, self._high).astype(np.float32)


class HoldStillPolicy:
    """Keeps every joint where it was at the start of the episode, grippers unchanged."""

    name = "hold-still"

    def __init__(self) -> None:
        self._hold: np.ndarray | None = None
        self._mode = "joint_pos"
        self._sizes: list[int] = []

    def reset(self, episode: EpisodeInfo) -> None:
        self._hold = None
        self._mode = episode.action.control_mode
        self._sizes = arm_block_sizes(episode)

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        if self._hold is None:
            self._hold = hold_action(observation, self._mode, self._sizes)
        return self._hold


def arm_block_sizes(episode: EpisodeInfo) -> list[int]:
    """How many non-gripper action components each arm has, in arm order."""
    return [sum(1 for label in episode.action.labels
                if label.startswith(f"{arm}.") and label != f"{arm}.gripper")
            for arm in episode.action.arms]


#: Control modes whose action is a change (or a velocity): holding still is zero.
RELATIVE_MODES = ("joint_delta", "joint_vel", "ee_delta")


def hold_action(observation: dict[str, Any], mode: str, sizes: list[int]) -> np.ndarray:
    """The action that keeps the robot where the observation says it is; ``sizes`` are
    the arms' block sizes without the gripper (joints, 7 for a pose, 6 for a pose delta)."""
    agent = observation["agent"]
    gripper = np.asarray(agent["gripper"], dtype=np.float32)
    if mode in RELATIVE_MODES:
        source = np.zeros(sum(sizes), dtype=np.float32)
    else:
        source = agent["qpos"] if mode == "joint_pos" else agent["tcp_pose"]
    blocks = np.split(np.asarray(source, dtype=np.float32), np.cumsum(sizes)[:-1])
    return np.concatenate([np.append(block, g) for block, g in zip(blocks, gripper)])


__all__ = ["RELATIVE_MODES", "HoldStillPolicy", "RandomPolicy", "arm_block_sizes", "hold_action"]
