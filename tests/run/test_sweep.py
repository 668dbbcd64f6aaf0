"""``sweep``: one dimension at a time from L0/W0/V0, 11 cells a scenario, not the grid."""

from __future__ import annotations

from collections import Counter

import pytest
from pydantic import ValidationError

from fsvla.run import PlannedScenario, RunConfig, config_differences, plan_episodes
from fsvla.run.config import GRID_FIELDS, LANGUAGES, LEVELS, VISIONS

SCENARIOS = [
    PlannedScenario(name="a", ref="a", suite="thermal", embodiment="panda", digest="d1"),
    PlannedScenario(name="b", ref="b", suite="force", embodiment="panda", digest="d2"),
]
SWEEP = RunConfig(policy="p", scenarios=("s",), levels=LEVELS, languages=LANGUAGES,
                  visions=VISIONS, sweep=True, episodes=3, warmup=1, obs_mode="rgb")


def test_a_sweep_plans_eleven_cells_a_scenario() -> None:
    assert SWEEP.cells() == (
        ("L0", "W0", "V0"), ("L1", "W0", "V0"), ("L2", "W0", "V0"),
        ("L0", "W1", "V0"), ("L0", "W2", "V0"), ("L0", "W3", "V0"), ("L0", "W4", "V0"),
        ("L0", "W0", "V1"), ("L0", "W0", "V2"), ("L0", "W0", "V3"), ("L0", "W0", "V4"))
    plan = [s for s in plan_episodes(SWEEP, SCENARIOS) if not s.key.warmup]
    cells = Counter((s.key.scenario, s.key.level, s.key.language, s.key.vision) for s in plan)
    assert len(cells) == 2 * 11 and set(cells.values()) == {3}  # the origin once, not thrice
    assert len(plan) == 2 * 11 * 3
    for s in plan:  # every cell varies one dimension at most
        assert sum((s.key.level != "L0", s.key.language != "W0", s.key.vision != "V0")) <= 1


def test_without_sweep_the_grid() -> None:
    grid = SWEEP.model_copy(update={"sweep": False})
    assert len(grid.cells()) == 3 * 5 * 5


def test_a_sweep_starts_at_the_origin() -> None:
    with pytest.raises(ValidationError, match="must include L0, W0 and V0"):
        RunConfig(policy="p", scenarios=("s",), levels=("L1", "L2"), sweep=True)
    partial = RunConfig(policy="p", scenarios=("s",), levels=("L0", "L2"), sweep=True)
    assert partial.cells() == (("L0", "W0", "V0"), ("L2", "W0", "V0"))


def test_a_sweep_can_be_extended_to_the_grid() -> None:
    assert "sweep" in GRID_FIELDS
    [difference] = config_differences(SWEEP, SWEEP.model_copy(update={"sweep": False}))
    assert (difference.field, difference.extendable) == ("sweep", True)
