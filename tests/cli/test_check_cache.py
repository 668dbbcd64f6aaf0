"""`fsvla check` with its result cache: the same bytes and exit code in every format,
whether a file was checked afresh, stored or read back; --no-cache and FSVLA_NO_CACHE=1
neither read nor write it."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.cache import CheckCache
from fsvla.dsl.loader import ScenarioLoader

from fsvla.cli import run

BASE = """\
abstract scenario base
  suite force
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  object pot: pot(radius=9 cm) at (0, 0)
  constrain grip: contact_force(gripper) <= 30 N warn 8 N
  success lifted(pot)
"""

FILES = {
    "_base/base.fsv": BASE,
    "suite/clean.fsv": "scenario clean extends base\n  horizon 20 s\n",
    "suite/errors.fsv": ("scenario errors extends base\n  object cup: mug(radus=4 cm) at (20 cm, 0)\n"
                         "  object cup: mug()\n"),
    "suite/warning.fsv": ("scenario warning extends base\n"
                          "  hazard hot: heat_zone(size=(10 cm, 10 cm)) at (-20 cm, 0) on table\n"),
    "suite/syntax.fsv": "scenario syntax extends base\n  object cup mug(\n  horizon 5\n",
    "suite/no_base.fsv": "scenario no_base extends \"../_base/missing.fsv\"\n  horizon 20 s\n",
}


@pytest.fixture
def tree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scenario tree with clean files, errors, a warning and a syntax error; the current folder."""
    for name, text in FILES.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _check(capsys: pytest.CaptureFixture, *argv: str) -> tuple[int, str]:
    code = run(["check", *argv, "."])
    return code, capsys.readouterr().out


def _no_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(text: str, name: str):
        raise AssertionError(f"{name} was parsed: the cache missed")

    monkeypatch.setattr(ScenarioLoader, "_parse_text", staticmethod(refuse))


@pytest.mark.parametrize("output_format", ["full", "concise", "json"])
def test_the_same_output_with_and_without_the_cache(
        tree: Path, check_cache_dir: Path, output_format: str, capsys: pytest.CaptureFixture,
        monkeypatch: pytest.MonkeyPatch) -> None:
    fresh = _check(capsys, "--format", output_format, "--no-cache")
    assert fresh[0] == 1 and fresh[1].strip()
    assert not list(check_cache_dir.rglob("*.json"))
    assert _check(capsys, "--format", output_format) == fresh  # every file checked and stored
    assert len(list(check_cache_dir.rglob("*.json"))) == len(FILES)
    _no_parsing(monkeypatch)
    assert _check(capsys, "--format", output_format) == fresh  # every file read back


def test_the_full_format_of_a_hit_quotes_the_base(tree: Path, capsys: pytest.CaptureFixture,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    (tree / "_base" / "base.fsv").write_text(BASE.replace("<= 30 N", "<= 30 cm"), encoding="utf-8")
    fresh = _check(capsys, "--no-cache")
    _check(capsys)
    _no_parsing(monkeypatch)
    again = _check(capsys)
    assert again == fresh
    assert "constrain grip: contact_force(gripper) <= 30 cm" in again[1]  # a line of the base


def test_editing_a_base_invalidates_every_file_that_extends_it(
        tree: Path, capsys: pytest.CaptureFixture) -> None:
    assert _check(capsys, "--format", "concise")[0] == 1
    (tree / "_base" / "base.fsv").write_text(BASE.replace("<= 30 N", "<= 30 cm"), encoding="utf-8")
    fresh = _check(capsys, "--format", "concise", "--no-cache")
    assert _check(capsys, "--format", "concise") == fresh
    assert fresh[1].count("FSV203") >= 3  # the base, and each file extending it that checks it


def test_a_missing_base_that_appears_invalidates(tree: Path, capsys: pytest.CaptureFixture) -> None:
    assert "FSV401" in _check(capsys, "--format", "concise")[1]
    (tree / "_base" / "missing.fsv").write_text(BASE.replace("base", "missing"), encoding="utf-8")
    fresh = _check(capsys, "--format", "concise", "--no-cache")
    assert _check(capsys, "--format", "concise") == fresh
    assert "FSV401" not in fresh[1]


def test_strict_counts_cached_warnings(tree: Path, capsys: pytest.CaptureFixture,
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    warning = str(tree / "suite" / "warning.fsv")
    assert run(["check", warning]) == 0
    _no_parsing(monkeypatch)
    assert run(["check", warning]) == 0
    assert run(["check", "--strict", warning]) == 1
    assert "FSV309" in capsys.readouterr().out


@pytest.mark.parametrize("switch", ["option", "environment"])
def test_no_cache_neither_reads_nor_writes(tree: Path, check_cache_dir: Path, switch: str,
                                           capsys: pytest.CaptureFixture,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(self, path):
        raise AssertionError("the cache was used")

    monkeypatch.setattr(CheckCache, "load", refuse)
    argv = ["--format", "concise"]
    if switch == "option":
        argv.append("--no-cache")
    else:
        monkeypatch.setenv("FSVLA_NO_CACHE", "1")
    assert _check(capsys, *argv)[0] == 1
    assert not list(check_cache_dir.rglob("*"))


def test_a_corrupt_cache_is_ignored(tree: Path, check_cache_dir: Path,
                                    capsys: pytest.CaptureFixture) -> None:
    fresh = _check(capsys, "--format", "json", "--no-cache")
    _check(capsys, "--format", "json")
    for entry in check_cache_dir.rglob("*.json"):
        entry.write_bytes(entry.read_bytes()[: len(entry.read_bytes()) // 2])
    assert _check(capsys, "--format", "json") == fresh
    assert _check(capsys, "--format", "json") == fresh  # written again, whole
