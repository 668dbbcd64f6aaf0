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
ignoring signals holds its actor. An actor that dies has its episode recorded as
``sim_error`` and is started again.
"""

from __future__ import annotations

import os
import sys
import time
from collections import deque
from collections.abc import Iterable, Iterator
from datetime import datetime, timezone
from typing import Any

from fsvla.results.models import EpisodeOutcome
from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.backend import BackendError, Finished
from fsvla.runner.worker import EpisodeWorker

INSTALL_HINT = "pip install 'ray>=2.9'"


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

    def __init__(self, config: RunConfig, workers: int, address: str | None = None) -> None:
        self.config = config
        self.size = workers
        self.address = address
        self._ray: Any = None
        self._actor_class: Any = None
        self._actors: list[Any] = []
        self._started_ray = False

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
        try:
            self._actors = [self._new_actor() for _ in range(self.size)]
            for answer in ray.get([actor.ready.remote() for actor in self._actors]):
                self._check_ready(answer)
        except BaseException:
            self.close()
            raise

    def run(self, specs: Iterable[EpisodeSpec]) -> Iterator[Finished]:
        ray = self._ray
        pending = deque(specs)
        idle = list(range(len(self._actors)))
        flight: dict[Any, tuple[int, EpisodeSpec, datetime, float]] = {}
        while pending or flight:
            while idle and pending:
                index = idle.pop()
                spec = pending.popleft()
                ref = self._actors[index].run.remote(spec)
                flight[ref] = (index, spec, datetime.now(timezone.utc), time.perf_counter())
            done, _ = ray.wait(list(flight), num_returns=1)
            for ref in done:
                index, spec, started, since = flight.pop(ref)
                try:
                    outcome = ray.get(ref)
                except ray.exceptions.RayActorError as err:
                    outcome = _lost(f"the Ray actor died while running the episode ({err}); "
                                    "the steps it ran are lost", started, since)
                    self._actors[index] = self._new_actor()
                except ray.exceptions.RayError as err:
                    outcome = _lost(f"Ray failed the episode: {err}", started, since)
                idle.append(index)
                yield spec, outcome

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

    def _check_ready(self, answer: tuple) -> None:
        if answer[0] == "ready":
            return
        _, kind, text = answer
        if kind == "policy":
            from fsvla.policies import PolicyLoadError

            raise PolicyLoadError(text)
        raise BackendError(f"a Ray worker failed to start: {text}")


def _lost(detail: str, started: datetime, since: float) -> EpisodeOutcome:
    return EpisodeOutcome(failure_reason="sim_error", failure_detail=detail, started_at=started,
                          finished_at=datetime.now(timezone.utc),
                          wall_time_s=time.perf_counter() - since)


__all__ = ["INSTALL_HINT", "RayBackend", "RayEpisodeWorker"]
