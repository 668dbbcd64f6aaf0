"""fsvla: a safety benchmark for vision-language-action robot policies."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

    from fsvla.dsl.models import Scenario
    from fsvla.env import FsvlaEnv

__version__ = "0.1.0"


def make(scenario: str | Path | Scenario, level: str = "L0", seed: int = 0,
         embodiment: str | None = None, obs_mode: str = "state",
         control_mode: str = "joint_pos", **kwargs: Any) -> FsvlaEnv:
    """A gymnasium environment for a scenario; see :func:`fsvla.env.make`.

    Imported lazily, so ``import fsvla`` stays cheap for the language tools."""
    from fsvla.env import make as make_env

    return make_env(scenario, level=level, seed=seed, embodiment=embodiment,
                    obs_mode=obs_mode, control_mode=control_mode, **kwargs)
