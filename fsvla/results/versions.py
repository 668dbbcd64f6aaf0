"""The software versions a run records (read from package metadata: nothing is imported)."""

from __future__ import annotations

import platform
from importlib import metadata

PACKAGES = ("fsvla", "sapien", "numpy", "pydantic", "pyarrow", "gymnasium")


def collect_versions() -> dict[str, str]:
    """``{"python": "3.11.7", "fsvla": "0.1.0", "sapien": ..., ...}``; absent ones are
    ``"not installed"``."""
    versions = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


__all__ = ["collect_versions"]
