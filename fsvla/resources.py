"""Where the data that ships with fsvla lies: the grammar and the built-in scenarios.

An installed wheel holds them inside the package (``fsvla/grammar``,
``fsvla/scenarios``); an editable install or a checkout keeps them at the
repository's top level, beside ``fsvla/``.
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def data_dir(name: str) -> Path:
    """The folder of shipped data called ``name`` ("grammar" or "scenarios")."""
    for candidate in (_PACKAGE_DIR / name, _PACKAGE_DIR.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"fsvla's `{name}` folder is missing from the installation at {_PACKAGE_DIR}")


def grammar_path() -> Path:
    return data_dir("grammar") / "fsv.lark"


def scenarios_dir() -> Path:
    return data_dir("scenarios")
