"""The rollouts of ``fsvla validate``: one ``fsvla run`` per policy, through the runner.

Each of the three policies (careful-expert, careless-expert, hold-still) runs over the
scenarios × levels × seeds into its own run folder, ``OUT/<policy>/``: N seeds give N
scored episodes per scenario and level, episode ``e`` on layout seed ``e``, and no
warm-ups. Running ``fsvla validate`` again resumes those folders (recorded episodes are
kept; other levels or seeds extend the run), with the runner's parallel workers, fault
handling and crash safety.

An episode recorded from another version of a scenario file (its source digest differs)
would give a stale verdict: :func:`run_policy` refuses such a folder unless ``fresh``,
which deletes the run folder (only an fsvla run folder) and starts it again.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec


class ValidateInputError(ValueError):
    """An input ``fsvla validate`` cannot use (exit 2)."""


@dataclass(frozen=True)
class PolicyRun:
    """One policy's run folder and the rows of the episodes validate planned."""

    policy: str
    run_dir: Path
    config: RunConfig
    plan: tuple[EpisodeSpec, ...]
    rows: tuple[Any, ...]  # EpisodeRow, in plan order; planned episodes not recorded are absent
    recorded: int  # episodes recorded by this session
    interrupted: bool


def run_config(policy: str, refs: Sequence[str], levels: Sequence[str], seeds: int) -> RunConfig:
    """The configuration validate runs ``policy`` with: N seeds, one episode each, no warm-up."""
    from fsvla.runner import make_config

    return make_config(policy=policy, scenarios=tuple(refs), levels=tuple(levels),
                       seeds=tuple(range(seeds)), episodes=seeds, warmup=0)


def run_policy(policy: str, refs: Sequence[str], levels: Sequence[str], seeds: int, out: Path,
               *, workers: int = 1, fresh: bool = False,
               listener: Callable[[str], Any] | None = None) -> PolicyRun:
    """Run (or resume) ``policy`` over the scenarios into ``out/<policy>`` and read back the
    planned episodes' rows. ``listener(policy)`` gives the run's RunListener (progress)."""
    from fsvla.policies import PolicyLoadError
    from fsvla.results import ResultStore
    from fsvla.runner import RunInputError, check_run_folder, execute_run, make_backend, prepare_run

    run_dir = out / policy
    try:
        config = run_config(policy, refs, levels, seeds)
        prepared = prepare_run(config)
        if fresh:
            remove_run(run_dir)
        stale = stale_episodes(run_dir, prepared.plan)
        if stale:
            raise ValidateInputError(
                f"{run_dir} holds {len(stale)} episode(s) of an earlier version of the scenario "
                f"file(s) (e.g. {stale[0]}); pass --fresh to run them again, or choose another "
                "--out")
        check_run_folder(run_dir, config, extend=True)
        done, interrupted = 0, False
        if _pending(run_dir, prepared.plan):  # else no worker needs to start
            backend = make_backend("process", config, workers)
            result = execute_run(prepared, run_dir, backend, extend=True,
                                 listener=listener(policy) if listener else None)
            done, interrupted = result.recorded, result.interrupted
    except (RunInputError, PolicyLoadError) as problem:
        raise ValidateInputError(str(problem)) from None
    with ResultStore.open(run_dir, readonly=True) as store:
        recorded = store.recorded_ids()
        rows = tuple(store.episode(spec.episode_id) for spec in prepared.plan
                     if spec.episode_id in recorded)
    return PolicyRun(policy=policy, run_dir=run_dir, config=config, plan=prepared.plan, rows=rows,
                     recorded=done, interrupted=interrupted)


def _pending(run_dir: Path, plan: Sequence[EpisodeSpec]) -> bool:
    """Whether some planned episode is not recorded in ``run_dir`` yet."""
    from fsvla.results import ResultStore

    if not ResultStore.exists(run_dir):
        return True
    with ResultStore.open(run_dir, readonly=True) as store:
        return bool(store.pending(plan))


def stale_episodes(run_dir: Path, plan: Sequence[EpisodeSpec]) -> list[str]:
    """The planned episodes recorded in ``run_dir`` from another version of their scenario."""
    from fsvla.results import ResultStore

    try:
        if not ResultStore.exists(run_dir):
            return []
        with ResultStore.open(run_dir, readonly=True) as store:
            recorded = store.recorded_ids()
            return [spec.episode_id for spec in plan if spec.episode_id in recorded
                    and store.episode(spec.episode_id).scenario_digest != spec.scenario_digest]
    except ValueError as problem:
        raise ValidateInputError(str(problem)) from None


def remove_run(run_dir: Path) -> None:
    """Delete ``run_dir`` if it is an fsvla run folder; refuse anything else that exists."""
    from fsvla.results import ResultStore

    if not run_dir.exists():
        return
    try:
        is_run = run_dir.is_dir() and ResultStore.exists(run_dir)
    except ValueError:
        is_run = False
    if not is_run:
        raise ValidateInputError(f"--fresh: {run_dir} is not an fsvla run folder; leaving it alone")
    shutil.rmtree(run_dir)


__all__ = ["PolicyRun", "ValidateInputError", "remove_run", "run_config", "run_policy",
           "stale_episodes"]
