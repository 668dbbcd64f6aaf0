"""A profile bound to one episode: fsvla's observation → the server's request, and the
server's chunk → fsvla actions (see :mod:`fsvla.policies.profile`).

Images go through ``openpi_client.image_tools`` (``resize_with_pad``, then
``convert_to_uint8``), the functions openpi's own example clients call, so a server sees
the pixels its checkpoint was trained on. Each row of a chunk is decoded per arm:
a driven arm's components are clipped and scaled and its gripper value mapped to an
opening in [0, 1]; an arm the profile does not drive holds still
(:func:`fsvla.policies.simple.hold_action`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import EpisodeInfo
from .profile import ImageInput, Profile, StatePart
from .simple import arm_block_sizes, hold_action


class ProfileMismatch(ValueError):
    """A profile that cannot serve this episode (its control mode, cameras or arms)."""


class ProfileAdapter:
    """``request(observation)`` and ``actions(chunk, observation)`` for one episode."""

    def __init__(self, profile: Profile, episode: EpisodeInfo) -> None:
        if profile.observation is None or profile.action is None:
            raise ValueError(f"profile {profile.name} is native: it maps nothing")
        self.profile = profile
        self.observation_map = profile.observation
        self.action_map = profile.action
        mode = episode.action.control_mode
        if mode != self.action_map.control_mode:
            raise ProfileMismatch(
                f"profile {profile.name} decodes {self.action_map.control_mode} actions, but "
                f"the episode runs {mode}: run with --control-mode "
                f"{self.action_map.control_mode}")
        self.mode = mode
        self.arms = episode.action.arms
        self.driven = self.arms[:1] if profile.arms == "first" else self.arms
        self.sizes = dict(zip(self.arms, arm_block_sizes(episode)))
        qpos_labels = episode.observation.state_layout.get("qpos", ())
        counts = [sum(1 for label in qpos_labels if label.startswith(f"{arm}."))
                  for arm in self.arms]
        ends = np.cumsum(counts)
        self._joints = {arm: slice(int(end - n), int(end))
                        for arm, n, end in zip(self.arms, counts, ends)}
        self._cameras = [self._camera(image, episode) for image in self.observation_map.images]
        for arm in self.driven:
            scale = self.action_map.scale
            if len(scale) not in (1, self.sizes[arm]):
                raise ProfileMismatch(
                    f"profile {profile.name}: `action.scale` has {len(scale)} factors; arm "
                    f"{arm} has {self.sizes[arm]} components in {mode} (give 1 or "
                    f"{self.sizes[arm]})")

    @property
    def width(self) -> int:
        """Columns of a server action: per driven arm, its components and a gripper."""
        return sum(self.sizes[arm] + 1 for arm in self.driven)

    # ------------------------------------------------------------------ observation
    def request(self, observation: dict[str, Any]) -> dict[str, Any]:
        """The server's request for ``observation`` (fsvla's observation dict)."""
        request: dict[str, Any] = {}
        if self.observation_map.prompt:
            request[self.observation_map.prompt] = observation["instruction"]
        for image, camera in zip(self.observation_map.images, self._cameras):
            if camera is not None:
                _put(request, image.under, image.key,
                     prepare_image(observation["images"][camera], image))
        agent = observation["agent"]
        for state in self.observation_map.state:
            values = [self._part(part, arm, agent) for arm in self.driven for part in state.parts]
            _put(request, state.under, state.key,
                 np.concatenate(values).astype(state.dtype))
        return request

    def _part(self, part: StatePart, arm: str, agent: dict[str, Any]) -> NDArray[np.float64]:
        index = self.arms.index(arm)
        pose = np.asarray(agent["tcp_pose"], dtype=np.float64)[7 * index:7 * index + 7]
        if part.part == "joints":
            return np.asarray(agent["qpos"], dtype=np.float64)[self._joints[arm]]
        if part.part == "gripper":
            closed, open_ = (np.asarray(v, dtype=np.float64) for v in part.gripper_values())
            return closed + float(agent["gripper"][index]) * (open_ - closed)
        if part.part == "tcp_position":
            return pose[:3]
        if part.part == "tcp_quaternion":
            return pose[3:]
        if part.part == "tcp_quaternion_xyzw":
            return pose[[4, 5, 6, 3]]
        return axis_angle(pose[3:])

    def _camera(self, image: ImageInput, episode: EpisodeInfo) -> str | None:
        """The fsvla camera that feeds ``image`` (None: an optional image left out)."""
        cameras = episode.observation.cameras
        if not cameras:
            raise ProfileMismatch(f"profile {self.profile.name} sends camera images "
                                  f"({image.key}); run with --obs-mode rgb")
        if image.camera == "world":
            found = [c.name for c in cameras if c.mount == "world"]
        elif image.camera == "wrist":
            arm = self.driven[image.arm] if image.arm < len(self.driven) else None
            found = [c.name for c in cameras if arm is not None and c.mount == arm]
        else:
            found = [c.name for c in cameras if c.name == image.camera]
        if found:
            return found[0]
        if image.optional:
            return None
        which = (f"a {image.camera} camera" + (f" on driven arm {image.arm}"
                                               if image.camera == "wrist" else "")
                 if image.camera in ("world", "wrist") else f"a camera {image.camera!r}")
        raise ProfileMismatch(
            f"profile {self.profile.name} sends {image.key} from {which}; the embodiment "
            f"{episode.key.embodiment} has {', '.join(f'{c.name} ({c.mount})' for c in cameras)}")

    # ------------------------------------------------------------------ actions
    def actions(self, answer: Any, observation: dict[str, Any]) -> NDArray[np.float64]:
        """The server's ``actions`` (a chunk ``(H, W)`` or one row) as fsvla actions
        ``(H, A)``; arms the profile does not drive hold where ``observation`` has them."""
        chunk = np.asarray(answer, dtype=np.float64)
        if chunk.ndim == 1:
            chunk = chunk[None, :]
        if chunk.ndim != 2 or chunk.shape[1] != self.width or chunk.shape[0] < 1:
            layout = " + ".join(f"{self.sizes[arm]} {self.mode} + 1 gripper ({arm})"
                                for arm in self.driven)
            raise ValueError(f"profile {self.profile.name}: the server's actions have shape "
                             f"{chunk.shape}; expected (H, {self.width}): {layout}")
        hold = np.split(hold_action(observation, self.mode, [self.sizes[a] for a in self.arms]),
                        np.cumsum([self.sizes[a] + 1 for a in self.arms])[:-1])
        rows = []
        for row in chunk:
            blocks, start = [], 0
            for arm, held in zip(self.arms, hold):
                if arm not in self.driven:
                    blocks.append(np.asarray(held, dtype=np.float64))
                    continue
                end = start + self.sizes[arm]
                blocks.append(np.append(self._arm(row[start:end]), self._opening(row[end])))
                start = end + 1
            rows.append(np.concatenate(blocks))
        return np.stack(rows)

    def _arm(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        clip = self.action_map.clip
        if clip is not None:
            values = np.clip(values, clip[0], clip[1])
        return values * np.asarray(self.action_map.scale, dtype=np.float64)

    def _opening(self, raw: float) -> float:
        """The server's gripper value as an opening in [0, 1] (a NaN stays NaN, for the
        environment to refuse)."""
        gripper = self.action_map.gripper
        closed, open_ = gripper.closed, gripper.open
        if gripper.binarize and math.isfinite(raw):
            raw = max(closed, open_) if raw > (closed + open_) / 2 else min(closed, open_)
        return float(np.clip((raw - closed) / (open_ - closed), 0.0, 1.0))


def prepare_image(image: Any, spec: ImageInput) -> np.ndarray:
    """An H × W × 3 uint8 camera image as ``spec`` sends it: resized with padding (as
    openpi's clients do), uint8 or float32 in [0, 1], HWC or CHW."""
    from openpi_client import image_tools

    height, width = spec.size
    pixels = image_tools.convert_to_uint8(
        image_tools.resize_with_pad(np.asarray(image), height, width))
    if spec.dtype == "float32":
        pixels = pixels.astype(np.float32) / 255.0
    if spec.layout == "CHW":
        pixels = np.transpose(pixels, (2, 0, 1))
    return np.ascontiguousarray(pixels)


def axis_angle(quaternion: Any) -> NDArray[np.float64]:
    """The axis-angle vector of a (w, x, y, z) quaternion as robosuite computes it (and
    LIBERO's state holds it): angle ``2·acos(w)`` in [0, 2π], no sign canonicalisation."""
    q = np.asarray(quaternion, dtype=np.float64)
    w = min(max(float(q[0]), -1.0), 1.0)
    den = math.sqrt(1.0 - w * w)
    if math.isclose(den, 0.0):
        return np.zeros(3)
    return q[1:] * 2.0 * math.acos(w) / den


def _put(request: dict[str, Any], under: str | None, key: str, value: Any) -> None:
    (request if under is None else request.setdefault(under, {}))[key] = value


__all__ = ["ProfileAdapter", "ProfileMismatch", "axis_angle", "prepare_image"]
