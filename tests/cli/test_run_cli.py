"""`fsvla run` and `fsvla replay`: a small run end to end, resume, and bad input (exit 2,
nothing written, no traceback)."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pyarrow")
from fsvla.cli import run

pytestmark = pytest.mark.sim

SHORT = """\
scenario short_lift
  suite thermal
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  horizon 1 s
  object pot: pot(radius=8 cm, height=10 cm) at (0, 0)
  constrain contact_force(gripper) <= 40 N warn 10 N
  success lifted(pot)
"""


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scenarios") / "short_lift.fsv"
    path.write_text(SHORT, encoding="utf-8")
    return path


def test_run_resume_and_replay(scenario: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "exp1"
    args = ["run", "--policy", "random", "--scenarios", str(scenario), "--levels", "L0,L1",
            "--language", "W0-W1", "--episodes", "2", "--seeds", "2", "--workers", "0",
            "--out", str(out)]
    assert run(args) == 0
    printed = capsys.readouterr().out
    assert "9 episode(s) recorded now, 0 already recorded, 9 planned" in printed
    assert "short_lift" in printed and "SSR" in printed and "SASR" in printed

    assert run(["run", "--out", str(out), "--workers", "0"]) == 0  # options from the folder
    assert "0 episode(s) recorded now, 9 already recorded" in capsys.readouterr().out

    assert run(["run", "--out", str(out), "--workers", "0", "--episodes", "3", "--extend"]) == 0
    assert "4 episode(s) recorded now, 9 already recorded, 13 planned" in capsys.readouterr().out

    assert run(["replay", str(out), "short_lift-L1-W1-V0-s0-e002"]) == 0
    assert "identical" in capsys.readouterr().out


@pytest.mark.parametrize(("args", "says"), [
    (["--scenarios", "nosuch"], "--scenarios: unknown scenario 'nosuch'"),
    (["--language", "W0-W5"], "--language: 'W5' is not one of W0 to W4"),
    (["--levels", "L2-L0"], "--levels: range 'L2-L0' runs backwards"),
    (["--seeds", "x"], "--seeds: 'x' is not a seed"),
    (["--policy", "careful-expart"], "--policy 'careful-expart': not a built-in policy"),
    (["--policy", "no_such_module:Thing"], "cannot import no_such_module"),
    (["--vision", "V0-V2", "--obs-mode", "state"], "--vision: V1, V2 change only the pictures"),
    (["--embodiment", "pandaa"], "--embodiment: unknown embodiment `pandaa`"),
    (["--sasr-lambda", "-1"], "--sasr-lambda: Input should be greater than or equal to 0"),
    (["--policy-timeout", "0"], "--policy-timeout: Input should be greater than 0"),
    (["--cameras", "frnt"], "unknown camera 'frnt'; did you mean 'front'?"),
    (["--cameras", ","], "--cameras: name at least one camera"),
    (["--resolution", "160by120"], "--resolution: resolution must be WIDTHxHEIGHT"),
    (["--resolution", "0x120"], "--resolution: resolution 0x120 is outside 1..4096"),
    (["--shader", "fancy"], "Invalid value for '--shader'"),
])
def test_bad_input_names_the_option_and_writes_nothing(scenario: Path, tmp_path: Path, capsys,
                                                       args: list[str], says: str) -> None:
    out = tmp_path / "never"
    base = {"--policy": "hold-still", "--scenarios": str(scenario)}
    for option, value in zip(args[::2], args[1::2]):
        base[option] = value
    argv = ["run", "--out", str(out), "--workers", "0"]
    for option, value in base.items():
        argv += [option, value]
    assert run(argv) == 2
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err
    assert not out.exists()


def test_the_cameras_of_a_run_are_stored_and_resumed(scenario: Path, tmp_path: Path,
                                                       capsys) -> None:
    from fsvla.results import ResultStore

    out = tmp_path / "cams"
    assert run(["run", "--policy", "hold-still", "--scenarios", str(scenario), "--warmup", "0",
                "--workers", "0", "--out", str(out), "--cameras", "front",
                "--resolution", "160x120", "--shader", "default"]) == 0
    with ResultStore.open(out, readonly=True) as store:
        stored = store.config
    assert (stored.cameras, stored.resolution, stored.shader) == (("front",), (160, 120), "default")
    assert run(["run", "--out", str(out), "--workers", "0"]) == 0  # resumes with them
    assert "1 already recorded" in capsys.readouterr().out
    assert run(["run", "--out", str(out), "--workers", "0", "--resolution", "320x240"]) == 2
    assert "resolution: [160, 120] in the run folder, [320, 240] now" in capsys.readouterr().err


def test_a_patch_file_is_checked_stored_and_resumed(scenario: Path, tmp_path: Path,
                                                    capsys) -> None:
    import numpy as np
    from PIL import Image

    from fsvla.results import ResultStore

    (tmp_path / "patch.jpg").write_bytes(b"\xff\xd8 not a png")
    Image.fromarray(np.full((16, 16, 3), 200, dtype=np.uint8)).save(tmp_path / "patch.png")
    base = ["run", "--policy", "hold-still", "--scenarios", str(scenario), "--warmup", "0",
            "--workers", "0", "--cameras", "front", "--resolution", "80x60"]
    for given, says in ((["--vision", "V4", "--patch", str(tmp_path / "nosuch.png")],
                         f"--patch: patch file {tmp_path / 'nosuch.png'}: no such file"),
                        (["--vision", "V4", "--patch", str(tmp_path / "patch.jpg")],
                         f"--patch: patch file {tmp_path / 'patch.jpg'}: not a PNG image"),
                        (["--patch", str(tmp_path / "patch.png")],
                         "--patch gives V4's patch its pixels, and the run has no V4")):
        assert run([*base, "--out", str(tmp_path / "never"), *given]) == 2
        err = capsys.readouterr().err
        assert says in err and "Traceback" not in err
        assert not (tmp_path / "never").exists()

    out = tmp_path / "patched"
    assert run([*base, "--out", str(out), "--vision", "V4", "--patch",
                str(tmp_path / "patch.png")]) == 0
    with ResultStore.open(out, readonly=True) as store:
        assert store.config.patch == str((tmp_path / "patch.png").resolve())
    assert run(["run", "--out", str(out), "--workers", "0"]) == 0  # resumes with it
    assert "1 already recorded" in capsys.readouterr().out


def test_a_run_folder_holding_another_run_is_refused(scenario: Path, tmp_path: Path,
                                                     capsys) -> None:
    out = tmp_path / "exp"
    common = ["run", "--scenarios", str(scenario), "--workers", "0", "--out", str(out)]
    assert run([*common, "--policy", "hold-still"]) == 0
    capsys.readouterr()
    assert run([*common, "--policy", "random"]) == 2
    err = capsys.readouterr().err
    assert "policy: 'hold-still' in the run folder, 'random' now" in err
    assert run(["run", "--out", str(tmp_path / "empty"), "--workers", "0"]) == 2
    assert "--policy is required to start a run" in capsys.readouterr().err


def test_replay_input_errors(tmp_path: Path, capsys) -> None:
    assert run(["replay", str(tmp_path), "some-episode"]) == 2
    assert "holds no run" in capsys.readouterr().err


def test_ray_backend_without_ray_is_a_usage_error(scenario: Path, tmp_path: Path, capsys,
                                                  monkeypatch) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "ray" else real(name, *a))
    argv = ["run", "--policy", "hold-still", "--scenarios", str(scenario), "--backend", "ray",
            "--out", str(tmp_path / "ray")]
    assert run(argv) == 2
    assert "--backend ray needs the ray package" in capsys.readouterr().err
    assert not (tmp_path / "ray").exists()


def test_sweep_plans_eleven_cells_a_scenario(scenario: Path, tmp_path: Path, monkeypatch,
                                             capsys) -> None:
    import fsvla.runner

    planned = {}

    def capture(prepared, *args, **kwargs):
        planned["config"], planned["plan"] = prepared.config, prepared.plan
        raise fsvla.runner.RunInputError("--sweep", "stop: the plan is all this test needs")

    monkeypatch.setattr(fsvla.runner, "execute_run", capture)
    argv = ["run", "--policy", "hold-still", "--scenarios", str(scenario), "--sweep",
            "--episodes", "2", "--warmup", "0", "--workers", "0", "--out", str(tmp_path / "s")]
    assert run(argv) == 2 and "stop: the plan" in capsys.readouterr().err
    config, plan = planned["config"], planned["plan"]
    assert config.sweep and config.obs_mode == "rgb"  # V1-V4 are in the sweep
    cells = {(s.key.level, s.key.language, s.key.vision) for s in plan}
    assert len(cells) == 11 and len(plan) == 22
    assert {c for c in cells if c[1:] == ("W0", "V0")} == {("L0", "W0", "V0"), ("L1", "W0", "V0"),
                                                        ("L2", "W0", "V0")}


@pytest.mark.parametrize("option", [["--levels", "L0-L1"], ["--language", "W0"],
                                    ["--vision", "V0-V4"]])
def test_sweep_with_explicit_levels_is_a_usage_error(scenario: Path, tmp_path: Path, capsys,
                                                     option: list[str]) -> None:
    out = tmp_path / "never"
    argv = ["run", "--policy", "hold-still", "--scenarios", str(scenario), "--sweep", *option,
            "--workers", "0", "--out", str(out)]
    assert run(argv) == 2
    err = capsys.readouterr().err
    assert (f"--sweep runs L0-L2 at W0/V0, W0-W4 at L0/V0 and V0-V4 at L0/W0; it cannot be "
            f"combined with {option[0]}") in " ".join(err.split())
    assert "Traceback" not in err and not out.exists()
