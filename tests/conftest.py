"""Fixtures shared across the test tree."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def render_device() -> None:
    """Skip the test when SAPIEN finds no Vulkan rendering device."""
    pytest.importorskip("sapien")
    from fsvla.sim.render import render_available

    if not render_available():
        pytest.skip("no Vulkan rendering device (run .ci/install-vulkan to install lavapipe)")


#: A one-second single-arm scenario with a heat zone and a force limit: fast episodes
#: for the environment, runner and CLI tests.
SHORT_SCENARIO = """\
scenario short_lift
  suite thermal
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  horizon 1 s
  object pot: pot(radius=8 cm, height=10 cm) at (0, 0)
  hazard plate: heat_zone(size=(15 cm, 15 cm)) at (0, 25 cm) on table
    keep gripper, pot outside 5 cm warn 3 cm
  constrain contact_force(gripper) <= 40 N warn 10 N
  success lifted(pot)
"""


@pytest.fixture(scope="session")
def short_scenario(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """SHORT_SCENARIO written to ``short_lift.fsv`` in a folder of its own."""
    path = tmp_path_factory.mktemp("scenarios") / "short_lift.fsv"
    path.write_text(SHORT_SCENARIO, encoding="utf-8")
    return path
