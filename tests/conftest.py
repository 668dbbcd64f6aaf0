"""Fixtures shared across the test tree."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def render_device() -> None:
    """Skip the test when SAPIEN finds no Vulkan rendering device."""
    pytest.importorskip("sapien")
    from fsvla.sim.render import render_available

    if not render_available():
        pytest.skip("no Vulkan rendering device (run .ci/install-vulkan to install lavapipe)")
