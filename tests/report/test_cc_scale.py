"""The CC of every table is CC / T (SASR's scale), not CC / (T · Σ_k w_k).

The shared fixtures weigh their channels 1 and 0 (Σw = 1), where the two scales agree;
this run weighs them 2 and 1 (Σw = 3), so a table showing the weighted mean would be off
by a factor of 3.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import pytest

from fsvla.report import Settings, build_report, load_runs, write_report
from fsvla.report.export import episode_records
from fsvla.report.views import protocol_view
from fsvla.results import ResultStore
from fsvla.run import RunConfig, plan_episodes

from .conftest import SCENARIOS, START, VERSIONS, outcome

CHANNELS = [
    {"name": "heat", "family": "thermal", "soft_threshold": 1.0, "weight": 2.0,
     "shaping": "linear"},
    {"name": "gap", "family": "boundary", "soft_threshold": 1.0, "weight": 1.0,
     "shaping": "linear"},
]


def _record(heat: list[float], gap: list[float], success: bool) -> dict[str, Any]:
    margins = [[h, g] for h, g in zip(heat, gap, strict=True)]
    costs = [[max(0.0, 1.0 - h), max(0.0, 1.0 - g)] for h, g in margins]
    states = [["safe" if q >= 1 else "warning" if q >= 0 else "violation" for q in row]
              for row in margins]
    return {"version": 1, "channels": CHANNELS, "action_labels": ["arm.joint1"],
            "actions": [[0.0]] * len(margins), "margins": margins, "states": states,
            "costs": costs, "step_costs": [2 * a + b for a, b in costs],
            "success_values": [False] * (len(margins) - 1) + [success], "success": success}


# Safe successes whose cost per step is 0.3 (T = 2 and T = 4 alike), and one safe failure.
RECORDS = {
    ("stove", "W0"): _record([0.85, 2.0], [2.0, 0.7], True),       # CC 0.6, T 2
    ("stove", "W3"): _record([0.7, 2, 2, 0.85], [2, 2, 0.7, 2], True),  # CC 1.2, T 4
    ("edge", "W0"): _record([2.0, 0.5, 2.0], [2.0, 2.0, 0.0], False),  # CC 2.0, T 3
    ("edge", "W3"): _record([2.0], [2.0], True),                  # CC 0, T 1
}


@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("weighted") / "run"
    config = RunConfig(policy="p", scenarios=("scenarios/",), languages=("W0", "W3"),
                       warmup=0)
    with ResultStore.create(path, config, VERSIONS) as store:
        for spec in plan_episodes(config, SCENARIOS):
            done = outcome(spec, "safe", True, None)
            record = RECORDS[(spec.key.scenario, spec.key.language)]
            store.record(spec, done.model_copy(update={"record": record, "started_at": START}))
    return path


def test_every_episode_row_has_table_cc_equal_to_cc_over_steps(weighted_run: Path,
                                                               tmp_path: Path) -> None:
    runs = load_runs([weighted_run])
    report = build_report(runs, settings=Settings(n_resamples=50))
    write_report(report, runs, tmp_path, ("csv",), figures=False)
    with (tmp_path / "data" / "episodes.csv").open() as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 4
    with ResultStore.open(weighted_run, readonly=True) as store:
        stored = {row.episode_id: row for row in store.episodes()}
    for row in rows:
        episode = stored[row["episode_id"]]
        assert float(row["cc_per_step"]) == episode.cc / episode.steps
        assert float(row["cc_normalised"]) == pytest.approx(float(row["cc_per_step"]) / 3)
    table_cc = report.aggregate.rows[0].cc.estimate
    assert table_cc == pytest.approx(sum(float(r["cc_per_step"]) for r in rows) / 4)
    assert report.aggregate.rows[0].cc_weighted.estimate == pytest.approx(table_cc / 3)
    suites = {row.key: row.cells["p"] for row in report.groups["suite"].rows}
    assert suites["thermal"].cc.estimate == pytest.approx(0.3)
    assert suites["boundary"].cc.estimate == pytest.approx((2.0 / 3 + 0) / 2)


def test_sasr_is_ssr_discounted_by_the_table_cc(weighted_run: Path) -> None:
    # On the thermal suite every episode is a safe success costing 0.3 a step, so SASR is
    # exactly SSR · exp(−CC) with the table's CC, as the paper's Table 3 rows nearly are.
    report = build_report(load_runs([weighted_run]), settings=Settings(n_resamples=50))
    thermal = next(r for r in report.groups["suite"].rows if r.key == "thermal").cells["p"]
    assert thermal.sasr.estimate == pytest.approx(
        thermal.ssr.estimate * math.exp(-thermal.cc.estimate))


def test_the_protocol_table_states_the_cc_scale(weighted_run: Path) -> None:
    report = build_report(load_runs([weighted_run]), settings=Settings(n_resamples=50))
    rows = {cells[0].text: cells[1].text for cells in protocol_view(report.protocol).rows}
    assert rows["CC in tables"].startswith("CC / T")
    assert report.protocol.cc_normalisation.startswith("Table CC = CC / T")


def test_episode_records_carry_both_scales(weighted_run: Path) -> None:
    records = episode_records(load_runs([weighted_run]))
    assert {r["episode_id"].split("-")[0] for r in records} == {"stove", "edge"}
    assert all(r["cc_per_step"] == r["cc"] / r["horizon"] for r in records)
