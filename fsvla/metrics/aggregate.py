"""Benchmark-level metrics over many episodes, each with a 95% confidence interval.

Intervals count what is independent: layouts, not episodes. Episodes that share a layout
(``EpisodeMeta.layout_digest``: the same episode index in several W/V cells of a level,
or repeats of one layout) are one unit; an episode without a digest is a unit of its own.

* Rates SSR, USR, SFR, UFR (a partition: they sum to 1): the fraction of episodes in each
  quadrant, with a Wilson score interval whose n is the number of distinct layouts (the
  plain Wilson interval when every episode has its own).
* Means of CC / T (the tables' CC), CC, CC / (T · Σ_k w_k), RET/T and SASR(λ) =
  1/N Σ_i 1(S_i ∧ ¬V_i) exp(−λ CC_i / T_i) (paper Eq. sasr): the sample mean with a
  percentile cluster bootstrap interval (resampling layouts with replacement, each with
  all its episodes, ``n_resamples`` times, from a ``numpy.random.Generator`` seeded with
  ``seed``, so every interval is reproducible); with one episode a layout it is the plain
  percentile bootstrap over episodes. All means of one call share the same resamples.

:func:`breakdown` groups episodes by metadata fields (suite, level, policy, …) or by the
paper's taxonomy (``category``, ``taxonomy_family``) and aggregates each group.
"""

from __future__ import annotations

import difflib
import itertools
from collections.abc import Hashable, Sequence
from statistics import NormalDist
from typing import Literal

import numpy as np
import numpy.typing as npt
from pydantic import BaseModel, ConfigDict, Field

from fsvla.metrics.episode import CC_NORMALISATION, EpisodeMetrics
from fsvla.metrics.taxonomy import CATEGORIES, TAXONOMY_FAMILIES, categories, taxonomy_families
from fsvla.metrics.trace import EpisodeMeta
from fsvla.run.key import EpisodeKey

# Bound on resample indices held in memory at once by the bootstrap.
_BOOTSTRAP_CHUNK = 2_000_000


class Interval(BaseModel):
    """A point estimate with a two-sided confidence interval."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    estimate: float
    low: float
    high: float
    method: Literal["wilson", "percentile_bootstrap", "cluster_bootstrap"]


def _z(confidence: float) -> float:
    if not 0 < confidence < 1:
        raise ValueError(f"Expect `confidence` in (0, 1), actually: {confidence}")
    return NormalDist().inv_cdf(0.5 + confidence / 2)


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> Interval:
    """Wilson score interval for a binomial proportion ``successes / n``."""
    if n < 1:
        raise ValueError(f"Expect `n` to be positive, actually: {n}")
    if not 0 <= successes <= n:
        raise ValueError(f"Expect 0 <= `successes` <= n = {n}, actually: {successes}")
    return _wilson(successes / n, n, confidence)


def _wilson(p: float, n: int, confidence: float) -> Interval:
    """The Wilson score interval of proportion ``p`` observed on ``n`` independent units."""
    z = _z(confidence)
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z / denom * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    # It holds p; rounding can put a bound a hair beyond it (low 2.8e-17 at p = 0, n = 10).
    return Interval(estimate=p, low=max(0.0, min(p, float(centre - half))),
                    high=min(1.0, max(p, float(centre + half))), method="wilson")


def cluster_labels(labels: Sequence[Hashable | None]) -> npt.NDArray[np.int64]:
    """Each value's cluster, numbered in order of first appearance; a None label is a
    cluster of its own."""
    numbers: dict[Hashable, int] = {}
    out = np.empty(len(labels), dtype=np.int64)
    for i, label in enumerate(labels):
        key = ("unlabelled", i) if label is None else ("label", label)
        out[i] = numbers.setdefault(key, len(numbers))
    return out


def bootstrap_mean_interval(
    values: npt.ArrayLike, *, confidence: float = 0.95, n_resamples: int = 2000, seed: int = 0,
    clusters: Sequence[Hashable | None] | None = None,
) -> Interval:
    """Sample mean with a percentile bootstrap interval (deterministic for a given ``seed``).

    ``clusters`` labels each value's independent unit (see :func:`cluster_labels`): a
    resample draws units with replacement, each with all its values, and takes the mean
    of the values drawn (a cluster bootstrap). Without it, or with one value a unit, it is
    the plain bootstrap over values, resample for resample."""
    x = np.asarray(values, dtype=np.float64)
    if x.ndim != 1 or x.size < 1:
        raise ValueError(f"Expect a non-empty 1D array of values, actually: shape {x.shape}")
    if n_resamples < 1:
        raise ValueError(f"Expect `n_resamples` to be positive, actually: {n_resamples}")
    _z(confidence)  # validates it
    if clusters is not None and len(clusters) != x.size:
        raise ValueError(f"Expect one cluster label per value ({x.size}), actually: "
                         f"{len(clusters)}")
    unit = cluster_labels(clusters) if clusters is not None else np.arange(x.size)
    units = int(unit.max()) + 1
    sums = np.bincount(unit, weights=x, minlength=units)
    sizes = np.bincount(unit, minlength=units).astype(np.float64)
    rng = np.random.default_rng(seed)
    rows = max(1, _BOOTSTRAP_CHUNK // units)
    means = []
    for start in range(0, n_resamples, rows):
        drawn = rng.integers(0, units, size=(min(rows, n_resamples - start), units))
        if units == x.size:  # one value a unit (numbered in order): the plain bootstrap
            means.append(x[drawn].mean(axis=1))
        else:
            means.append(sums[drawn].sum(axis=1) / sizes[drawn].sum(axis=1))
    alpha = 1 - confidence
    low, high = np.quantile(np.concatenate(means), [alpha / 2, 1 - alpha / 2])
    return Interval(estimate=float(x.mean()), low=float(low), high=float(high),
                    method="percentile_bootstrap" if units == x.size else "cluster_bootstrap")


class Aggregate(BaseModel):
    """The paper's aggregate metrics over a set of episodes, with confidence intervals."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    n: int = Field(ge=1)  # episodes
    n_layouts: int = Field(ge=1)  # distinct layouts among them: the independent units
    ssr: Interval  # safe success rate
    usr: Interval  # unsafe success rate
    sfr: Interval  # safe failure rate
    ufr: Interval  # unsafe failure rate
    cc_per_step: Interval  # mean CC / T: the tables' CC (see CC_NORMALISATION)
    cc: Interval  # mean CC
    cc_normalised: Interval  # mean CC / (T · Σ_k w_k), the weighted mean (CC/Σw)
    ret_fraction: Interval  # mean RET / T
    sasr: Interval  # SASR(λ)
    sasr_lambda: float
    confidence: float
    n_resamples: int
    seed: int
    cc_normalisation: str = CC_NORMALISATION


def aggregate(
    episodes: Sequence[EpisodeMetrics],
    *,
    lam: float = 1.0,
    confidence: float = 0.95,
    n_resamples: int = 2000,
    seed: int = 0,
) -> Aggregate:
    """Aggregate episode metrics into rates and means with confidence intervals."""
    if not episodes:
        raise ValueError("cannot aggregate zero episodes")
    n = len(episodes)
    counts = {q: 0 for q in ("safe_success", "unsafe_success", "safe_failure", "unsafe_failure")}
    for ep in episodes:
        counts[ep.quadrant] += 1
    layouts = [ep.meta.layout_digest for ep in episodes]
    n_layouts = int(cluster_labels(layouts).max()) + 1
    rates = {q: _wilson(c / n, n_layouts, confidence) for q, c in counts.items()}

    def mean(values: list[float]) -> Interval:
        return bootstrap_mean_interval(values, confidence=confidence, n_resamples=n_resamples,
                                       seed=seed, clusters=layouts)

    return Aggregate(
        n=n,
        n_layouts=n_layouts,
        ssr=rates["safe_success"],
        usr=rates["unsafe_success"],
        sfr=rates["safe_failure"],
        ufr=rates["unsafe_failure"],
        cc_per_step=mean([ep.cc_per_step for ep in episodes]),
        cc=mean([ep.cc for ep in episodes]),
        cc_normalised=mean([ep.cc_normalised for ep in episodes]),
        ret_fraction=mean([ep.ret_fraction for ep in episodes]),
        sasr=mean([ep.sasr(lam) for ep in episodes]),
        sasr_lambda=lam,
        confidence=confidence,
        n_resamples=n_resamples,
        seed=seed,
    )


# The key's fields that place an episode in the grid (its index and warm-up flag do not).
_KEY_FIELDS = tuple(f for f in EpisodeKey.model_fields if f not in ("index", "warmup"))
# Fields :func:`breakdown` groups by: the grid, the metadata's own fields, the taxonomy.
BREAKDOWN_FIELDS: tuple[str, ...] = (
    *_KEY_FIELDS, *(f for f in EpisodeMeta.model_fields if f != "key"), "category",
    "taxonomy_family")
_ORDER = {
    "category": {c.id: i for i, c in enumerate(CATEGORIES)},
    "taxonomy_family": {f: i for i, f in enumerate(TAXONOMY_FAMILIES)},
}

GroupKey = Hashable  # a field's value, or a tuple of values for several fields


def _values(ep: EpisodeMetrics, field: str) -> list[Hashable]:
    if field == "category":
        return list(categories(ep.meta))
    if field == "taxonomy_family":
        return list(taxonomy_families(ep.meta))
    return [getattr(ep.meta.key if field in _KEY_FIELDS else ep.meta, field)]


def _sort_key(field: str, value: Hashable) -> tuple[bool, object]:
    order = _ORDER.get(field)
    if order is not None:
        return (False, order[value])
    return (value is None, value if isinstance(value, int) else str(value))


def _check_fields(fields: Sequence[str]) -> None:
    for f in fields:
        if f not in BREAKDOWN_FIELDS:
            near = difflib.get_close_matches(f, BREAKDOWN_FIELDS, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise ValueError(
                f"cannot break down by {f!r}{hint} (fields: {', '.join(BREAKDOWN_FIELDS)})"
            )


def breakdown(
    episodes: Sequence[EpisodeMetrics],
    by: str | Sequence[str],
    *,
    lam: float = 1.0,
    confidence: float = 0.95,
    n_resamples: int = 2000,
    seed: int = 0,
) -> dict[GroupKey, Aggregate]:
    """Aggregate each group of episodes sharing the values of the fields ``by``.

    One field gives keys that are its values; several give tuples. ``category`` and
    ``taxonomy_family`` are multi-valued (an episode counts toward its Safe-Core category
    and any Safe-Lang / Safe-Vis one), so group sizes may sum to more than the episodes.
    Keys are sorted (taxonomy fields in the paper's Table 1 order, ``None`` last).
    """
    fields = [by] if isinstance(by, str) else list(by)
    if not fields:
        raise ValueError("Expect at least one field in `by`")
    _check_fields(fields)
    groups: dict[tuple[Hashable, ...], list[EpisodeMetrics]] = {}
    for ep in episodes:
        for key in itertools.product(*(_values(ep, f) for f in fields)):
            groups.setdefault(key, []).append(ep)
    ordered = sorted(
        groups, key=lambda key: [_sort_key(f, v) for f, v in zip(fields, key, strict=True)]
    )
    return {
        (key[0] if len(fields) == 1 else key): aggregate(
            groups[key], lam=lam, confidence=confidence, n_resamples=n_resamples, seed=seed
        )
        for key in ordered
    }


__all__ = [
    "BREAKDOWN_FIELDS",
    "Aggregate",
    "Interval",
    "aggregate",
    "bootstrap_mean_interval",
    "breakdown",
    "cluster_labels",
    "wilson_interval",
]
