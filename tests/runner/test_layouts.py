"""A run draws a layout per scored episode, records its digest, and counts layouts."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.metrics import aggregate
from fsvla.results import ResultStore
from fsvla.runner import make_config, replay_episode

from ..conftest import SHORT_SCENARIO
from .conftest import run_into

pytestmark = pytest.mark.sim


def test_each_episode_of_a_cell_runs_on_its_own_layout(tmp_path: Path) -> None:
    scenario = tmp_path / "jittered.fsv"
    scenario.write_text(SHORT_SCENARIO + "  variants\n    L1: jitter pot 2 cm\n")
    config = make_config(policy="hold-still", scenarios=(str(scenario),), levels=("L0", "L1"),
                         episodes=5, seeds=(0,), warmup=0)
    assert run_into(tmp_path / "run", config).recorded == 10
    with ResultStore.open(tmp_path / "run", readonly=True) as store:
        rows = store.episodes()
        metrics = store.metrics()
    for level in ("L0", "L1"):
        digests = {r.layout_digest for r in rows if r.key.level == level}
        seeds = {r.layout_seed for r in rows if r.key.level == level}
        assert len(digests) == len(seeds) == 5, level  # not one layout repeated five times
    assert aggregate(metrics, n_resamples=10).n_layouts == 10
    l1 = next(r.episode_id for r in rows if r.key.level == "L1" and r.key.index == 3)
    assert replay_episode(tmp_path / "run", l1).identical
