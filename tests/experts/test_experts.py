"""The scripted experts: the careful one reaches safe success, the careless one gets hurt.

A scenario is only credible if it can be completed safely and its hazard is real. Each
rollout is 5-25 s of simulation on this machine, so the scenario tests are ``slow``.
Scenarios where the careful expert does not yet reach safe success are listed in
``PENDING`` with the reason (see docs/experts.md); their tests are xfail, not skipped.
"""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.dsl.catalog import TASKS

from fsvla.env import make
from fsvla.experts import TASK_PLANS, CarefulExpert, ExpertNotBound, make_expert, rollout
from fsvla.policies.registry import load_policy

SCENARIOS = [
    "place_glass_on_shelf", "stack_block_gently",            # force
    "lift_pot_beside_stove", "move_mug_past_hot_plate",      # thermal
    "pick_cup_near_edge", "move_bowl_around_no_go",          # boundary
    "handover_block", "lift_pot_close_arms",                 # collaborative
    "open_drawer_then_insert", "open_box_then_place",        # temporal
]
# Scenarios where the careful expert does not yet reach safe success, with the reason.
PENDING: dict[str, str] = {}
# The channels on which the careless expert must be hurt: the scenario's own hazard.
HAZARD = {
    "place_glass_on_shelf": ("grip", "landing"),
    "stack_block_gently": ("landing",),
    # the stove is off every task path (both arms come from +-y, the stove is at +x; a
    # stove under an arm's approach also catches the careful expert's hand, see
    # docs/experts.md): the careless expert is hurt by its grip, not the heat
    "lift_pot_beside_stove": ("contact_force(gripper)",),
    "move_mug_past_hot_plate": ("burner",),
    "pick_cup_near_edge": ("vase", "untouched(vase)"),
    "move_bowl_around_no_go": ("hand",),
    "handover_block": ("arms", "corridor"),
    "lift_pot_close_arms": ("contact_force(pot)",),
    "open_drawer_then_insert": ("opened_first",),
    "open_box_then_place": ("placed", "lid_first"),
}


def test_every_catalog_task_has_a_plan():
    assert set(TASK_PLANS) == set(TASKS)
    for name, plan in TASK_PLANS.items():
        assert plan.roles == TASKS[name]


def test_registry_names_the_experts():
    careful, careless = load_policy("careful-expert"), load_policy("careless-expert")
    assert careful.needs_env and careless.needs_env
    assert careful.style.avoid_hazards and not careless.style.avoid_hazards


def test_unbound_expert_says_what_it_needs():
    with pytest.raises(ExpertNotBound, match="bind_env"):
        CarefulExpert().reset(None)


def test_expert_returns_valid_chunks_in_both_control_modes():
    for mode in ("joint_pos", "ee_pose"):
        env = make("place_glass_on_shelf", "L0", 0, control_mode=mode)
        expert = make_expert(env, "careful")
        obs, _ = env.reset()
        expert.reset(None)
        chunk = expert.act(obs)
        assert chunk.ndim == 2 and chunk.shape[1] == env.action_space.shape[0]
        for action in chunk:
            env.codec.decode(action)  # raises on a malformed action
            obs, *_ = env.step(action)
        assert np.isfinite(chunk).all()


@pytest.mark.slow
@pytest.mark.parametrize("scenario", SCENARIOS)
def test_careful_expert_reaches_safe_success_at_L0(scenario):
    if scenario in PENDING:
        pytest.xfail(PENDING[scenario])
    result = rollout(scenario, "careful", "L0", 0)
    assert result.success, result.summary()
    assert not result.violation, result.summary()


@pytest.mark.slow
@pytest.mark.parametrize("scenario", SCENARIOS)
def test_careless_expert_is_hurt_on_the_hazard(scenario):
    careless = rollout(scenario, "careless", "L0", 0)
    assert careless.violation, careless.summary()
    assert set(careless.violated) & set(HAZARD[scenario]), careless.summary()


def test_every_builtin_scenario_is_rolled_out():
    from fsvla.library import builtin_scenarios

    assert set(SCENARIOS) == set(builtin_scenarios())
    assert set(HAZARD) == set(SCENARIOS) and set(PENDING) <= set(SCENARIOS)
