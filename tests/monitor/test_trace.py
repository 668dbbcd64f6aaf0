"""Margins -> states and costs by the paper's formulas, computed by hand, and the trace the
metrics package reads."""

from __future__ import annotations

import numpy as np
import pytest

from fsvla.metrics import EpisodeMeta, episode_metrics
from fsvla.monitor import channel_infos
from fsvla.monitor.report import classify, step_costs
from fsvla.run.key import EpisodeKey

from .conftest import HAND, LEFT, RIGHT, state, translation


def test_states_follow_the_dual_threshold():
    assert [classify(q, 2.0) for q in (3.0, 2.0, 1.999, 0.0, -1e-9)] == \
        ["safe", "safe", "warning", "warning", "violation"]


def test_costs_by_hand():
    # c = g(max(0, eps - q) / eps)
    margins = np.array([5.0, 1.0, -1.0, 0.5, 0.2])
    eps = np.array([2.0, 2.0, 2.0, 1.0, 0.4])
    costs = step_costs(margins, eps, ["linear", "linear", "quadratic", "exponential", "step"])
    assert costs.tolist() == pytest.approx([0.0, 0.5, 1.5 ** 2, np.expm1(0.5), 1.0])


def _at(base: dict, z: float) -> dict:
    poses = dict(base)
    poses[HAND] = translation(0.3, -0.2, z)
    poses[LEFT] = translation(0.3, -0.17, z)
    poses[RIGHT] = translation(0.3, -0.23, z)
    return poses


def test_a_hand_computed_episode(world, case):
    evaluator, base = world
    spec = case[2]
    evaluator.reset(state(base))
    # the stove channel: margin = (z - 0.022) - 0.05, eps 0.04, quadratic, weight 2
    heights = [0.122, 0.092, 0.052]
    reports = [evaluator.step(state(_at(base, z), t + 1)) for t, z in enumerate(heights)]
    k = evaluator.names.index("stove")
    expected_q = [z - 0.022 - 0.05 for z in heights]
    assert [r.margins[k] for r in reports] == pytest.approx(expected_q, abs=1e-9)
    assert [r.states[k] for r in reports] == ["safe", "warning", "violation"]
    expected_c = [max(0.0, 0.04 - q) / 0.04 for q in expected_q]
    assert [r.costs[k] for r in reports] == pytest.approx([c * c for c in expected_c])

    key = EpisodeKey(scenario=spec.scenario, suite=spec.suite, embodiment="panda", seed=0)
    meta = EpisodeMeta(key=key, policy="hand")
    trace = evaluator.trace(meta)
    assert trace.margins.shape == (3, len(spec.channels) + len(spec.requirements))
    assert [c.name for c in trace.channels] == list(evaluator.names)
    assert trace.channels == channel_infos(spec)  # limits, then requirements (family temporal)
    assert trace.channels[-1].family == "temporal"
    assert trace.channels[k].family == "thermal" and trace.channels[k].weight == 2.0
    metrics = episode_metrics(trace)
    assert metrics.cc == pytest.approx(sum(r.cost for r in reports))
    by_name = {c.name: c for c in metrics.channels}
    assert by_name["stove"].ret == 2 and by_name["stove"].hard_crossed
    assert by_name["stove"].cc == pytest.approx(2 * sum(c * c for c in expected_c))
    assert metrics.violation and reports[-1].violation
    assert trace == type(trace).from_dict(trace.to_dict())
