"""A recorded episode replayed step by step, with the monitor's own world state at each.

``fsvla validate`` explains a failed verdict by replaying one of its episodes: the
recorded actions in a fresh environment built from the episode's spec and the run's
config (as ``fsvla replay`` does: the same layout and physics, bit for bit), reading at
every control step the :class:`~fsvla.monitor.state.WorldState` the monitor evaluated and
the step's ``info``. :mod:`.conjuncts` tracks the success condition's parts that way,
:mod:`.crossing` the contacts behind a crossed force limit.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np


@dataclass(frozen=True)
class ReplayedStep:
    """One control step of a replay."""

    index: int  # 0-based, as the episode's metrics count
    state: Any  # the monitor's WorldState at the step's end
    info: dict[str, Any]  # the environment's step info (channel states, margins)


class Replay:
    """The recorded episode ``episode_id`` of the run in ``run_dir``, ready to replay."""

    def __init__(self, run_dir: Path, episode_id: str) -> None:
        from fsvla.results import ResultStore

        with ResultStore.open(run_dir, readonly=True) as store:
            self.row = store.episode(episode_id)
            self.config = store.config
            record = store.trace(episode_id)
        if record is None:
            raise ValueError(f"episode {episode_id} has no trace to replay")
        self.record: dict[str, Any] = record
        self.env: Any = None
        self.control_dt = 0.0  # s per control step, once the environment is built

    def steps(self) -> Iterator[ReplayedStep]:
        """Build the environment, reset it and step it through the recorded actions,
        yielding each step until the episode ends; the environment (``self.env``, with its
        monitor spec and evaluator) is open while this runs and closed after."""
        from fsvla.runner.worker import make_env

        self.env = make_env(self.row.spec(), self.config)
        try:
            self.env.reset()
            self.control_dt = float(self.env.control_dt)
            evaluator = self.env.monitor.evaluator
            seen: dict[str, Any] = {}
            step = evaluator.step

            def watched(state: Any) -> Any:
                seen["state"] = state
                return step(state)

            evaluator.step = watched
            for index, action in enumerate(self.record["actions"]):
                _, _, terminated, truncated, info = self.env.step(
                    np.asarray(action, dtype=np.float64))
                yield ReplayedStep(index, seen["state"], info)
                if terminated or truncated:
                    break
        finally:
            self.env.close()


__all__ = ["Replay", "ReplayedStep"]
