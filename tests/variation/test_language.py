"""The language dimension: W0-W4 instructions, seeded, from templates or the scenario."""

from __future__ import annotations

import pytest
from fsvla.dsl.catalog import TASKS
from fsvla.library import builtin_scenarios, load_scenario
from fsvla.variation.language import _table, instruction_for

LEVELS = ("W0", "W1", "W2", "W3", "W4")


@pytest.fixture(scope="module")
def scenarios():
    return {name: load_scenario(name) for name in builtin_scenarios()}


def test_w0_is_the_canonical_instruction(scenarios) -> None:
    for scenario in scenarios.values():
        assert instruction_for(scenario, "W0", seed=7).text == scenario.instruction


def test_same_seed_same_text_and_seeds_vary_the_choice(scenarios) -> None:
    scenario = scenarios["pick_cup_near_edge"]
    for level in LEVELS:
        assert instruction_for(scenario, level, 3) == instruction_for(scenario, level, 3)
    texts = {instruction_for(scenario, "W1", seed).text for seed in range(20)}
    assert len(texts) > 1


def test_the_scenario_language_block_wins(scenarios) -> None:
    scenario = scenarios["lift_pot_beside_stove"]
    written = {v.text for v in scenario.language["W1"]}
    for seed in range(5):
        chosen = instruction_for(scenario, "W1", seed)
        assert chosen.origin == "scenario" and chosen.text in written


def test_w3_uses_the_categories_the_scenario_writes(scenarios) -> None:
    scenario = scenarios["lift_pot_beside_stove"]  # writes W3 unsafe and ambiguous
    categories = {instruction_for(scenario, "W3", seed).category for seed in range(30)}
    assert categories == {"unsafe", "ambiguous"}
    chosen = instruction_for(scenario, "W3", 0)
    assert chosen.metric_category == f"{chosen.category}_instruction"


def test_w4_appends_a_hijacking_suffix_to_the_canonical_instruction(scenarios) -> None:
    for scenario in scenarios.values():
        chosen = instruction_for(scenario, "W4", 1)
        assert chosen.category == "hijack"
        assert chosen.text.startswith(scenario.instruction)
        assert len(chosen.text) > len(scenario.instruction)


def test_template_words_name_the_scenario_objects(scenarios) -> None:
    chosen = instruction_for(scenarios["pick_cup_near_edge"], "W2", 0)
    assert chosen.origin == "template:pick_place"
    assert "mug" in chosen.text and "tray" in chosen.text


def test_every_task_has_paraphrase_and_compositional_templates() -> None:
    table = _table()
    for task in TASKS:
        assert task in table, f"no instruction templates for base task {task}"
        assert table[task].get("W1") and table[task].get("W2")
        assert table[task].get("verb") and table[task].get("done")


@pytest.mark.parametrize("level", LEVELS)
def test_every_level_renders_for_every_scenario_and_seed(scenarios, level: str) -> None:
    for scenario in scenarios.values():
        for seed in range(8):
            text = instruction_for(scenario, level, seed).text
            assert text and "{{" not in text and "  " not in text
