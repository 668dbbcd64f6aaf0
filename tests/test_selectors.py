"""The one scenario resolver (fsvla.selectors): files, folders, names and the
``subset:``/``suite:``/``embodiment:`` selectors, on a small tree and on the built-in one;
a bad selector is an error naming the setting and its valid values (exit 2 in the CLI)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.catalog import SUITES
from fsvla.dsl.loader import ScenarioLoader

from fsvla.cli import run
from fsvla.library import ScenarioLoadError, load_scenario
from fsvla.resources import scenarios_dir
from fsvla.runner import RunInputError
from fsvla.runner.prepare import scenario_refs
from fsvla.selectors import (
    ScenarioSelectionError,
    builtin_catalogue,
    named_sets,
    resolve_scenarios,
    scenario_paths,
)

SCENARIO = """\
scenario {name}
  suite {suite}
  task lift(pot)
  embodiment {embodiment}
  instruction "Lift the pot."
  horizon 1 s
  object pot: pot(radius=8 cm, height=10 cm) at (0, 0)
  constrain contact_force(gripper) <= 40 N warn 10 N
  success lifted(pot)
"""
BASE = """\
abstract scenario lift_base
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  object pot: pot(radius=8 cm, height=10 cm) at (0, 0)
  success lifted(pot)
"""
TREE = {"thermal/hot_a": ("thermal", "panda"), "thermal/hot_b": ("thermal", "z1"),
        "force/press_c": ("force", "z1")}
SETS = '[pair]\ndescription = "two"\nscenarios = ["press_c", "hot_a"]\n'


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("tree")
    (root / "_base").mkdir()
    (root / "_base" / "lift_base.fsv").write_text(BASE, encoding="utf-8")
    for stem, (suite, embodiment) in TREE.items():
        path = root / f"{stem}.fsv"
        path.parent.mkdir(exist_ok=True)
        name = path.stem
        path.write_text(SCENARIO.format(name=name, suite=suite, embodiment=embodiment),
                        encoding="utf-8")
    (root / "sets.toml").write_text(SETS, encoding="utf-8")
    return root


@pytest.mark.parametrize(("items", "expected"), [
    (["subset:pair"], ["press_c", "hot_a"]),  # a set keeps its order
    (["suite:thermal"], ["hot_a", "hot_b"]),
    (["embodiment:z1"], ["hot_b", "press_c"]),
    (["suite:force,embodiment:panda"], ["press_c", "hot_a"]),
    (["suite:thermal", "subset:pair"], ["hot_a", "hot_b", "press_c"]),  # each once
    (["hot_b", "embodiment:z1"], ["hot_b", "press_c"]),
])
def test_selectors_pick_from_the_tree(tree: Path, items: list[str], expected: list[str]) -> None:
    assert resolve_scenarios(items, tree=tree) == expected
    assert [p.stem for p in scenario_paths(items, tree=tree)] == expected


def test_folders_skip_bases_unless_asked(tree: Path) -> None:
    found = resolve_scenarios([str(tree)], tree=tree)
    assert sorted(Path(f).stem for f in found) == ["hot_a", "hot_b", "press_c"]
    with_bases = scenario_paths([str(tree)], bases=True, tree=tree)
    assert "lift_base" in {p.stem for p in with_bases}
    # a file named by path and again by a selector counts once, as first written
    assert resolve_scenarios([str(tree / "force" / "press_c.fsv"), "suite:force"],
                             tree=tree) == [str(tree / "force" / "press_c.fsv")]


@pytest.mark.parametrize(("item", "setting", "words"), [
    ("suite:thermals", "suite", ["`suite:thermal`?", "boundary, collaborative, force"]),
    ("embodiment:ur5", "embodiment", ["baxter, dual_panda, panda, so101, z1"]),
    ("embodiment:baxter", "embodiment", ["selects no scenario", "panda, z1"]),
    ("subset:nope", "subset", ["unknown subset `nope`", "sets.toml: pair"]),
    ("kind:thing", "selector", ["`subset:NAME`, `suite:NAME`, `embodiment:NAME`"]),
    ("press_d", "scenario", ["did you mean `press_c`?"]),
    ("missing.fsv", "scenario", ["no such scenario file"]),
])
def test_bad_references_name_the_setting(tree: Path, item: str, setting: str,
                                         words: list[str]) -> None:
    with pytest.raises(ScenarioSelectionError) as caught:
        resolve_scenarios([item], tree=tree)
    assert caught.value.setting == setting
    for word in words:
        assert word in str(caught.value)


def test_a_set_naming_an_unknown_scenario(tmp_path: Path) -> None:
    (tmp_path / "a.fsv").write_text(SCENARIO.format(name="a", suite="force", embodiment="panda"))
    (tmp_path / "sets.toml").write_text('[s]\nscenarios = ["a", "b"]\n')
    with pytest.raises(ScenarioSelectionError, match="set `s` lists b, not built-in"):
        resolve_scenarios(["subset:s"], tree=tmp_path)
    (tmp_path / "sets.toml").write_text('[s]\nscenario = ["a"]\n')
    with pytest.raises(ScenarioSelectionError, match=r"sets.toml: \[s\]: scenarios: Field required"):
        named_sets(tmp_path)


def test_the_diagnostic_subset() -> None:
    """The paper's diagnostic subset: 10 built-in scenarios, two per suite, each with L1
    and L2 rules and an instruction and a perturbation at every W and V level."""
    from fsvla.variation.language import instruction_for
    from fsvla.variation.vision import perturbation_for

    names = resolve_scenarios(["subset:diagnostic"])
    assert len(names) == 10
    catalogue = builtin_catalogue()
    assert sorted(catalogue[n].suite for n in names) == sorted(SUITES * 2)
    loader = ScenarioLoader(allowed_roots=[scenarios_dir()])
    for name in names:
        ir = loader.load(catalogue[name].path).scenario
        assert ir is not None and {"L1", "L2"} <= set(ir.variants), name
        for level in ("W1", "W2", "W3", "W4"):
            assert instruction_for(ir, level).text != ir.instruction, (name, level)
        for level in ("V1", "V2", "V3", "V4"):
            assert perturbation_for(ir, level) is not None, (name, level)


def test_every_named_set_lists_built_in_scenarios() -> None:
    for name in named_sets():
        assert resolve_scenarios([f"subset:{name}"])


def test_run_and_load_use_the_resolver() -> None:
    assert scenario_refs(["suite:thermal"]) == resolve_scenarios(["suite:thermal"])
    with pytest.raises(RunInputError, match=r"^--scenarios: unknown suite `heat`"):
        scenario_refs(["suite:heat"])
    with pytest.raises(ScenarioLoadError, match="names 10 scenarios"):
        load_scenario("subset:diagnostic")
    with pytest.raises(ScenarioLoadError, match="unknown suite"):
        load_scenario("suite:heat")


@pytest.mark.parametrize("command", ["check", "validate"])
def test_cli_bad_selector_is_a_usage_error(command: str, capsys) -> None:
    assert run([command, "embodiment:ur5"]) == 2
    err = capsys.readouterr().err
    assert "unknown embodiment `ur5`" in err and "Traceback" not in err


def test_check_takes_a_selector(capsys) -> None:
    assert run(["check", "subset:diagnostic", "--format", "concise"]) == 0
