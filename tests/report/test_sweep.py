"""Fig. 4 from one-axis sweeps: a point per level on each axis, each saying its protocol."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from fsvla.report import Settings, build_report, load_runs
from fsvla.report.views import group_view, protocol_view
from fsvla.results import ResultStore
from fsvla.run import RunConfig, plan_episodes
from fsvla.run.config import LANGUAGES, LEVELS, VISIONS
from fsvla.variation.language import Instruction

from .conftest import SCENARIOS, VERSIONS, outcome, perturbation


def _outcome(spec: Any) -> Any:
    # safe successes, the cost growing with the severity of whichever level is not at 0
    rank = int(spec.key.level[1]) + int(spec.key.language[1]) + int(spec.key.vision[1])
    kind = "warn" if rank >= 2 else "safe"
    done = outcome(spec, kind, True, None)
    category = {"W3": "unsafe", "W4": "hijack"}.get(spec.key.language)
    instruction = Instruction(level=spec.key.language, category=category, text="Lift it.",
                              origin="canonical")
    return done.model_copy(update={"instruction": instruction,
                                   "perturbation": perturbation(spec.key.vision)
                                   .model_copy(update={"level": spec.key.vision})})


def _run(path: Path, config: RunConfig) -> Path:
    with ResultStore.create(path, config, VERSIONS) as store:
        for spec in plan_episodes(config, SCENARIOS):
            store.record(spec, _outcome(spec))
    return path


@pytest.fixture(scope="module")
def sweep_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    config = RunConfig(policy="p", scenarios=("s",), levels=LEVELS, languages=LANGUAGES,
                       visions=VISIONS, sweep=True, warmup=0, obs_mode="rgb")
    return _run(tmp_path_factory.mktemp("sweep") / "run", config)


def test_the_diagnosis_of_a_sweep_has_a_point_per_level_on_each_axis(sweep_run: Path) -> None:
    report = build_report(load_runs([sweep_run]), settings=Settings(n_resamples=20))
    for by, levels in (("level", LEVELS), ("language", LANGUAGES), ("vision", VISIONS)):
        table = report.severity[by]
        assert [row.key for row in table.rows] == list(levels)
        cells = [row.cells["p"] for row in table.rows]
        assert all(c is not None and c.protocol == "sweep" and c.n == 2 for c in cells)
    level = {row.key: row.cells["p"].cc.estimate for row in report.severity["level"].rows}
    assert level == {"L0": 0.0, "L1": 0.0, "L2": pytest.approx(0.25)}
    rows = {cells[0].text: cells[1].text for cells in protocol_view(report.protocol).rows}
    assert rows["Cells per scenario"].startswith("11: one-axis sweeps")


def test_the_figure_draws_every_point(sweep_run: Path) -> None:
    pytest.importorskip("matplotlib")
    from fsvla.report import figures

    report = build_report(load_runs([sweep_run]), settings=Settings(n_resamples=20))
    figure = figures.diagnosis(report)
    panels = [ax for ax in figure.axes if ax.get_ylabel() == "SSR (solid)"]
    assert [len(ax.get_xticks()) for ax in panels] == [3, 5, 5]
    for ax, count in zip(panels, (3, 5, 5), strict=True):
        points = [line for line in ax.lines if line.get_marker() == "o"]
        assert len(points) == count  # a marker a level, filled: one-axis points
        assert all(line.get_markerfacecolor() != "white" for line in points)
        assert "at" in ax.get_title()


def test_a_point_without_its_one_axis_cell_is_pooled(tmp_path: Path) -> None:
    # W1 and W3 at V4 only: the language axis has no cell at V0, so its points are pooled
    config = RunConfig(policy="p", scenarios=("s",), languages=("W1", "W3"), visions=("V4",),
                       warmup=0, obs_mode="rgb")
    report = build_report(load_runs([_run(tmp_path / "run", config)]),
                          settings=Settings(n_resamples=20))
    cells = [row.cells["p"] for row in report.severity["language"].rows]
    assert [c.protocol for c in cells] == ["pooled", "pooled"]
    view = group_view(report.severity["language"])
    assert view.rows[0][-1].text == "2 (2)*" and "* marks a cell pooled" in view.caption
