"""The process pool and Ray give the same episodes as in-process execution; the pool
survives workers that hang or die."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from fsvla.results import ResultStore
from fsvla.runner.pool import hard_limit
from fsvla.runner.replay import compare_traces

from ..conftest import require
from .conftest import policy, run_into

pytestmark = pytest.mark.sim

#: Row fields that must match between backends (timestamps, sessions, wall times may not).
SAME = ("status", "failure_reason", "steps", "instruction", "perturbation", "layout_digest",
        "success", "violation", "quadrant", "cc", "ret", "sasr", "channels")


@pytest.fixture(scope="module")
def grid(make_run_config):
    return make_run_config(policy="random", levels=("L0", "L1"), languages=("W0", "W2"),
                           episodes=2, seeds=(0, 1), warmup=1)


@pytest.fixture(scope="module")
def in_process(grid, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("in_process")
    assert run_into(out, grid, workers=0).recorded == 9
    return out


def assert_same_episodes(expected: Path, actual: Path) -> None:
    with ResultStore.open(expected, readonly=True) as a, ResultStore.open(actual, readonly=True) as b:
        assert a.recorded_ids() == b.recorded_ids()
        for episode_id in sorted(a.recorded_ids()):
            left, right = a.episode(episode_id), b.episode(episode_id)
            assert [getattr(left, f) for f in SAME] == [getattr(right, f) for f in SAME]
            assert compare_traces(a.trace(episode_id), b.trace(episode_id)) == []


def test_the_process_pool_gives_the_same_episodes(grid, in_process, tmp_path) -> None:
    result = run_into(tmp_path, grid, workers=2)
    assert (result.recorded, result.faults) == (9, {})
    assert_same_episodes(in_process, tmp_path)


@pytest.mark.slow
def test_ray_gives_the_same_episodes(grid, in_process, tmp_path) -> None:
    require(importlib.util.find_spec("ray") is not None, "ray is not installed: pip install "
            "-e '.[dev]'")  # under CI=true a failure, not a skip
    result = run_into(tmp_path, grid, workers=2, backend="ray")
    assert (result.recorded, result.faults) == (9, {})
    assert_same_episodes(in_process, tmp_path)


def test_a_call_deaf_to_the_timeout_gets_its_worker_killed(make_run_config, tmp_path) -> None:
    config = make_run_config(policy=policy("Deaf"), policy_timeout_s=0.3, levels=("L0", "L1"))
    result = run_into(tmp_path, config, workers=1)
    assert result.faults == {"policy_timeout": 2}  # the worker was replaced for the second
    with ResultStore.open(tmp_path, readonly=True) as store:
        rows = store.episodes()
    for row in rows:
        assert row.steps == 0 and "worker process was killed" in row.failure_detail
        assert hard_limit(0.3) <= row.wall_time_s < hard_limit(0.3) + 5


def test_a_worker_that_dies_costs_its_episode_only(make_run_config, tmp_path) -> None:
    config = make_run_config(policy=policy("Dies"))
    result = run_into(tmp_path, config, workers=1)
    assert result.faults == {"sim_error": 1}
    with ResultStore.open(tmp_path, readonly=True) as store:
        (row,) = store.episodes()
    assert "worker process died (exit code 3)" in row.failure_detail


def test_the_pool_reports_a_bad_policy_before_writing(make_run_config, tmp_path) -> None:
    from fsvla.policies import PolicyLoadError

    with pytest.raises(PolicyLoadError, match="no weights here"):
        run_into(tmp_path / "run", make_run_config(policy=policy("Unbuildable")), workers=2)
    assert not (tmp_path / "run").exists()
