"""Run an expert through a scenario's gymnasium env and summarise the episode (what the
expert tests and ``bench`` scripts need; the benchmark's runner does its own loop)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .policy import make_expert


@dataclass
class Rollout:
    """One expert episode: outcome, cost and the channels that were hit."""

    scenario: str
    style: str
    steps: int
    success: bool
    violation: bool
    cost: float  # CC: the sum over steps of the monitor's weighted step cost
    violated: dict[str, int] = field(default_factory=dict)  # channel -> violating steps
    costs: dict[str, float] = field(default_factory=dict)  # channel -> summed c_k
    min_margin: dict[str, float] = field(default_factory=dict)
    segments: list[str] = field(default_factory=list)
    ik_misses: int = 0

    @property
    def safe_success(self) -> bool:
        return self.success and not self.violation

    def summary(self) -> str:
        hit = ", ".join(f"{k}×{v}" for k, v in self.violated.items()) or "none"
        return (f"{self.scenario} [{self.style}] success={self.success} violation={self.violation}"
                f" CC={self.cost:.2f} steps={self.steps} violated: {hit}")


def rollout(scenario: str, style: str = "careful", level: str = "L0", seed: int = 0,
            stop_on_success: bool = True, **env_kwargs: Any) -> Rollout:
    """Run the ``style`` expert on ``scenario`` until success (or the horizon)."""
    from fsvla.env import make

    env = make(scenario, level, seed, **env_kwargs)
    expert = make_expert(env, style)
    obs, _ = env.reset()
    expert.reset(None)
    result = Rollout(scenario=env.config.scenario, style=style, steps=0, success=False,
                     violation=False, cost=0.0)
    done = False
    while not done:
        for action in expert.act(obs):
            obs, _, terminated, truncated, info = env.step(action)
            result.steps += 1
            result.cost += float(info.get("cost", 0.0))
            result.success = result.success or bool(info.get("success", False))
            for name, state in info.get("states", {}).items():
                margin = float(info["margins"][name])
                result.min_margin[name] = min(result.min_margin.get(name, np.inf), margin)
                if state == "violation":
                    result.violation = True
                    result.violated[name] = result.violated.get(name, 0) + 1
            done = truncated or (terminated and stop_on_success)
            if done:
                break
    record = env.episode_record()
    result.costs = _channel_costs(record)
    result.segments = list(expert.log)
    result.ik_misses = expert.ik_misses
    env.close()
    return result


def _channel_costs(record: Any) -> dict[str, float]:
    names = getattr(record, "channels", None)
    costs = getattr(record, "costs", None)
    if names is None or costs is None:
        return {}
    arr = np.asarray(costs)
    if arr.ndim != 2:
        return {}
    return {str(getattr(n, "name", n)): float(arr[:, i].sum()) for i, n in enumerate(names)}


__all__ = ["Rollout", "rollout"]
