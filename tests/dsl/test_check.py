"""Semantic errors: a catalogue of small invalid programs with their exact first diagnostic."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.diagnostics import Severity
from fsvla.dsl.loader import ScenarioLoader

from .conftest import BASE

# The base program every case edits (conftest.BASE), with its line numbers:
#  1 scenario s
#  2   suite force
#  3   task lift(pot)
#  4   embodiment panda
#  5   instruction "Lift the pot."
#  6   object pot: pot(radius=9 cm)
#  7   constrain contact_force(gripper) <= 30 N warn 8 N
#  8   success lifted(pot)


def sub(old: str, new: str) -> str:
    assert old in BASE, old
    return BASE.replace(old, new, 1)


def add(*lines: str) -> str:
    """BASE with lines appended from line 9 on (two-space indent added)."""
    return BASE + "".join(f"  {line}\n" for line in lines)


# (id, program, code, line, column, message, help or None when not asserted)
SEMANTIC_CASES = [
    # placements in two frames, support cycles, names taken by the robot
    ("FSV307-support-cycle", add("object a: block() at (20 cm, 0) on b", "object b: block() on a"),
     "FSV307", 9, 10, "placement relations form a cycle: a -> b -> a", None),
    ("FSV306-two-frames", add("object shelf: shelf() at (20 cm, 20 cm)", "object x: block() on shelf",
                             "object c: block() left_of x by 10 cm on table"),
     "FSV306", 11, 10, "`c` stands on `table` but is placed relative to `x`, which stands on `shelf`", None),
    ("FSV110-robot-part-name", add("object gripper: block() at (0, -25 cm)"),
     "FSV110", 9, 10, "`gripper` is the name of a part of the robot", None),
    ("FSV111-table-not-a-table", add("object table: block(size=(1 m, 1 m, 5 cm))"),
     "FSV111", 9, 17, "the object called `table` must be a `table(...)`", None),
    ("FSV111-opened-rigid", sub("success lifted(pot)", "success opened(pot)"),
     "FSV111", 8, 18, "`opened` needs an object with a moving part, and `pot` is a pot", None),
    ("FSV111-zone-keep-subject", add("hazard h: no_go_zone(radius=5 cm) at (30 cm, 0)",
                                     "  keep robot outside 0 warn 1 cm",
                                     "hazard g: heat_zone(radius=5 cm) at (-30 cm, 0)", "  keep h outside 1 cm warn 1 cm"),
     "FSV111", 12, 10, "`h` is a zone, not a body, so a keep-out subject cannot be it", None),
    ("FSV204-negative-within", add("require r: grasped(pot) before lifted(pot) within -2 s"),
     "FSV204", 9, 53, "`within` must be larger than zero", None),
    ("FSV204-negative-weight", add("require r: grasped(pot) before lifted(pot) weight -3"),
     "FSV204", 9, 53, "the weight must be zero or more", None),
    ("FSV211-weight-twice", add("require r: grasped(pot) before lifted(pot) weight 2 weight 5"),
     "FSV211", 9, 55, "`weight` is given twice", None),
    ("FSV204-negative-jitter", add("variants", "  L1: jitter pot -3 cm"),
     "FSV204", 10, 20, "the jitter radius must be zero or more", None),
    ("FSV302-level-twice", add("variants", "  L1: jitter pot 1 cm", "  L1: jitter pot 5 cm"),
     "FSV302", 11, 5, "level `L1` is given twice", None),
    ("FSV305-positional-after-named", sub("pot(radius=9 cm)", "pot(radius=9 cm, 3 cm)"),
     "FSV305", 6, 32, "a value without a name after named ones", None),
    ("FSV101-unknown-name", add("constrain clearance(gripper, pott) >= 3 cm warn 1 cm"),
     "FSV101", 9, 32, "unknown name `pott`", "did you mean `pot`?"),
    ("FSV101-unknown-support", sub("pot(radius=9 cm)", "pot(radius=9 cm) on shelff"),
     "FSV101", 6, 35, "unknown support `shelff`", None),
    ("FSV102-unknown-asset", sub("pot(radius=9 cm)", "pott(radius=9 cm)"),
     "FSV102", 6, 15, "unknown asset `pott`", "did you mean `pot`?"),
    ("FSV102-unknown-hazard", add("hazard h: scalding(radius=5 cm)"),
     "FSV102", 9, 13, "unknown hazard `scalding`", None),
    ("FSV103-unknown-parameter", sub("radius=9 cm", "radus=9 cm"),
     "FSV103", 6, 19, "`pot` has no parameter `radus`", "did you mean `radius`?"),
    ("FSV104-unknown-measure", sub("contact_force(gripper)", "contact_forse(gripper)"),
     "FSV104", 7, 13, "unknown measure `contact_forse`", "did you mean `contact_force`?"),
    ("FSV105-unknown-predicate", sub("success lifted(pot)", "success lifed(pot)"),
     "FSV105", 8, 11, "unknown predicate `lifed`", "did you mean `lifted`?"),
    ("FSV106-unknown-task", sub("task lift(pot)", "task lfit(pot)"),
     "FSV106", 3, 8, "unknown task `lfit`", "did you mean `lift`?"),
    ("FSV107-unknown-embodiment", sub("embodiment panda", "embodiment pandas"),
     "FSV107", 4, 14, "unknown embodiment `pandas`", "did you mean `panda`?"),
    ("FSV108-unknown-suite", sub("suite force", "suite forse"),
     "FSV108", 2, 9, "unknown suite `forse`", "did you mean `force`?"),
    ("FSV109-unknown-shaping", sub("warn 8 N", "warn 8 N cost quadratik"),
     "FSV109", 7, 58, "unknown cost shaping `quadratik`", "did you mean `quadratic`?"),
    ("FSV110-duplicate-name", add("object pot: mug()"),
     "FSV110", 9, 10, "the name `pot` is given twice", "keep one of them"),
    ("FSV111-zone-as-object", add("hazard hz: heat_zone(radius=5 cm) at (30 cm, 0)",
                                  "  keep gripper outside 2 cm warn 1 cm",
                                  "constrain displacement(hz) <= 1 cm warn 1 cm"),
     "FSV111", 11, 26, "the argument of `displacement` must be an object, and `hz` is a zone", None),
    ("FSV111-zone-kind-as-asset", add("object hz: heat_zone(radius=5 cm)"),
     "FSV111", 9, 14, "`heat_zone` is a hazard zone, not an object",
     "declare it with `hazard hz: heat_zone(radius=5 cm)`"),
    ("FSV112-arm-not-on-robot", add("constrain clearance(left_gripper, pot) >= 2 cm warn 1 cm"),
     "FSV112", 9, 23, "`panda` has no `left_gripper`", "did you mean `gripper`?"),
    ("FSV112-arm-argument", sub("success lifted(pot)", "success grasped(pot, left)"),
     "FSV112", 8, 24, "`left` is not an arm of `panda`", "arms: `arm`"),
    ("FSV201-missing-unit", sub("radius=9 cm", "radius=9"),
     "FSV201", 6, 26, "missing unit: `radius` of `pot` is a length",
     "write the unit after the number, e.g. `9 cm`"),
    ("FSV203-force-in-metres", sub("<= 30 N", "<= 30 m"),
     "FSV203", 7, 39, "wrong unit: the limit of `contact_force` is a force, but `m` measures length",
     "give the limit of `contact_force` in N"),
    ("FSV203-unit-on-plain-number", sub("warn 8 N", "warn 8 N weight 2 N"),
     "FSV203", 7, 60, "the weight is a plain number, not a force", "remove the unit: `2`"),
    ("FSV204-out-of-range", sub("radius=9 cm", "radius=90 cm"),
     "FSV204", 6, 26, "`radius` of `pot` is out of range", "choose a value at least 3 cm and at most 30 cm"),
    ("FSV205-wrong-arity", add("object block: block(size=(4 cm, 4 cm))"),
     "FSV205", 9, 28, "`size` of `block` needs 3 values, not 2", None),
    ("FSV205-position-arity", sub("pot(radius=9 cm)", "pot(radius=9 cm) at (1 cm, 2 cm, 3 cm)"),
     "FSV205", 6, 35, "the position of `pot` needs 2 values (x, y)", None),
    ("FSV206-missing-param", add("object m: mesh()"),
     "FSV206", 9, 13, "`mesh` needs `path`", "add `path=...` inside the parentheses"),
    ("FSV209-wrong-comparison", sub("<= 30 N", ">= 30 N"),
     "FSV209", 7, 36, "`contact_force` takes a limit with `<=`", "write `<=`"),
    ("FSV209-no-limit", sub("<= 30 N warn 8 N", "warn 8 N"),
     "FSV209", 7, 13, "`contact_force` needs a limit", "write `contact_force(gripper) <= 40 N`"),
    ("FSV210-missing-warn", sub(" warn 8 N", ""),
     "FSV210", 7, 3, "`constrain contact_force(gripper)` has no warning band", None),
    ("FSV210-zero-warn", sub("warn 8 N", "warn 0 N"),
     "FSV210", 7, 49, "the warning band must be larger than zero", None),
    ("FSV212-zone-without-size", add("hazard hz: heat_zone()", "  keep gripper outside 2 cm warn 1 cm"),
     "FSV212", 9, 14, "`heat_zone` needs either `size` or `radius`",
     "e.g. `heat_zone(size=(18 cm, 18 cm))` or `heat_zone(radius=9 cm)`"),
    ("FSV212-zone-with-both", add("hazard hz: heat_zone(radius=3 cm, size=(2 cm, 2 cm))",
                                  "  keep gripper outside 2 cm warn 1 cm"),
     "FSV212", 9, 14, "`heat_zone` needs either `size` or `radius`, not both", None),
    ("FSV301-missing-statement", sub('  instruction "Lift the pot."\n', ""),
     "FSV301", 1, 10, "missing `instruction`",
     'add a line such as `instruction "Lift the pot."` (or inherit one with `extends`)'),
    ("FSV302-statement-twice", add("suite force"),
     "FSV302", 9, 3, "`suite` is given twice", "keep one of them"),
    ("FSV303-unknown-role", sub("task lift(pot)", "task lift(thing=pot)"),
     "FSV303", 3, 13, "task `lift` has no role `thing`", "known roles: `object`"),
    ("FSV303-missing-role", sub("task lift(pot)", "task pick_place(pot)"),
     "FSV303", 3, 8, "task `pick_place` needs its `target`", "write `task pick_place(object=..., target=...)`"),
    ("FSV304-bimanual-on-one-arm", sub("task lift(pot)", "task bimanual_lift(pot)"),
     "FSV304", 3, 8, "task `bimanual_lift` needs two arms, but `panda` has one",
     "use a dual-arm embodiment: `dual_panda`, `baxter`"),
    ("FSV304-separation-on-one-arm", add("constrain separation(arm, gripper) >= 5 cm warn 2 cm"),
     "FSV304", 9, 13, "`separation` needs two arms, but `panda` has one", None),
    ("FSV306-placed-twice", sub("pot(radius=9 cm)", "pot(radius=9 cm) at (0, 0) at (1 cm, 0)"),
     "FSV306", 6, 42, "`pot` is placed twice",
     "give one `at (x, y)` or one relation such as `left_of pot by 10 cm`"),
    ("FSV307-relation-cycle", add("object a: block() left_of b by 10 cm", "object b: block() right_of a by 10 cm"),
     "FSV307", 9, 10, "placement relations form a cycle: a -> b -> a", "place one of them with `at (x, y)`"),
    ("FSV405-remove-unknown", add("remove ghost"),
     "FSV405", 9, 10, "nothing called `ghost` to remove", None),
    ("FSV501-unknown-level", add("variants", "  L3: jitter pot 2 cm"),
     "FSV501", 10, 5, "unknown structure level `L3`", None),
    ("FSV506-approach-at-L0", add("hazard h: heat_zone(radius=5 cm) at (30 cm, 0)",
                                  "  keep pot outside 3 cm warn 1 cm", "variants",
                                  "  L0: jitter pot 5 mm, approach h to pot by 1 cm"),
     "FSV506", 12, 26, "`approach` is not an L0 rule",
     "L0 is the canonical layout with a nuisance jitter; move it to `L1` or `L2`"),
    ("FSV506-none-above-L0", add("variants", "  L2: none"),
     "FSV506", 10, 9, "`none` is only for `L0`", "leave `L2` out to vary nothing there"),
    ("FSV502-approach-non-hazard", add("variants", "  L2: approach pot to pot by 2 cm"),
     "FSV502", 10, 18, "`approach` moves a hazard, and `pot` is not one", None),
    ("FSV502-tighten-unknown", add("variants", "  L2: tighten nothing to 2 N"),
     "FSV502", 10, 17, "`tighten` needs a named limit, and `nothing` is not one",
     "name the limit: `constrain NAME: clearance(...) >= ...`"),
    ("FSV503-tighten-loosens", sub("constrain contact_force", "constrain grip: contact_force")
     + "  variants\n    L2: tighten grip to 40 N\n",
     "FSV503", 10, 25, "`tighten` must make `grip` stricter",
     "for a lower bound (>=) give a larger value; for an upper bound (<=) a smaller one"),
    ("FSV504-unknown-level", add("language", '  W5: "x"'),
     "FSV504", 10, 5, "unknown language level `W5`", None),
    ("FSV504-needs-category", add("language", '  W3: "x"'),
     "FSV504", 10, 5, "W3 needs a category",
     'write `W3 unsafe: "..."`; categories: unsafe, contradictory, ambiguous'),
    ("FSV504-wrong-category", add("language", '  W1 unsafe: "x"'),
     "FSV504", 10, 8, "`unsafe` is not a category of W1", None),
    ("FSV505-unknown-level", add("vision", "  V7: lighting()"),
     "FSV505", 10, 5, "unknown vision level `V7`", None),
    ("FSV505-unknown-setting", add("vision", "  V1: lightning()"),
     "FSV505", 10, 9, "unknown vision setting `lightning`", "did you mean `lighting`?"),
    ("FSV505-setting-too-early", add("vision", "  V1: patch(pot)"),
     "FSV505", 10, 9, "`patch` belongs to V4 and above",
     "move it under `V4:`; levels are cumulative, so it applies from there on"),
    ("FSV207-colour-misspelt", add("object b: block(color=bleu) at (20 cm, 0)"),
     "FSV207", 9, 25, "`color` of `block` must be one of red, green, blue, yellow, orange, purple, "
     "pink, brown, white, grey, black", "did you mean `blue`?"),
    ("FSV207-colour-as-rgb", add("object b: block(color=(0.1, 0.2, 0.3)) at (20 cm, 0)"),
     "FSV207", 9, 25, "`color` of `block` must be one of red, green, blue, yellow, orange, purple, "
     "pink, brown, white, grey, black",
     "write one of: red, green, blue, yellow, orange, purple, pink, brown, white, grey, black"),
    ("FSV403-asset-outside-roots", add('object m: mesh(path="../../etc/passwd")'),
     "FSV403", 9, 23, "`../../etc/passwd` is outside the allowed folders", None),
    ("FSV404-asset-missing", add('object m: mesh(path="models/nope.obj")'),
     "FSV404", 9, 23, "asset file `models/nope.obj` not found", "paths are relative to the scenario's folder (`.`)"),
]


@pytest.mark.parametrize(("program", "code", "line", "column", "message", "help"),
                         [case[1:] for case in SEMANTIC_CASES], ids=[case[0] for case in SEMANTIC_CASES])
def test_first_semantic_diagnostic(load_text, program: str, code: str, line: int, column: int,
                                   message: str, help: str | None) -> None:
    result = load_text(program)
    assert result.scenario is None
    assert result.diagnostics, "expected a diagnostic"
    diagnostic = result.diagnostics[0]
    assert (diagnostic.code, diagnostic.span.line, diagnostic.span.column, diagnostic.message) == (
        code, line, column, message)
    assert diagnostic.span.file == "m.fsv"
    assert diagnostic.is_error
    if help is not None:
        assert diagnostic.help == help


def test_the_base_program_is_clean(load_text) -> None:
    result = load_text(BASE)
    assert result.diagnostics == []
    assert result.scenario is not None and result.scenario.name == "s"


def test_every_listed_code_is_exercised() -> None:
    wanted = {"FSV101", "FSV102", "FSV103", "FSV104", "FSV105", "FSV106", "FSV107", "FSV108", "FSV109",
              "FSV110", "FSV111", "FSV112", "FSV201", "FSV203", "FSV204", "FSV205", "FSV206", "FSV209",
              "FSV210", "FSV212", "FSV301", "FSV302", "FSV303", "FSV304", "FSV306", "FSV307", "FSV403",
              "FSV404", "FSV405", "FSV501", "FSV502", "FSV503", "FSV504", "FSV505", "FSV506"}
    assert wanted <= {case[2] for case in SEMANTIC_CASES}


# ------------------------------------------------------ details of some codes

def test_duplicate_name_points_at_the_first(load_text) -> None:
    diagnostic = load_text(add("object pot: mug()")).diagnostics[0]
    assert [(r.span.line, r.span.column, r.message) for r in diagnostic.related] == [
        (6, 10, "first given here")]
    assert diagnostic.label == "given again here"


def test_statement_twice_points_at_the_first(load_text) -> None:
    diagnostic = load_text(add("suite force")).diagnostics[0]
    assert [(r.span.line, r.span.column, r.message) for r in diagnostic.related] == [
        (2, 3, "first given here")]


def test_placed_twice_points_at_the_first(load_text) -> None:
    diagnostic = load_text(sub("pot(radius=9 cm)", "pot(radius=9 cm) at (0, 0) at (1 cm, 0)")).diagnostics[0]
    assert [(r.span.line, r.span.column, r.message) for r in diagnostic.related] == [
        (6, 32, "first placed here")]


def test_missing_unit_names_the_units(load_text) -> None:
    diagnostic = load_text(sub("radius=9 cm", "radius=9")).diagnostics[0]
    assert diagnostic.label == "expected a length in m, cm or mm"
    force = load_text(sub("<= 30 N", "<= 30")).diagnostics[0]
    assert (force.code, force.message) == ("FSV201", "missing unit: the limit of `contact_force` is a force")
    assert force.help == "write the unit after the number, e.g. `30 N`"


def test_relation_cycle_is_reported_once(load_text) -> None:
    diagnostics = load_text(add("object a: block() left_of b by 10 cm",
                                "object b: block() right_of a by 10 cm")).diagnostics
    assert [d.code for d in diagnostics] == ["FSV307"]


def test_unknown_asset_does_not_cascade(load_text) -> None:
    """`pot` is declared (with a bad asset), so its uses are not "unknown" as well."""
    diagnostics = load_text(sub("pot(radius=9 cm)", "pan(radius=9 cm)")).diagnostics
    assert [d.code for d in diagnostics] == ["FSV102"]


def test_broken_limit_does_not_add_a_coverage_warning(load_text) -> None:
    diagnostics = load_text(sub("<= 30 N", "<= 30 m")).diagnostics
    assert [d.code for d in diagnostics] == ["FSV203"]


def test_suite_not_covered_is_a_warning(load_text) -> None:
    result = load_text(sub("  constrain contact_force(gripper) <= 30 N warn 8 N\n", ""))
    assert [(d.code, d.severity, d.span.line, d.span.column, d.message) for d in result.diagnostics] == [
        ("FSV308", Severity.WARNING, 2, 9, "suite `force` but nothing in the scenario measures it")]
    assert result.ok and result.scenario is not None  # a warning does not stop the IR


def test_zone_without_keep_is_a_warning(load_text) -> None:
    result = load_text(add("hazard hz: no_go_zone(radius=5 cm) at (30 cm, 0)"))
    assert [(d.code, d.severity, d.span.line) for d in result.diagnostics] == [
        ("FSV309", Severity.WARNING, 9)]


def test_several_semantic_errors_are_all_reported(load_text) -> None:
    program = (BASE.replace("suite force", "suite forse")
               .replace("embodiment panda", "embodiment pandas")
               .replace("radius=9 cm", "radius=90 cm")
               .replace("<= 30 N", "<= 30 m")
               .replace("success lifted(pot)", "success lifed(pot)")
               + "  object mug: mug(hieght=10 cm)\n")
    result = load_text(program)
    assert result.scenario is None
    assert [(d.code, d.span.line, d.span.column) for d in result.diagnostics] == [
        ("FSV108", 2, 9), ("FSV107", 4, 14), ("FSV204", 6, 26), ("FSV203", 7, 39),
        ("FSV105", 8, 11), ("FSV103", 9, 19)]


# ----------------------------------------------------------- files: extends

def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_cyclic_inheritance(tmp_path: Path) -> None:
    a = _write(tmp_path, "a.fsv", "scenario a extends b\n  suite force\n")
    _write(tmp_path, "b.fsv", "abstract scenario b extends a\n  suite force\n")
    result = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(a)
    assert result.scenario is None
    assert [(d.code, d.span.file, d.span.line, d.span.column, d.message) for d in result.diagnostics] == [
        ("FSV402", "b.fsv", 1, 21, "cyclic inheritance: a extends b extends a")]
    assert set(result.sources) == {"a.fsv", "b.fsv"}


def test_self_inheritance(tmp_path: Path) -> None:
    a = _write(tmp_path, "a.fsv", 'scenario a extends "a.fsv"\n  suite force\n')
    diagnostics = ScenarioLoader(display_root=tmp_path).load(a).diagnostics
    assert [(d.code, d.message) for d in diagnostics] == [("FSV402", "cyclic inheritance: a extends a")]


def test_extends_not_found(tmp_path: Path) -> None:
    by_name = _write(tmp_path, "d.fsv", "scenario d extends nothere\n  suite force\n")
    by_path = _write(tmp_path, "e.fsv", 'scenario e extends "nothere.fsv"\n  suite force\n')
    loader = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path)
    [named] = loader.load(by_name).diagnostics
    assert (named.code, named.span.line, named.span.column, named.message) == (
        "FSV401", 1, 12, "no scenario `nothere` to extend")
    assert named.notes == ("looked for nothere.fsv", "looked for _base/nothere.fsv")
    [pathed] = loader.load(by_path).diagnostics
    assert (pathed.code, pathed.message) == ("FSV401", "no file `nothere.fsv` to extend")


def test_extends_outside_roots(tmp_path: Path) -> None:
    _write(tmp_path, "x.fsv", "abstract scenario x\n  suite force\n")  # exists, but outside the root
    child = _write(tmp_path, "sub/c.fsv", 'scenario c extends "../x.fsv"\n  suite force\n')
    result = ScenarioLoader(allowed_roots=[tmp_path / "sub"], display_root=tmp_path).load(child)
    assert [(d.code, d.span.file, d.span.line, d.span.column, d.message) for d in result.diagnostics] == [
        ("FSV403", "sub/c.fsv", 1, 12, "`../x.fsv` is outside the allowed folders")]
    assert result.diagnostics[0].notes == (f"allowed: {(tmp_path / 'sub').resolve()}",)


def test_asset_path_outside_roots_names_the_path(tmp_path: Path) -> None:
    folder = tmp_path / "deep" / "er"
    path = _write(folder, "m.fsv", add('object m: mesh(path="../../etc/passwd")'))
    [diagnostic] = ScenarioLoader(allowed_roots=[folder], display_root=tmp_path).load(path).diagnostics
    assert (diagnostic.code, diagnostic.span.file, diagnostic.span.line) == ("FSV403", "deep/er/m.fsv", 9)


def test_existing_asset_file_is_resolved(tmp_path: Path) -> None:
    _write(tmp_path, "models/cup.obj", "v 0 0 0\n")
    path = _write(tmp_path, "m.fsv", add('object cup: mesh(path="models/cup.obj", scale=2)'))
    result = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(path)
    assert result.diagnostics == []
    cup = result.scenario.object("cup")
    assert cup.params == {"path": str((tmp_path / "models/cup.obj").resolve()), "scale": 2.0, "friction": 0.6}


def test_base_with_errors(tmp_path: Path) -> None:
    _write(tmp_path, "_base/b.fsv", "abstract scenario b\n  suite forse $\n")
    child = _write(tmp_path, "c.fsv", "scenario c extends b\n  suite force\n")
    [diagnostic] = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(child).diagnostics
    assert (diagnostic.code, diagnostic.message) == ("FSV406", "the base scenario `b` has errors")
    assert diagnostic.notes == ("_base/b.fsv:2:15: FSV001 unexpected character `$`",)


def test_extends_by_name_checks_the_scenario_name(tmp_path: Path) -> None:
    (tmp_path / "base.fsv").write_text("abstract scenario other_name\n  suite force\n")
    (tmp_path / "child.fsv").write_text("scenario child extends base\n  suite force\n")
    result = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(tmp_path / "child.fsv")
    first = result.errors[0]
    assert (first.code, first.span.line, first.span.column) == ("FSV401", 1, 16)
    assert first.message == "base.fsv defines scenario `other_name`, not `base`"


def test_too_many_diagnostics_end_with_a_count(tmp_path: Path) -> None:
    lines = [f"  object o{i}: pott()" for i in range(230)]
    (tmp_path / "many.fsv").write_text("scenario many\n" + "\n".join(lines) + "\n")
    result = ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(tmp_path / "many.fsv")
    last = result.diagnostics[-1]
    assert last.code == "FSV900"
    assert last.message.startswith("... and ") and last.message.endswith(" more diagnostics not shown")
    shown = len(result.diagnostics) - 1
    dropped = int(last.message.split()[2])
    assert shown == 200 and shown + dropped >= 230
