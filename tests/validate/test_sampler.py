"""The scenario sampler: every draw checks clean (also ``--deep``), lowers at every level,
covers every task and embodiment, and is a pure function of its seed; a few draws roll out
with both experts as recorded outcomes."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.catalog import EMBODIMENTS, TASKS
from fsvla.dsl.loader import ScenarioLoader
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fsvla.validate.sampler import (
    GRIPPER_OPENING,
    REACH,
    capable_embodiments,
    sample_scenario,
    sample_scenarios,
    scenario_problems,
)

SEEDS = st.integers(min_value=0, max_value=2**31 - 1)


def lowers(text: str) -> None:
    """The draw lowers as ``fsvla compile`` does, at L0, L1 and L2."""
    from fsvla.compiler.variants import generate_variant

    scenario = ScenarioLoader().loads(text, "sampled.fsv").scenario
    assert scenario is not None
    for level in ("L0", "L1", "L2"):
        generate_variant(scenario, level, 0)


@given(seed=SEEDS)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_every_draw_checks_clean_and_lowers(seed: int) -> None:
    sampled = sample_scenario(seed, deep=False)
    result = ScenarioLoader().loads(sampled.text, "sampled.fsv")
    assert result.ok, (sampled.text, result.errors)
    assert not result.diagnostics, (sampled.text, result.diagnostics)
    assert result.scenario is not None and result.scenario.name == sampled.name
    assert result.scenario.task.name == sampled.task
    assert result.scenario.embodiment == sampled.embodiment
    lowers(sampled.text)


@pytest.mark.sim
@given(seed=SEEDS)
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_every_draw_passes_the_static_checks(seed: int) -> None:
    sampled = sample_scenario(seed)
    assert scenario_problems(sampled.text, deep=True) == [], sampled.text


@given(seed=SEEDS, task=st.sampled_from(tuple(TASKS)), data=st.data())
@settings(max_examples=40, deadline=None)
def test_the_same_seed_draws_the_same_text(seed: int, task: str, data: st.DataObject) -> None:
    embodiment = data.draw(st.sampled_from(capable_embodiments(task)))
    first = sample_scenario(seed, task=task, embodiment=embodiment, deep=False)
    again = sample_scenario(seed, task=task, embodiment=embodiment, deep=False)
    assert first == again
    assert (first.task, first.embodiment) == (task, embodiment)


def test_every_task_and_embodiment_is_drawn() -> None:
    drawn = sample_scenarios(3 * len(TASKS), deep=False)
    assert {s.task for s in drawn} == set(TASKS)
    assert {s.embodiment for s in drawn} == set(EMBODIMENTS)
    assert {s.suite for s in drawn} >= {"force", "thermal", "boundary", "collaborative", "temporal"}
    unguided = {sample_scenario(seed, deep=False).embodiment for seed in range(40)}
    assert unguided == set(EMBODIMENTS)


def test_two_arm_tasks_only_on_two_arm_robots() -> None:
    assert capable_embodiments("handover") == ("dual_panda", "baxter")
    with pytest.raises(ValueError, match="two-arm"):
        sample_scenario(0, task="bimanual_lift", embodiment="so101")
    with pytest.raises(ValueError, match="unknown task"):
        sample_scenario(0, task="juggle")


@pytest.mark.sim
def test_the_sampler_tables_match_the_robot_models() -> None:
    """GRIPPER_OPENING is what the robot models measure, and REACH's corners are reached."""
    from fsvla.embodiments import load_embodiment
    from fsvla.validate.robots import robot_model

    for name in EMBODIMENTS:
        model = robot_model(load_embodiment(name))
        assert min(model.opening(arm) for arm in model.arms) == pytest.approx(
            GRIPPER_OPENING[name], abs=2e-3)
        x0, x1, y0, y1 = REACH[name]
        for x, y in ((x0, 0.0), (x1, 0.0), ((x0 + x1) / 2, y0), ((x0 + x1) / 2, y1)):
            assert min(model.reach_gap(arm, (x, y, 0.02)) for arm in model.arms) == 0.0, (name, x, y)


@pytest.mark.slow
@pytest.mark.sim
def test_sampled_scenarios_roll_out_as_recorded_outcomes(tmp_path: Path) -> None:
    """Both experts at L0 on four draws: every episode is recorded (an expert that fails
    says why), none crashes the runner. Rates are the bench's business, not this test's."""
    from fsvla.results import ResultStore
    from fsvla.runner import execute_run, make_backend, make_config, prepare_run

    folder = tmp_path / "scenarios"
    folder.mkdir()
    drawn = sample_scenarios(4, start=0)
    for sampled in drawn:
        (folder / sampled.filename()).write_text(sampled.text, encoding="utf-8")
    for expert in ("careful", "careless"):
        config = make_config(policy=f"{expert}-expert", scenarios=(str(folder),), levels=("L0",),
                             episodes=1, seeds=(0,), warmup=0, obs_mode="state")
        run_dir = tmp_path / expert
        result = execute_run(prepare_run(config), run_dir, make_backend("process", config, 1))
        assert result.recorded == len(drawn)
        with ResultStore.open(run_dir, readonly=True) as store:
            rows = store.episodes(include_warmup=False)
        assert len(rows) == len(drawn)
        for row in rows:
            assert row.status == "completed" or row.failure_reason == "policy_error", row
            assert row.failure_reason != "sim_error", (row.key.scenario, row.failure_detail)
            if row.status == "faulted":
                assert row.failure_detail, row


@pytest.mark.sim
@given(seed=SEEDS, task=st.sampled_from(("press", "push", "lift", "open", "close", "pick_place")))
@settings(max_examples=8, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
def test_a_draw_starts_outside_every_warning_band(tmp_path: Path, seed: int, task: str) -> None:
    """The robot at home, held still, is outside every warning band at every level: an
    episode whose layout starts inside one refuses to start (FSV604), so a hazard drawn
    beside the arm's home pose (a hot kettle under a Z1's hand) is no scenario."""
    from fsvla.env import make
    from fsvla.policies.simple import hold_action

    sampled = sample_scenario(seed, task=task, deep=False)
    path = tmp_path / sampled.filename()
    path.write_text(sampled.text, encoding="utf-8")
    for level in ("L0", "L1", "L2"):
        env = make(str(path), level, seed)
        try:
            observation, _ = env.reset()
            arms = len(observation["agent"]["gripper"])
            hold = hold_action(observation, "joint_pos", [len(observation["agent"]["qpos"]) // arms] * arms)
            for _ in range(5):
                observation, _, _, _, info = env.step(hold)
                assert [c for c, s in info["states"].items() if s != "safe"] == [], (level, sampled.text)
        finally:
            env.close()


@given(seed=SEEDS)
@settings(max_examples=10, deadline=None)
def test_a_pour_succeeds_only_while_the_container_is_held(seed: int) -> None:
    """Tipped near the target is not a pour when the container has slipped out of the hand
    and lies on its side beside it: the success asks that it is held."""
    sampled = sample_scenario(seed, task="pour", deep=False)
    success = next(line.strip() for line in sampled.text.splitlines()
                   if line.strip().startswith("success "))
    obj = sampled.roles["object"]
    assert f"tilted({obj}," in success and f"grasped({obj})" in success, success
