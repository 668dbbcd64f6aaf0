"""Recording an episode as it runs: :class:`EpisodeRecorder` fills an
:class:`~fsvla.results.record.EpisodeRecord` (the record is results data and lives in
:mod:`fsvla.results.record`; it is re-exported here).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.monitor import MonitorSpec
from fsvla.monitor import StepReport, channel_infos
from fsvla.results.record import RECORD_FORMAT_VERSION, EpisodeRecord


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


__all__ = ["RECORD_FORMAT_VERSION", "EpisodeRecord", "EpisodeRecorder"]
