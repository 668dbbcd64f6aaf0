"""What a report reads: each run folder's configuration, versions and scored episodes.

A report is made from result stores alone. :func:`load_runs` opens each run folder
read-only, once, and keeps every non-warm-up episode as an :class:`Episode`: its stored
row (id, coordinates, status, trace path) next to the :class:`EpisodeMetrics` the store
scores it as. Faulted episodes count as failures, exactly as
``ResultStore.metrics()`` counts them by default (scored on the steps that ran, or, with
none, as a safe failure without exposure); warm-ups are left out and only counted.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict

from fsvla.metrics import EpisodeMetrics
from fsvla.results import EpisodeRow, ResultStore, RunInfo
from fsvla.results.rows import row_metrics, unscored_failure


class Episode(BaseModel):
    """One scored episode: its row (where it came from) and its metrics (what it counts as)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    row: EpisodeRow
    metrics: EpisodeMetrics

    @property
    def id(self) -> str:
        return self.row.episode_id


class RunData(BaseModel):
    """One run folder as a report sees it: one policy, its protocol, its scored episodes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    label: str  # the policy's name in tables and figures
    run_dir: Path
    info: RunInfo
    sessions: tuple[dict[str, Any], ...]
    episodes: tuple[Episode, ...]  # scored: warm-ups out, faults in (as failures)
    warmups: int  # warm-up episodes recorded (excluded from every number)

    @property
    def policy(self) -> str:
        return self.info.config.policy

    @property
    def metrics(self) -> list[EpisodeMetrics]:
        return [e.metrics for e in self.episodes]

    @property
    def sasr_lambda(self) -> float:
        return self.info.config.sasr_lambda

    def fault_counts(self) -> dict[str, int]:
        """Faulted episodes by failure reason (they are counted as failures)."""
        counts = Counter(e.row.failure_reason for e in self.episodes if e.row.status == "faulted")
        return {str(reason): n for reason, n in sorted(counts.items())}

    def episode(self, episode_id: str) -> Episode:
        for ep in self.episodes:
            if ep.id == episode_id:
                return ep
        raise KeyError(f"no scored episode {episode_id!r} in {self.run_dir}")


class ReportInputError(ValueError):
    """The runs given cannot be reported (not a run, no episodes, bad labels)."""

    exit_code = 2  # a usage error: the command line names something that is not there


class NothingToReport(ReportInputError):
    """A run folder holds no scored episode yet."""

    exit_code = 1


def load_run(run_dir: Path, label: str | None = None) -> RunData:
    """Read one run folder (read-only; also while a run is writing it)."""
    run_dir = Path(run_dir)
    try:
        store = ResultStore.open(run_dir, readonly=True)
    except FileNotFoundError as err:
        raise ReportInputError(str(err)) from None
    with store:
        info = store.info()
        sessions = tuple(store.sessions())
        rows = store.episodes(include_warmup=True)
    # The store's default (ResultStore.metrics()): faults are failures, warm-ups out.
    episodes = tuple(Episode(row=row, metrics=row_metrics(row) or unscored_failure(row))
                     for row in rows if not row.key.warmup)
    if not episodes:
        raise NothingToReport(f"{run_dir} holds no scored episode yet "
                               f"({len(rows)} warm-up episode(s) recorded)")
    return RunData(label=label or info.config.policy, run_dir=run_dir, info=info,
                   sessions=sessions, episodes=episodes, warmups=len(rows) - len(episodes))


def load_runs(run_dirs: Sequence[Path], labels: Sequence[str] | None = None) -> list[RunData]:
    """Read several run folders, one policy each; labels default to the policies' names
    (made unique with the folder name where two runs share a policy)."""
    if not run_dirs:
        raise ReportInputError("name at least one run folder")
    if labels is not None and len(labels) not in (0, len(run_dirs)):
        raise ReportInputError(f"{len(labels)} label(s) for {len(run_dirs)} run folder(s): "
                               "give one --label per run folder, in the same order")
    runs = [load_run(d, labels[i] if labels else None) for i, d in enumerate(run_dirs)]
    names = [r.label for r in runs]
    if labels:
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise ReportInputError(f"labels must be unique, repeated: {', '.join(repeated)}")
        return runs
    unique = []
    for run in runs:
        name = run.label
        if names.count(name) > 1:
            name = f"{name} ({run.run_dir.name or run.run_dir})"
        unique.append(run.model_copy(update={"label": name}))
    final = [r.label for r in unique]
    if len(set(final)) != len(final):
        raise ReportInputError("two run folders have the same policy and folder name; "
                               "give each a --label")
    return unique


__all__ = ["Episode", "NothingToReport", "ReportInputError", "RunData", "load_run", "load_runs"]
