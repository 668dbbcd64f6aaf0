"""The `fsvla` command line: exit codes, the three output formats, compile and schema."""

from __future__ import annotations

import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.render import render_full
from rich.console import Console

from fsvla.cli import run

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
CONCRETE_NAMES = sorted(p.stem for p in SCENARIOS.rglob("*.fsv") if "_base" not in p.parts)

BROKEN = """\
scenario s
  suite force
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  object pot: pot(radus=9 cm)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(pot)
  object pot: mug()
"""


@pytest.fixture
def broken(tmp_path: Path) -> Path:
    path = tmp_path / "broken.fsv"
    path.write_text(BROKEN, encoding="utf-8")
    return path


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


# ------------------------------------------------------------------ exit codes

def test_clean_scenarios_exit_0(capsys: pytest.CaptureFixture) -> None:
    assert run(["check", str(SCENARIOS)]) == 0
    out = capsys.readouterr().out
    assert out.strip().splitlines()[-1] == f"{len(CONCRETE_NAMES) + 1} files checked: no problems"


def test_errors_exit_1(broken: Path, capsys: pytest.CaptureFixture) -> None:
    assert run(["check", str(broken)]) == 1
    assert "1 file checked: 2 errors, 0 warnings" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [
    ["check", "--bogus", "scenarios"],
    ["check"],
    ["check", "does/not/exist.fsv"],
    ["check", "--format", "xml", "scenarios"],
    ["frobnicate"],
], ids=["unknown-option", "missing-path", "path-does-not-exist", "unknown-format", "unknown-command"])
def test_usage_errors_exit_2(argv: list[str], capsys: pytest.CaptureFixture, monkeypatch) -> None:
    monkeypatch.chdir(REPO)
    assert run(argv) == 2
    assert "Error:" in capsys.readouterr().err


def test_folder_without_scenarios_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert run(["check", str(tmp_path)]) == 2
    assert "no .fsv files under" in capsys.readouterr().err


def test_strict_makes_warnings_fail(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    path = tmp_path / "warn.fsv"
    path.write_text(BROKEN.replace("radus", "radius").replace("  object pot: mug()\n", "")
                    .replace("  constrain contact_force(gripper) <= 30 N warn 8 N\n", ""), encoding="utf-8")
    assert run(["check", str(path)]) == 0
    assert run(["check", "--strict", str(path)]) == 1
    assert "FSV308" in capsys.readouterr().out


# --------------------------------------------------------------------- formats

def test_concise_format(broken: Path, in_tmp: Path, capsys: pytest.CaptureFixture) -> None:
    assert run(["check", "--format", "concise", "broken.fsv"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines == [
        "broken.fsv:6:19: FSV103 `pot` has no parameter `radus` (did you mean `radius`?)",
        "broken.fsv:9:10: FSV110 the name `pot` is given twice (keep one of them)",
    ]
    assert all(re.match(r"^[^:]+:\d+:\d+: FSV\d{3} ", line) for line in lines)


def test_json_format(broken: Path, in_tmp: Path, capsys: pytest.CaptureFixture) -> None:
    assert run(["check", "--format", "json", "broken.fsv"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert isinstance(data, list) and len(data) == 2
    assert [(d["code"], d["severity"], d["span"]["line"], d["span"]["column"]) for d in data] == [
        ("FSV103", "error", 6, 19), ("FSV110", "error", 9, 10)]
    assert data[0]["span"] == {"file": "broken.fsv", "line": 6, "column": 19, "end_line": 6, "end_column": 24}
    assert data[1]["related"] == [{"span": {"file": "broken.fsv", "line": 6, "column": 10, "end_line": 6,
                                            "end_column": 13}, "message": "first given here"}]


def test_json_format_clean_is_an_empty_list(capsys: pytest.CaptureFixture) -> None:
    assert run(["check", "--format", "json", str(SCENARIOS)]) == 0
    assert json.loads(capsys.readouterr().out) == []


def test_full_format_on_stdout(broken: Path, in_tmp: Path, capsys: pytest.CaptureFixture) -> None:
    assert run(["check", "broken.fsv"]) == 1
    out = capsys.readouterr().out
    assert "\x1b[" not in out  # no colour when not on a terminal
    assert out == FULL_EXPECTED + "\n1 file checked: 2 errors, 0 warnings\n"


FULL_EXPECTED = """\
error[FSV103]: `pot` has no parameter `radus`
 --> broken.fsv:6:19
  |
6 |   object pot: pot(radus=9 cm)
  |                   ^^^^^ unknown parameter
help: did you mean `radius`?

error[FSV110]: the name `pot` is given twice
 --> broken.fsv:9:10
  |
9 |   object pot: mug()
  |          ^^^ given again here
  |
6 |   object pot: pot(radus=9 cm)
  |          --- first given here
help: keep one of them
"""


def _render(diagnostic, sources) -> str:
    stream = io.StringIO()
    Console(file=stream, color_system=None, width=200, highlight=False, soft_wrap=True).print(
        render_full(diagnostic, sources), end="")
    return stream.getvalue()


def test_rendered_caret_is_under_the_exact_columns() -> None:
    result = ScenarioLoader().loads("scenario s\n  horizon 20 fortnights\n", "m.fsv")
    text = _render(result.diagnostics[0], result.sources)
    assert text == (
        "error[FSV202]: unknown unit `fortnights`\n"
        " --> m.fsv:2:14\n"
        "  |\n"
        "2 |   horizon 20 fortnights\n"
        "  |              ^^^^^^^^^^ not a unit\n"
        "help: known units: `Hz`, `N`, `Nm`, `cm`, `deg`, `g`, `kg`, `m`, `mm`, `ms`, `rad`, `s`\n")
    source_line, caret_line = text.splitlines()[3:5]
    start = caret_line.index("^")
    assert source_line[start:start + len("fortnights")] == "fortnights"


def test_rendered_notes_and_wide_gutter(tmp_path: Path) -> None:
    program = "scenario s\n" + "  # filler\n" * 10 + "  suite force\n  suite force extra\n"
    result = ScenarioLoader().loads(program, "m.fsv")
    assert _render(result.diagnostics[0], result.sources) == (
        "error[FSV009]: unexpected `extra` after a complete statement\n"
        "  --> m.fsv:13:15\n"
        "   |\n"
        "13 |   suite force extra\n"
        "   |               ^^^^^ the statement already ended before this\n"
        "help: remove it, or put it on a line of its own\n")


# --------------------------------------------------------------------- compile

def test_compile_writes_concrete_scenarios(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "out"
    assert run(["compile", str(SCENARIOS), "-o", str(out)]) == 0
    assert sorted(p.stem for p in out.glob("*.json")) == CONCRETE_NAMES
    assert not (out / "lift_pot.json").exists()  # the abstract base is not written
    assert list(out.glob(".*")) == []  # no temporary files left behind
    data = json.loads((out / "lift_pot_beside_stove.json").read_text(encoding="utf-8"))
    assert data["name"] == "lift_pot_beside_stove" and data["schema_version"] == "1.0"
    assert f"{len(CONCRETE_NAMES)} scenario(s) compiled, 0 error(s)" in capsys.readouterr().out


def test_compile_leaves_old_output_of_a_failing_file(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    good = BROKEN.replace("radus", "radius").replace("  object pot: mug()\n", "")
    source = tmp_path / "s.fsv"
    source.write_text(good, encoding="utf-8")
    out = tmp_path / "out"
    assert run(["compile", str(source), "-o", str(out), "--format", "concise"]) == 0
    before = (out / "s.json").read_text(encoding="utf-8")
    assert json.loads(before)["name"] == "s"
    source.write_text(BROKEN, encoding="utf-8")
    assert run(["compile", str(source), "-o", str(out), "--format", "concise"]) == 1
    assert (out / "s.json").read_text(encoding="utf-8") == before
    assert "FSV103" in capsys.readouterr().out


def test_compile_nothing_to_write_creates_no_folder(broken: Path, tmp_path: Path) -> None:
    out = tmp_path / "never"
    assert run(["compile", str(broken), "-o", str(out), "--format", "json"]) == 1
    assert not out.exists()


def test_compile_requires_output(capsys: pytest.CaptureFixture) -> None:
    assert run(["compile", str(SCENARIOS)]) == 2
    assert "Missing option" in capsys.readouterr().err


# ---------------------------------------------------------------------- schema

def test_schema_is_a_json_schema_of_the_ir(capsys: pytest.CaptureFixture) -> None:
    assert run(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["title"] == "fsvla scenario IR"
    assert schema["$id"] == "urn:fsvla:schema:scenario:1.0"
    assert schema["type"] == "object"
    assert {"name", "suite", "task", "objects", "limits", "requirements", "success", "variants"} <= set(
        schema["properties"])
    assert {"ObjectSpec", "ZoneSpec", "LimitSpec", "Requirement", "Predicate", "Task", "Jitter",
            "Tighten", "LanguageVariant", "VisionSetting", "SourceRef"} <= set(schema["$defs"])
    assert schema["$defs"]["LimitSpec"]["properties"]["comparison"]["enum"] == ["<=", ">="]


def test_schema_accepts_the_compiled_ir(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    assert run(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    out = tmp_path / "out"
    assert run(["compile", str(SCENARIOS), "-o", str(out), "--format", "concise"]) == 0
    for path in out.glob("*.json"):
        jsonschema.validate(json.loads(path.read_text(encoding="utf-8")), schema)


def test_version(capsys: pytest.CaptureFixture) -> None:
    assert run(["--version"]) == 0
    assert capsys.readouterr().out.startswith("fsvla, version ")


# ------------------------------------------------------------------ subprocess

def test_python_dash_m(broken: Path) -> None:
    env = {**os.environ, "NO_COLOR": "1", "TERM": "dumb"}
    clean = subprocess.run([sys.executable, "-m", "fsvla", "check", "--format", "concise", str(SCENARIOS)],
                           capture_output=True, text=True, env=env, timeout=60, check=False)
    assert (clean.returncode, clean.stdout, clean.stderr) == (0, "", "")
    failing = subprocess.run([sys.executable, "-m", "fsvla", "check", "--format", "concise", "broken.fsv"],
                             capture_output=True, text=True, env=env, timeout=60, cwd=broken.parent,
                             check=False)
    assert failing.returncode == 1
    assert failing.stdout.splitlines()[0] == (
        "broken.fsv:6:19: FSV103 `pot` has no parameter `radus` (did you mean `radius`?)")
    assert "Traceback" not in failing.stderr
    usage = subprocess.run([sys.executable, "-m", "fsvla", "check", "--nope"], capture_output=True,
                           text=True, env=env, timeout=60, check=False)
    assert usage.returncode == 2 and "No such option" in usage.stderr


def test_check_a_suite_folder_finds_the_shared_bases() -> None:
    # scenarios/thermal/ extends scenarios/_base/lift_pot.fsv: the root is the scenario tree.
    assert run(["check", "--format", "concise", str(SCENARIOS / "thermal")]) == 0
