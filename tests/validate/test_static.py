"""The static checks on small scenarios written inline: the exact code, message and line."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.loader import ScenarioLoader

from fsvla.cli import run
from fsvla.embodiments import load_embodiment
from fsvla.resources import scenarios_dir
from fsvla.validate.robots import robot_model
from fsvla.validate.sources import Located, span_text
from fsvla.validate.static import static_diagnostics

pytestmark = pytest.mark.sim

HEAD = """\
scenario {name}
  suite {suite}
  task {task}
  embodiment {embodiment}
  instruction "Do it."
"""


def write(folder: Path, name: str, body: str, *, task: str, embodiment: str = "panda",
          suite: str = "force") -> Path:
    path = folder / f"{name}.fsv"
    path.write_text(HEAD.format(name=name, suite=suite, task=task, embodiment=embodiment) + body,
                    encoding="utf-8")
    return path


def findings(path: Path):
    result = ScenarioLoader(allowed_roots=[path.parent], display_root=path.parent).load(path)
    assert result.ok, result.diagnostics
    located = Located(result.path, result.scenario, result.sources)
    return located, static_diagnostics(located, [path.parent])


def only(diagnostics, code: str):
    found = [d for d in diagnostics if d.code == code]
    assert len(found) == 1, [(d.code, d.message) for d in diagnostics]
    return found[0]


def test_an_object_beyond_the_arm_is_out_of_reach(tmp_path: Path) -> None:
    path = write(tmp_path, "far_cube", """
  object cube: block(size=(4 cm, 4 cm, 4 cm), mass=0.1 kg) at (34 cm, 30 cm)
  object tray: tray(size=(20 cm, 16 cm)) at (0, -15 cm)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success on(cube, tray)
""", task="pick_place(cube, tray)")
    located, found = findings(path)
    reach = only(found, "FSV701")
    assert reach.message == "panda cannot reach `cube` at (34 cm, 30 cm): 3.3 cm beyond its workspace"
    assert (reach.span.line, reach.span.column, reach.severity.value) == (7, 10, "warning")
    assert span_text(reach.span, located.sources).startswith("cube: block(")
    assert reach.help == "move `cube` at least 3.3 cm closer to the robot's base"
    assert [d.code for d in found] == ["FSV701"]  # inside the compiler's margin: no FSV603


def test_far_out_of_reach_on_so101_also_fails_the_layout(tmp_path: Path) -> None:
    path = write(tmp_path, "cube_far", """
  object cube: block(size=(3 cm, 3 cm, 3 cm)) at (41 cm, -8 cm)
  object bowl: bowl(radius=6 cm) at (5 cm, 8 cm)
  constrain contact_force(gripper) <= 20 N warn 5 N
  success inside(cube, bowl)
""", task="pick_place(cube, bowl)", embodiment="so101")
    _, found = findings(path)
    reach = only(found, "FSV701")
    assert reach.message == "so101 cannot reach `cube` at (41 cm, -8 cm): 13.5 cm beyond its workspace"
    assert reach.span.line == 7
    assert only(found, "FSV603").span.line == 7  # the compiler's own reach margin, too


def test_the_knob_of_a_lid_standing_open_out_of_reach(tmp_path: Path) -> None:
    """The box is in reach, but its lid, open 90 %, holds its knob high over the box's
    back edge: closing it starts beyond the arm."""
    body = """
  object lidded_box: lidded_box(size=(17.4 cm, 13.3 cm, 10 cm), open={open}) at (28.4 cm, 5.2 cm)
  success {success}(lidded_box) for 1 s
"""
    path = write(tmp_path, "far_lid", body.format(open=0.9, success="closed"),
                 task="close(object=lidded_box)")
    located, found = findings(path)
    reach = only(found, "FSV701")
    assert reach.message == ("panda cannot reach the knob of `lidded_box`'s `lid` (open 90%) at "
                             "(40.41 cm, 5.2 cm, 26.7 cm): 1.1 cm beyond its workspace")
    assert (reach.span.line, reach.span.column) == (7, 10)
    assert span_text(reach.span, located.sources).startswith("lidded_box: lidded_box(")
    assert reach.help == ("move `lidded_box` at least 1.1 cm closer to the robot's base, or "
                          "start it less open")
    # shut, the knob is at the box's front edge, 20 cm nearer the robot: in reach
    path = write(tmp_path, "far_lid", body.format(open=0.0, success="opened"),
                 task="open(object=lidded_box)")
    assert [d.code for d in findings(path)[1]] == []


def test_a_force_limit_below_the_weight(tmp_path: Path) -> None:
    path = write(tmp_path, "weak_grip", """
  object cube: block(size=(4 cm, 4 cm, 4 cm), mass=0.5 kg) at (0, 10 cm)
  object tray: tray(size=(20 cm, 16 cm)) at (0, -15 cm)
  constrain grip: contact_force(gripper) <= 2 N warn 1 N
  constrain landing: contact_force(cube) <= 30 N warn 8 N
  success on(cube, tray)
""", task="pick_place(cube, tray)")
    _, found = findings(path)
    weight = only(found, "FSV703")
    assert weight.message == ("the 2 N limit on `contact_force(gripper)` is below the 4.91 N that "
                              "lifting `cube` (0.5 kg) needs")
    assert (weight.span.line, weight.span.column) == (9, 3)
    assert weight.notes == (("the task `pick_place` lifts `cube`: two fingers with friction 0.5 must "
                            "each press on it with m·g/(2·0.5) = 4.91 N to hold it up"),)


def test_a_two_arm_lift_shares_the_weight(tmp_path: Path) -> None:
    path = write(tmp_path, "heavy_pot", """
  object pot: pot(radius=9 cm, height=10 cm, mass=1 kg) at (0, 0)
  constrain contact_force(left_gripper) <= 4 N warn 1 N
  constrain contact_force(right_gripper) <= 6 N warn 1 N
  success lifted(pot)
""", task="bimanual_lift(pot)", embodiment="dual_panda")
    _, found = findings(path)
    weight = only(found, "FSV703")
    assert weight.message == ("the 4 N limit on `contact_force(left_gripper)` is below the 4.91 N "
                              "that lifting `pot` (1 kg) needs")
    assert weight.span.line == 8


def test_an_object_wider_than_the_gripper(tmp_path: Path) -> None:
    path = write(tmp_path, "wide_block", """
  object big: block(size=(12 cm, 12 cm, 12 cm)) at (0, 0)
  object cup: mug(radius=5 cm, height=10 cm) at (10 cm, 20 cm)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(big)
""", task="lift(big)")
    _, found = findings(path)
    wide = only(found, "FSV702")
    assert wide.message == "`big` is 12 cm wide at its narrowest, but the panda gripper opens 8 cm"
    assert (wide.span.line, wide.label) == (7, "too wide to grasp")
    # a mug 10 cm wide has a handle and walls the fingers fit around: no finding
    cup = write(tmp_path, "wide_cup", """
  object cup: mug(radius=5 cm, height=10 cm) at (0, 0)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(cup)
""", task="lift(cup)")
    assert findings(cup)[1] == []


def test_an_object_thinner_than_the_shut_fingers(tmp_path: Path) -> None:
    # Baxter's fingertips stop apart when shut: 1.6 cm on the left, 0.65 cm on the right
    path = write(tmp_path, "thin_peg", """
  object peg: block(size=(0.8 cm, 0.8 cm, 6 cm)) at (-5 cm, 10 cm)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(peg)
""", task="lift(peg)", embodiment="baxter")
    _, found = findings(path)
    thin = only(found, "FSV702")
    assert thin.message == ("`peg` has no part the gripper of arm `right` of baxter closes on: each "
                            "is wider than it opens (4.17 cm) or thinner than its shut fingers "
                            "squeeze (1.05 cm)")
    assert (thin.span.line, thin.label) == (7, "nothing to grasp")
    # a bar 1.2 cm thick: the right arm squeezes it, the left does not; a lift takes
    # either arm, a handover needs both
    bar = """
  object bar: block(size=(1.2 cm, 16 cm, 1.2 cm)) at (-25 cm, 15 cm) yaw 90 deg
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(bar)
"""
    assert findings(write(tmp_path, "bar_lift", bar, task="lift(bar)", embodiment="baxter"))[1] == []
    handed = only(findings(write(tmp_path, "bar_handover", bar, task="handover(bar)",
                                 embodiment="baxter"))[1], "FSV702")
    assert handed.message.startswith("`bar` has no part the gripper of arm `left` of baxter")
    assert "(2 cm)" in handed.message


def test_a_bowl_is_held_only_across_its_wall(tmp_path: Path) -> None:
    """A bowl's wall segments meet each other at their ends and the base at their feet:
    fingers close only across the wall's thickness, which Baxter's shut fingers leave
    loose (the experts refuse it: "no grasp of `bowl`")."""
    from fsvla.compiler.assets.registry import build_asset

    from fsvla.validate.static import graspable_widths, piece_widths

    bowl = build_asset("bowl", {"radius": 0.063, "height": 0.065})
    walls = [shape for shape in bowl.collision if shape.name.startswith("wall")]
    assert walls and all(max(piece_widths(w)) > 0.02 for w in walls)  # 2.9 cm along the wall
    assert all(w < 0.01 or w > 0.05 for w in graspable_widths(bowl))
    path = write(tmp_path, "bowl_baxter", """
  object bowl: bowl(radius=6.3 cm, height=6.5 cm) at (3.7 cm, -8.1 cm)
  success lifted(bowl)
""", task="lift(bowl)", embodiment="baxter")
    found = only(findings(path)[1], "FSV702")
    assert found.message.startswith("`bowl` has no part the gripper of arm `right` of baxter closes on")
    assert found.span.line == 7
    panda = write(tmp_path, "bowl_panda", """
  object bowl: bowl(radius=6.3 cm, height=6.5 cm) at (3.7 cm, 8.1 cm)
  success lifted(bowl)
""", task="lift(bowl)")
    assert [d for d in findings(panda)[1] if d.code == "FSV702"] == []


def test_the_shut_gap_is_measured_on_the_fingers() -> None:
    gaps = {name: [robot_model(load_embodiment(name)).shut_gap(arm)
                   for arm in robot_model(load_embodiment(name)).arms]
            for name in ("panda", "baxter", "so101", "z1")}
    assert gaps == {"panda": [0.0], "baxter": [pytest.approx(0.016, abs=1e-3),
                                                pytest.approx(0.0065, abs=1e-3)],
                    "so101": [0.0], "z1": [0.0]}


def test_a_hazard_covering_the_target(tmp_path: Path) -> None:
    path = write(tmp_path, "tray_on_stove", """
  object mug: mug(radius=3.5 cm, height=9 cm) at (-20 cm, -20 cm)
  object tray: tray(size=(20 cm, 16 cm)) at (10 cm, 10 cm)

  hazard stove: heat_zone(size=(30 cm, 30 cm)) at (10 cm, 10 cm) on table
    keep gripper, mug outside 5 cm warn 3 cm

  success on(mug, tray)
""", task="pick_place(mug, tray)", suite="thermal")
    _located, found = findings(path)
    covered = only(found, "FSV704")
    assert covered.message == ("hazard `stove` covers the target `tray`: with `mug` set down "
                               "anywhere on it, `mug` is within 5 cm of `stove`")
    assert (covered.span.line, covered.span.column) == (11, 5)
    assert [(r.span.line, r.message) for r in covered.related] == [(8, "the task's target")]
    assert [d.code for d in found] == ["FSV704"]
    # the same stove beside the tray leaves room on it
    moved = path.read_text(encoding="utf-8").replace("at (10 cm, 10 cm) on table",
                                                     "at (10 cm, 30 cm) on table")
    path.write_text(moved, encoding="utf-8")
    assert findings(path)[1] == []


def test_the_shipped_scenarios_have_no_static_finding() -> None:
    root = scenarios_dir()
    loader = ScenarioLoader(allowed_roots=[root])
    for path in sorted(root.rglob("*.fsv")):
        if "_base" in path.parts:
            continue
        result = loader.load(path)
        found = static_diagnostics(Located(result.path, result.scenario, result.sources), [root])
        assert found == [], (path, [d.message for d in found])


def test_gripper_openings_measured_at_the_tcp() -> None:
    assert robot_model(load_embodiment("panda")).opening("arm") == pytest.approx(0.08, abs=1e-3)
    so101 = robot_model(load_embodiment("so101"))
    assert 0.07 < so101.opening("arm") < 0.10  # a jaw swinging 1.15 rad
    assert so101.reach_gap("arm", (0.0, 0.0, 0.03)) == 0.0


def test_check_deep_adds_the_static_findings(tmp_path: Path, capsys) -> None:
    path = write(tmp_path, "wide_block", """
  object big: block(size=(12 cm, 12 cm, 12 cm)) at (0, 0)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(big)
""", task="lift(big)")
    assert run(["check", str(path), "--format", "concise"]) == 0
    assert "FSV702" not in capsys.readouterr().out
    assert run(["check", "--deep", str(path), "--format", "concise"]) == 0  # a warning
    out = capsys.readouterr().out
    assert f"{path}:7:10: FSV702 `big` is 12 cm wide at its narrowest" in out
    assert run(["check", "--deep", "--strict", str(path)]) == 1
