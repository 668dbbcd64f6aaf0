"""Find and load embodiment specs: the built-in TOML files, or a user's own TOML file."""

from __future__ import annotations

import difflib
import sys
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .spec import EmbodimentSpec

if TYPE_CHECKING:
    from importlib.resources.abc import Traversable

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


class UnknownEmbodimentError(KeyError):
    """Raised for a name that is neither a built-in embodiment nor a TOML file."""

    def __str__(self) -> str:
        return str(self.args[0])


def builtin_embodiments() -> tuple[str, ...]:
    """Names of the built-in embodiments, sorted."""
    folder = _builtin_folder()
    return tuple(sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml")))


def load_embodiment(name_or_path: str | Path) -> EmbodimentSpec:
    """Load a built-in embodiment by name (``"panda"``) or a user's TOML file by path.

    In a user's file, a relative ``urdf``/``srdf`` path that names an existing file
    next to the TOML file is made absolute; other relative paths are taken relative
    to example-robot-data's ``robots`` folder, as in the built-ins.
    """
    text = str(name_or_path)
    if text in builtin_embodiments():
        data = tomllib.loads((_builtin_folder() / f"{text}.toml").read_text())
        return EmbodimentSpec.model_validate(_anchor_pieces(data, Path(str(_builtin_folder()))))
    path = Path(text).expanduser()
    if path.suffix == ".toml" or path.is_file():
        if not path.is_file():
            raise FileNotFoundError(f"embodiment file not found: {path}")
        data = tomllib.loads(path.read_text())
        base = path.parent.resolve()
        return EmbodimentSpec.model_validate(_anchor_pieces(_anchor_paths(data, base), base))
    raise UnknownEmbodimentError(_unknown_message(text))


def _builtin_folder() -> Traversable:
    return resources.files("fsvla.embodiments") / "builtin"


def _unknown_message(name: str) -> str:
    known = builtin_embodiments()
    message = f"unknown embodiment `{name}`; built-in embodiments: {', '.join(known)}"
    close = difflib.get_close_matches(name, known, n=1)
    if close:
        message += f"; did you mean `{close[0]}`?"
    return message + " (or give the path of a .toml file)"


def _anchor_paths(data: dict[str, Any], base: Path) -> dict[str, Any]:
    robots = data.get("robots")
    if not isinstance(robots, list):
        return data
    anchored = []
    for robot in robots:
        if isinstance(robot, dict):
            robot = dict(robot)
            for key in ("urdf", "srdf"):
                value = robot.get(key)
                if isinstance(value, str) and not Path(value).is_absolute():
                    local = base / value
                    if local.is_file():
                        robot[key] = str(local)
        anchored.append(robot)
    return {**data, "robots": anchored}


def _anchor_pieces(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """Each robot's ``collision_pieces`` folders made absolute, relative to ``base`` (the
    embodiment file's folder)."""
    robots = data.get("robots")
    if not isinstance(robots, list):
        return data
    anchored = []
    for robot in robots:
        if isinstance(robot, dict) and isinstance(robot.get("collision_pieces"), dict):
            robot = {**robot, "collision_pieces": {
                name: str(folder if Path(folder).is_absolute() else base / folder)
                for name, folder in robot["collision_pieces"].items()}}
        anchored.append(robot)
    return {**data, "robots": anchored}


__all__ = ["UnknownEmbodimentError", "builtin_embodiments", "load_embodiment"]
