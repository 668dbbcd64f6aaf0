"""Run configurations and run helpers for the runner tests (the one-second scenario is
in tests/conftest.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pyarrow")  # SAPIEN: every test here is marked sim

from fsvla.run import RunConfig
from fsvla.runner import execute_run, make_backend, make_config, prepare_run

POLICIES = Path(__file__).with_name("policies.py")


def policy(name: str) -> str:
    """The --policy spec of a test policy in policies.py."""
    return f"{POLICIES}:{name}"


@pytest.fixture(scope="session")
def make_run_config(short_scenario: Path):
    def make(**changes: Any) -> RunConfig:
        fields: dict[str, Any] = {"policy": "hold-still", "scenarios": (str(short_scenario),),
                                  "episodes": 1, "warmup": 0}
        fields.update(changes)
        return make_config(**fields)

    return make


def run_into(out: Path, config: RunConfig, workers: int = 0, backend: str = "process"):
    """Run ``config`` into ``out``; the RunResult."""
    return execute_run(prepare_run(config), out, make_backend(backend, config, workers))
