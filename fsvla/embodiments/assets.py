"""Where robot description files live and how spec paths resolve to files."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

ROBOT_DATA_DIST = "example-robot-data"
ROBOTS_SUBDIR = "cmeel.prefix/share/example-robot-data/robots"


def robots_root() -> Path:
    """The ``robots`` folder of the installed example-robot-data package.

    ``package://`` URIs in its URDFs resolve from the ``share`` folder two levels up.
    Raises ``FileNotFoundError`` with an install hint when the package is missing.
    """
    try:
        dist = metadata.distribution(ROBOT_DATA_DIST)
    except metadata.PackageNotFoundError as exc:
        raise FileNotFoundError(
            f"the `{ROBOT_DATA_DIST}` package is not installed; "
            "install it with `pip install example-robot-data` (or `pip install fsvla[sim]`)"
        ) from exc
    root = Path(str(dist.locate_file(ROBOTS_SUBDIR)))
    if not root.is_dir():
        raise FileNotFoundError(f"`{ROBOT_DATA_DIST}` is installed but {root} does not exist")
    return root


def package_share_root() -> Path:
    """The folder ``package://`` URIs of example-robot-data resolve against."""
    return robots_root().parent.parent


def resolve_asset(path: str) -> Path:
    """An absolute path as is; a relative one under example-robot-data's ``robots``."""
    p = Path(path).expanduser()
    resolved = p if p.is_absolute() else robots_root() / p
    if not resolved.is_file():
        raise FileNotFoundError(f"robot description file not found: {resolved}")
    return resolved


__all__ = ["package_share_root", "resolve_asset", "robots_root"]
