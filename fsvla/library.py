"""Find and load scenarios: the built-in library by name, or any ``.fsv`` file by path.

The runtime (``fsvla.make``, ``fsvla run``) accepts a scenario as a built-in name
(``lift_pot_beside_stove``), a path to a ``.fsv`` file, or an already checked
:class:`~fsvla.dsl.models.Scenario`. A file that does not check raises
:class:`ScenarioLoadError` carrying every diagnostic, rendered concisely in its message.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from fsvla.dsl.diagnostics import Diagnostic
from fsvla.dsl.loader import BASE_FOLDER, ScenarioLoader
from fsvla.dsl.models import Scenario
from fsvla.dsl.render import render_concise
from fsvla.resources import scenarios_dir

ScenarioRef = str | Path | Scenario


class ScenarioLoadError(ValueError):
    """A scenario that cannot be found or does not check."""

    def __init__(self, message: str, diagnostics: Sequence[Diagnostic] = ()) -> None:
        self.diagnostics = tuple(diagnostics)
        lines = [message, *(render_concise(d) for d in self.diagnostics)]
        super().__init__("\n".join(lines))


def scenario_root(path: Path) -> Path:
    """The folder a scenario may read from: the nearest one at or above ``path`` that holds
    a ``_base/`` folder (a scenario tree), else the file's own folder."""
    path = path.resolve()
    folder = path if path.is_dir() else path.parent
    tree = next((f for f in (folder, *folder.parents) if (f / BASE_FOLDER).is_dir()), None)
    return tree or folder


def builtin_scenarios() -> dict[str, Path]:
    """The concrete built-in scenarios by name (abstract bases under ``_base/`` excluded)."""
    root = scenarios_dir()
    found: dict[str, Path] = {}
    for path in sorted(root.rglob("*.fsv")):
        if BASE_FOLDER in path.relative_to(root).parts:
            continue
        found[path.stem] = path
    return found


def load_scenario(ref: ScenarioRef) -> Scenario:
    """A checked scenario from a built-in name, a ``.fsv`` path, or a Scenario (returned as is)."""
    if isinstance(ref, Scenario):
        return ref
    path = _locate(ref)
    loader = ScenarioLoader(allowed_roots=[scenario_root(path)])
    result = loader.load(path)
    if not result.ok or result.scenario is None:
        if result.abstract and result.ok:
            raise ScenarioLoadError(f"{result.path}: scenario is abstract: load one that extends it")
        raise ScenarioLoadError(f"{result.path}: the scenario does not check "
                                f"(run `fsvla check {result.path}`)", result.errors)
    if result.abstract:
        raise ScenarioLoadError(f"{result.path}: scenario {result.scenario.name!r} is abstract: "
                                "load one that extends it")
    return result.scenario


def _locate(ref: str | Path) -> Path:
    path = Path(ref)
    if path.suffix == ".fsv" or path.exists():
        if not path.is_file():
            raise ScenarioLoadError(f"{path}: no such scenario file")
        return path
    from fsvla.selectors import scenario_paths

    found = scenario_paths([str(ref)])
    if len(found) != 1:
        raise ScenarioLoadError(f"{ref} names {len(found)} scenarios "
                                f"({', '.join(p.stem for p in found)}): name one")
    return found[0]


__all__ = ["ScenarioLoadError", "ScenarioRef", "builtin_scenarios", "load_scenario", "scenario_root"]
