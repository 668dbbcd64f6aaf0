"""What the monitor says about one control step: margins, states, costs, success."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from fsvla.metrics.shaping import SHAPING_FUNCTIONS

ChannelState = Literal["safe", "warning", "violation"]


def classify(margin: float, soft_threshold: float) -> ChannelState:
    """The dual-threshold state (paper Eq. threshold): safe q >= ε, warning 0 <= q < ε, violation q < 0."""
    if margin < 0.0:
        return "violation"
    return "warning" if margin < soft_threshold else "safe"


def step_costs(margins: Sequence[float], soft_thresholds: Sequence[float],
               shapings: Sequence[str]) -> NDArray[np.float64]:
    """c_k = g_k(max(0, ε_k - q_k) / ε_k) per channel, as ``fsvla.metrics.shaping.soft_cost``."""
    costs = np.zeros(len(margins))  # g(0) = 0 for every shaping: only channels below ε cost
    for k, (q, eps) in enumerate(zip(margins, soft_thresholds)):
        if not q >= eps:  # a NaN margin gets a NaN cost, as numpy would give it
            costs[k] = SHAPING_FUNCTIONS[shapings[k]](np.array([(eps - q) / eps]))[0]
    return costs


@dataclass(frozen=True)
class StepReport:
    """The monitor's reading of control step ``step`` (1-based; 0 is the state at reset)."""

    step: int
    time: float  # s since reset
    names: tuple[str, ...]
    margins: NDArray[np.float64]  # q_k
    states: tuple[ChannelState, ...]
    costs: NDArray[np.float64]  # c_k (unweighted, dimensionless)
    weights: NDArray[np.float64]  # w_k
    success_value: bool  # the success condition holds now
    success_held: float  # s it has held without a break, up to now
    success: bool  # it has held for the scenario's `for` time

    @property
    def violations(self) -> NDArray[np.bool_]:
        return self.margins < 0.0

    @property
    def any_violation(self) -> bool:
        """Whether some channel is past its hard limit (q_k < 0) at this step."""
        return "violation" in self.states

    violation = any_violation

    @property
    def cost(self) -> float:
        """Σ_k w_k c_k at this step (this step's term of CC)."""
        return float(self.weights @ self.costs)

    @property
    def exposed(self) -> bool:
        """Whether some channel is below its soft threshold (this step counts in RET)."""
        return any(s != "safe" for s in self.states)

    def info(self) -> dict[str, Any]:
        """A flat, JSON-ready summary for an env's ``info`` dict."""
        return {
            "cost": self.cost,
            "violation": self.any_violation,
            "margins": dict(zip(self.names, self.margins.tolist())),
            "states": dict(zip(self.names, self.states)),
            "success": self.success,
        }


__all__ = ["ChannelState", "StepReport", "classify", "step_costs"]
