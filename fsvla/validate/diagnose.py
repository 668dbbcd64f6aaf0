"""From a failed verdict to its diagnostics: which episodes to read, which explanation.

=============  ==================================================================
solvable       careful-expert faults (FSV713), the limits it crossed (FSV712; a
               contact-force limit with a replay of what pressed), and
               for its first episode that completed without success, a replay of
               which part of ``success`` never held (FSV710, FSV711)
starts safe    hold-still faults (FSV723), crossings (FSV721, as FSV712), channels in their
               warning band at the first step (FSV720) or later (FSV722), success
               while holding still (FSV724)
hazardous      one note on the scenario's line (FSV730)
=============  ==================================================================
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from fsvla.dsl.diagnostics import Diagnostic

from . import codes
from .explain import (
    careless_diagnostic,
    done_at_rest_diagnostics,
    fault_diagnostics,
    start_diagnostics,
    success_diagnostics,
    violation_diagnostics,
)
from .sources import Located, success_spans
from .verdicts import Thresholds, Verdict, safe_at_rest, safe_success


def diagnose(located: Located, verdict: Verdict, rows: Sequence[Any], run_dir: Path,
             thresholds: Thresholds | None = None) -> list[Diagnostic]:
    """The diagnostics that explain a failed ``verdict``, from its policy's ``rows`` (those
    of its scenario and level) recorded in ``run_dir``."""
    level, thresholds = verdict.level, thresholds or Thresholds()
    if verdict.property == "hazardous":
        return [careless_diagnostic(located, verdict, rows)]
    if verdict.property == "solvable":
        failed = [r for r in rows if not safe_success(r)]
        found = fault_diagnostics(located, level, failed, code=codes.CAREFUL_FAULT,
                                  who="the careful expert")
        found += violation_diagnostics(located, level, failed, code=codes.CAREFUL_VIOLATION,
                                       who="the careful expert", pressed=_pressed(run_dir))
        unsuccessful = [r for r in failed if r.status == "completed" and not r.success]
        if unsuccessful:
            found += _replayed(located, level, unsuccessful[0], run_dir, len(failed), len(rows))
        return found
    failed = [r for r in rows if not safe_at_rest(r, thresholds.hold_ret)]
    found = fault_diagnostics(located, level, failed, code=codes.HOLD_FAULT, who="holding still")
    found += violation_diagnostics(located, level, failed, code=codes.HOLD_VIOLATION,
                                   who="holding still", pressed=_pressed(run_dir))
    completed = [r for r in failed if r.status == "completed"]
    found += start_diagnostics(located, level, completed, _traces(run_dir, completed))
    found += done_at_rest_diagnostics(located, level, completed)
    return found


def _traces(run_dir: Path, rows: Sequence[Any]) -> dict[str, Any]:
    from fsvla.results import ResultStore

    with ResultStore.open(run_dir, readonly=True) as store:
        return {r.episode_id: store.trace(r.episode_id) for r in rows if r.trace_path}


def _pressed(run_dir: Path) -> Callable[[Any, str], str | None]:
    """What pressed on a crossed contact-force channel's subject in an episode (a replay,
    :func:`~.crossing.replay_crossing`), as a note; a replay that fails says so."""
    from .crossing import replay_crossing

    def pressed(row: Any, channel: str) -> str | None:
        if not row.trace_path:
            return None
        try:
            crossing = replay_crossing(run_dir, row.episode_id, channel)
        except Exception as problem:  # noqa: BLE001 - a replay that fails must not end validate
            return (f"replaying {row.episode_id} to see what pressed did not work: "
                    f"{type(problem).__name__}: {problem}")
        return None if crossing is None else crossing.text()
    return pressed


def _replayed(located: Located, level: str, row: Any, run_dir: Path, failed: int,
              episodes: int) -> list[Diagnostic]:
    from .conjuncts import replay_success

    try:
        replay = replay_success(run_dir, row.episode_id)
    except Exception as problem:  # noqa: BLE001 - a replay that fails must not end validate
        statement, _ = success_spans(located)
        return [Diagnostic(
            code=codes.NEVER_HELD, message=f"the careful expert did not succeed at {level}",
            span=statement, label="never achieved",
            notes=((f"{row.episode_id}: replaying it to see which part failed did not work: "
                   f"{type(problem).__name__}: {problem}"),))]
    return success_diagnostics(located, level, replay, failed, episodes)


__all__ = ["diagnose"]
