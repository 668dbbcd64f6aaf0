"""``fsvla run`` and ``fsvla replay``: play a run's episodes and record them; replay one.

What runs where (see ``docs/running.md``):

* the run loop (:mod:`fsvla.runner.loop`), in the calling process, loads the scenarios,
  plans the episodes, opens the run folder and is its only writer;
* episodes run in an :class:`~fsvla.runner.worker.EpisodeWorker` (the policy, the loaded
  scenarios, a fresh environment per episode) inside a backend (:mod:`fsvla.runner.backend`): this process
  (``--workers 0``), spawned worker processes (:mod:`fsvla.runner.pool`), or Ray actors
  (:mod:`fsvla.runner.ray_backend`);
* :func:`fsvla.runner.episode.play` executes a policy's action chunks step by step and
  turns every failure into a fault with its reason.

Importing this package imports neither SAPIEN nor Ray.
"""

import importlib
from typing import Any

#: Where each public name lives; imported on first use, so that ``fsvla --help`` and the
#: CLI's ``run``/``replay`` option parsing stay cheap.
_HOMES = {
    "BACKENDS": "backend", "Backend": "backend", "BackendError": "backend",
    "InProcessBackend": "backend", "Rerun": "backend", "make_backend": "backend",
    "Fault": "episode", "episode_info": "episode", "play": "episode",
    "RunListener": "loop", "RunResult": "loop", "execute_run": "loop",
    "PreparedRun": "prepare", "RunInputError": "prepare", "check_run_folder": "prepare",
    "make_config": "prepare", "prepare_run": "prepare",
    "ReplayInputError": "replay", "ReplayResult": "replay", "replay_episode": "replay",
    "SummaryRow": "summary", "summarize": "summary",
    "EpisodeWorker": "worker",
}


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module 'fsvla.runner' has no attribute {name!r}")
    return getattr(importlib.import_module(f"fsvla.runner.{_HOMES[name]}"), name)


__all__ = [
    "BACKENDS",
    "Backend",
    "BackendError",
    "EpisodeWorker",
    "Fault",
    "InProcessBackend",
    "PreparedRun",
    "ReplayInputError",
    "ReplayResult",
    "Rerun",
    "RunInputError",
    "RunListener",
    "RunResult",
    "SummaryRow",
    "check_run_folder",
    "episode_info",
    "execute_run",
    "make_backend",
    "make_config",
    "play",
    "prepare_run",
    "replay_episode",
    "summarize",
]
