"""Per-step records of an episode: what the metrics are computed from, and can be traced to.

An :class:`EpisodeRecord` keeps, for every control step t = 1..T, the action the policy
sent, every channel's margin q_k and state, the unweighted soft costs c_k, the step
cost Σ_k w_k c_k, and whether the success condition held. ``record.trace(meta)`` is
the :class:`~fsvla.metrics.trace.EpisodeTrace` the metrics take; ``record.to_dict()``
is plain JSON so any number in a report can be followed back to the steps that made it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.monitor import MonitorSpec
from fsvla.metrics.trace import ChannelInfo, EpisodeMeta, EpisodeTrace
from fsvla.monitor import StepReport, channel_infos

RECORD_FORMAT_VERSION = 1


@dataclass(frozen=True)
class EpisodeRecord:
    """One episode's steps (row t = control step t+1)."""

    channels: tuple[ChannelInfo, ...]
    action_labels: tuple[str, ...]
    actions: NDArray[np.float64]  # T × A
    margins: NDArray[np.float64]  # T × K
    states: tuple[tuple[str, ...], ...]  # T × K: safe / warning / violation
    costs: NDArray[np.float64]  # T × K, unweighted c_k
    step_costs: NDArray[np.float64]  # T, Σ_k w_k c_k
    success_values: NDArray[np.bool_]  # T, the success condition at each step
    success: bool  # held for its hold time at some step

    @property
    def steps(self) -> int:
        return int(self.margins.shape[0])

    def trace(self, meta: EpisodeMeta) -> EpisodeTrace:
        if self.steps == 0:
            raise ValueError("the episode has no steps yet: call step() at least once")
        return EpisodeTrace(channels=self.channels, margins=self.margins, success=self.success,
                            meta=meta)

    def to_dict(self) -> dict[str, Any]:
        return {
            "version": RECORD_FORMAT_VERSION,
            "channels": [c.model_dump(mode="json") for c in self.channels],
            "action_labels": list(self.action_labels),
            "actions": self.actions.tolist(),
            "margins": self.margins.tolist(),
            "states": [list(s) for s in self.states],
            "costs": self.costs.tolist(),
            "step_costs": self.step_costs.tolist(),
            "success_values": self.success_values.tolist(),
            "success": self.success,
        }


class EpisodeRecorder:
    """Collects :class:`StepReport`s and actions as an episode runs."""

    def __init__(self, spec: MonitorSpec, action_labels: tuple[str, ...]) -> None:
        self.channels = channel_infos(spec)  # limits, then temporal requirements
        self.action_labels = action_labels
        self.start()

    def start(self) -> None:
        self._actions: list[NDArray[np.float64]] = []
        self._reports: list[StepReport] = []

    def add(self, action: NDArray[np.float64], report: StepReport) -> None:
        self._actions.append(np.asarray(action, dtype=np.float64).copy())
        self._reports.append(report)

    def record(self) -> EpisodeRecord:
        reports = self._reports
        k = len(self.channels)
        return EpisodeRecord(
            channels=self.channels,
            action_labels=self.action_labels,
            actions=np.array(self._actions, dtype=np.float64).reshape(len(reports),
                                                                     len(self.action_labels)),
            margins=np.array([r.margins for r in reports], dtype=np.float64).reshape(len(reports), k),
            states=tuple(tuple(r.states) for r in reports),
            costs=np.array([r.costs for r in reports], dtype=np.float64).reshape(len(reports), k),
            step_costs=np.array([r.cost for r in reports], dtype=np.float64),
            success_values=np.array([r.success_value for r in reports], dtype=bool),
            success=any(r.success for r in reports),
        )


__all__ = ["EpisodeRecord", "EpisodeRecorder", "RECORD_FORMAT_VERSION"]
