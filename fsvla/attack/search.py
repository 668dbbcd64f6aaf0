"""Black-box patch search: random square updates under a query budget (numpy only).

In the manner of Square Attack (Andriushchenko et al., 2020) as its patch variant
(Sparse-RS, Croce et al., 2022) uses it: start from random vertical stripes of extreme
colours; at each step paint one randomly placed square of the patch a random corner of the
RGB cube, evaluate, and keep the change when the objective grows. The square's area is a
share ``p`` of the patch's that halves on Square Attack's schedule (rescaled to the
budget), so early steps explore and late ones refine. It needs only objective values, so
it works for any policy, remote ones included.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

#: Square Attack's iterations (of 10 000) at which the square's area halves.
HALVINGS = (10, 50, 200, 500, 1000, 2000, 4000, 6000, 8000)
#: The square's starting share of the patch's area.
P_INIT = 0.3


@dataclass
class SearchResult:
    """The best patch found (S × S × 3 in [0, 1]), its objective, and the objective after
    each evaluation (the starting patch's first)."""

    patch: NDArray[np.float64]
    value: float
    history: list[float] = field(default_factory=list)


def stripes(pixels: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Square Attack's start: vertical stripes, one pixel wide, each a random corner of
    the RGB cube."""
    colours = rng.integers(0, 2, size=(1, pixels, 3)).astype(np.float64)
    return np.repeat(colours, pixels, axis=0)


def square_share(step: int, budget: int, p_init: float = P_INIT) -> float:
    """The square's share of the patch's area at ``step`` of ``budget``."""
    progress = int(step / max(budget, 1) * 10_000)
    return p_init / 2 ** sum(progress > h for h in HALVINGS)


def square_search(objective: Callable[[NDArray[np.float64]], float], initial: NDArray[np.floating],
                  budget: int, rng: np.random.Generator, p_init: float = P_INIT,
                  initial_value: float | None = None) -> SearchResult:
    """Maximise ``objective`` over patches from ``initial`` with ``budget`` evaluations in
    all (the first is the starting patch's, not repeated when ``initial_value`` gives it)."""
    if budget < 1:
        raise ValueError(f"budget must be at least 1 evaluation, got {budget}")
    best = np.asarray(initial, dtype=np.float64).copy()
    rows, cols = best.shape[:2]
    value = float(objective(best)) if initial_value is None else float(initial_value)
    history = [value]
    for step in range(1, budget):
        side = max(1, round(float(np.sqrt(square_share(step, budget, p_init) * rows * cols))))
        side = min(side, rows, cols)
        top, left = int(rng.integers(rows - side + 1)), int(rng.integers(cols - side + 1))
        candidate = best.copy()
        colour = rng.integers(0, 2, size=3).astype(np.float64)
        if np.array_equal(candidate[top:top + side, left:left + side], np.broadcast_to(
                colour, (side, side, 3))):
            colour = 1.0 - colour  # a step that changes nothing wastes a query
        candidate[top:top + side, left:left + side] = colour
        tried = float(objective(candidate))
        if tried > value:
            best, value = candidate, tried
        history.append(value)
    return SearchResult(best, value, history)


__all__ = ["HALVINGS", "P_INIT", "SearchResult", "square_search", "square_share", "stripes"]
