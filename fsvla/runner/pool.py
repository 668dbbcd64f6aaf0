"""The process backend: N spawned worker processes on this machine (``--workers N``).

Each worker process holds an :class:`~fsvla.runner.worker.EpisodeWorker` (its policy and
its loaded scenarios) and talks to the run loop over its own pipe: ``("ready", pid)``
once the policy is loaded (or ``("error", kind, text)``), then one ``("done", id,
outcome)`` per episode it is sent. The run loop keeps one episode in flight per worker,
so a crash or a kill loses at most those.

A worker sets a shared clock value while a policy call runs. The soft timeout (an alarm
inside the worker, :mod:`fsvla.runner.timeout`) ends most hanging calls with the steps
kept; a call that is still running :func:`hard_limit` seconds in (stuck in C code, signals
ignored) gets its worker killed and replaced, and its episode recorded as
``policy_timeout`` without steps. A worker that dies (a segfault in the simulator or the
policy) has its episode recorded as ``sim_error`` and is replaced.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from datetime import datetime, timezone
from multiprocessing.connection import Connection, wait
from typing import Any

from fsvla.results.models import EpisodeOutcome
from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.backend import BackendError, Finished, Rerun
from fsvla.runner.worker import EpisodeWorker

#: Seconds between looks at the workers' clocks while waiting for results.
POLL_S = 0.1
#: Seconds a worker gets to exit after being asked to.
EXIT_WAIT_S = 5.0


def hard_limit(timeout: float) -> float:
    """When a policy call that ignored the soft timeout gets its worker killed."""
    return timeout + max(1.0, 0.5 * timeout)


def render_threads(workers: int) -> int:
    """Threads each worker's software renderer may use: the cores shared out among the
    workers (Mesa's lavapipe otherwise starts one per core in every worker, and two
    workers rendering on two cores fight over four threads)."""
    return max(1, (os.cpu_count() or 1) // workers)


def serve(conn: Connection, config_json: str, clock: Any, threads: int | None = None) -> None:
    """A worker process's main function: load the policy, then play what it is sent.
    ``threads``: the software renderer's thread budget (``LP_NUM_THREADS``, unless the
    user set it), None to leave it alone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the run loop handles Ctrl-C
    if threads is not None:
        os.environ.setdefault("LP_NUM_THREADS", str(threads))  # before any Vulkan device
    try:
        from fsvla.policies import PolicyLoadError

        config = RunConfig.model_validate_json(config_json)

        def on_call(active: bool) -> None:
            clock.value = time.monotonic() if active else 0.0

        worker = EpisodeWorker(config, on_call=on_call)
        try:
            worker.start()
        except PolicyLoadError as err:
            conn.send(("error", "policy", str(err)))
            return
        conn.send(("ready", os.getpid()))
    except Exception as err:  # noqa: BLE001 - reported to the run loop
        from fsvla.runner.episode import describe

        conn.send(("error", "start", describe(err)))
        return
    try:
        while True:
            spec = conn.recv()
            if spec is None:
                break
            conn.send(("done", spec.episode_id, worker.run(spec)))
    except (EOFError, OSError):  # the run loop is gone: stop
        pass
    finally:
        worker.close()


@dataclass
class _Slot:
    """One worker process as the run loop sees it."""

    process: Any
    conn: Connection
    clock: Any
    state: str = "starting"  # starting, idle, busy
    spec: EpisodeSpec | None = None
    started: datetime = field(default_factory=lambda: datetime.now(timezone.utc))
    since: float = 0.0


class ProcessBackend:
    """Episodes in ``workers`` spawned processes (see the module doc)."""

    name = "process"

    def __init__(self, config: RunConfig, workers: int) -> None:
        if workers < 1:
            raise ValueError(f"Expect `workers` to be positive, actually: {workers}")
        self.config = config
        self.size = workers
        self._context = multiprocessing.get_context("spawn")
        self._slots: list[_Slot] = []
        self.replaced = 0  # workers killed or lost and started again
        self.reruns: list[Rerun] = []  # none: a lost worker costs its episode (sim_error)

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        """Start the workers and wait until each has loaded the policy; raises
        ``PolicyLoadError`` (a bad ``--policy``) or :class:`BackendError`."""
        self._slots = [self._spawn() for _ in range(self.size)]
        try:
            for slot in self._slots:
                self._await_ready(slot)
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Stop every worker: idle ones are asked to exit, busy ones are killed."""
        for slot in self._slots:
            if slot.state == "busy":
                slot.process.kill()
            else:
                try:
                    slot.conn.send(None)
                except OSError:
                    pass
        deadline = time.monotonic() + EXIT_WAIT_S
        for slot in self._slots:
            slot.process.join(max(0.0, deadline - time.monotonic()))
            if slot.process.is_alive():
                slot.process.kill()
                slot.process.join()
            slot.conn.close()
        self._slots = []

    # ------------------------------------------------------------------ the run
    def run(self, specs: Iterable[EpisodeSpec]) -> Iterator[Finished]:
        pending = deque(specs)
        while pending or any(s.state != "idle" for s in self._slots):
            self._hand_out(pending)
            active = [s for s in self._slots if s.state != "idle"]
            if not active:
                if pending:
                    raise BackendError("no worker process is left to run episodes")
                break
            wait([s.conn for s in active] + [s.process.sentinel for s in active], POLL_S)
            checked = (self._check(slot, bool(pending)) for slot in active)
            finished = [f for f in checked if f is not None]
            # the workers that finished get their next episode before the caller records
            # these (a trace write and a database commit): they do not wait for the writer
            self._hand_out(pending)
            yield from finished

    def _hand_out(self, pending: deque[EpisodeSpec]) -> None:
        for slot in self._slots:
            if slot.state == "idle" and pending:
                self._dispatch(slot, pending.popleft())

    # ------------------------------------------------------------------ internals
    def _spawn(self) -> _Slot:
        ours, theirs = self._context.Pipe(duplex=True)
        clock = self._context.Value("d", 0.0, lock=False)
        process = self._context.Process(target=serve, name="fsvla-worker", daemon=True,
                                        args=(theirs, self.config.model_dump_json(), clock,
                                              render_threads(self.size) if self.size > 1 else None))
        process.start()
        theirs.close()
        return _Slot(process=process, conn=ours, clock=clock)

    def _await_ready(self, slot: _Slot) -> None:
        try:
            message = slot.conn.recv()
        except (EOFError, OSError):
            raise BackendError(f"a worker process exited while starting "
                               f"({_exit_text(slot.process)})") from None
        self._ready(slot, message)

    def _ready(self, slot: _Slot, message: tuple) -> None:
        if message[0] == "ready":
            slot.state = "idle"
            return
        _, kind, text = message
        if kind == "policy":
            from fsvla.policies import PolicyLoadError

            raise PolicyLoadError(text)
        raise BackendError(f"a worker process failed to start: {text}")

    def _dispatch(self, slot: _Slot, spec: EpisodeSpec) -> None:
        slot.conn.send(spec)
        slot.state, slot.spec = "busy", spec
        slot.started, slot.since = datetime.now(timezone.utc), time.perf_counter()

    def _check(self, slot: _Slot, more: bool) -> Finished | None:
        """A finished episode of ``slot``, if any; handles a dead or hung worker."""
        message = None
        if slot.conn.poll():
            try:
                message = slot.conn.recv()
            except (EOFError, OSError):
                message = None
        if message is not None:
            if slot.state == "starting":
                self._ready(slot, message)
                return None
            spec, slot.spec, slot.state = slot.spec, None, "idle"
            assert spec is not None and message[1] == spec.episode_id
            return spec, message[2]
        if not slot.process.is_alive():
            if slot.state == "starting":
                raise BackendError(f"a worker process exited while starting "
                                   f"({_exit_text(slot.process)})")
            detail = (f"the worker process died ({_exit_text(slot.process)}) while running the "
                      "episode; the steps it ran are lost")
            return self._lose(slot, "sim_error", detail, more)
        timeout = self.config.policy_timeout_s
        since = slot.clock.value
        if (timeout is not None and slot.state == "busy" and since
                and time.monotonic() - since > hard_limit(timeout)):
            slot.process.kill()
            slot.process.join()
            detail = (f"act() did not return within {timeout:g} s and did not respond to the "
                      f"interrupt; its worker process was killed after "
                      f"{hard_limit(timeout):g} s and the steps it ran are lost")
            return self._lose(slot, "policy_timeout", detail, more)
        return None

    def _lose(self, slot: _Slot, reason: str, detail: str, more: bool) -> Finished:
        spec = slot.spec
        assert spec is not None
        outcome = EpisodeOutcome(failure_reason=reason, failure_detail=detail,  # type: ignore[arg-type]
                                 started_at=slot.started, finished_at=datetime.now(timezone.utc),
                                 wall_time_s=time.perf_counter() - slot.since)
        slot.conn.close()
        index = self._slots.index(slot)
        if more:
            self._slots[index] = self._spawn()
            self.replaced += 1
        else:
            del self._slots[index]
        return spec, outcome


def _exit_text(process: Any) -> str:
    process.join(1.0)
    code = process.exitcode
    if code is None:
        return "still running"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"


__all__ = ["ProcessBackend", "hard_limit", "serve"]
