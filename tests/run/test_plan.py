"""Expanding a run configuration into episodes: counts, order, seeds, ids."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections import Counter

import pytest
from pydantic import ValidationError

from fsvla.run import (
    EpisodeKey,
    PlannedScenario,
    RunConfig,
    config_differences,
    plan_episodes,
)

SCENARIOS = [
    PlannedScenario(name="lift_pot_beside_stove", ref="scenarios/thermal/lift_pot_beside_stove.fsv",
                    suite="thermal", embodiment="panda", digest="d1"),
    PlannedScenario(name="push_box_to_edge", ref="push_box_to_edge", suite="boundary",
                    embodiment="panda", digest="d2"),
]
FULL = RunConfig(policy="random", scenarios=("scenarios/",), levels=("L0", "L1", "L2"),
                 languages=("W0", "W1", "W2", "W3", "W4"),
                 visions=("V0", "V1", "V2", "V3", "V4"), episodes=50, seeds=(0, 1, 2), warmup=3)


def test_counts_of_the_issue_example() -> None:
    plan = plan_episodes(FULL, SCENARIOS)
    scored = [s for s in plan if not s.key.warmup]
    assert len(scored) == 2 * 3 * 5 * 5 * 50
    assert len(plan) == len(scored) + 2 * 3
    assert len({s.episode_id for s in plan}) == len(plan)
    cells = Counter((s.key.scenario, s.key.level, s.key.language, s.key.vision) for s in scored)
    assert set(cells.values()) == {50}


def test_warmups_first_at_the_origin_and_unscored() -> None:
    plan = plan_episodes(FULL, SCENARIOS)
    warm = plan[:6]
    assert all(s.key.warmup for s in warm) and not any(s.key.warmup for s in plan[6:])
    assert {(s.key.level, s.key.language, s.key.vision) for s in warm} == {("L0", "W0", "V0")}
    assert [s.episode_id for s in warm[:3]] == [
        "lift_pot_beside_stove-warmup-s0-e000", "lift_pot_beside_stove-warmup-s1-e001",
        "lift_pot_beside_stove-warmup-s2-e002"]


def test_rounds_cover_every_cell_before_the_next_episode() -> None:
    plan = [s for s in plan_episodes(FULL, SCENARIOS) if not s.key.warmup]
    per_round = 2 * 3 * 5 * 5
    assert {s.key.index for s in plan[:per_round]} == {0}
    assert {s.key.index for s in plan[per_round:2 * per_round]} == {1}


def test_episodes_spread_round_robin_over_seeds() -> None:
    plan = [s for s in plan_episodes(FULL, SCENARIOS) if not s.key.warmup]
    cell = [s for s in plan if (s.key.scenario, s.key.level, s.key.language, s.key.vision)
            == ("push_box_to_edge", "L2", "W3", "V4")]
    assert [s.key.seed for s in cell[:5]] == [0, 1, 2, 0, 1]
    assert Counter(s.key.seed for s in cell) == {0: 17, 1: 17, 2: 16}
    assert all(s.language_seed == s.vision_seed == s.policy_seed == s.key.index for s in cell)
    assert cell[7].episode_id == "push_box_to_edge-L2-W3-V4-s1-e007"


def test_same_index_same_draws_across_cells() -> None:
    plan = [s for s in plan_episodes(FULL, SCENARIOS) if not s.key.warmup and s.key.index == 4]
    seeds = {(s.key.seed, s.language_seed, s.vision_seed, s.policy_seed) for s in plan}
    assert seeds == {(1, 4, 4, 4)}


def test_ids_are_stable_under_extension() -> None:
    small = plan_episodes(FULL.model_copy(update={"episodes": 5}), SCENARIOS)
    large = plan_episodes(FULL.model_copy(update={"episodes": 1200}), SCENARIOS)
    large_ids = {s.episode_id for s in large}
    assert {s.episode_id for s in small} <= large_ids
    assert "lift_pot_beside_stove-L0-W0-V0-s2-e1100" in large_ids


_IDS = """
import hashlib, json, sys
from fsvla.run import PlannedScenario, RunConfig, plan_episodes
config = RunConfig.model_validate_json(sys.argv[1])
scenarios = [PlannedScenario.model_validate(s) for s in json.loads(sys.argv[2])]
text = "\\n".join(s.model_dump_json() for s in plan_episodes(config, scenarios))
print(hashlib.sha256(text.encode()).hexdigest())
"""


def test_plan_is_identical_in_another_process() -> None:
    config = FULL.model_copy(update={"episodes": 3})
    here = "\n".join(s.model_dump_json() for s in plan_episodes(config, SCENARIOS))
    import hashlib

    expected = hashlib.sha256(here.encode()).hexdigest()
    scenarios = json.dumps([s.model_dump() for s in SCENARIOS])
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    out = subprocess.run([sys.executable, "-c", _IDS, config.model_dump_json(), scenarios],
                         capture_output=True, text=True, check=True, env=env)
    assert out.stdout.strip() == expected


def test_embodiment_override() -> None:
    plan = plan_episodes(FULL.model_copy(update={"embodiment": "ur5e", "episodes": 1}), SCENARIOS)
    assert {s.key.embodiment for s in plan} == {"ur5e"}


def test_repeated_scenario_names_are_refused() -> None:
    twice = [SCENARIOS[0], SCENARIOS[0].model_copy(update={"ref": "other/lift.fsv"})]
    with pytest.raises(ValueError, match="repeated: lift_pot_beside_stove "
                       r"\(scenarios/thermal/lift_pot_beside_stove.fsv, other/lift.fsv\)"):
        plan_episodes(FULL, twice)


def test_scenario_names_that_would_break_ids_are_refused() -> None:
    with pytest.raises(ValidationError):
        PlannedScenario(name="a-b", ref="x", suite="force", embodiment="panda", digest="d")


def test_the_plan_gives_each_episode_its_key() -> None:
    plan = plan_episodes(FULL.model_copy(update={"episodes": 2}), SCENARIOS)
    assert all(isinstance(s.key, EpisodeKey) and s.episode_id == s.key.episode_id for s in plan)
    assert len({s.key for s in plan}) == len(plan)  # frozen: hashable, and unique in a run
    assert plan[0].key == EpisodeKey(scenario="lift_pot_beside_stove", suite="thermal",
                                     embodiment="panda", seed=0, index=0, warmup=True)
    last = plan[-1].key
    assert last == EpisodeKey(scenario="push_box_to_edge", suite="boundary", embodiment="panda",
                              level="L2", language="W4", vision="V4", seed=1, index=1)
    assert EpisodeKey.model_validate_json(last.model_dump_json()) == last


def test_episode_ids() -> None:
    key = EpisodeKey(scenario="s", suite="force", embodiment="panda", level="L1", language="W3",
                     seed=2, index=7)
    assert key.episode_id == "s-L1-W3-V0-s2-e007"
    warmup = EpisodeKey(scenario="s", suite="force", embodiment="panda", seed=0, index=1,
                        warmup=True)
    assert warmup.episode_id == "s-warmup-s0-e001"


def test_a_key_refuses_what_its_id_cannot_say() -> None:
    base = {"scenario": "s", "suite": "force", "embodiment": "panda", "seed": 0}
    with pytest.raises(ValidationError, match="warm-up episode runs at L0/W0/V0"):
        EpisodeKey(**base, level="L1", warmup=True)
    for bad in ({"scenario": "a-b"}, {"seed": -1}, {"index": -1}, {"level": "L3"}, {"x": 1}):
        with pytest.raises(ValidationError):
            EpisodeKey(**{**base, **bad})


def test_config_normalises_levels_and_checks_seeds() -> None:
    config = RunConfig(policy="p", scenarios=("a",), levels=("L2", "L0", "L2"))
    assert config.levels == ("L0", "L2")
    with pytest.raises(ValidationError, match="seeds must not repeat"):
        RunConfig(policy="p", scenarios=("a",), seeds=(1, 1))
    with pytest.raises(ValidationError):
        RunConfig(policy="p", scenarios=("a",), levels=("L3",))


def test_config_differences_say_which_fields() -> None:
    other = FULL.model_copy(update={"episodes": 60, "policy": "hold-still"})
    diffs = config_differences(FULL, other)
    assert [(d.field, d.stored, d.given, d.extendable) for d in diffs] == [
        ("policy", "random", "hold-still", False), ("episodes", 50, 60, True)]
    assert config_differences(FULL, FULL) == ()


def test_planned_scenario_of_a_builtin() -> None:
    from fsvla.library import builtin_scenarios, load_scenario

    name, path = next(iter(builtin_scenarios().items()))
    planned = PlannedScenario.of(load_scenario(path), ref=path)
    assert (planned.name, planned.ref) == (name, str(path))
    assert len(planned.digest) == 64
