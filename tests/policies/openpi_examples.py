"""In-process policy servers speaking openpi's websocket protocol, as a server of one of
openpi's example checkpoints (DROID, LIBERO, ALOHA) would.

The transport follows openpi's ``WebsocketPolicyServer``: on connect, the metadata (a
msgpack map); then, per request, the msgpack-numpy observation in and the reply map
(``actions`` and ``server_timing``) out; when the policy raises, the traceback as a text
frame and a close with code 1011. Each "checkpoint" checks a request as openpi's input
transforms would read it: a KeyError unless it holds exactly the example client's keys,
then the shapes and dtypes those clients send; it answers with a chunk in the
checkpoint's action space.
"""

from __future__ import annotations

import threading
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, ClassVar

import numpy as np
from openpi_client import msgpack_numpy
from websockets.sync.server import serve

IMAGE_HWC = ((224, 224, 3), np.uint8)
IMAGE_CHW = ((3, 224, 224), np.uint8)


def exact_keys(request: dict[str, Any], expected: set[str], where: str = "request") -> None:
    missing, extra = sorted(expected - set(request)), sorted(set(request) - expected)
    if missing or extra:
        raise KeyError(f"{where}: missing {missing}, unexpected {extra}")


def expect(value: Any, shape: tuple[int, ...], dtype: Any, name: str) -> np.ndarray:
    array = np.asarray(value)
    if array.shape != shape or array.dtype != np.dtype(dtype):
        raise ValueError(f"{name}: expected {np.dtype(dtype)} {shape}, got {array.dtype} "
                         f"{array.shape}")
    return array


class Droid:
    """pi0-FAST-DROID's input keys; answers 10 rows of 7 normalised joint velocities and a
    gripper position (0 open, 1 closed)."""

    KEYS: ClassVar[set[str]] = {"observation/exterior_image_1_left", "observation/wrist_image_left",
            "observation/joint_position", "observation/gripper_position", "prompt"}

    def __init__(self, velocity: tuple[float, ...] = (0.1, -0.1, 0, 0, 0, 0, 0)) -> None:
        self.velocity = velocity

    def infer(self, obs: dict[str, Any]) -> dict[str, Any]:
        exact_keys(obs, self.KEYS)
        expect(obs["observation/exterior_image_1_left"], *IMAGE_HWC, "exterior image")
        expect(obs["observation/wrist_image_left"], *IMAGE_HWC, "wrist image")
        expect(obs["observation/joint_position"], (7,), np.float64, "joint_position")
        gripper = expect(obs["observation/gripper_position"], (1,), np.float64, "gripper")
        assert 0.0 <= gripper[0] <= 1.0 and isinstance(obs["prompt"], str)
        return {"actions": np.tile([*self.velocity, 0.2], (10, 1))}  # 0.2: stays open


class Libero:
    """pi0-LIBERO's input keys; answers 10 rows of an end-effector delta in [-1, 1] and a
    gripper command (-1 open, +1 close)."""

    KEYS: ClassVar[set[str]] = {"observation/image", "observation/wrist_image", "observation/state", "prompt"}

    def __init__(self, delta: tuple[float, ...] = (0, 0, 0.2, 0, 0, 0)) -> None:
        self.delta = delta

    def infer(self, obs: dict[str, Any]) -> dict[str, Any]:
        exact_keys(obs, self.KEYS)
        expect(obs["observation/image"], *IMAGE_HWC, "image")
        expect(obs["observation/wrist_image"], *IMAGE_HWC, "wrist image")
        state = expect(obs["observation/state"], (8,), np.float64, "state")
        assert state[6] >= 0.0 >= state[7] and isinstance(obs["prompt"], str)  # the fingers
        return {"actions": np.tile([*self.delta, -1.0], (10, 1))}


class Aloha:
    """pi0-ALOHA's input keys (no prompt: the server has a default one); answers 50 rows
    of absolute joints and gripper openings per arm: the first state it saw, with
    ``offset`` added to every arm's first joint."""

    CAMERAS: ClassVar[set[str]] = {"cam_high", "cam_low", "cam_left_wrist", "cam_right_wrist"}

    def __init__(self, arms: int = 2, joints: int = 7, offset: float = 0.2) -> None:
        self.width = arms * (joints + 1)
        self.joints = joints
        self.offset = offset
        self.start: np.ndarray | None = None

    def infer(self, obs: dict[str, Any]) -> dict[str, Any]:
        exact_keys(obs, {"state", "images"})
        images = obs["images"]
        if "cam_high" not in images or set(images) - self.CAMERAS:
            raise ValueError(f"images must hold cam_high and only {sorted(self.CAMERAS)}, "
                             f"got {sorted(images)}")
        for name, image in images.items():
            expect(image, *IMAGE_CHW, name)
        state = expect(obs["state"], (self.width,), np.float64, "state")
        if self.start is None:
            self.start = state.copy()
        target = self.start.copy()
        target[::self.joints + 1] += self.offset
        return {"actions": np.tile(target, (50, 1))}


#: A user's profile file: state only, joint deltas.
JOINT_DELTA_PROFILE = """\
description = "a server that reads joints and gripper under one key, and answers joint deltas"
replan_steps = 4

[observation]
prompt = "task"

[[observation.state]]
key = "qpos"
parts = ["joints", "gripper"]

[action]
control_mode = "joint_delta"
scale = 0.01
"""


class JointDelta:
    """A server for JOINT_DELTA_PROFILE (a user's profile file): accepts exactly its keys;
    answers 4 rows of +1 (× 0.01 rad) on the first joint."""

    def infer(self, obs: dict[str, Any]) -> dict[str, Any]:
        exact_keys(obs, {"qpos", "task"})
        expect(obs["qpos"], (8,), np.float32, "qpos")
        return {"actions": np.tile([1.0, 0, 0, 0, 0, 0, 0, 1.0], (4, 1))}


class OpenpiServer:
    """Serves one checkpoint; keeps every request, and every error it reported."""

    def __init__(self, policy: Any) -> None:
        self.policy = policy
        self.requests: list[dict[str, Any]] = []
        self.errors: list[str] = []

    def handle(self, connection: Any) -> None:
        connection.send(msgpack_numpy.packb({"example": type(self.policy).__name__}))
        for message in connection:
            request = msgpack_numpy.unpackb(message)
            self.requests.append(request)
            try:
                reply = self.policy.infer(request)
            except Exception:  # noqa: BLE001 - reported to the client, as openpi's server does
                self.errors.append(traceback.format_exc())
                connection.send(self.errors[-1])
                connection.close(code=1011, reason="Internal server error. Traceback included "
                                                   "in previous frame.")
                return
            reply["server_timing"] = {"infer_ms": 0.0}
            connection.send(msgpack_numpy.packb(reply))


@contextmanager
def serving(policy: Any) -> Iterator[tuple[OpenpiServer, str]]:
    """``policy`` served on 127.0.0.1 (a free port): the server and its ws:// address."""
    server = OpenpiServer(policy)
    with serve(server.handle, "127.0.0.1", 0, compression=None, max_size=None) as running:
        thread = threading.Thread(target=running.serve_forever, daemon=True)
        thread.start()
        try:
            yield server, f"ws://127.0.0.1:{running.socket.getsockname()[1]}"
        finally:
            running.shutdown()
