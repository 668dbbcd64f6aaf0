"""Every scored episode draws its own layout, from the run seed and its index."""

from __future__ import annotations

import math
from collections import Counter

from fsvla.compiler.pose import quat_yaw
from fsvla.compiler.variants import NUISANCE_DISTANCE, NUISANCE_YAW, generate_variant

from fsvla.library import load_scenario
from fsvla.results.models import layout_digest
from fsvla.run import PlannedScenario, RunConfig, layout_seed, plan_episodes

STOVE = load_scenario("lift_pot_beside_stove")
PLANNED = [PlannedScenario.of(STOVE, ref="lift_pot_beside_stove")]


def _plan(**fields):
    config = RunConfig(policy="p", scenarios=("lift_pot_beside_stove",), **fields)
    return [s for s in plan_episodes(config, PLANNED) if not s.key.warmup]


def test_each_episode_of_a_cell_has_its_own_layout_seed() -> None:
    plan = _plan(levels=("L0", "L1"), languages=("W0", "W3"), episodes=50, seeds=(0, 1, 2))
    cells = Counter((s.key.level, s.key.language) for s in plan)
    assert set(cells.values()) == {50}
    for cell in cells:
        seeds = [s.layout_seed for s in plan if (s.key.level, s.key.language) == cell]
        assert len(set(seeds)) == 50  # not 3 layouts repeated ~17 times
    # the same index shares its layout seed across the cells (common random numbers)
    by_index = {}
    for s in plan:
        by_index.setdefault(s.key.index, set()).add(s.layout_seed)
    assert all(len(seeds) == 1 for seeds in by_index.values())
    assert all(s.layout_seed == layout_seed(s.key.seed, s.key.index) for s in plan)


def test_one_run_seed_still_gives_a_layout_per_episode_and_warmups_apart() -> None:
    config = RunConfig(policy="p", scenarios=("x",), episodes=5, seeds=(7,), warmup=2)
    plan = plan_episodes(config, PLANNED)
    warm = [s.layout_seed for s in plan if s.key.warmup]
    scored = [s.layout_seed for s in plan if not s.key.warmup]
    assert len(set(scored)) == 5 and not set(warm) & set(scored)
    assert all(0 <= s < 2**31 for s in warm + scored)
    assert layout_seed(7, 3) == layout_seed(7, 3) != layout_seed(8, 3)


def _layouts(level: str, scenario=STOVE, episodes: int = 5):
    plan = _plan(levels=(level,), episodes=episodes, seeds=(0,))
    return [generate_variant(scenario, level, s.layout_seed) for s in plan]


def test_five_l1_episodes_have_five_distinct_layouts() -> None:
    variants = _layouts("L1")
    assert len({layout_digest(v.scene) for v in variants}) == 5


def test_l0_episodes_differ_only_within_the_nuisance_bounds() -> None:
    variants = _layouts("L0")
    assert len({layout_digest(v.scene) for v in variants}) == 5
    canonical = generate_variant(
        STOVE.model_copy(update={"variants": {**STOVE.variants, "L0": ()}}), "L0").scene
    for variant in variants:
        for body in variant.scene.bodies:
            before = canonical.body(body.name)
            move = math.dist(body.pose.position, before.pose.position)
            turn = quat_yaw(body.pose.quaternion) - quat_yaw(before.pose.quaternion)
            turn = abs((turn + math.pi) % (2 * math.pi) - math.pi)
            if body.name == "pot":  # the task's object
                assert 0 < move <= NUISANCE_DISTANCE + 1e-9 and turn <= NUISANCE_YAW + 1e-9
            else:
                assert (move, turn) == (0.0, 0.0), body.name
        assert variant.scene.zones == canonical.zones


def test_without_a_nuisance_every_l0_episode_shares_one_layout() -> None:
    fixed = STOVE.model_copy(update={"variants": {**STOVE.variants, "L0": ()}})
    variants = _layouts("L0", fixed)
    assert len({v.scene.seed for v in variants}) == 5  # five seeds ...
    assert len({layout_digest(v.scene) for v in variants}) == 1  # ... one layout, one unit
