"""What the environment shows a policy: proprioception, the instruction, camera images.

An observation is a dict:

- ``"agent"``: ``"qpos"`` — every arm's joint positions, arms in the embodiment's order
  (the same order and units as a ``joint_pos`` action without its gripper entries);
  ``"gripper"`` — each arm's gripper opening in [0, 1] (0 closed, 1 open);
  ``"tcp_pose"`` — each arm's tool centre point in the world (table) frame as
  ``[x, y, z, qw, qx, qy, qz]`` (quaternion scalar first), concatenated per arm.
- ``"instruction"``: the task instruction as a string.
- ``"images"`` (``obs_mode="rgb"`` only): one ``H × W × 3`` ``uint8`` RGB array per camera,
  keyed by camera name (the head/front view and one per wrist); a
  :class:`~fsvla.env.frames.LazyImages` that renders them when they are first read.
"""

from __future__ import annotations

import string
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from fsvla.compiler.scene import SceneCamera
from fsvla.sim.robot import LoadedRobot

#: Characters an instruction may contain (gymnasium's Text space needs a finite charset).
INSTRUCTION_CHARSET = frozenset(string.printable) | frozenset("äöüßéèàçñ’‘“”–—…°")
INSTRUCTION_MAX_LENGTH = 1024
#: Slack (rad or m) on joint limits in the observation space: drives overshoot a little.
JOINT_SLACK = 0.05
#: Bound (m) of tool positions in the observation space, table frame.
TCP_BOUND = 3.0


def observation_space(joint_low: Sequence[float], joint_high: Sequence[float], arms: int,
                      cameras: Sequence[SceneCamera], with_images: bool) -> Any:
    """The gymnasium Dict space of observations. ``joint_low``/``joint_high`` bound every
    arm joint (arms in order; widened by :data:`JOINT_SLACK` for the drives' overshoot)."""
    from gymnasium import spaces

    low = np.asarray(joint_low, dtype=np.float32) - JOINT_SLACK
    high = np.asarray(joint_high, dtype=np.float32) + JOINT_SLACK
    pose_low = np.tile(np.array([-TCP_BOUND] * 3 + [-1.0] * 4, dtype=np.float32), arms)
    agent = spaces.Dict({
        "qpos": spaces.Box(low, high, dtype=np.float32),
        "gripper": spaces.Box(0.0, 1.0, shape=(arms,), dtype=np.float32),
        "tcp_pose": spaces.Box(pose_low, -pose_low, dtype=np.float32),
    })
    parts: dict[str, Any] = {
        "agent": agent,
        "instruction": spaces.Text(max_length=INSTRUCTION_MAX_LENGTH, min_length=0,
                                   charset=INSTRUCTION_CHARSET),
    }
    if with_images:
        parts["images"] = spaces.Dict({
            c.name: spaces.Box(0, 255, shape=(c.height, c.width, 3), dtype=np.uint8)
            for c in cameras
        })
    return spaces.Dict(parts)


def check_instruction(text: str) -> str:
    """``text`` if the observation space can hold it, else a ValueError naming the problem."""
    bad = sorted({c for c in text if c not in INSTRUCTION_CHARSET})
    if bad:
        raise ValueError(f"instruction {text!r} has characters the observation space does not "
                         f"allow: {''.join(bad)!r}")
    if len(text) > INSTRUCTION_MAX_LENGTH:
        raise ValueError(f"instruction is {len(text)} characters, more than "
                         f"{INSTRUCTION_MAX_LENGTH}")
    return text


def proprioception(robot: LoadedRobot) -> dict[str, np.ndarray]:
    """The ``"agent"`` part of an observation."""
    qpos, gripper, tcp = [], [], []
    for arm in robot.arms.values():
        qpos.append(arm.qpos())
        gripper.append(arm.gripper_opening())
        pose = arm.tcp_pose()
        tcp.append(np.concatenate([np.asarray(pose.p), np.asarray(pose.q)]))
    return {
        "qpos": np.concatenate(qpos).astype(np.float32),
        "gripper": np.asarray(gripper, dtype=np.float32),
        "tcp_pose": np.concatenate(tcp).astype(np.float32),
    }


def assemble(agent: Mapping[str, np.ndarray], instruction: str,
             images: Mapping[str, np.ndarray] | None) -> dict[str, Any]:
    obs: dict[str, Any] = {"agent": dict(agent), "instruction": instruction}
    if images is not None:  # a dict (LazyImages: rendered when read) is kept as it is
        obs["images"] = images if isinstance(images, dict) else dict(images)
    return obs


__all__ = ["INSTRUCTION_CHARSET", "assemble", "check_instruction", "observation_space",
           "proprioception"]
