"""Demonstrations: the careful expert's safe successes as a LeRobot dataset (`fsvla collect`).

The names below load on first use, so registering the command (``fsvla.collect.command``)
keeps ``fsvla check`` free of numpy and the dataset writer.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_HOMES = {"PROGRESS_FILE": "collect", "CollectProgress": "collect", "collect": "collect",
          "CODEBASE_VERSION": "lerobot", "DatasetMismatch": "lerobot", "Frame": "lerobot",
          "LeRobotWriter": "lerobot", "features": "lerobot"}

__all__ = ["CODEBASE_VERSION", "PROGRESS_FILE", "CollectProgress", "DatasetMismatch", "Frame",
           "LeRobotWriter", "collect", "features"]


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'fsvla.collect' has no attribute {name!r}")
    value = getattr(import_module(f".{home}", __name__), name)
    globals()[name] = value  # the function `collect`, not the module of that name
    return value
