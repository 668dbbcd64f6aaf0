"""The result cache of `fsvla check`: a hit gives what a fresh check gives; any change to any
input (the file, a base it extends, a file a search would now find first) is a miss; a
corrupt or unusable cache is only a miss."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.cache import CheckCache, CheckedFile, cache_folder, code_fingerprint
from fsvla.dsl.loader import ScenarioLoader

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

# One error (a misspelt parameter) and one warning (a hazard nothing keeps out).
CHILD = """\
scenario child extends base
  object cup: mug(radus=4 cm) at (20 cm, 0)
  hazard hot: heat_zone(size=(10 cm, 10 cm)) at (-20 cm, 0) on table
"""


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A scenario tree: ``_base/base.fsv`` and ``suite/child.fsv``, which extends it by name."""
    root = tmp_path / "tree"
    (root / "_base").mkdir(parents=True)
    (root / "suite").mkdir()
    (root / "_base" / "base.fsv").write_text(BASE, encoding="utf-8")
    (root / "suite" / "child.fsv").write_text(CHILD, encoding="utf-8")
    return root


def _loader(tree: Path) -> ScenarioLoader:
    return ScenarioLoader(allowed_roots=[tree], display_root=tree)


def _cached(tree: Path, folder: Path, name: str = "suite/child.fsv") -> CheckedFile:
    """Check ``name`` through a cache in ``folder``, with a fresh loader (as a new process has)."""
    return CheckCache(_loader(tree), folder).load(tree / name)


def _fresh(tree: Path, name: str = "suite/child.fsv") -> CheckedFile:
    return CheckedFile.of(_loader(tree).load(tree / name))


def _no_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(text: str, name: str):
        raise AssertionError(f"{name} was parsed: the cache missed")

    monkeypatch.setattr(ScenarioLoader, "_parse_text", staticmethod(refuse))


def test_the_child_has_an_error_and_a_warning(tree: Path) -> None:
    result = _fresh(tree)
    assert sorted((d.code, d.severity.value) for d in result.diagnostics) == [
        ("FSV103", "error"), ("FSV309", "warning")]
    assert set(result.sources) == {"suite/child.fsv", "_base/base.fsv"}


def test_a_hit_gives_what_a_fresh_check_gives_without_parsing(
        tree: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "cache"
    first = _cached(tree, folder)
    assert first == _fresh(tree)
    assert len(list(folder.glob("*.json"))) == 1
    _no_parsing(monkeypatch)
    assert _cached(tree, folder) == first


def test_editing_the_base_invalidates(tree: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    before = _cached(tree, folder)
    (tree / "_base" / "base.fsv").write_text(BASE.replace("<= 30 N", "<= 30 cm"), encoding="utf-8")
    after = _cached(tree, folder)
    assert after == _fresh(tree)
    assert "FSV203" in {d.code for d in after.diagnostics} - {d.code for d in before.diagnostics}


def test_editing_the_file_invalidates(tree: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    _cached(tree, folder)
    (tree / "suite" / "child.fsv").write_text(CHILD.replace("radus", "radius"), encoding="utf-8")
    assert [d.code for d in _cached(tree, folder).diagnostics] == ["FSV309"]


def test_a_base_that_the_search_now_finds_first_invalidates(tree: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    _cached(tree, folder)
    (tree / "suite" / "_base").mkdir()
    (tree / "suite" / "_base" / "base.fsv").write_text(BASE.replace("suite force", "suite forse"),
                                                       encoding="utf-8")
    after = _cached(tree, folder)
    assert after == _fresh(tree)
    assert "suite/_base/base.fsv" in after.sources


def test_a_base_that_disappears_invalidates(tree: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    _cached(tree, folder)
    (tree / "_base" / "base.fsv").unlink()
    assert [d.code for d in _cached(tree, folder).diagnostics] == ["FSV401"]


def test_another_display_root_is_another_entry(tree: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    _cached(tree, folder)
    elsewhere = CheckCache(ScenarioLoader(allowed_roots=[tree], display_root=tmp_path), folder)
    assert elsewhere.load(tree / "suite" / "child.fsv").path == "tree/suite/child.fsv"
    assert len(list(folder.glob("*.json"))) == 2


@pytest.mark.parametrize("damage", [b"", b"{not json", b'{"format": 1}', b"[]", b"\xff\xfe\0"],
                         ids=["empty", "not-json", "not-an-entry", "a-list", "binary"])
def test_a_corrupt_entry_is_a_miss(tree: Path, tmp_path: Path, damage: bytes) -> None:
    folder = tmp_path / "cache"
    expected = _cached(tree, folder)
    (entry,) = folder.glob("*.json")
    entry.write_bytes(damage)
    assert _cached(tree, folder) == expected
    assert entry.read_bytes() != damage  # written again, whole


def test_a_tampered_fact_is_a_miss(tree: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "cache"
    _cached(tree, folder)
    (entry,) = folder.glob("*.json")
    entry.write_text(entry.read_text(encoding="utf-8").replace('"read"', '"peek"'), encoding="utf-8")
    calls = []
    monkeypatch.setattr(ScenarioLoader, "_parse_text",
                        staticmethod(lambda text, name, real=ScenarioLoader._parse_text:
                                     calls.append(name) or real(text, name)))
    assert _cached(tree, folder) == _fresh(tree)
    assert calls  # parsed again


def test_an_unusable_cache_folder_is_only_slower(tree: Path, tmp_path: Path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder", encoding="utf-8")
    assert _cached(tree, blocker / "cache") == _fresh(tree)  # cannot be created: nothing stored
    folder = tmp_path / "cache"
    context = CheckCache(_loader(tree), folder).context(tree / "suite" / "child.fsv")
    (folder / f"{context}.json").mkdir(parents=True)  # the entry's name is taken by a folder
    assert _cached(tree, folder) == _fresh(tree)
    assert not list(folder.glob(".*.tmp"))  # no temporary file left behind


def test_an_unknown_question_never_holds(tree: Path) -> None:
    loader = _loader(tree)
    path = str(tree / "suite" / "child.fsv")
    assert loader.still_holds(("is_file", path, "yes"))
    assert not loader.still_holds(("is_file", path, "no"))
    assert not loader.still_holds(("listdir", path, ""))


def test_the_facts_include_the_searched_places(tree: Path) -> None:
    result = _loader(tree).load(tree / "suite" / "child.fsv")
    asked = [(question, Path(where).relative_to(tree).as_posix(), answer)
             for question, where, answer in result.inputs if question != "resolve"]
    assert [fact[:2] for fact in asked] == [
        ("read", "suite/child.fsv"), ("is_file", "suite/base.fsv"),
        ("is_file", "suite/_base/base.fsv"), ("is_file", "_base/base.fsv"), ("read", "_base/base.fsv")]
    assert [fact[2] for fact in asked[1:4]] == ["no", "no", "yes"]


@pytest.mark.parametrize(("environ", "expected"), [
    ({"HOME": "/home/u"}, "/home/u/.cache/fsvla/check"),
    ({"HOME": "/home/u", "XDG_CACHE_HOME": "/xdg"}, "/xdg/fsvla/check"),
    ({"HOME": "/home/u", "XDG_CACHE_HOME": "relative"}, "/home/u/.cache/fsvla/check"),
    ({"HOME": "/home/u", "XDG_CACHE_HOME": "/xdg", "FSVLA_CACHE_DIR": "/mine"}, "/mine/check"),
    ({"HOME": "/home/u", "FSVLA_CACHE_DIR": "/mine", "FSVLA_NO_CACHE": "1"}, None),
    ({"HOME": "/home/u", "FSVLA_NO_CACHE": "0"}, "/home/u/.cache/fsvla/check"),
    ({"HOME": "/home/u", "FSVLA_NO_CACHE": ""}, "/home/u/.cache/fsvla/check"),
], ids=["home", "xdg", "relative-xdg", "fsvla-cache-dir", "no-cache", "no-cache-0", "no-cache-empty"])
def test_cache_folder(environ: dict[str, str], expected: str | None,
                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOME", environ["HOME"])
    folder = cache_folder(environ)
    assert (None if folder is None else folder.as_posix()) == expected


def test_the_code_fingerprint_is_a_sha256() -> None:
    assert len(code_fingerprint()) == 64 and int(code_fingerprint(), 16) >= 0
