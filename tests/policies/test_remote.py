"""The remote policy against a small openpi-protocol server built here."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest

pytest.importorskip("openpi_client")
from fsvla.policies import load_policy  # noqa: E402
from fsvla.policies.remote import ConnectionLost, PolicyTimeout, RemotePolicy  # noqa: E402
from openpi_client import msgpack_numpy  # noqa: E402
from websockets.sync.server import serve  # noqa: E402

from .test_policies import _episode  # noqa: E402

OBS = {"agent": {"qpos": np.array([0.1, 0.2, 0.3]), "gripper": np.array([1.0, 0.5]),
                 "tcp_pose": np.zeros(14)},
       "instruction": "lift the pot", "images": {"front": np.zeros((4, 6, 3), np.uint8)}}


class Server:
    """Answers each observation with a chunk of 4 copies of its state; records requests."""

    def __init__(self, behaviour: str = "echo") -> None:
        self.behaviour = behaviour
        self.requests: list[dict] = []

    def handle(self, connection) -> None:  # noqa: ANN001
        connection.send(msgpack_numpy.packb({"policy": "echo"}))
        for message in connection:
            request = msgpack_numpy.unpackb(message)
            self.requests.append(request)
            if self.behaviour == "hang":
                time.sleep(2.0)
                continue
            if self.behaviour == "drop":
                connection.close()
                return
            chunk = np.tile(request["state"], (4, 1))
            connection.send(msgpack_numpy.packb({"actions": chunk}))


@pytest.fixture
def server(request) -> Iterator[tuple[Server, str]]:
    behaviour = getattr(request, "param", "echo")
    handler = Server(behaviour)
    with serve(handler.handle, "127.0.0.1", 0, compression=None, max_size=None) as running:
        port = running.socket.getsockname()[1]
        thread = threading.Thread(target=running.serve_forever, daemon=True)
        thread.start()
        yield handler, f"ws://127.0.0.1:{port}"
        running.shutdown()


def test_chunks_come_back_and_the_schema_goes_out_once(server) -> None:
    handler, uri = server
    policy = load_policy(uri)
    assert isinstance(policy, RemotePolicy)
    policy.reset(_episode())
    chunk = policy.act(OBS)
    policy.act(OBS)
    assert chunk.shape == (4, 5)
    assert chunk[0].tolist() == pytest.approx([0.1, 0.2, 0.3, 1.0, 0.5])
    first, second = handler.requests
    assert first["prompt"] == "lift the pot" and first["images"]["front"].shape == (4, 6, 3)
    episode = json.loads(first["fsvla/episode"])
    assert episode["action"]["quaternion_order"] == "wxyz"
    assert episode["schema_version"] == "2.0" and episode["episode_id"] == "s-L0-W0-V0-s0-e000"
    assert episode["key"] == {"scenario": "s", "suite": "force", "embodiment": "dual_panda",
                              "level": "L0", "language": "W0", "vision": "V0", "seed": 0,
                              "index": 0, "warmup": False}
    assert "fsvla/episode" not in second
    assert policy.server_metadata == {"policy": "echo"}
    policy.close()


@pytest.mark.parametrize("server", ["hang"], indirect=True)
def test_a_silent_server_times_out(server) -> None:
    _, uri = server
    policy = RemotePolicy(uri, reply_timeout=0.3)
    policy.reset(_episode())
    with pytest.raises(PolicyTimeout, match="no reply within 0.3 s"):
        policy.act(OBS)
    policy.close()


@pytest.mark.parametrize("server", ["drop"], indirect=True)
def test_a_dropped_connection_is_reported(server) -> None:
    _, uri = server
    policy = RemotePolicy(uri, reply_timeout=5.0)
    policy.reset(_episode())
    with pytest.raises(ConnectionLost, match="connection lost"):
        policy.act(OBS)


def test_an_unreachable_server_is_reported() -> None:
    policy = RemotePolicy("ws://127.0.0.1:9", connect_timeout=2.0)
    with pytest.raises(ConnectionLost, match="cannot connect"):
        policy.reset(_episode())
