"""Seeded random generators that are the same on every machine and Python version.

Python's ``hash()`` of a string changes with each process (PYTHONHASHSEED), so seeds
derive from SHA-256 over the parts that identify a draw instead: e.g. a scenario's
source digest, the dimension ("L", "W", "V"), the level and the episode seed.
"""

from __future__ import annotations

import hashlib

import numpy as np


def stable_seed(*parts: object) -> int:
    """A 64-bit seed from ``parts`` (each rendered with ``str``), stable everywhere."""
    text = "\x1f".join(str(p) for p in parts)
    return int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:8], "little")


def stable_rng(*parts: object) -> np.random.Generator:
    """A numpy generator seeded with :func:`stable_seed` of ``parts``."""
    return np.random.default_rng(stable_seed(*parts))


__all__ = ["stable_rng", "stable_seed"]
