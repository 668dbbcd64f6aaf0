"""The policy interface: what fsvla asks of anything it evaluates.

A policy is an object with two methods::

    reset(episode: EpisodeInfo) -> None         # once, before the first observation
    act(observation: dict) -> np.ndarray          # an action, or a chunk of actions

``act`` returns either one action of shape ``(A,)`` or a chunk ``(H, A)`` that the
benchmark executes step by step (asking again when the chunk is used up); the monitor
sees every action and every physics substep of a chunk. ``A`` and the meaning of each
component are in :attr:`EpisodeInfo.action` (see :mod:`fsvla.env.actions`); the
observation's layout is in :attr:`EpisodeInfo.observation` (see
:mod:`fsvla.env.observations`). Quaternions are (w, x, y, z); gripper openings are in
[0, 1] with 1 open.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np
from pydantic import BaseModel, ConfigDict, computed_field

from fsvla.run.key import EpisodeKey

# 2.0: the episode's coordinates under "key", the policy's seed as "policy_seed"
SCHEMA_VERSION = "2.0"


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ActionSchema(_Model):
    control_mode: str  # joint_pos, joint_delta, joint_vel, ee_pose or ee_delta (fsvla.env.actions)
    labels: tuple[str, ...]  # one per component: "<arm>.<joint>", "<arm>.gripper", "<arm>.qw", ...
    low: tuple[float, ...]
    high: tuple[float, ...]
    arms: tuple[str, ...]
    quaternion_order: str = "wxyz"
    gripper_range: tuple[float, float] = (0.0, 1.0)  # closed, open


class CameraSchema(_Model):
    name: str
    height: int
    width: int
    mount: str  # "world" or the arm it rides on


class ObservationSchema(_Model):
    state_layout: dict[str, tuple[str, ...]]  # agent key -> the label of each component
    cameras: tuple[CameraSchema, ...]  # empty in state-only mode
    image_format: str = "HWC uint8 RGB"
    frame: str = "table frame: origin at the table-top centre, +x away from the robot, +y left, +z up"


class EpisodeInfo(_Model):
    """What a policy is told at the start of an episode (also sent to remote policies, with
    ``episode_id``)."""

    schema_version: str = SCHEMA_VERSION
    key: EpisodeKey  # where the episode sits in the run; its embodiment is the one that runs
    policy_seed: int  # seed the policy's own randomness with this
    instruction: str
    control_rate: float  # Hz
    max_steps: int
    action: ActionSchema
    observation: ObservationSchema

    @computed_field  # type: ignore[prop-decorator]
    @property
    def episode_id(self) -> str:
        return self.key.episode_id


@runtime_checkable
class Policy(Protocol):
    def reset(self, episode: EpisodeInfo) -> None: ...

    def act(self, observation: dict[str, Any]) -> np.ndarray: ...


__all__ = ["ActionSchema", "CameraSchema", "EpisodeInfo", "ObservationSchema", "Policy"]
