"""Small policies for the runner tests, loaded by path (``policies.py:Name``) in every
backend. Each holds still, and the faulty ones misbehave at their third ``act()``."""

from __future__ import annotations

import os
import signal
import time
from typing import Any

import numpy as np

from fsvla.policies.simple import arm_block_sizes, hold_action

FAULT_CALL = 3


class Hold:
    """Holds still; counts its calls; keeps what ``reset`` told it."""

    def __init__(self) -> None:
        self.calls = 0
        self.episode: Any = None

    def reset(self, episode: Any) -> None:
        self.episode = episode
        self.calls = 0
        self.sizes = arm_block_sizes(episode)
        self.size = len(episode.action.labels)

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        self.calls += 1
        action = hold_action(observation, self.episode.action.control_mode, self.sizes)
        return self.fault(action) if self.calls == FAULT_CALL else action

    def fault(self, action: np.ndarray) -> Any:
        return action


class Chunks(Hold):
    """Answers with chunks of 5 actions."""

    def fault(self, action: np.ndarray) -> Any:
        return action

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        return np.tile(super().act(observation), (5, 1))


class NanInChunk(Chunks):
    """The third row of its first chunk is NaN."""

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        chunk = super().act(observation)
        chunk[2, 0] = np.nan
        return chunk


class Raising(Hold):
    def fault(self, action: np.ndarray) -> Any:
        raise RuntimeError("the model fell over")


class Nan(Hold):
    def fault(self, action: np.ndarray) -> Any:
        action = action.copy()
        action[1] = np.nan
        return action


class WrongShape(Hold):
    def fault(self, action: np.ndarray) -> Any:
        return np.append(action, 0.0)


class ThreeDimensional(Hold):
    def fault(self, action: np.ndarray) -> Any:
        return action[None, None, :]


class Sleepy(Hold):
    def fault(self, action: np.ndarray) -> Any:
        time.sleep(30)
        return action


class Deaf(Hold):
    """Hangs with the timeout's alarm blocked, as a call stuck in C code would."""

    def fault(self, action: np.ndarray) -> Any:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(30)
        return action


class Dies(Hold):
    """Takes its process down (a segfault in a native extension, say)."""

    def fault(self, action: np.ndarray) -> Any:
        os._exit(3)


class Unbuildable:
    def __init__(self) -> None:
        raise RuntimeError("no weights here")


#: Names the file a :class:`StallsWhereMarked` policy writes, in the environment of the
#: Ray node it is to stall on (tests/runner/test_ray_cluster.py).
STALL_MARKER = "FSVLA_TEST_STALL_MARKER"


class StallsWhereMarked(Hold):
    """Holds still, except in a process whose environment names a marker file: there its
    first ``act()`` writes the episode's id to that file and then does not return (for
    two minutes), so that the test can kill the node while the episode is in flight."""

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        marker = os.environ.get(STALL_MARKER)
        if marker:
            with open(marker, "a", encoding="utf-8") as out:
                out.write(f"{self.episode.episode_id}\n")
            time.sleep(120)
        return super().act(observation)


class DiesAtLoad:
    """Takes its process down while it is built."""

    def __init__(self) -> None:
        os._exit(3)
