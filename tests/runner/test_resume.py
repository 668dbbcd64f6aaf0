"""A run killed mid-way resumes: no episode lost, none counted twice."""

from __future__ import annotations

import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fsvla.results import ResultStore
from fsvla.runner import prepare_run

pytestmark = pytest.mark.sim


def recorded(out: Path) -> int:
    try:
        db = sqlite3.connect(f"file:{out / 'results.sqlite'}?mode=ro", uri=True, timeout=5)
        try:
            return db.execute("SELECT count(*) FROM episodes").fetchone()[0]
        finally:
            db.close()
    except sqlite3.Error:  # not created yet
        return 0


def test_a_killed_run_resumes_without_losing_or_repeating_episodes(short_scenario: Path,
                                                                   tmp_path: Path) -> None:
    out = tmp_path / "run"
    command = [sys.executable, "-m", "fsvla", "run", "--policy", "random", "--scenarios",
               str(short_scenario), "--levels", "L0-L1", "--language", "W0,W1", "--episodes",
               "4", "--seeds", "2", "--warmup", "1", "--workers", "0", "--no-progress",
               "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while recorded(out) < 3:
        assert process.poll() is None, process.stderr.read().decode()
        assert time.monotonic() < deadline, "the run recorded nothing in 2 minutes"
        time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    before = recorded(out)
    assert 3 <= before < 17

    finished = subprocess.run(command, check=False, capture_output=True, text=True, timeout=300)
    assert finished.returncode == 0, finished.stderr
    assert f"{17 - before} episode(s) recorded now, {before} already recorded" in finished.stdout

    with ResultStore.open(out, readonly=True) as store:
        plan = prepare_run(store.config).plan
        rows = store.episodes()
        assert sorted(r.episode_id for r in rows) == sorted(s.episode_id for s in plan)
        assert len(rows) == len(plan) == 17  # each exactly once
        assert [s["kind"] for s in store.sessions()] == ["create", "resume"]
        assert store.orphan_traces() == []
