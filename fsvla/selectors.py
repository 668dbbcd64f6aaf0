"""The one resolver of scenario references, and the selectors it understands.

Every command that takes scenarios (``fsvla check``, ``compile``, ``validate``, ``run
--scenarios``, ``collect``, ``attack``, ``fsvla.make``, ``bench/experts.py``) resolves
what it is given here. Each item (comma-separated within an argument) is one of:

- a ``.fsv`` file; a folder, searched recursively (its ``_base/`` folders, which hold
  abstract bases, only when the caller asks for bases: ``fsvla check`` does);
- a built-in scenario name (``lift_pot_beside_stove``);
- a selector over the built-in scenarios: ``subset:NAME`` (a named set of
  ``scenarios/sets.toml``), ``suite:NAME`` (every concrete scenario of a Safe-Core suite),
  ``embodiment:NAME`` (every concrete scenario on that robot).

A reference that resolves to nothing raises :class:`ScenarioSelectionError`, whose message
names the setting and its valid values. Importing this module loads nothing of the
simulator; a selector over suites or embodiments checks the built-in scenarios (their IR
says which suite and robot each is on).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from fsvla.dsl.catalog import SUITES
from fsvla.dsl.diagnostics import suggest
from fsvla.dsl.loader import BASE_FOLDER
from fsvla.dsl.models import Scenario
from fsvla.library import ScenarioLoadError, builtin_scenarios
from fsvla.resources import scenarios_dir

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: The file of named sets, in the built-in scenario tree.
SETS_FILE = "sets.toml"
#: Selector kinds, in the order help texts list them.
KINDS = ("subset", "suite", "embodiment")


class ScenarioSelectionError(ScenarioLoadError):
    """A scenario reference that selects nothing: ``setting`` names what was wrong (the
    selector kind, ``scenario`` for a name or path) and ``valid`` its valid values."""

    def __init__(self, setting: str, message: str, valid: Iterable[str] = ()) -> None:
        self.setting = setting
        self.valid = tuple(valid)
        super().__init__(message)


class ScenarioSet(BaseModel):
    """One named set of ``sets.toml``: built-in scenario names, in order."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    description: str = ""
    scenarios: tuple[str, ...] = Field(min_length=1)


@dataclass(frozen=True)
class BuiltinScenario:
    """What selectors read of a concrete built-in scenario."""

    name: str
    path: Path
    suite: str
    embodiment: str
    scenario: Scenario  # the checked IR


def named_sets(tree: Path | None = None) -> dict[str, ScenarioSet]:
    """The named sets of ``tree``'s ``sets.toml`` (default: the built-in scenario tree);
    none when the file is absent."""
    path = (tree or scenarios_dir()) / SETS_FILE
    if not path.is_file():
        return {}
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as err:
        raise ScenarioSelectionError("subset", f"{path}: not valid TOML: {err}") from None
    sets = {}
    for name, body in data.items():
        try:
            sets[name] = ScenarioSet.model_validate(body)
        except ValidationError as err:
            first = err.errors()[0]
            where = ".".join(str(part) for part in first["loc"]) or "the set"
            raise ScenarioSelectionError("subset", f"{path}: [{name}]: {where}: "
                                         f"{first['msg']}") from None
    return sets


def builtin_catalogue(tree: Path | None = None) -> dict[str, BuiltinScenario]:
    """Every concrete scenario of ``tree`` (default: the built-in tree) by name (its file's
    stem, as built-in names go), with its suite and embodiment; a file that does not check
    raises. Kept while no ``.fsv`` file of the tree changes."""
    tree = tree or scenarios_dir()
    stamp = tuple((str(p), p.stat().st_mtime_ns) for p in sorted(tree.rglob("*.fsv")))
    return dict(_catalogue(tree, stamp))


@lru_cache(maxsize=4)
def _catalogue(tree: Path, _stamp: tuple[tuple[str, int], ...]) -> tuple[
        tuple[str, BuiltinScenario], ...]:
    from fsvla.dsl.loader import ScenarioLoader

    loader = ScenarioLoader(allowed_roots=[tree])
    found = []
    for stem, path in _tree_files(tree).items():
        result = loader.load(path)
        if not result.ok or result.scenario is None:
            raise ScenarioSelectionError("scenario", f"{path}: the scenario does not check "
                                         f"(run `fsvla check {path}`), so selectors cannot read it")
        if result.abstract:
            continue
        ir = result.scenario
        found.append((stem, BuiltinScenario(stem, path, ir.suite, ir.embodiment, ir)))
    return tuple(found)


def _tree_files(tree: Path) -> dict[str, Path]:
    if tree == scenarios_dir():
        return builtin_scenarios()
    return {p.stem: p for p in sorted(tree.rglob("*.fsv"))
            if BASE_FOLDER not in p.relative_to(tree).parts}


def select(kind: str, value: str, tree: Path | None = None) -> list[str]:
    """The built-in scenario names that ``kind:value`` selects, in order (a named set's
    order; otherwise by name)."""
    tree = tree or scenarios_dir()
    if kind == "subset":
        return _subset(value, tree)
    if kind not in ("suite", "embodiment"):
        raise ScenarioSelectionError("selector", f"unknown selector `{kind}:`; selectors are "
                                     + ", ".join(f"`{k}:NAME`" for k in KINDS), KINDS)
    catalogue = builtin_catalogue(tree)
    valid = SUITES if kind == "suite" else _embodiments()
    if value not in valid:
        raise ScenarioSelectionError(kind, _unknown(kind, value, valid), valid)
    chosen = sorted(name for name, item in catalogue.items() if getattr(item, kind) == value)
    if not chosen:
        present = sorted({getattr(item, kind) for item in catalogue.values()})
        raise ScenarioSelectionError(kind, f"`{kind}:{value}` selects no scenario: no built-in "
                                     f"scenario is on {kind} {value} (those in use: "
                                     f"{', '.join(present) or 'none'})", present)
    return chosen


def _subset(value: str, tree: Path) -> list[str]:
    sets = named_sets(tree)
    if value not in sets:
        raise ScenarioSelectionError("subset", _unknown("subset", value, sets, str(tree / SETS_FILE)),
                                     sets)
    known = _tree_files(tree)
    missing = [name for name in sets[value].scenarios if name not in known]
    if missing:
        raise ScenarioSelectionError("subset", f"{tree / SETS_FILE}: set `{value}` lists "
                                     f"{', '.join(missing)}, not built-in scenario(s)", known)
    return list(dict.fromkeys(sets[value].scenarios))


def _unknown(kind: str, value: str, valid: Iterable[str], where: str = "") -> str:
    valid = sorted(valid)
    best = suggest(value, valid)
    hint = f" (did you mean `{kind}:{best}`?)" if best else ""
    source = f" in {where}" if where else ""
    return (f"unknown {kind} `{value}` in `{kind}:{value}`{hint}; valid {kind} values{source}: "
            f"{', '.join(valid) or 'none'}")


def _embodiments() -> tuple[str, ...]:
    from fsvla.embodiments.registry import builtin_embodiments

    return builtin_embodiments()


def resolve_scenarios(items: Iterable[str | Path], *, bases: bool = False,
                      tree: Path | None = None) -> list[str]:
    """The scenarios ``items`` name, as references :func:`fsvla.library.load_scenario`
    takes: a path (as written) for a file or each file of a folder, a built-in name for a
    name or a selector's choice. Items may hold several, comma-separated; the same file
    named twice counts once. ``bases``: a folder's ``_base/`` files too."""
    refs: dict[Path, str] = {}
    tree = tree or scenarios_dir()
    builtin = _tree_files(tree)
    for item in _split(items):
        for ref in _resolve_one(item, bases, tree, builtin):
            refs.setdefault(_file_of(ref, builtin).resolve(), ref)
    if not refs:
        raise ScenarioSelectionError("scenario", "name at least one scenario: a .fsv file, a "
                                     "folder, a built-in scenario or a selector ("
                                     + ", ".join(f"{k}:NAME" for k in KINDS) + ")")
    return list(refs.values())


def scenario_paths(items: Iterable[str | Path], *, bases: bool = False,
                   tree: Path | None = None) -> list[Path]:
    """The ``.fsv`` files ``items`` name (as :func:`resolve_scenarios`, built-in names and
    selections given as their files)."""
    tree = tree or scenarios_dir()
    builtin = _tree_files(tree)
    return [_file_of(ref, builtin) for ref in resolve_scenarios(items, bases=bases, tree=tree)]


def _file_of(ref: str, builtin: Mapping[str, Path]) -> Path:
    """The file of a resolved reference: a path as written, a built-in name's file."""
    path = Path(ref)
    return path if path.exists() or ref not in builtin else builtin[ref]


def _split(items: Iterable[str | Path]) -> list[str]:
    parts = []
    for value in items:
        if isinstance(value, Path):
            parts.append(str(value))
        else:
            parts.extend(part.strip() for part in value.split(",") if part.strip())
    return parts


def _resolve_one(item: str, bases: bool, tree: Path, builtin: Mapping[str, Path]) -> list[str]:
    path = Path(item)
    if path.is_dir():
        found = [str(p) for p in sorted(path.rglob("*.fsv"))
                 if p.is_file() and (bases or BASE_FOLDER not in p.relative_to(path).parts)]
        if not found:
            raise ScenarioSelectionError("scenario", f"no .fsv files under {item}")
        return found
    if path.is_file():
        return [item]
    kind, colon, value = item.partition(":")
    if colon and kind in KINDS:
        return select(kind, value, tree)
    if colon and not path.suffix:
        raise ScenarioSelectionError("selector", f"unknown selector `{kind}:` in `{item}`; "
                                     "selectors are " + ", ".join(f"`{k}:NAME`" for k in KINDS),
                                     KINDS)
    if path.suffix == ".fsv":
        raise ScenarioSelectionError("scenario", f"{item}: no such scenario file")
    if item in builtin:
        return [item]
    best = suggest(item, builtin)
    raise ScenarioSelectionError(
        "scenario", f"unknown scenario {item!r}: not a built-in scenario, a .fsv file, a "
        "folder nor a selector (" + ", ".join(f"{k}:NAME" for k in KINDS) + ")"
        + (f"; did you mean `{best}`?" if best else f"; built-in: {', '.join(builtin)}"),
        builtin)


__all__ = ["KINDS", "SETS_FILE", "BuiltinScenario", "ScenarioSelectionError", "ScenarioSet",
           "builtin_catalogue", "named_sets", "resolve_scenarios",
           "scenario_paths", "select"]
