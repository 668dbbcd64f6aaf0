"""The gymnasium environment of fsvla.

``fsvla.make(scenario, level="L0", seed=0, ...)`` returns a :class:`FsvlaEnv`. Importing
this package also registers every built-in scenario with gymnasium as
``fsvla/<scenario>-v0``, so after ``import fsvla.env``::

    env = gymnasium.make("fsvla/lift_pot_beside_stove-v0", level="L1", seed=3)

(or, without the import, ``gymnasium.make("fsvla.env:fsvla/lift_pot_beside_stove-v0")``).
"""

from __future__ import annotations

from typing import Any

import gymnasium

from fsvla.library import ScenarioRef, builtin_scenarios

from .actions import ActionCodec, ControlMode, InvalidActionError
from .env import EnvConfig, FsvlaEnv

NAMESPACE = "fsvla"


def make(scenario: ScenarioRef, level: str = "L0", seed: int = 0, embodiment: str | None = None,
         obs_mode: str = "state", control_mode: str = "joint_pos", **kwargs: Any) -> FsvlaEnv:
    """An environment for ``scenario`` (a built-in name, a ``.fsv`` path or a Scenario)."""
    return FsvlaEnv(scenario, level=level, seed=seed, embodiment=embodiment,  # type: ignore[arg-type]
                    obs_mode=obs_mode, control_mode=control_mode, **kwargs)


def env_id(scenario: str) -> str:
    return f"{NAMESPACE}/{scenario}-v0"


def register_builtin_scenarios() -> list[str]:
    """Register ``fsvla/<name>-v0`` for every built-in scenario; returns the ids."""
    ids = []
    for name in builtin_scenarios():
        ident = env_id(name)
        if ident not in gymnasium.registry:
            gymnasium.register(id=ident, entry_point="fsvla.env.env:FsvlaEnv",
                               kwargs={"scenario": name}, disable_env_checker=False)
        ids.append(ident)
    return ids


register_builtin_scenarios()

__all__ = ["ActionCodec", "ControlMode", "EnvConfig", "FsvlaEnv", "InvalidActionError",
           "env_id", "make", "register_builtin_scenarios"]
