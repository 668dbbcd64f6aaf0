"""Shared helpers for the language tests: load text from a file in a temporary folder."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.dsl.loader import LoadResult, ScenarioLoader

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"

# A complete, clean scenario that the check tables mutate one line at a time.
BASE = """\
scenario s
  suite force
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  object pot: pot(radius=9 cm)
  constrain contact_force(gripper) <= 30 N warn 8 N
  success lifted(pot)
"""


@pytest.fixture
def load_text(tmp_path: Path):
    """Write ``text`` to ``m.fsv`` in a fresh folder and load it (that folder is the only root)."""

    def load(text: str, name: str = "m.fsv") -> LoadResult:
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return ScenarioLoader(allowed_roots=[tmp_path], display_root=tmp_path).load(path)

    return load


@pytest.fixture
def base_text() -> str:
    return BASE


@pytest.fixture
def repo_root() -> Path:
    return REPO
