"""Where episodes run: the seam between the run loop and the processes that play episodes.

A backend is started (which loads the policy wherever it will run, so a bad ``--policy``
is reported before anything is written), then handed the pending episodes and yields
``(spec, outcome)`` pairs as episodes finish, in any order, with at most one episode in
flight per worker; then closed. Only the run loop's process writes the store.

* ``in-process`` (``--workers 0``): in the calling process, one episode at a time.
* ``process`` (``--workers N``, the default): N spawned worker processes
  (:mod:`fsvla.runner.pool`).
* ``ray`` (``--backend ray``): N Ray actors, locally or on a cluster
  (:mod:`fsvla.runner.ray_backend`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Protocol

from fsvla.results.models import EpisodeOutcome
from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.worker import EpisodeWorker

BACKENDS = ("process", "ray")

Finished = tuple[EpisodeSpec, EpisodeOutcome]


class BackendError(RuntimeError):
    """A backend that cannot start or keep its workers (not an episode's fault)."""


@dataclass(frozen=True)
class Rerun:
    """An episode handed out again because the worker playing it was lost (a node that
    died, a crashed actor): nothing of the lost attempt reached the run folder."""

    episode_id: str
    attempt: int  # the attempt that was lost: 1 for the first
    reason: str  # why, e.g. "ActorDiedError: ..."


class Backend(Protocol):
    name: str
    reruns: list[Rerun]  # episodes handed out again this session (the Ray backend's only)

    def start(self) -> None: ...

    def run(self, specs: Iterable[EpisodeSpec]) -> Iterator[Finished]: ...

    def close(self) -> None: ...


class InProcessBackend:
    """Episodes in the calling process, one at a time (``--workers 0``)."""

    name = "in-process"

    def __init__(self, config: RunConfig) -> None:
        self.worker = EpisodeWorker(config)
        self.size = 1
        self.reruns: list[Rerun] = []

    def start(self) -> None:
        self.worker.start()

    def run(self, specs: Iterable[EpisodeSpec]) -> Iterator[Finished]:
        for spec in specs:
            yield spec, self.worker.run(spec)

    def close(self) -> None:
        self.worker.close()


def make_backend(kind: str, config: RunConfig, workers: int,
                 ray_address: str | None = None) -> Backend:
    """The backend ``--backend kind --workers N`` names (``process`` with 0 workers runs
    in this process)."""
    if kind == "process":
        if workers == 0:
            return InProcessBackend(config)
        from fsvla.runner.pool import ProcessBackend

        return ProcessBackend(config, workers)
    if kind == "ray":
        from fsvla.runner.ray_backend import RayBackend

        return RayBackend(config, max(1, workers), address=ray_address)
    raise ValueError(f"Expect `kind` to be one of {', '.join(BACKENDS)}, actually: {kind!r}")


__all__ = ["BACKENDS", "Backend", "BackendError", "Finished", "InProcessBackend", "Rerun",
           "make_backend"]
