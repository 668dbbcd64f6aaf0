"""Turn a ``--policy`` argument into a policy object.

Accepted forms:

- a built-in name: ``random``, ``hold-still`` (and the scripted experts once they exist);
- ``module:Class`` (or ``module:factory``): any importable class or callable that returns
  an object with ``reset(episode)`` and ``act(observation)``; ``path/to/file.py:Class``
  imports a file;
- ``ws://host:port``: a policy server speaking the openpi websocket protocol, with the
  keys and action space of a profile (``droid``, ``libero``, ``aloha``, ``fsvla`` or a TOML
  file: :mod:`fsvla.policies.profile`);
- ``lerobot:PATH``: a LeRobot pretrained-policy folder (:mod:`fsvla.policies.lerobot`;
  needs ``pip install lerobot``).
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from pathlib import Path
from typing import Any

from fsvla.dsl.diagnostics import did_you_mean

from .base import Policy
from .simple import HoldStillPolicy, RandomPolicy


def _careful_expert() -> Any:
    from fsvla.experts import CarefulExpert

    return CarefulExpert()


def _careless_expert() -> Any:
    from fsvla.experts import CarelessExpert

    return CarelessExpert()


BUILTIN: dict[str, Callable[[], Any]] = {
    "random": RandomPolicy,
    "hold-still": HoldStillPolicy,
    # scripted experts: they need bind_env(env) before reset (see fsvla.experts)
    "careful-expert": _careful_expert,
    "careless-expert": _careless_expert,
}


class PolicyLoadError(ValueError):
    """A ``--policy`` value that names nothing usable."""


def load_policy(spec: str, profile: str | None = None) -> Policy:
    """The policy ``spec`` names (see the module doc), a policy server speaking
    ``profile`` (a built-in profile's name or a TOML file; None: fsvla's own keys);
    raises :class:`PolicyLoadError`."""
    remote = spec.startswith(("ws://", "wss://"))
    if profile is not None and not remote:
        raise PolicyLoadError(f"--policy-profile {profile}: profiles map the keys of a policy "
                              f"server (--policy ws://host:port), and --policy {spec!r} is none")
    if spec in BUILTIN:
        return BUILTIN[spec]()
    if spec.startswith("lerobot:"):
        from .lerobot import LeRobotPolicy

        return LeRobotPolicy(spec.removeprefix("lerobot:"))
    if remote:
        from .profile import load_profile
        from .remote import RemotePolicy

        return RemotePolicy(spec, profile=load_profile(profile) if profile else None)
    if ":" not in spec:
        hint = did_you_mean(spec, BUILTIN)
        raise PolicyLoadError(f"--policy {spec!r}: not a built-in policy, `module:Class`, "
                              f"ws://host:port or lerobot:PATH" + (f"; {hint}" if hint else ""))
    module_name, _, attribute = spec.rpartition(":")
    module = _import(module_name, spec)
    factory = getattr(module, attribute, None)
    if factory is None or not callable(factory):
        raise PolicyLoadError(f"--policy {spec!r}: {module_name} has no class or factory "
                              f"{attribute!r}")
    try:
        policy = factory()
    except Exception as err:  # the user's constructor failed: say so, without a traceback
        raise PolicyLoadError(f"--policy {spec!r}: constructing {attribute} failed: "
                              f"{type(err).__name__}: {err}") from err
    if not isinstance(policy, Policy):
        raise PolicyLoadError(f"--policy {spec!r}: {attribute}() returned a "
                              f"{type(policy).__name__}, which lacks reset(episode) and "
                              "act(observation)")
    return policy


def _import(name: str, spec: str) -> Any:
    if name.endswith(".py"):
        path = Path(name)
        if not path.is_file():
            raise PolicyLoadError(f"--policy {spec!r}: no such file {name}")
        loader_spec = importlib.util.spec_from_file_location(path.stem, path)
        assert loader_spec is not None and loader_spec.loader is not None
        module = importlib.util.module_from_spec(loader_spec)
        try:
            loader_spec.loader.exec_module(module)
        except Exception as err:
            raise PolicyLoadError(f"--policy {spec!r}: importing {name} failed: "
                                  f"{type(err).__name__}: {err}") from err
        return module
    try:
        return importlib.import_module(name)
    except Exception as err:
        raise PolicyLoadError(f"--policy {spec!r}: cannot import {name}: "
                              f"{type(err).__name__}: {err}") from err


__all__ = ["BUILTIN", "PolicyLoadError", "load_policy"]
