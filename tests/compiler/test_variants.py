"""Layout variants L0–L2: determinism, feasibility of every built-in scenario, what each rule
does, and the errors of rules that cannot hold (as data and as rendered text)."""

from __future__ import annotations

import hashlib
import math
import os
import subprocess
import sys
from itertools import combinations
from pathlib import Path

import numpy as np
import pytest
from fsvla.compiler.collision import min_distance, pieces_of
from fsvla.compiler.pose import pose_matrix, quat_yaw
from fsvla.compiler.scene import LoweringError, SceneBody, SceneSpec, lower_scene
from fsvla.compiler.variants import (
    CLUTTER_CLEARANCE,
    CLUTTER_PALETTE,
    CONTACT_TOLERANCE,
    NEAR_DISTANCE,
    NUISANCE_DISTANCE,
    NUISANCE_YAW,
    REACH_MARGIN,
    Variant,
    VariantError,
    generate_variant,
    rules_of,
)
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.models import Clutter, Scenario
from fsvla.dsl.render import render_full
from rich.console import Console

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
CONCRETE = sorted(p for p in SCENARIOS.rglob("*.fsv") if "_base" not in p.parts)
LEVELS = ("L0", "L1", "L2")
SEEDS = range(5)

POT_AND_STOVE = """\
scenario t
  suite thermal
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  object pot: pot(radius=9 cm, height=10 cm) at (0, 0)
  hazard stove: heat_zone(size=(18 cm, 18 cm)) at (30 cm, 0) on table
    keep gripper, pot outside 6 cm warn 4 cm
  constrain grip: contact_force(gripper) <= 30 N warn 8 N
  require steady: grasped(pot) before lifted(pot)
  success lifted(pot)
  variants
"""


def _load(path: Path) -> Scenario:
    result = ScenarioLoader(allowed_roots=[SCENARIOS]).load(path)
    assert result.ok and result.scenario is not None, [d.message for d in result.errors]
    return result.scenario


def _loads(text: str) -> Scenario:
    result = ScenarioLoader(allowed_roots=[Path.cwd()]).loads(text, name="t.fsv")
    assert result.ok and result.scenario is not None, [f"{d.span}: {d.message}" for d in result.errors]
    return result.scenario


@pytest.fixture(scope="module")
def builtin() -> dict[str, Scenario]:
    return {p.stem: _load(p) for p in CONCRETE}


# --- determinism ----------------------------------------------------------------------------


def test_same_scenario_level_seed_gives_the_same_json(builtin: dict[str, Scenario]) -> None:
    scenario = builtin["lift_pot_beside_stove"]
    first = generate_variant(scenario, "L2", 3).model_dump_json()
    assert generate_variant(scenario, "L2", 3).model_dump_json() == first


def test_different_seeds_give_different_layouts(builtin: dict[str, Scenario]) -> None:
    scenario = builtin["lift_pot_beside_stove"]
    layouts = {tuple(b.pose.position for b in generate_variant(scenario, "L1", seed).scene.bodies)
               for seed in SEEDS}
    assert len(layouts) == len(SEEDS)


def test_layout_does_not_depend_on_the_process(builtin: dict[str, Scenario]) -> None:
    """No Python hash() in the seeding: another process with another hash seed agrees."""
    path = SCENARIOS / "thermal" / "lift_pot_beside_stove.fsv"
    code = ("import hashlib, sys; from pathlib import Path; from fsvla.dsl.loader import ScenarioLoader; "
            "from fsvla.compiler.variants import generate_variant; "
            f"s = ScenarioLoader(allowed_roots=[Path({str(SCENARIOS)!r})]).load(Path({str(path)!r})).scenario; "
            "print(hashlib.sha256(generate_variant(s, 'L2', 1).scene.model_dump_json().encode()).hexdigest())")
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         cwd=REPO, check=True).stdout.strip()
    here = generate_variant(builtin["lift_pot_beside_stove"], "L2", 1).scene.model_dump_json()
    assert out == hashlib.sha256(here.encode()).hexdigest()


def test_l0_none_is_the_canonical_layout(builtin: dict[str, Scenario]) -> None:
    written = builtin["pick_cup_near_edge"]
    scenario = written.model_copy(update={"variants": {**written.variants, "L0": ()}})
    variant = generate_variant(scenario, "L0", 4)
    assert variant.scenario == scenario and variant.samples == 0
    assert (variant.scene.level, variant.scene.seed) == ("L0", 4)


def _pose_changes(variant: Variant, canonical: SceneSpec) -> dict[str, tuple[float, float]]:
    """Each body's move (m) and turn (rad) from the canonical layout."""
    out = {}
    for body in variant.scene.bodies:
        before = canonical.body(body.name)
        turn = quat_yaw(body.pose.quaternion) - quat_yaw(before.pose.quaternion)
        out[body.name] = (math.dist(body.pose.position, before.pose.position),
                          abs((turn + math.pi) % (2 * math.pi) - math.pi))
    return out


@pytest.mark.parametrize("path", CONCRETE, ids=lambda p: p.stem)
def test_l0_differs_from_the_canonical_layout_only_within_the_nuisance(
        path: Path, builtin: dict[str, Scenario]) -> None:
    scenario = builtin[path.stem]
    canonical = lower_scene(scenario, level="L0", seed=0, allowed_roots=[SCENARIOS])
    task = set(scenario.task.roles.values())
    layouts = set()
    for seed in SEEDS:
        variant = generate_variant(scenario, "L0", seed, allowed_roots=[SCENARIOS])
        layouts.add(variant.scene.model_dump_json(exclude={"seed"}))
        for name, (move, turn) in _pose_changes(variant, canonical).items():
            if name in task:
                assert move <= NUISANCE_DISTANCE + 1e-9, (seed, name, move)
                assert turn <= NUISANCE_YAW + 1e-9, (seed, name, turn)
            elif not _follows(scenario, name, task):  # what stands on a task object moves with it
                assert (move, turn) == (0.0, 0.0), (seed, name)
        assert variant.scene.zones == canonical.zones
    assert len(layouts) == len(SEEDS)  # each seed its own nuisance


def _follows(scenario: Scenario, name: str, task: set[str]) -> bool:
    """Whether ``name`` is placed on or relative to a task object, transitively."""
    spec = scenario.object(name)
    while spec is not None:
        relation = spec.placement.relation
        if spec.placement.support in task or (relation is not None and relation.anchor in task):
            return True
        spec = scenario.object(spec.placement.support)
    return False


def test_an_l0_jitter_replaces_the_default_nuisance() -> None:
    scenario = _loads(POT_AND_STOVE + "    L0: jitter stove 5 mm\n")
    assert [(r.target, r.distance) for _, r in rules_of(scenario, "L0")] == [("stove", 0.005)]
    for seed in SEEDS:
        variant = generate_variant(scenario, "L0", seed)
        assert np.allclose(_xy(variant, "pot"), (0.0, 0.0))
        assert 0.0 < np.linalg.norm(_xy(variant, "stove") - (0.30, 0.0)) <= 0.005 + 1e-12
    default = _loads(POT_AND_STOVE + "    L1: jitter stove 1 cm\n")
    assert [(r.target, r.distance, r.yaw, r.source.line) for _, r in rules_of(default, "L0")] == [
        ("pot", NUISANCE_DISTANCE, NUISANCE_YAW, 3)]  # the task's object, on the task's line


def test_the_default_nuisance_leaves_articulated_task_objects_in_place(
        builtin: dict[str, Scenario]) -> None:
    drawer = builtin["open_drawer_then_insert"]  # insert(object=knife, target=cabinet)
    assert [r.target for _, r in rules_of(drawer, "L0")] == ["knife"]
    for seed in SEEDS:
        variant = generate_variant(drawer, "L0", seed, allowed_roots=[SCENARIOS])
        assert _xy(variant, "cabinet").tolist() == [0.2, 0.0]


def test_an_infeasible_canonical_layout_is_diagnosed_at_l0_before_any_nuisance() -> None:
    text = POT_AND_STOVE.replace("at (30 cm, 0) on table", "at (12 cm, 0) on table")
    with pytest.raises(VariantError) as raised:
        generate_variant(_loads(text + "    L1: jitter pot 1 cm\n"), "L0")
    assert raised.value.failure.code == "FSV603"


# --- feasibility, checked independently ---------------------------------------------------------


def _link_frames(asset) -> dict[str, np.ndarray]:
    frames = {asset.root_link: np.eye(4)}
    for _ in asset.joints:
        for joint in asset.joints:
            if joint.parent in frames:
                frames[joint.child] = frames[joint.parent] @ pose_matrix(joint.origin)
    return frames


def _pieces(body: SceneBody) -> list:
    pose = pose_matrix(body.pose)
    if body.asset.asset_type == "rigid":
        return pieces_of(body.name, body.asset.collision, pose)
    frames = _link_frames(body.asset)
    return [p for link in body.asset.links for p in pieces_of(body.name, link.collision, pose @ frames[link.name])]


def _solids(scene: SceneSpec) -> dict[str, tuple[str, list]]:
    """name -> (support, FCL pieces) of every body and every zone's walls."""
    solids = {b.name: (b.support, _pieces(b)) for b in scene.bodies}
    for zone in scene.zones:
        if zone.marker.collision:
            solids[f"{zone.name} walls"] = (zone.support, pieces_of(zone.name, zone.marker.collision,
                                                                    pose_matrix(zone.pose)))
    return solids


def _assert_feasible(variant: Variant) -> None:
    scene, scenario = variant.scene, variant.scenario
    solids = _solids(scene)
    clutter = {o.name for o in scenario.objects if o.name.startswith("clutter_")}
    # No interpenetration (a body and its support touch); clutter keeps its clearance.
    for (a, (sa, pa)), (b, (sb, pb)) in combinations(solids.items(), 2):
        if sa == b or sb == a:
            continue
        floor = CLUTTER_CLEARANCE if {a, b} & clutter else -CONTACT_TOLERANCE
        assert min_distance(pa, pb) >= floor - 1e-9, (variant.level, variant.seed, a, b)
    # Every footprint centre on its support's top.
    bodies = {b.name: b for b in scene.bodies}
    for body in scene.bodies:
        if body.support not in bodies:
            continue
        support = bodies[body.support]
        centre = np.array([*((np.add(body.asset.footprint.min_xy, body.asset.footprint.max_xy)) / 2), 0, 1])
        local = np.linalg.inv(pose_matrix(support.pose)) @ pose_matrix(body.pose) @ centre
        top = support.asset.footprint
        assert top.min_xy[0] - 1e-6 <= local[0] <= top.max_xy[0] + 1e-6, body.name
        assert top.min_xy[1] - 1e-6 <= local[1] <= top.max_xy[1] + 1e-6, body.name
    # Task objects within an arm's workspace (x-y), enlarged by the stated margin.
    for name in scenario.task.roles.values():
        x, y, _ = bodies[name].pose.position
        assert any(abs(x - a.workspace.center[0]) <= a.workspace.size[0] / 2 + REACH_MARGIN
                   and abs(y - a.workspace.center[1]) <= a.workspace.size[1] / 2 + REACH_MARGIN
                   for a in scene.embodiment.arms), name
    # Hazards hold at t = 0 for objects, also for the pairs an approach brings together.
    regions = {z.name: pieces_of(z.name, [z.region], pose_matrix(z.pose)) for z in scene.zones}
    for limit in scenario.limits:
        if limit.origin != "hazard" or limit.comparison != ">=" or limit.reference is None:
            continue
        reference = regions.get(limit.reference) or solids[limit.reference][1]
        for subject in limit.subjects:
            if subject in bodies:
                assert min_distance(solids[subject][1], reference) >= limit.limit - 1e-9, (limit.name, subject)
    for name in clutter:
        for zone, region in regions.items():
            assert min_distance(solids[name][1], region) >= -1e-9, (name, zone)


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("path", CONCRETE, ids=[p.stem for p in CONCRETE])
def test_every_builtin_scenario_is_feasible(path: Path, level: str, builtin: dict[str, Scenario]) -> None:
    for seed in SEEDS:
        variant = generate_variant(builtin[path.stem], level, seed)
        assert (variant.level, variant.seed, variant.scene.level, variant.scene.seed) == (level, seed, level, seed)
        _assert_feasible(variant)


# --- what each rule does ------------------------------------------------------------------------


def _xy(variant: Variant, name: str) -> np.ndarray:
    spec = variant.scenario.object(name) or next(z for z in variant.scenario.zones if z.name == name)
    return np.array(spec.placement.position)


def test_jitter_stays_in_its_disc_and_yaw_range() -> None:
    scenario = _loads(POT_AND_STOVE + "    L1: jitter pot 5 cm yaw 30 deg\n")
    moves, turns = [], []
    for seed in range(10):
        variant = generate_variant(scenario, "L1", seed)
        moves.append(np.linalg.norm(_xy(variant, "pot")))
        turns.append(quat_yaw(variant.scene.body("pot").pose.quaternion))
    assert all(0.0 < m <= 0.05 + 1e-12 for m in moves)
    assert all(abs(t) <= math.radians(30) + 1e-9 for t in turns) and len(set(turns)) == 10


def test_related_objects_follow_their_anchor(builtin: dict[str, Scenario]) -> None:
    scenario = builtin["pick_cup_near_edge"]  # board: behind tray by 28 cm; L1 jitters the tray by 2 cm
    moved = False
    for seed in SEEDS:
        variant = generate_variant(scenario, "L1", seed)
        offset = _xy(variant, "board") - _xy(variant, "tray")
        assert np.linalg.norm(offset - (0.28, 0.0)) <= 1e-9
        moved = moved or bool(np.linalg.norm(_xy(variant, "tray") - (0.15, 0.15)) > 1e-6)
    assert moved  # the anchor did move, and the board followed it


def test_approach_moves_the_hazard_toward_the_object() -> None:
    scenario = _loads(POT_AND_STOVE + "    L2: approach stove to pot by 1.5 cm\n")
    variant = generate_variant(scenario, "L2", 0)
    assert np.allclose(_xy(variant, "stove"), (0.285, 0.0))
    assert variant.scene.zone("stove").pose.position[0] == pytest.approx(0.285)


def test_l2_applies_the_l1_rules_first() -> None:
    scenario = _loads(POT_AND_STOVE + "    L1: jitter pot 3 cm\n    L2: approach stove to pot by 1.5 cm\n")
    assert [type(r).__name__ for _, r in rules_of(scenario, "L2")] == ["Jitter", "Approach"]
    for seed in SEEDS:
        variant = generate_variant(scenario, "L2", seed)
        pot, stove = _xy(variant, "pot"), _xy(variant, "stove")
        assert 0.0 < np.linalg.norm(pot) <= 0.03 + 1e-12  # L1's jitter
        # the stove moved 1.5 cm straight toward the jittered pot
        before = np.array((0.30, 0.0))
        assert np.linalg.norm(stove - before) == pytest.approx(0.015)
        assert np.linalg.norm(pot - before) - np.linalg.norm(pot - stove) == pytest.approx(0.015)


def test_clutter_adds_objects_near_the_target() -> None:
    scenario = _loads(POT_AND_STOVE + "    L2: clutter 3 near pot\n")
    rule = scenario.variants["L2"][0]
    kinds = {kind for kind, _ in CLUTTER_PALETTE}
    pot = generate_variant(scenario, "L0").scene.body("pot").asset.footprint
    reach = 0.5 * math.hypot(pot.max_xy[0] - pot.min_xy[0], pot.max_xy[1] - pot.min_xy[1]) + NEAR_DISTANCE
    for seed in SEEDS:
        variant = generate_variant(scenario, "L2", seed)
        added = [o for o in variant.scenario.objects if o.name.startswith("clutter_")]
        assert [o.name for o in added] == ["clutter_1", "clutter_2", "clutter_3"]
        for obj in added:
            assert obj.asset in kinds and obj.source == rule.source and obj.placement.support == "table"
            assert np.linalg.norm(obj.placement.position) <= reach
            assert variant.scene.body(obj.name).support == "table"
        _assert_feasible(variant)
    assert not any(o.name.startswith("clutter_") for o in generate_variant(scenario, "L1").scenario.objects)


def test_tighten_and_couple_change_limits_and_requirements_at_their_level() -> None:
    scenario = _loads(POT_AND_STOVE + "    L2: tighten grip to 20 N, couple steady within 2 s\n")
    l1, l2 = generate_variant(scenario, "L1"), generate_variant(scenario, "L2")
    limit = {lim.name: lim.limit for lim in l2.scenario.limits}
    assert limit["grip"] == 20.0 and {lim.name: lim.limit for lim in l1.scenario.limits}["grip"] == 30.0
    assert l2.scenario.requirements[0].within == 2.0 and l1.scenario.requirements[0].within is None
    assert l2.scene.bodies == l1.scene.bodies  # no placement rule: the canonical layout


# --- rules that cannot hold ---------------------------------------------------------------------


def test_a_jitter_larger_than_the_table_fails_before_sampling() -> None:
    text = POT_AND_STOVE + "    L1: jitter pot 2 m\n"
    with pytest.raises(VariantError) as err:
        generate_variant(_loads(text), "L1")
    assert str(err.value) == (
        "t.fsv:13:9: L1 rule `jitter pot 200 cm` of 't' can never hold: its disc (radius 200 cm) is "
        "larger than the top of 'table' (120 cm x 80 cm)\n"
        "  remedies:\n"
        "    1. reduce the jitter of 'pot' (now 200 cm; the top of 'table' is 120 cm x 80 cm)\n"
        "    2. put 'pot' on a larger support")
    failure = err.value.failure
    assert (failure.code, failure.samples, failure.source.line, failure.source.column) == ("FSV601", 0, 13, 9)
    assert isinstance(err.value, LoweringError)


def test_more_clutter_than_fits_fails_before_sampling() -> None:
    scenario = _loads(POT_AND_STOVE + "    L2: clutter 2 near pot\n")
    rule = scenario.variants["L2"][0]
    scenario = scenario.model_copy(update={"variants": {"L2": (Clutter(count=50, near="pot", source=rule.source),)}})
    with pytest.raises(VariantError) as err:
        generate_variant(scenario, "L2")
    assert str(err.value) == (
        "t.fsv:13:9: L2 rule `clutter 50 near pot` of 't' can never hold: 50 clutter objects cannot fit "
        "within 29.6 cm of 'pot': 0.219 m² is free, room for at most 30\n"
        "  remedies:\n"
        "    1. ask for at most 30 clutter objects (now 50)\n"
        "    2. make room around 'pot', or drop `near pot`")


def test_an_approach_past_its_target_fails_before_sampling() -> None:
    with pytest.raises(VariantError, match=r"would move 'stove' past 'pot': their centres are 30 cm apart, "
                                           r"the approach is 35 cm") as err:
        generate_variant(_loads(POT_AND_STOVE + "    L2: approach stove to pot by 35 cm\n"), "L2")
    assert "below their gap of 12 cm (now 35 cm)" in str(err.value)


def test_an_exhausted_budget_names_the_rule_the_shares_and_remedies() -> None:
    text = POT_AND_STOVE + "    L1: jitter pot 40 cm, tighten stove to 50 cm\n"
    with pytest.raises(VariantError) as err:
        generate_variant(_loads(text), "L1", budget=50)
    assert str(err.value) == (
        "t.fsv:13:9: no feasible L1 layout of 't' in 50 samples; 50 of the rejections involve L1 rule "
        "`jitter pot 40 cm`\n"
        "  rejected 50 of 50 samples: hazard violated 88%, unreachable 12%\n"
        "  most often: 'pot' is within 50 cm of 'stove' (limit 'stove') (44 of 50)\n"
        "  remedies:\n"
        "    1. reduce the jitter of 'pot' (now 40 cm)\n"
        "    2. move 'pot' farther from 'stove' in the canonical layout\n"
        "    3. loosen `tighten stove to 50 cm`\n"
        "    4. raise the budget (now 50 samples)")
    failure = err.value.failure
    assert failure.code == "FSV602" and failure.rejected == {"hazard violated": 44, "unreachable": 6}


def test_the_error_renders_as_a_diagnostic() -> None:
    text = POT_AND_STOVE + "    L1: jitter pot 40 cm, tighten stove to 50 cm\n"
    with pytest.raises(VariantError) as err:
        generate_variant(_loads(text), "L1", budget=50)
    console = Console(width=200, record=True, highlight=False, soft_wrap=True)
    console.print(render_full(err.value.diagnostic(text), {"t.fsv": text}))
    assert console.export_text() == (
        "error[FSV602]: no feasible L1 layout of 't' in 50 samples; 50 of the rejections involve L1 rule "
        "`jitter pot 40 cm`\n"
        "  --> t.fsv:13:9\n"
        "   |\n"
        "13 |     L1: jitter pot 40 cm, tighten stove to 50 cm\n"
        "   |         ^^^^^^^^^^^^^^^^ no feasible layout with this rule\n"
        "   = note: rejected 50 of 50 samples: hazard violated 88%, unreachable 12%\n"
        "   = note: most often: 'pot' is within 50 cm of 'stove' (limit 'stove') (44 of 50)\n"
        "help: try: 1. reduce the jitter of 'pot' (now 40 cm); 2. move 'pot' farther from 'stove' in the "
        "canonical layout; 3. loosen `tighten stove to 50 cm`; 4. raise the budget (now 50 samples)\n\n")


def test_an_infeasible_canonical_layout_points_at_the_object() -> None:
    text = POT_AND_STOVE.replace("at (0, 0)", "at (-45 cm, 0)") + "    L1: jitter pot 1 cm\n"
    with pytest.raises(VariantError) as err:
        generate_variant(_loads(text), "L0")
    assert str(err.value) == (
        "t.fsv:6:10: the canonical layout of 't' is infeasible: 'pot' is out of reach of every arm\n"
        "  remedies:\n"
        "    1. move 'pot' closer to the arms' workspace ('arm' x -0.10..0.10 m, y -0.10..0.10 m; "
        "up to 25 cm beyond it counts)")
    assert err.value.failure.code == "FSV603"
