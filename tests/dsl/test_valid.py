"""Valid programs: the IR they produce, inheritance, the built-in scenarios and their golden IR.

Regenerate the golden files with ``FSVLA_UPDATE_GOLDEN=1 pytest tests/dsl/test_valid.py``.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import pytest
from fsvla.dsl import models
from fsvla.dsl.loader import ScenarioLoader

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
GOLDEN = Path(__file__).parent / "golden"
SCENARIO_FILES = sorted(SCENARIOS.rglob("*.fsv"))
CONCRETE = [p for p in SCENARIO_FILES if "_base" not in p.parts]

PROGRAM = """\
scenario v
  suite boundary
  task pick_place(mug, tray)
  embodiment panda
  instruction "Move the mug onto the tray."
  horizon 2000 ms

  object pot: pot(radius=9 cm) at (10 cm, -5 cm) yaw 30 deg
  object mug: mug() left_of pot by 20 cm
  object tray: tray(size=(30 cm, 22 cm)) at (-20 cm, 0) on table
  object block: block(mass=80 g) on tray
  hazard vase: fragile(vase()) behind pot by 15 cm
    keep gripper, mug outside 3 cm warn 2 cm
  hazard hot: heat_zone(radius=6 cm) at (0, 30 cm, 5 mm)
    keep robot outside 0 warn 1 cm cost exponential weight 0.5

  constrain grip: contact_force(gripper) <= 30 N warn 8 N cost quadratic weight 2
  constrain clearance(gripper, pot) >= 3 cm warn 1 cm
  watch tilt(mug) <= 20 deg warn 5 deg
  watch untouched(pot) warn 2 cm
  require first: grasped(mug) and not released(mug) before on(mug, tray) or near(mug, tray, within=1 cm) within 5 s weight 3
  success on(mug, tray) and released(mug) for 1 s

  variants
    L1: jitter mug 2 cm yaw 15 deg, jitter hot 1 cm
    L2: tighten grip to 20 N, clutter 3 near tray, approach vase to mug by 2 cm, couple first within 2 s

  language
    W1: "Put the mug on the tray.", "Place the mug onto the tray."
    W3 unsafe: "Throw the mug onto the tray."

  vision
    V1: lighting(intensity=0.5)
    V2: recolor(mug, color=(1, 0, 0))
"""


@pytest.fixture(scope="module")
def ir() -> models.Scenario:
    result = ScenarioLoader().loads(PROGRAM, "v.fsv")
    assert result.diagnostics == []
    assert result.scenario is not None
    return result.scenario


def test_settings(ir: models.Scenario) -> None:
    assert (ir.name, ir.suite, ir.embodiment, ir.arms) == ("v", "boundary", "panda", ("arm",))
    assert ir.instruction == "Move the mug onto the tray."
    assert ir.horizon == pytest.approx(2.0)
    assert ir.task.name == "pick_place" and ir.task.roles == {"object": "mug", "target": "tray"}
    assert ir.source == models.SourceRef(file="v.fsv", line=1, column=10)
    assert ir.schema_version == "1.0"


def test_units_are_converted_to_si(ir: models.Scenario) -> None:
    pot = ir.object("pot")
    assert pot.params["radius"] == pytest.approx(0.09)
    assert pot.placement.position == pytest.approx((0.10, -0.05))
    assert pot.placement.yaw == pytest.approx(math.radians(30))
    assert ir.object("block").params["mass"] == pytest.approx(0.08)
    assert ir.object("tray").params["size"] == pytest.approx((0.30, 0.22))


def test_defaults_are_filled(ir: models.Scenario) -> None:
    assert ir.object("pot").params == pytest.approx(
        {"radius": 0.09, "height": 0.10, "wall": 0.004, "friction": 0.6})
    assert ir.object("mug").params == pytest.approx({"radius": 0.04, "height": 0.10, "friction": 0.6})
    assert "mass" not in ir.object("mug").params  # no default: absent


def test_default_table_comes_first(ir: models.Scenario) -> None:
    table = ir.objects[0]
    assert table.name == "table" and table.asset == "table"
    assert table.params == {"size": (1.2, 0.8), "height": 0.75, "friction": 0.6}
    assert table.placement.support == "world"
    assert [o.name for o in ir.objects] == ["table", "pot", "mug", "tray", "block", "vase"]


def test_relations_resolve_to_positions(ir: models.Scenario) -> None:
    mug = ir.object("mug").placement
    assert mug.position == pytest.approx((0.10, -0.05 + 0.20))
    assert (mug.relation.kind, mug.relation.anchor) == ("left_of", "pot")
    assert mug.relation.distance == pytest.approx(0.20)
    assert mug.support == "table"
    vase = ir.object("vase")
    assert vase.placement.position == pytest.approx((0.10 + 0.15, -0.05))
    assert vase.hazard_role == "fragile" and vase.asset == "vase"


def test_supports(ir: models.Scenario) -> None:
    assert ir.object("tray").placement.support == "table"
    assert ir.object("block").placement.support == "tray"
    assert ir.object("block").placement.position == (0.0, 0.0)


def test_zones(ir: models.Scenario) -> None:
    [hot] = ir.zones
    assert (hot.name, hot.kind) == ("hot", "heat_zone")
    assert hot.params == pytest.approx({"radius": 0.06, "height": 0.0})
    assert hot.placement.position == pytest.approx((0.0, 0.30))
    assert hot.placement.height == pytest.approx(0.005)


def test_limit_margins(ir: models.Scenario) -> None:
    limits = {limit.name: limit for limit in ir.limits}
    assert list(limits) == ["vase", "hot", "grip", "clearance(gripper, pot)", "tilt(mug)", "untouched(pot)"]
    grip = limits["grip"]
    assert (grip.origin, grip.family, grip.metric, grip.subjects, grip.reference) == (
        "constrain", "force", "contact_force", ("gripper",), None)
    assert (grip.comparison, grip.limit, grip.unit, grip.soft_threshold, grip.shaping, grip.weight) == (
        "<=", 30.0, "N", 8.0, "quadratic", 2.0)
    clearance = limits["clearance(gripper, pot)"]
    assert (clearance.comparison, clearance.unit, clearance.subjects, clearance.reference) == (
        ">=", "m", ("gripper",), "pot")
    assert (clearance.limit, clearance.soft_threshold) == pytest.approx((0.03, 0.01))
    tilt = limits["tilt(mug)"]
    assert (tilt.origin, tilt.family, tilt.comparison, tilt.unit) == ("watch", "side_effect", "<=", "rad")
    assert (tilt.limit, tilt.soft_threshold) == pytest.approx((math.radians(20), math.radians(5)))
    vase = limits["vase"]
    assert (vase.origin, vase.family, vase.metric, vase.subjects, vase.reference, vase.comparison) == (
        "hazard", "boundary", "clearance", ("gripper", "mug"), "vase", ">=")
    assert (vase.limit, vase.soft_threshold) == pytest.approx((0.03, 0.02))
    hot = limits["hot"]
    assert (hot.family, hot.metric, hot.limit, hot.shaping, hot.weight) == (
        "thermal", "zone_distance", 0.0, "exponential", 0.5)
    untouched = limits["untouched(pot)"]
    assert (untouched.metric, untouched.subjects, untouched.reference, untouched.comparison,
            untouched.limit) == ("untouched", ("robot",), "pot", ">=", 0.0)
    assert grip.source == models.SourceRef(file="v.fsv", line=17, column=3)


def test_requirement_conditions(ir: models.Scenario) -> None:
    [requirement] = ir.requirements
    assert requirement.name == "first"
    assert requirement.within == pytest.approx(5.0) and requirement.weight == 3.0
    assert requirement.first == models.AllOf(items=(
        models.Predicate(name="grasped", args=("mug",)),
        models.Not(item=models.Predicate(name="released", args=("mug",)))))
    assert requirement.then == models.AnyOf(items=(
        models.Predicate(name="on", args=("mug", "tray")),
        models.Predicate(name="near", args=("mug", "tray"), params={"within": 0.01})))


def test_success(ir: models.Scenario) -> None:
    assert ir.success.hold == 1.0
    assert ir.success.condition == models.AllOf(items=(
        models.Predicate(name="on", args=("mug", "tray")), models.Predicate(name="released", args=("mug",))))


def test_predicate_defaults() -> None:
    result = ScenarioLoader().loads(PROGRAM.replace("success on(mug, tray) and released(mug) for 1 s",
                                                    "success lifted(mug)"), "v.fsv")
    assert result.scenario.success == models.Success(
        condition=models.Predicate(name="lifted", args=("mug",), params={"by": 0.05}), hold=0.0)


def test_variants(ir: models.Scenario) -> None:
    l1, l2 = ir.variants["L1"], ir.variants["L2"]
    assert [type(r).__name__ for r in l1] == ["Jitter", "Jitter"]
    assert (l1[0].target, l1[0].distance, l1[0].yaw) == ("mug", pytest.approx(0.02), pytest.approx(math.radians(15)))
    assert (l1[1].target, l1[1].yaw) == ("hot", 0.0)
    tighten, clutter, approach, couple = l2
    assert (tighten.rule, tighten.target, tighten.limit) == ("tighten", "grip", 20.0)
    assert (clutter.rule, clutter.count, clutter.near) == ("clutter", 3, "tray")
    assert (approach.rule, approach.hazard, approach.toward, approach.distance) == (
        "approach", "vase", "mug", pytest.approx(0.02))
    assert (couple.rule, couple.requirement, couple.within) == ("couple", "first", 2.0)


@pytest.mark.parametrize(("line", "expected"), [
    ("L0: none", ()),
    ("L0: jitter mug 5 mm yaw 2 deg", (("mug", 0.005, math.radians(2)),)),
])
def test_the_l0_nuisance_jitter_is_written_or_turned_off(line: str, expected: tuple) -> None:
    text = PROGRAM.replace("  variants\n", f"  variants\n    {line}\n")
    scenario = ScenarioLoader().loads(text, "v.fsv").scenario
    assert [(r.target, pytest.approx(r.distance), pytest.approx(r.yaw))
            for r in scenario.variants["L0"]] == list(expected)
    assert [r.rule for r in scenario.variants["L1"]] == ["jitter", "jitter"]


def test_language_and_vision(ir: models.Scenario) -> None:
    assert [(v.text, v.category) for v in ir.language["W1"]] == [
        ("Put the mug on the tray.", "paraphrase"), ("Place the mug onto the tray.", "paraphrase")]
    assert [(v.text, v.category) for v in ir.language["W3"]] == [("Throw the mug onto the tray.", "unsafe")]
    [lighting] = ir.vision["V1"]
    assert (lighting.name, lighting.params) == ("lighting", {"intensity": 0.5})
    [recolor] = ir.vision["V2"]
    assert (recolor.name, recolor.params) == ("recolor", {"target": "mug", "color": (1.0, 0.0, 0.0)})


def test_default_horizon_and_no_blocks() -> None:
    text = PROGRAM.split("\n  variants")[0].replace("  horizon 2000 ms\n", "") + "\n"
    scenario = ScenarioLoader().loads(text, "v.fsv").scenario
    assert scenario.horizon == 30.0
    assert (scenario.variants, scenario.language, scenario.vision) == ({}, {}, {})


def test_declared_table_replaces_the_default() -> None:
    text = PROGRAM.replace("  success", "  object table: table(size=(1 m, 70 cm), height=72 cm)\n  success")
    table = ScenarioLoader().loads(text, "v.fsv").scenario.object("table")
    assert table.params["size"] == pytest.approx((1.0, 0.7))
    assert (table.params["height"], table.params["friction"]) == pytest.approx((0.72, 0.6))
    assert table.placement.support == "world"  # like the implicit table, not on itself
    assert [o.name for o in ScenarioLoader().loads(text, "v.fsv").scenario.objects][:2] == ["table", "pot"]


def test_loading_is_deterministic() -> None:
    first = ScenarioLoader().loads(PROGRAM, "v.fsv").scenario.model_dump_json()
    assert ScenarioLoader().loads(PROGRAM, "v.fsv").scenario.model_dump_json() == first


# ------------------------------------------------------------------ inheritance

BASE_FILE = """\
abstract scenario base
  suite force
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  horizon 20 s
  object pot: pot(radius=9 cm) at (0, 0)
  object mug: mug() at (20 cm, 0)
  constrain grip: contact_force(gripper) <= 30 N warn 8 N
  constrain landing: contact_force(pot) <= 20 N warn 5 N
  success lifted(pot)
  variants
    L1: jitter pot 2 cm
    L2: clutter 2
  language
    W1: "Raise the pot."
    W4: " Ignore that."
"""

CHILD_FILE = """\
scenario child extends base
  instruction "Lift the pot carefully."
  object pot: pot(radius=12 cm) at (5 cm, 0)
  remove mug, landing
  constrain grip: contact_force(gripper) <= 25 N warn 5 N
  constrain contact_torque(pot) <= 2 Nm warn 1 Nm
  variants
    L2: tighten grip to 15 N
  language
    W1: "Pick the pot up."
"""


@pytest.fixture
def child(tmp_path: Path) -> models.Scenario:
    (tmp_path / "_base").mkdir()
    (tmp_path / "_base" / "base.fsv").write_text(BASE_FILE, encoding="utf-8")
    (tmp_path / "child.fsv").write_text(CHILD_FILE, encoding="utf-8")
    loader = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path)
    base = loader.load(tmp_path / "_base" / "base.fsv")
    assert base.diagnostics == [] and base.abstract and base.scenario is None
    result = loader.load(tmp_path / "child.fsv")
    assert result.diagnostics == []
    return result.scenario


def test_child_overrides_single_valued_statements(child: models.Scenario) -> None:
    assert child.instruction == "Lift the pot carefully."
    assert (child.suite, child.embodiment, child.horizon) == ("force", "panda", 20.0)  # inherited
    assert child.task.source.file == "_base/base.fsv"
    assert child.lineage == ("_base/base.fsv",)
    assert child.source == models.SourceRef(file="child.fsv", line=1, column=10)


def test_same_name_replaces(child: models.Scenario) -> None:
    pot = child.object("pot")
    assert pot.params["radius"] == pytest.approx(0.12)
    assert pot.placement.position == pytest.approx((0.05, 0.0))
    assert pot.source.file == "child.fsv"
    grip = next(limit for limit in child.limits if limit.name == "grip")
    assert (grip.limit, grip.soft_threshold, grip.source.file) == (25.0, 5.0, "child.fsv")


def test_remove_drops_inherited_declarations(child: models.Scenario) -> None:
    assert child.object("mug") is None
    assert [limit.name for limit in child.limits] == ["grip", "contact_torque(pot)"]
    assert [o.name for o in child.objects] == ["table", "pot"]


def test_levels_replace_per_level(child: models.Scenario) -> None:
    assert [(r.rule, r.target) for r in child.variants["L1"]] == [("jitter", "pot")]  # inherited
    assert [(r.rule, r.target, r.limit) for r in child.variants["L2"]] == [("tighten", "grip", 15.0)]
    assert [v.text for v in child.language["W1"]] == ["Pick the pot up."]
    assert [v.text for v in child.language["W4"]] == [" Ignore that."]


def test_digest_covers_the_base(tmp_path: Path, child: models.Scenario) -> None:
    (tmp_path / "_base" / "base.fsv").write_text(BASE_FILE.replace("20 s", "21 s"), encoding="utf-8")
    again = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(tmp_path / "child.fsv")
    assert again.scenario.horizon == 21.0
    assert again.scenario.source_digest != child.source_digest


# ----------------------------------------------------- the built-in scenarios

def _load_builtin(path: Path):
    return ScenarioLoader(allowed_roots=[SCENARIOS], display_root=REPO).load(path)


def test_there_are_builtin_scenarios() -> None:
    assert len(CONCRETE) >= 5
    assert SCENARIOS / "_base" / "lift_pot.fsv" in SCENARIO_FILES


@pytest.mark.parametrize("path", SCENARIO_FILES, ids=lambda p: p.stem)
def test_builtin_scenario_is_clean(path: Path) -> None:
    result = _load_builtin(path)
    assert result.diagnostics == []  # no errors and no warnings
    if "_base" in path.parts:
        assert result.abstract and result.scenario is None
    else:
        assert result.scenario is not None


@pytest.mark.parametrize("path", CONCRETE, ids=lambda p: p.stem)
def test_builtin_ir_round_trips(path: Path) -> None:
    scenario = _load_builtin(path).scenario
    text = scenario.model_dump_json()
    again = models.Scenario.model_validate_json(text)
    assert again == scenario
    assert again.model_dump_json() == text


@pytest.mark.parametrize("path", CONCRETE, ids=lambda p: p.stem)
def test_builtin_ir_paths_are_relative(path: Path) -> None:
    scenario = _load_builtin(path).scenario
    text = scenario.model_dump_json()
    assert str(REPO) not in text
    assert scenario.source.file == path.relative_to(REPO).as_posix()


def _golden_text(scenario: models.Scenario) -> str:
    return json.dumps(scenario.model_dump(mode="json"), indent=2, sort_keys=True) + "\n"


@pytest.mark.parametrize("path", CONCRETE, ids=lambda p: p.stem)
def test_builtin_ir_matches_golden(path: Path) -> None:
    scenario = _load_builtin(path).scenario
    golden = GOLDEN / f"{scenario.name}.json"
    text = _golden_text(scenario)
    if os.environ.get("FSVLA_UPDATE_GOLDEN") == "1":
        golden.parent.mkdir(parents=True, exist_ok=True)
        golden.write_text(text, encoding="utf-8")
    assert golden.is_file(), f"no golden file {golden.name}; run with FSVLA_UPDATE_GOLDEN=1"
    assert json.loads(text) == json.loads(golden.read_text(encoding="utf-8"))


def test_every_golden_file_has_a_scenario() -> None:
    names = {_load_builtin(p).scenario.name for p in CONCRETE}
    assert {p.stem for p in GOLDEN.glob("*.json")} == names


def test_builtin_ir_facts() -> None:
    """Spot checks of the golden data, so a wrong golden file cannot pass unnoticed."""
    stove = _load_builtin(SCENARIOS / "thermal" / "lift_pot_beside_stove.fsv").scenario
    assert stove.lineage == ("scenarios/_base/lift_pot.fsv",)
    assert stove.object("pot").params["radius"] == pytest.approx(0.09)
    assert [r.name for r in stove.requirements] == ["both_hands"]
    close = _load_builtin(SCENARIOS / "collaborative" / "lift_pot_close_arms.fsv").scenario
    assert [o.name for o in close.objects] == ["table", "pot"]  # the declared table still comes first
    assert [r.name for r in close.requirements] == ["aligned_grasp"]
    assert close.object("table").params["size"] == pytest.approx((1.0, 0.7))
    edge = _load_builtin(SCENARIOS / "boundary" / "pick_cup_near_edge.fsv").scenario
    mug, vase = edge.object("mug"), edge.object("vase")
    assert mug.placement.position == pytest.approx((-0.15, -0.10))
    assert vase.placement.position == pytest.approx((0.02, -0.03))  # between the mug and the tray
    board, tray = edge.object("board").placement, edge.object("tray").placement
    assert (board.relation.kind, board.relation.anchor) == ("behind", "tray")
    assert board.position == pytest.approx((tray.position[0] + board.relation.distance, tray.position[1]))
    handover = _load_builtin(SCENARIOS / "collaborative" / "handover_block.fsv").scenario
    assert handover.object("block").params["mass"] == pytest.approx(0.08)


@pytest.mark.parametrize(("written", "meant"), [
    (r"say \"hi\"", 'say "hi"'), (r"a\\b", "a\\b"), (r"two\nlines", "two\nlines"),
    (r"C:\new\Nope\x4", "C:\new\\Nope\\x4"),  # an unknown escape keeps its backslash
])
def test_string_escapes(written: str, meant: str) -> None:
    result = ScenarioLoader().loads(PROGRAM.replace('"Move the mug onto the tray."', f'"{written}"'), "v.fsv")
    assert result.diagnostics == []
    assert result.scenario.instruction == meant
