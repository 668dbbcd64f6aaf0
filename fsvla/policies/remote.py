"""A policy served over the openpi websocket protocol (pi0, pi0.5, any VLA wrapped alike).

The protocol is openpi's: on connect the server sends its metadata (a msgpack map); then
each request is one msgpack-numpy-encoded observation map and each reply a map holding
``"actions"``, an ``(H, A)`` chunk (or one ``(A,)`` action). Encoding goes through the
``openpi-client`` package, the transport through ``websockets`` (its dependency), so
that every receive can carry a timeout.

What fsvla sends, per request::

    {"images": {camera: H×W×3 uint8}, "state": float32 [qpos..., grippers...],
     "tcp_pose": float32, "prompt": instruction,
     "fsvla/episode": EpisodeInfo as JSON}     # on the first request of an episode only

The episode message states the whole observation/action schema (camera names, state and
action layout, quaternion order, gripper range), so a server can check it is talking
to the embodiment it was trained for.

That is the ``fsvla`` profile. With another profile (``droid``, ``libero``, ``aloha`` or a
user's TOML file; :mod:`fsvla.policies.profile`) the request holds exactly the keys of
that profile's example client and each reply's actions are decoded from its action
space (:mod:`fsvla.policies.adapter`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .adapter import ProfileAdapter
from .base import EpisodeInfo
from .profile import Profile

CONNECT_TIMEOUT = 30.0  # s
REPLY_TIMEOUT = 120.0  # s: generous, a large VLA on a busy GPU is slow


class PolicyTimeout(RuntimeError):
    """The server did not answer within the timeout."""


class ConnectionLost(RuntimeError):
    """The server could not be reached, or closed the connection."""


class RemotePolicy:
    """A client of one openpi-protocol policy server at ``ws://host:port``, speaking
    ``profile`` (None: fsvla's own request)."""

    def __init__(self, uri: str, *, profile: Profile | None = None,
                 reply_timeout: float = REPLY_TIMEOUT,
                 connect_timeout: float = CONNECT_TIMEOUT) -> None:
        self.uri = uri
        self.name = uri
        self.profile = profile
        self._adapter: ProfileAdapter | None = None
        self.reply_timeout = reply_timeout
        self.connect_timeout = connect_timeout
        self.server_metadata: dict[str, Any] = {}
        self._connection: Any = None
        self._episode: EpisodeInfo | None = None
        self._first = True

    def reset(self, episode: EpisodeInfo) -> None:
        profile = self.profile  # a profile that cannot serve the episode fails before connecting
        self._adapter = (ProfileAdapter(profile, episode)
                         if profile is not None and not profile.native else None)
        if self._connection is None:
            self._connect()
        self._episode = episode
        self._first = True

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        from openpi_client import msgpack_numpy
        from websockets.exceptions import ConnectionClosed

        adapter = self._adapter
        request = adapter.request(observation) if adapter else self._request(observation)
        try:
            self._connection.send(msgpack_numpy.packb(request))
            reply = self._connection.recv(timeout=self.reply_timeout)
        except TimeoutError as err:
            raise PolicyTimeout(f"{self.uri}: no reply within {self.reply_timeout:g} s") from err
        except (ConnectionClosed, OSError) as err:
            self._connection = None
            raise ConnectionLost(f"{self.uri}: connection lost: {err}") from err
        if isinstance(reply, str):
            raise RuntimeError(f"{self.uri}: the server reported an error: {reply}")
        answer = msgpack_numpy.unpackb(reply)
        if not isinstance(answer, dict) or "actions" not in answer:
            keys = ", ".join(map(str, answer)) if isinstance(answer, dict) else type(answer).__name__
            raise RuntimeError(f"{self.uri}: the reply has no 'actions' (got {keys})")
        actions = np.asarray(answer["actions"])
        return adapter.actions(actions, observation) if adapter else actions

    def close(self) -> None:
        if self._connection is not None:
            self._connection.close()
            self._connection = None

    def _connect(self) -> None:
        from openpi_client import msgpack_numpy
        from websockets.sync.client import connect

        try:
            # ``connect`` returns a context manager in recent websockets and a connection in
            # older ones; entering either gives the connection.
            self._connection = connect(self.uri, compression=None, max_size=None,
                                       open_timeout=self.connect_timeout,
                                       proxy=None).__enter__()
            self.server_metadata = msgpack_numpy.unpackb(
                self._connection.recv(timeout=self.connect_timeout))
        except TimeoutError as err:
            raise ConnectionLost(f"{self.uri}: the server sent no metadata within "
                                 f"{self.connect_timeout:g} s") from err
        except OSError as err:
            raise ConnectionLost(f"{self.uri}: cannot connect: {err}") from err

    def _request(self, observation: dict[str, Any]) -> dict[str, Any]:
        agent = observation["agent"]
        request: dict[str, Any] = {
            "state": np.concatenate([np.asarray(agent["qpos"], dtype=np.float32),
                                     np.asarray(agent["gripper"], dtype=np.float32)]),
            "tcp_pose": np.asarray(agent["tcp_pose"], dtype=np.float32),
            "prompt": observation["instruction"],
        }
        if "images" in observation:
            request["images"] = {k: np.asarray(v) for k, v in observation["images"].items()}
        if self._first and self._episode is not None:
            request["fsvla/episode"] = self._episode.model_dump_json()
            self._first = False
        return request


__all__ = ["ConnectionLost", "PolicyTimeout", "RemotePolicy"]
