"""The Ray backend scales out and survives losing a node: a run on a local two-node Ray
cluster started with Ray's CLI, whose second node is killed mid-run, records every planned
episode exactly once; an actor that keeps dying costs its episode after its retries; one
lost while the run starts stops it with a message, before anything is written.

Slow (a Ray cluster starts in about 10 s on two cores); CI runs it, and under ``CI=true``
a missing ``ray`` fails instead of skipping (tests/conftest.py).
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fsvla.results import ResultStore
from fsvla.runner import BackendError, execute_run, prepare_run, summarize
from fsvla.runner.ray_backend import RayBackend

from ..conftest import require
from .conftest import policy
from .policies import STALL_MARKER
from .ray_cluster import TwoNodeCluster, ray_command

pytestmark = [pytest.mark.sim, pytest.mark.slow]

EPISODES = 4
#: Seconds the whole run may take (the policy stalls for 120 s if the node is not killed).
RUN_LIMIT_S = 240


@pytest.fixture
def ray_cli() -> str:
    require(importlib.util.find_spec("ray") is not None,
            "ray is not installed: pip install -e '.[dev]' (or '.[ray]')")
    command = ray_command()
    require(command is not None, "the ray command is not installed beside this Python")
    assert command is not None
    return command


def fsvla_run(*options: str, env: dict[str, str]) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fsvla", "run", "--no-progress", *options],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def await_marker(marker: Path, driver: subprocess.Popen, timeout: float = 120.0) -> str:
    """The episode id the stalling policy wrote once it started on the second node."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if marker.exists() and marker.read_text().strip():
            return marker.read_text().split()[0]
        if driver.poll() is not None:
            pytest.fail(f"fsvla run ended before the second node ran an episode:\n"
                        f"{driver.communicate()[0]}")
        time.sleep(0.2)
    driver.kill()
    pytest.fail(f"no episode started on the second node in {timeout:.0f} s:\n"
                f"{driver.communicate()[0]}")


def test_a_run_survives_losing_a_node(ray_cli, short_scenario, tmp_path) -> None:
    marker = tmp_path / "stalled"
    run_dir = tmp_path / "run"
    with TwoNodeCluster(ray_cli, second_env={STALL_MARKER: str(marker)}) as cluster:
        driver = fsvla_run(
            "--policy", policy("StallsWhereMarked"), "--scenarios", str(short_scenario),
            "--episodes", str(EPISODES), "--seeds", "2", "--warmup", "0",
            "--terminate-on-violation", "--obs-mode", "state",
            "--backend", "ray", "--workers", "2", "--ray-address", cluster.address,
            "--out", str(run_dir), env=cluster.env)
        stalled = await_marker(marker, driver)  # one actor per node: 1 CPU each
        cluster.kill("second")
        try:
            output, _ = driver.communicate(timeout=RUN_LIMIT_S)
        except subprocess.TimeoutExpired:
            driver.kill()
            pytest.fail(f"fsvla run did not end:\n{driver.communicate()[0]}\n"
                        f"head node:\n{cluster.log('head')[-3000:]}")
    assert driver.returncode == 0, output
    assert "1 episode(s) run again after their worker was lost" in output, output

    with ResultStore.open(run_dir, readonly=True) as store:
        rows = store.episodes()
        planned = [spec.episode_id for spec in prepare_run(store.config).plan]
        summary = summarize(store)
    ids = [row.episode_id for row in rows]
    assert len(ids) == len(set(ids)) == len(planned) == EPISODES
    assert set(ids) == set(planned)
    assert all(row.status == "completed" for row in rows), [r.failure_detail for r in rows]
    assert stalled in ids and {row.session_id for row in rows} == {1}
    assert summary[-1].episodes == EPISODES and summary[-1].faults == 0

    report = subprocess.run([sys.executable, "-m", "fsvla", "report", str(run_dir), "--out",
                             str(tmp_path / "report"), "--formats", "json", "--no-figures",
                             "--resamples", "20"], check=False, capture_output=True, text=True)
    assert report.returncode == 0, report.stdout + report.stderr
    assert len(list((tmp_path / "report").glob("*.json"))) >= 1


def test_an_actor_that_keeps_dying_costs_its_episode(ray_cli, make_run_config,
                                                     tmp_path) -> None:
    config = make_run_config(policy=policy("Dies"))
    backend = RayBackend(config, 1, max_retries=1)
    result = execute_run(prepare_run(config), tmp_path, backend)
    assert result.faults == {"sim_error": 1} and result.reruns == 1
    (rerun,) = backend.reruns
    assert rerun.attempt == 1 and rerun.reason.startswith("ActorDiedError")
    with ResultStore.open(tmp_path, readonly=True) as store:
        (row,) = store.episodes()
    assert "lost 2 times" in row.failure_detail and "attempt 2: ActorDiedError" in row.failure_detail
    assert row.steps == 0 and row.trace_path is None
    assert "\n" not in row.failure_detail


def test_a_worker_lost_while_starting_is_a_backend_error(ray_cli, make_run_config,
                                                         tmp_path) -> None:
    config = make_run_config(policy=policy("DiesAtLoad"))
    with pytest.raises(BackendError, match="a Ray worker was lost while starting: "
                                           "ActorDiedError"):
        execute_run(prepare_run(config), tmp_path / "run", RayBackend(config, 1))
    assert not (tmp_path / "run").exists()
