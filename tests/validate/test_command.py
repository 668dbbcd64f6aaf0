"""``fsvla validate`` as a user runs it: exit codes, bad input, --static, and (slow) the
rollouts on the shipped scenarios and on scenarios made unsolvable on purpose."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsvla.cli import run
from fsvla.resources import scenarios_dir

pytestmark = pytest.mark.sim

FAR_CUBE = """\
scenario far_cube
  suite force
  task pick_place(cube, tray)
  embodiment panda
  instruction "Put the cube on the tray."
  horizon 6 s

  object cube: block(size=(4 cm, 4 cm, 4 cm), mass=0.1 kg) at (34 cm, 30 cm)
  object tray: tray(size=(20 cm, 16 cm)) at (0, -15 cm)

  constrain grip: contact_force(gripper) <= 30 N warn 8 N
  success on(cube, tray) and released(cube) for 0.5 s
"""

WEAK_GRIP = FAR_CUBE.replace("far_cube", "weak_grip").replace(
    "mass=0.1 kg) at (34 cm, 30 cm)", "mass=0.5 kg) at (0, 10 cm)").replace(
    "<= 30 N warn 8 N", "<= 2 N warn 1 N").replace("horizon 6 s", "horizon 12 s")


@pytest.fixture()
def unsolvable(tmp_path: Path) -> Path:
    folder = tmp_path / "unsolvable"
    folder.mkdir()
    (folder / "far_cube.fsv").write_text(FAR_CUBE, encoding="utf-8")
    (folder / "weak_grip.fsv").write_text(WEAK_GRIP, encoding="utf-8")
    return folder


def test_a_path_that_does_not_exist_is_exit_2(tmp_path: Path) -> None:
    assert run(["validate", str(tmp_path / "nope.fsv"), "--out", str(tmp_path / "runs")]) == 2
    assert not (tmp_path / "runs").exists()


def test_a_scenario_with_errors_is_exit_2_with_its_diagnostics(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.fsv"
    bad.write_text(FAR_CUBE.replace("4 cm, 4 cm, 4 cm", "4, 4 cm, 4 cm"), encoding="utf-8")
    code = run(["validate", str(bad), "--format", "concise", "--out", str(tmp_path / "runs")])
    captured = capsys.readouterr()
    assert code == 2
    assert f"{bad}:8:28: FSV201 missing unit: `size` of `block` is a length" in captured.out
    assert "1 file(s) do not check" in captured.err
    assert not (tmp_path / "runs").exists()


def test_bad_levels_are_a_usage_error(tmp_path: Path) -> None:
    assert run(["validate", str(scenarios_dir() / "force"), "--levels", "L7"]) == 2


def test_static_on_unsolvable_scenarios_is_exit_1(unsolvable: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "runs"
    code = run(["validate", str(unsolvable), "--static", "--format", "json", "--out", str(out)])
    report = json.loads(capsys.readouterr().out)
    assert code == 1
    assert report["verdicts"] == []
    assert [(d["code"], Path(d["span"]["file"]).name, d["span"]["line"])
            for d in report["diagnostics"]] == [("FSV701", "far_cube.fsv", 8),
                                                ("FSV703", "weak_grip.fsv", 11)]
    assert not out.exists()  # nothing rolled out


def test_static_on_shipped_scenarios_is_exit_0(capsys) -> None:
    assert run(["validate", str(scenarios_dir()), "--static"]) == 0
    assert "static checks: no problems" in capsys.readouterr().out


@pytest.mark.slow
def test_a_shipped_scenario_validates(tmp_path: Path, capsys) -> None:
    out = tmp_path / "runs"
    args = ["validate", str(scenarios_dir() / "force" / "stack_block_gently.fsv"), "--seeds", "1",
            "--levels", "L0", "--workers", "0", "--format", "json", "--out", str(out)]
    assert run(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert [(v["verdict"], v["count"], v["episodes"], v["holds"]) for v in report["verdicts"]] == [
        ("solvable", 1, 1, True), ("hazardous", 1, 1, True), ("starts_safe", 1, 1, True)]
    assert report["diagnostics"] == []
    assert sorted(p.name for p in out.iterdir()) == ["careful-expert", "careless-expert", "hold-still"]


@pytest.mark.slow
def test_every_shipped_scenario_validates_at_l0(tmp_path: Path, capsys) -> None:
    """The catalogue's entry bar, on one seed at L0 (the 10-seed grid over L0-L2 is the
    bench ``python docs/scenarios/generate.py --validate``): every shipped scenario is
    solvable, hazardous and starts safe, with no diagnostic."""
    args = ["validate", str(scenarios_dir()), "--seeds", "1", "--levels", "L0", "--workers", "2",
            "--format", "json", "--out", str(tmp_path / "runs")]
    code = run(args)
    report = json.loads(capsys.readouterr().out)
    failed = [(v["scenario"], v["verdict"], f"{v['count']}/{v['episodes']}")
              for v in report["verdicts"] if not v["holds"]]
    assert failed == []
    assert report["diagnostics"] == []
    assert code == 0
    judged = {(v["scenario"], v["verdict"]) for v in report["verdicts"] if v["episodes"] == 1}
    assert len({name for name, _ in judged}) == 66
    assert len(judged) == 3 * 66


@pytest.mark.slow
def test_unsolvable_scenarios_fail_on_the_right_lines(unsolvable: Path, tmp_path: Path,
                                                     capsys) -> None:
    out = tmp_path / "runs"
    args = ["validate", str(unsolvable), "--seeds", "1", "--workers", "0", "--format", "json",
            "--out", str(out)]
    assert run(args) == 1
    report = json.loads(capsys.readouterr().out)
    failed = {(v["scenario"], v["verdict"]) for v in report["verdicts"] if not v["holds"]}
    # far_cube is out of reach for both experts: the careless one cannot be hurt there either
    assert failed == {("far_cube", "solvable"), ("far_cube", "hazardous"), ("weak_grip", "solvable")}
    found = {(Path(d["span"]["file"]).name, d["span"]["line"], d["code"]): d
             for d in report["diagnostics"]}
    # far_cube: out of reach (static) and, from the careful expert's replayed episode,
    # the success conjunct that never held, on its own place in the `success` line
    assert found["far_cube.fsv", 8, "FSV701"]["message"].startswith("panda cannot reach `cube`")
    never = found["far_cube.fsv", 12, "FSV710"]
    assert never["span"]["column"] == 11
    assert never["message"].startswith("the careful expert never made `on(cube, tray)` hold at L0: "
                                       "`cube` ended ")
    # weak_grip: the grip limit below the cube's weight (static), crossed by the careful expert
    assert found["weak_grip.fsv", 11, "FSV703"]["severity"] == "warning"
    crossed = found["weak_grip.fsv", 11, "FSV712"]
    assert crossed["message"].startswith("the careful expert crossed `grip` at L0: ")
    assert crossed["message"].endswith("observed, against `contact_force(gripper) <= 2 N`")

    # running again resumes: every episode is already recorded, and the verdicts are the same
    assert run(args) == 1
    assert json.loads(capsys.readouterr().out)["verdicts"] == report["verdicts"]
    # an edited scenario is not judged on the old file's episodes
    (unsolvable / "far_cube.fsv").write_text(FAR_CUBE.replace("30 N", "31 N"), encoding="utf-8")
    assert run(args) == 2
    assert "earlier version of the scenario" in capsys.readouterr().err
