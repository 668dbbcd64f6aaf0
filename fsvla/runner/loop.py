"""The run loop: start the backend, open the run folder, record outcomes as they come.

::

    backend.start()                                  # the policy loads where it will run
    with ResultStore.open_or_create(out, config) as store:
        for spec, outcome in backend.run(store.pending(plan)):
            store.record(spec, outcome)              # here only: one writer

Finished episodes are skipped (``pending``), so running again on a folder resumes it,
and a kill loses at most the episodes in flight. An outcome the store refuses (e.g. a
completed episode whose margins are not finite) is recorded as a ``sim_error`` instead.
Ctrl-C stops the backend, keeps what was recorded and returns with ``interrupted``.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from fsvla.results import EpisodeOutcome, EpisodeRow, ResultStore
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.backend import Backend
from fsvla.runner.prepare import PreparedRun


@dataclass
class RunResult:
    """What one ``fsvla run`` did."""

    run_dir: Path
    planned: int = 0  # episodes in the plan
    skipped: int = 0  # already recorded when this session started
    recorded: int = 0  # recorded by this session
    faults: Counter[str] = field(default_factory=Counter)  # failure_reason -> episodes
    reruns: int = 0  # episodes handed out again after their worker was lost (backend.reruns)
    interrupted: bool = False
    startup_s: float = 0.0  # starting the backend (workers, policy loading)
    episodes_s: float = 0.0  # from the first episode handed out to the last recorded

    @property
    def per_minute(self) -> float:
        return 60.0 * self.recorded / self.episodes_s if self.episodes_s > 0 else 0.0


@dataclass
class RunListener:
    """Callbacks of a run (the CLI's progress bar): totals at the start, each row."""

    started: Callable[[int, int], None] = lambda total, done: None
    recorded: Callable[[EpisodeRow], None] = lambda row: None


def execute_run(prepared: PreparedRun, out: Path, backend: Backend, *, extend: bool = False,
                listener: RunListener | None = None) -> RunResult:
    """Run every pending episode of ``prepared`` into the run folder ``out``."""
    listener = listener or RunListener()
    result = RunResult(run_dir=Path(out), planned=len(prepared.plan))
    clock = time.perf_counter()
    try:
        backend.start()
        result.startup_s = time.perf_counter() - clock
        with ResultStore.open_or_create(out, prepared.config, extend=extend) as store:
            pending = store.pending(prepared.plan)
            result.skipped = result.planned - len(pending)
            listener.started(result.planned, result.skipped)
            clock = time.perf_counter()
            try:
                for spec, outcome in backend.run(pending):
                    row = record_outcome(store, spec, outcome)
                    result.recorded += 1
                    if row.failure_reason is not None:
                        result.faults[row.failure_reason] += 1
                    listener.recorded(row)
            except KeyboardInterrupt:
                result.interrupted = True
            result.episodes_s = time.perf_counter() - clock
            result.reruns = len(backend.reruns)
    finally:
        backend.close()
    return result


def record_outcome(store: ResultStore, spec: EpisodeSpec, outcome: EpisodeOutcome) -> EpisodeRow:
    """``store.record``; an outcome it refuses is recorded as a ``sim_error`` fault."""
    try:
        return store.record(spec, outcome)
    except ValueError as err:
        if outcome.failure_reason is not None and outcome.record is None:
            raise
        refused = f"the episode's outcome could not be stored as it was: {err}"
        detail = "; ".join(filter(None, (outcome.failure_detail, refused)))
        faulted = outcome.model_copy(update={"failure_reason": outcome.failure_reason
                                             or "sim_error", "failure_detail": detail})
        try:
            return store.record(spec, faulted)
        except ValueError:
            return store.record(spec, faulted.model_copy(update={
                "record": None, "instruction": None, "perturbation": None}))


__all__ = ["RunListener", "RunResult", "execute_run", "record_outcome"]
