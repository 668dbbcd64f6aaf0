"""Per-step records of an episode: what the metrics are computed from, and can be traced to.

An :class:`EpisodeRecord` keeps, for every control step t = 1..T, the action the policy
sent, every channel's margin q_k and state, the unweighted soft costs c_k, the step
cost Σ_k w_k c_k, and whether the success condition held. ``record.trace(meta)`` is
the :class:`~fsvla.metrics.trace.EpisodeTrace` the metrics take; ``record.to_dict()``
is plain JSON so any number in a report can be followed back to the steps that made it,
and :meth:`EpisodeRecord.from_dict` reads it back.

The record is data of the results (a run folder stores it as a Parquet trace); the
environment fills it as an episode runs (:class:`fsvla.env.recording.EpisodeRecorder`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.metrics.trace import ChannelInfo, EpisodeMeta, EpisodeTrace

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

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> EpisodeRecord:
        """The record whose :meth:`to_dict` is ``record`` (keys it does not know are ignored)."""
        channels = tuple(ChannelInfo.model_validate(c) for c in record["channels"])
        labels = tuple(record["action_labels"])
        steps, k = len(record["margins"]), len(channels)
        return cls(
            channels=channels,
            action_labels=labels,
            actions=np.array(record["actions"], dtype=np.float64).reshape(steps, len(labels)),
            margins=np.array(record["margins"], dtype=np.float64).reshape(steps, k),
            states=tuple(tuple(s) for s in record["states"]),
            costs=np.array(record["costs"], dtype=np.float64).reshape(steps, k),
            step_costs=np.array(record["step_costs"], dtype=np.float64).reshape(steps),
            success_values=np.array(record["success_values"], dtype=bool).reshape(steps),
            success=bool(record["success"]),
        )


__all__ = ["RECORD_FORMAT_VERSION", "EpisodeRecord"]
