"""Shared fixtures of the SAPIEN runtime tests: loading built-in scenarios, a render gate."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.models import Scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.fixture(scope="session")
def load_scenario() -> Callable[[Path], Scenario | None]:
    """Load a built-in ``.fsv`` file: its checked scenario, None when abstract."""

    def load(path: Path) -> Scenario | None:
        result = ScenarioLoader(allowed_roots=[SCENARIOS]).load(path)
        assert result.ok, [d.message for d in result.errors]
        return result.scenario

    return load
