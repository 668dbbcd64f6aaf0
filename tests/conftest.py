"""Fixtures shared across the test tree, and the gate of tests that need what not every
machine has.

The gate (:func:`require`): a test that needs SAPIEN or a Vulkan device skips where it is
missing, but fails under CI (``CI=true``, set by CI services and by ``.ci/run``), which
installs both, so that a broken install is never a quiet skip there. SAPIEN-backed tests
are marked ``sim`` (``pytestmark = pytest.mark.sim``), which gates them; a module that
needs the ``sapien`` module itself binds it with ``sapien = require_sapien()``. Rendering
tests take the ``render_device`` fixture. (LeRobot's gate, ``FSVLA_REQUIRE_LEROBOT=1``,
works alike: see ``tests/collect/lerobot_loader.py``.)
"""

from __future__ import annotations

import os
from pathlib import Path
from types import ModuleType

import pytest

CI_INSTALLS = "CI installs it (.ci/run), so under CI=true this is a failure, not a skip"


def in_ci() -> bool:
    """Whether the tests run under CI: ``CI`` is set to anything but empty, 0, false or no."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def require(met: bool, why: str) -> None:
    """Skip the calling test, or the calling module at module level, unless ``met``; under
    CI, fail instead (see the module doc)."""
    if met:
        return
    if in_ci():
        pytest.fail(f"{why}; {CI_INSTALLS}", pytrace=False)
    pytest.skip(why, allow_module_level=True)


def require_sapien() -> ModuleType:
    """The ``sapien`` module, through the gate."""
    try:
        import sapien
    except ImportError as err:
        why = f"SAPIEN is not installed ({err}): pip install -e '.[sim]'"
    else:
        return sapien
    require(False, why)  # skips or fails: does not return
    raise AssertionError(why)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item: pytest.Item) -> None:
    """Tests marked ``sim`` need SAPIEN: the gate runs before their fixtures."""
    if item.get_closest_marker("sim") is not None:
        require_sapien()


@pytest.fixture(scope="session")
def render_device() -> None:
    """A Vulkan device SAPIEN can render with, through the gate."""
    require_sapien()
    from fsvla.sim.render import render_available

    require(render_available(),
            "no Vulkan rendering device (run .ci/install-vulkan to install lavapipe)")


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


@pytest.fixture(autouse=True)
def check_cache_dir(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """`fsvla check`'s result cache in a fresh temporary folder for each test, never the
    user's (subprocesses inherit it through the environment)."""
    folder = tmp_path_factory.mktemp("fsvla-cache")
    monkeypatch.setenv("FSVLA_CACHE_DIR", str(folder))
    monkeypatch.delenv("FSVLA_NO_CACHE", raising=False)
    return folder
