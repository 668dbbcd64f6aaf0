"""The Ray backend: the same episode workers as Ray actors (``--backend ray``).

``ray`` is imported only here, when this backend starts, so it stays an optional
dependency (``pip install 'ray>=2.9'``). Without ``--ray-address`` a local Ray instance is
started with one CPU per worker and shut down at the end; with an address the actors are
placed on that cluster, whose nodes need fsvla installed and the run's scenario paths
readable (built-in scenario names always are). Each actor runs an
:class:`~fsvla.runner.worker.EpisodeWorker`; outcomes come back to the run loop, which alone
writes the store, exactly as with the process pool.

A Ray actor runs its calls in its process's main thread, so the policy timeout is the
same alarm as in a worker process. There is no hard kill here: a call stuck in C code
ignoring signals holds its actor.

**Lost workers.** An actor can be lost with its episode: its node died or was removed,
its process crashed. Ray then fails the call (``RayActorError`` and its kinds,
``WorkerCrashedError``, ``NodeDiedError``, ``ObjectLostError``) and no outcome reaches
the driver, so nothing of that attempt is in the run folder. The episode is handed out
again, first in line, up to ``max_retries`` times (each time in :attr:`RayBackend.reruns`);
lost once more, it is recorded as ``sim_error`` with every loss in its detail. The lost
actor is replaced; the replacement gets episodes once it has started, wherever Ray can
place it, and a replacement that cannot be placed (the cluster shrank) leaves the run to
the other actors. When no actor is left and none could be placed in
``placement_timeout_s``, the run stops with :class:`BackendError` (run again to resume).
"""

from __future__ import annotations

import os
import sys
import time
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Any

from fsvla.results.models import EpisodeOutcome
from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.backend import BackendError, Finished, Rerun
from fsvla.runner.worker import EpisodeWorker

INSTALL_HINT = "pip install 'ray>=2.9'"

#: Times an episode whose worker was lost is handed out again (see the module doc).
MAX_RETRIES = 2
#: Seconds the run waits for a replacement actor when no other is left.
PLACEMENT_TIMEOUT_S = 600.0
#: The Ray errors that say the worker was lost, not that the episode failed.
LOST_ERRORS = ("RayActorError", "WorkerCrashedError", "NodeDiedError", "ObjectLostError")


class RayEpisodeWorker:
    """The actor class (wrapped by ``ray.remote`` when the backend starts)."""

    def __init__(self, config_json: str, cwd: str, path: list[str]) -> None:
        if os.path.isdir(cwd):  # a local cluster: resolve relative scenario paths as the driver does
            os.chdir(cwd)
        sys.path.extend(p for p in path if p not in sys.path)
        self.worker = EpisodeWorker(RunConfig.model_validate_json(config_json))

    def ready(self) -> tuple:
        from fsvla.policies import PolicyLoadError
        from fsvla.runner.episode import describe

        try:
            self.worker.start()
        except PolicyLoadError as err:
            return ("error", "policy", str(err))
        except Exception as err:  # noqa: BLE001 - reported to the run loop
            return ("error", "start", describe(err))
        return ("ready", os.getpid())

    def run(self, spec: EpisodeSpec) -> EpisodeOutcome:
        return self.worker.run(spec)


class RayBackend:
    """Episodes on ``workers`` Ray actors (see the module doc)."""

    name = "ray"

    def __init__(self, config: RunConfig, workers: int, address: str | None = None, *,
                 max_retries: int = MAX_RETRIES,
                 placement_timeout_s: float = PLACEMENT_TIMEOUT_S) -> None:
        if max_retries < 0:
            raise ValueError(f"Expect `max_retries` to be >= 0, actually: {max_retries}")
        if placement_timeout_s <= 0:
            raise ValueError("Expect `placement_timeout_s` to be positive, actually: "
                             f"{placement_timeout_s}")
        self.config = config
        self.size = workers
        self.address = address
        self.max_retries = max_retries
        self.placement_timeout_s = placement_timeout_s
        self.reruns: list[Rerun] = []
        self._ray: Any = None
        self._actor_class: Any = None
        self._actors: list[Any] = []
        self._started_ray = False
        self._lost: tuple[type[BaseException], ...] = ()

    def start(self) -> None:
        try:
            import ray
        except ImportError:
            raise BackendError(f"--backend ray needs the ray package ({INSTALL_HINT})") from None
        self._ray = ray
        if not ray.is_initialized():
            options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                                       "logging_level": "warning"}
            if self.address is None:
                options["num_cpus"] = self.size
            try:
                ray.init(address=self.address, **options)
            except Exception as err:  # noqa: BLE001 - no cluster at the address, ...
                raise BackendError(f"--ray-address {self.address}: cannot connect to Ray: {err}"
                                   if self.address else f"cannot start a local Ray instance: "
                                   f"{err}") from None
            self._started_ray = True
        self._actor_class = ray.remote(num_cpus=1)(RayEpisodeWorker)
        self._lost = tuple(getattr(ray.exceptions, name) for name in LOST_ERRORS
                           if hasattr(ray.exceptions, name))
        try:
            self._actors = [self._new_actor() for _ in range(self.size)]
            try:
                answers = ray.get([actor.ready.remote() for actor in self._actors])
            except ray.exceptions.RayError as err:  # a node died, an actor crashed, ...
                raise BackendError(f"a Ray worker was lost while starting: {_why(err)}; run "
                                   "the same command again") from None
            for answer in answers:
                self._check_ready(answer)
        except BaseException:
            self.close()
            raise

    def run(self, specs: Iterable[EpisodeSpec]) -> Iterator[Finished]:
        pending = deque(specs)
        run = _Run(idle=list(range(len(self._actors))))
        while pending or run.flight:
            while run.idle and pending:
                index = run.idle.pop()
                spec = pending.popleft()
                ref = self._actors[index].run.remote(spec)
                run.flight[ref] = _Flight(index, spec, datetime.now(timezone.utc),
                                          time.perf_counter())
            for ref in self._wait(run):
                if ref in run.starting:
                    self._started(run, run.starting.pop(ref), ref)
                    continue
                flight = run.flight.pop(ref)
                outcome = self._outcome(run, flight, ref)
                if outcome is None:  # lost: handed out again
                    pending.appendleft(flight.spec)
                    continue
                run.idle.append(flight.index)
                yield flight.spec, outcome

    def close(self) -> None:
        ray = self._ray
        if ray is None:
            return
        for actor in self._actors:
            try:
                ray.kill(actor)
            except Exception:  # noqa: BLE001, S110 - already gone
                pass
        self._actors = []
        if self._started_ray:
            ray.shutdown()
            self._started_ray = False

    def _new_actor(self) -> Any:
        return self._actor_class.remote(self.config.model_dump_json(), os.getcwd(),
                                        [p for p in sys.path if p])

    def _check_ready(self, answer: tuple, *, replacement: bool = False) -> None:
        if answer[0] == "ready":
            return
        _, kind, text = answer
        if kind == "policy" and not replacement:
            from fsvla.policies import PolicyLoadError

            raise PolicyLoadError(text)
        raise BackendError(f"a{' replacement' if replacement else ''} Ray worker failed to "
                           f"start: {text}")

    def _wait(self, run: _Run) -> list[Any]:
        """The calls that finished: episodes, or replacements that started. Raises
        :class:`BackendError` when no actor is left and none is placed in time."""
        refs = list(run.flight) + list(run.starting)
        if not refs:
            raise BackendError("every Ray worker was lost and none could be started again; "
                               "run the same command to resume")
        timeout = None if run.flight else self.placement_timeout_s
        done, _ = self._ray.wait(refs, num_returns=1, timeout=timeout)
        if not done:
            raise BackendError(f"every Ray worker was lost and no replacement was placed in "
                               f"{self.placement_timeout_s:.0f} s (does the cluster have a free "
                               "CPU?); run the same command to resume")
        return done

    def _outcome(self, run: _Run, flight: _Flight, ref: Any) -> EpisodeOutcome | None:
        """The episode's outcome; None when its actor was lost and it is to run again."""
        try:
            return self._ray.get(ref)
        except self._lost as err:
            why = _why(err)
        except self._ray.exceptions.RayError as err:
            return _lost(f"Ray failed the episode: {_why(err)}", flight.started, flight.since)
        self._replace(run, flight.index)
        losses = run.losses.setdefault(flight.spec.episode_id, [])
        losses.append(why)
        if len(losses) <= self.max_retries:
            self.reruns.append(Rerun(flight.spec.episode_id, len(losses), why))
            return None
        told = "; ".join(f"attempt {n}: {text}" for n, text in enumerate(losses, start=1))
        return _lost(f"the Ray worker running the episode was lost {len(losses)} times, with "
                     f"the steps it had run ({told})", flight.started, flight.since)

    def _replace(self, run: _Run, index: int) -> None:
        """Start a new actor in slot ``index`` in place of a lost one."""
        try:
            self._ray.kill(self._actors[index])
        except Exception:  # noqa: BLE001, S110 - already gone
            pass
        self._actors[index] = self._new_actor()
        run.starting[self._actors[index].ready.remote()] = index

    def _started(self, run: _Run, index: int, ref: Any) -> None:
        """A replacement answered, or was lost in turn: then it is replaced again, up to
        ``max_retries`` times in a row, after which its slot stays empty."""
        try:
            answer = self._ray.get(ref)
        except self._lost:
            run.failed_starts[index] = run.failed_starts.get(index, 0) + 1
            if run.failed_starts[index] <= self.max_retries:
                self._replace(run, index)
            return
        self._check_ready(answer, replacement=True)
        run.failed_starts.pop(index, None)
        run.idle.append(index)


@dataclass
class _Flight:
    """An episode in flight: its actor's slot, the spec, when it was handed out."""

    index: int
    spec: EpisodeSpec
    started: datetime
    since: float


@dataclass
class _Run:
    """The state of one :meth:`RayBackend.run`: slots idle, episodes in flight, replacement
    actors starting, and the losses of each episode and each slot."""

    idle: list[int]
    flight: dict[Any, _Flight] = field(default_factory=dict)
    starting: dict[Any, int] = field(default_factory=dict)  # ready() call -> slot
    losses: dict[str, list[str]] = field(default_factory=dict)  # episode id -> why, per loss
    failed_starts: dict[int, int] = field(default_factory=dict)  # slot -> replacements lost


def _why(err: BaseException) -> str:
    """One line for a Ray error: its kind and the first line of its message."""
    lines = str(err).strip().splitlines()
    text = f"{type(err).__name__}: {lines[0] if lines else ''}".strip()
    return text if len(text) <= 300 else text[:297] + "..."


def _lost(detail: str, started: datetime, since: float) -> EpisodeOutcome:
    return EpisodeOutcome(failure_reason="sim_error", failure_detail=detail, started_at=started,
                          finished_at=datetime.now(timezone.utc),
                          wall_time_s=time.perf_counter() - since)


__all__ = ["INSTALL_HINT", "LOST_ERRORS", "MAX_RETRIES", "PLACEMENT_TIMEOUT_S", "RayBackend",
           "RayEpisodeWorker"]
