"""The command-line tests keep `fsvla check`'s result cache in their own temporary folder,
never in the user's (subprocesses inherit it through the environment)."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(autouse=True)
def check_cache_dir(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh, empty FSVLA_CACHE_DIR for each test."""
    folder = tmp_path_factory.mktemp("fsvla-cache")
    monkeypatch.setenv("FSVLA_CACHE_DIR", str(folder))
    monkeypatch.delenv("FSVLA_NO_CACHE", raising=False)
    return folder
