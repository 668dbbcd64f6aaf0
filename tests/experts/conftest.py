"""Helpers the experts' tests share."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from fsvla.experts.world import World


@contextmanager
def world_of(path: Path, seed: int = 0) -> Iterator[World]:
    """The world the experts read from ``path``'s env at L0, reset; closed on leaving."""
    from fsvla.env import make

    env = make(str(path), "L0", seed)
    env.reset()
    try:
        yield World.of_env(env)
    finally:
        env.close()
