"""The black-box square search, numpy only, on a cheap synthetic objective: it beats random
patches by far within its budget, never gets worse, spends exactly its budget, and is
deterministic for a seed."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from fsvla.attack.search import square_search, square_share, stripes
from fsvla.variation.patch import patch_pixels

PIXELS = 32


def _objective(seed: int = 0):
    """A stand-in for a policy's response: how strongly the patch matches a hidden
    pattern of blobs (a linear filter), in absolute value."""
    rng = np.random.default_rng(seed)
    coarse = rng.normal(size=(4, 4, 3))
    weights = np.kron(coarse, np.ones((PIXELS // 4, PIXELS // 4, 1)))
    calls = []

    def objective(patch: np.ndarray) -> float:
        calls.append(1)
        return float(abs(((patch - 0.5) * weights).mean()))

    return objective, calls


def test_the_search_beats_random_patches_twice_over() -> None:
    objective, calls = _objective()
    random_mean = np.mean([objective(patch_pixels(s, PIXELS) / 255.0) for s in range(10)])
    calls.clear()
    rng = np.random.default_rng(0)
    result = square_search(objective, stripes(PIXELS, rng), 300, rng)
    assert len(calls) == 300 and len(result.history) == 300
    assert result.value >= 2 * random_mean
    assert all(b >= a for a, b in pairwise(result.history))
    assert result.patch.min() >= 0 and result.patch.max() <= 1


def test_the_search_is_deterministic_for_a_seed() -> None:
    runs = [square_search(_objective()[0], stripes(PIXELS, np.random.default_rng(3)), 50,
                          np.random.default_rng(3)) for _ in range(2)]
    assert np.array_equal(runs[0].patch, runs[1].patch)


def test_the_square_shrinks_over_the_budget() -> None:
    shares = [square_share(step, 1000) for step in range(1000)]
    assert shares[0] == pytest.approx(0.3) and shares[-1] < shares[0] / 100
    assert all(b <= a for a, b in pairwise(shares))


def test_a_budget_below_one_is_refused() -> None:
    with pytest.raises(ValueError, match="budget"):
        square_search(lambda p: 0.0, np.zeros((4, 4, 3)), 0, np.random.default_rng(0))


def test_a_known_starting_value_is_not_asked_again() -> None:
    objective, calls = _objective()
    rng = np.random.default_rng(0)
    start = stripes(PIXELS, rng)
    result = square_search(objective, start, 20, rng, initial_value=objective(start))
    assert len(calls) == 1 + 19 and len(result.history) == 20
