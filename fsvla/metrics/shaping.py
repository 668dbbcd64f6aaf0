"""Monotone shaping functions g_k of the soft safety cost (paper §4.1, Eq. soft_cost).

The monitor turns a channel's signed margin q (larger is safer) into an *incursion depth*
d = max(0, ε − q) ≥ 0 and charges the cost c = g(d). fsvla makes the cost dimensionless by
shaping the *normalised depth* x = d / ε instead of d itself, so that channels measured in
newtons, metres or seconds can be summed in CC:

* x = 0      the margin is at or above its soft threshold (safe, no cost);
* 0 < x ≤ 1  the margin is inside the warning band 0 ≤ q < ε;
* x > 1      the margin is past the hard limit (q < 0, a violation).

The shapings, all with g(0) = 0, nonnegative and monotone non-decreasing in x:

============  ==============  ==========================================
name          g(x)            value at the hard limit (x = 1)
============  ==============  ==========================================
linear        x               1
quadratic     x²              1
exponential   exp(x) − 1      e − 1 ≈ 1.718
step          1 if x > 0      1
============  ==============  ==========================================

``exponential`` overflows to ``inf`` (numpy warns) only for incursions beyond ~709 warning
bands; margins are finite, so nothing else can produce a non-finite cost.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Literal, get_args

import numpy as np
import numpy.typing as npt

ShapingName = Literal["linear", "quadratic", "exponential", "step"]
SHAPINGS: tuple[str, ...] = get_args(ShapingName)

FloatArray = npt.NDArray[np.float64]


def _linear(x: FloatArray) -> FloatArray:
    return x


def _quadratic(x: FloatArray) -> FloatArray:
    return x * x


def _exponential(x: FloatArray) -> FloatArray:
    return np.expm1(x)


def _step(x: FloatArray) -> FloatArray:
    return (x > 0).astype(np.float64)


# g(x) of the normalised depth x = d / ε, keyed by shaping name (read-only).
SHAPING_FUNCTIONS: Mapping[str, Callable[[FloatArray], FloatArray]] = MappingProxyType(
    {"linear": _linear, "quadratic": _quadratic, "exponential": _exponential, "step": _step}
)


def incursion_depth(margin: npt.ArrayLike, soft_threshold: float) -> FloatArray:
    """d = max(0, ε − q), elementwise, in the margin's own unit."""
    q = np.asarray(margin, dtype=np.float64)
    return np.maximum(0.0, soft_threshold - q)


def shape(name: str, normalised_depth: npt.ArrayLike) -> FloatArray:
    """g(x) for the named shaping, elementwise over x = d / ε ≥ 0."""
    try:
        fn = SHAPING_FUNCTIONS[name]
    except KeyError:
        raise ValueError(
            f"unknown shaping {name!r}; expected one of {', '.join(SHAPINGS)}"
        ) from None
    x = np.asarray(normalised_depth, dtype=np.float64)
    if np.any(x < 0):
        raise ValueError(f"a normalised incursion depth must be >= 0, actually: {x.min()}")
    return fn(x)


def soft_cost(margin: npt.ArrayLike, soft_threshold: float, shaping: str) -> FloatArray:
    """c = g(max(0, ε − q) / ε): the dimensionless soft cost of margins q (paper Eq. soft_cost)."""
    if not soft_threshold > 0:
        raise ValueError(f"Expect `soft_threshold` to be positive, actually: {soft_threshold}")
    return shape(shaping, incursion_depth(margin, soft_threshold) / soft_threshold)


__all__ = [
    "SHAPINGS",
    "SHAPING_FUNCTIONS",
    "ShapingName",
    "incursion_depth",
    "shape",
    "soft_cost",
]
