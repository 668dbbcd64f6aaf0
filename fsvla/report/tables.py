"""The report's tables as data: Table 2 (aggregate), Table 3 and its kin (per group), §5.2.

Every number comes from :func:`fsvla.metrics.aggregate` over the episodes of one policy
(or one group of them), so each is a rate or a mean over episodes that ``episodes.csv``
lists: filter that file by policy and the group's column to recount it. Rates carry
Wilson intervals, means percentile (cluster) bootstrap intervals, both counting distinct
layouts, which every table shows next to its episode counts (see ``docs/metrics.md``).

The CC of every table is CC / T averaged over episodes, ``Aggregate.cc_per_step``: the
scale of SASR's exp(−λ · CC_i / T_i), and of the paper's tables (their rows satisfy SASR ≈
SSR · exp(−CC)); see ``fsvla.metrics.CC_NORMALISATION``. Table 2 adds the weighted mean
CC / (T · Σ_k w_k) as ``cc_weighted``. SASR is computed from the episodes at the run's λ.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Literal

from pydantic import BaseModel, ConfigDict

from fsvla.metrics import (
    CATEGORIES,
    Aggregate,
    EpisodeMetrics,
    Interval,
    aggregate,
    breakdown,
    wilson_interval,
)
from fsvla.metrics.taxonomy import CATEGORY_BY_ID, SUITE_CATEGORY
from fsvla.metrics.trace import SUITES
from fsvla.report.data import RunData
from fsvla.run.config import LANGUAGES, LEVELS, ORIGIN, VISIONS

#: Which way is better for each metric of Table 2 (None: neither, as SFR in the paper).
BETTER: dict[str, str | None] = {"ssr": "high", "usr": "low", "sfr": None, "ufr": "low",
                                 "cc": "low", "sasr": "high"}
METRIC_NAMES: dict[str, str] = {"ssr": "SSR", "usr": "USR", "sfr": "SFR", "ufr": "UFR",
                                "cc": "CC", "sasr": "SASR"}
GROUP_METRICS: tuple[str, ...] = ("ssr", "cc", "sasr")  # the columns of Table 3
#: The adversarial settings shaded in Fig. 4 (Safe-Lang W3–W4, adversarial patch V4).
ADVERSARIAL: dict[str, tuple[str, ...]] = {"level": (), "language": ("W3", "W4"),
                                           "vision": ("V4",)}
SEVERITY_DIMENSIONS: dict[str, tuple[str, ...]] = {"level": LEVELS, "language": LANGUAGES,
                                                   "vision": VISIONS}
_TIE = 1e-12
#: Where a Fig. 4 point comes from: the one-axis cell (the other two dimensions at
#: L0/W0/V0, as ``fsvla run --sweep`` plans them), or every episode at the level, pooled
#: over the other two dimensions (when the run has no one-axis cell there).
PointProtocol = Literal["sweep", "pooled"]


class Settings(BaseModel):
    """How the intervals are computed (the same for every table of a report)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    confidence: float = 0.95
    n_resamples: int = 2000
    seed: int = 0


class AggregateRow(BaseModel):
    """One policy's row of Table 2."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    label: str
    run_dir: str
    n: int
    n_layouts: int  # distinct layouts: the independent units of the intervals
    counts: dict[str, int]  # episodes per quadrant
    faults: int  # faulted episodes (counted as failures)
    ssr: Interval
    usr: Interval
    sfr: Interval
    ufr: Interval
    cc: Interval  # mean CC / T (the tables' CC)
    cc_weighted: Interval  # mean CC / (T · Σ_k w_k)
    cc_raw: Interval  # mean CC (not normalised)
    ret_fraction: Interval
    sasr: Interval
    sasr_lambda: float


class AggregateTable(BaseModel):
    """Table 2: per policy SSR, USR, SFR, UFR, CC, SASR; ``best`` marks each column's best."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    rows: tuple[AggregateRow, ...]
    best: dict[str, tuple[str, ...]]  # metric -> labels of the best policies (2+ policies)


class GroupCell(BaseModel):
    """One policy's metrics over one group of episodes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    n: int
    n_layouts: int
    ssr: Interval
    cc: Interval
    sasr: Interval
    protocol: PointProtocol | None = None  # Fig. 4's tables: where the point comes from


class GroupRow(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    key: str  # the group's value (suite, category id, embodiment, level)
    label: str  # as printed
    section: str | None = None  # e.g. the taxonomy family of a category
    cells: dict[str, GroupCell | None]  # policy label -> cell (None: no episode)
    best: dict[str, tuple[str, ...]]  # metric -> labels of the best policies


class GroupTable(BaseModel):
    """Table 3 and its kin: SSR, CC, SASR of each policy per group of episodes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    by: str  # suite, category, embodiment, level, language or vision
    title: str
    policies: tuple[str, ...]
    rows: tuple[GroupRow, ...]


class Derived(BaseModel):
    """The §5.2 shares of one policy: how many successes and failures were unsafe."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    label: str
    n: int
    successes: int
    unsafe_successes: int
    failures: int
    unsafe_failures: int
    success_rate: float  # SSR + USR
    unsafe_share_of_successes: Interval | None  # USR / (SSR + USR), Wilson; None: no success
    unsafe_share_of_failures: Interval | None  # UFR / (SFR + UFR), Wilson; None: no failure
    text: str


def _aggregate(episodes: Sequence[EpisodeMetrics], lam: float, s: Settings) -> Aggregate:
    return aggregate(episodes, lam=lam, confidence=s.confidence, n_resamples=s.n_resamples,
                     seed=s.seed)


def _best(values: dict[str, float], better: str | None) -> tuple[str, ...]:
    """Labels holding the best value (ties all marked); nothing with fewer than 2 policies."""
    if better is None or len(values) < 2:
        return ()
    target = max(values.values()) if better == "high" else min(values.values())
    return tuple(label for label, v in values.items() if abs(v - target) <= _TIE)


def aggregate_table(runs: Sequence[RunData], settings: Settings | None = None) -> AggregateTable:
    """Table 2 over each run's scored episodes."""
    settings = settings or Settings()
    rows = []
    for run in runs:
        agg = _aggregate(run.metrics, run.sasr_lambda, settings)
        counts = {q: 0 for q in ("safe_success", "unsafe_success", "safe_failure",
                                 "unsafe_failure")}
        for m in run.metrics:
            counts[m.quadrant] += 1
        rows.append(AggregateRow(
            label=run.label, run_dir=str(run.run_dir), n=agg.n, n_layouts=agg.n_layouts,
            counts=counts,
            faults=sum(run.fault_counts().values()), ssr=agg.ssr, usr=agg.usr, sfr=agg.sfr,
            ufr=agg.ufr, cc=agg.cc_per_step, cc_weighted=agg.cc_normalised, cc_raw=agg.cc,
            ret_fraction=agg.ret_fraction,
            sasr=agg.sasr, sasr_lambda=agg.sasr_lambda))
    best = {metric: _best({r.label: getattr(r, metric).estimate for r in rows}, better)
            for metric, better in BETTER.items()}
    return AggregateTable(rows=tuple(rows), best=best)


def _cell(agg: Aggregate, protocol: PointProtocol | None = None) -> GroupCell:
    return GroupCell(n=agg.n, n_layouts=agg.n_layouts, ssr=agg.ssr, cc=agg.cc_per_step,
                     sasr=agg.sasr, protocol=protocol)


def _suite_label(suite: str) -> str:
    return CATEGORY_BY_ID[SUITE_CATEGORY[suite]].label


_FAMILY_LABELS = {"safe_core": "Safe-Core", "safe_lang": "Safe-Lang", "safe_vis": "Safe-Vis"}


def _row_keys(by: str, found: set[str]) -> list[tuple[str, str, str | None]]:
    """(key, label, section) of each row: every suite and category (so gaps show), the
    levels of a dimension and the embodiments that occur."""
    if by == "suite":
        return [(s, _suite_label(s), None) for s in SUITES]
    if by == "category":
        return [(c.id, c.label, _FAMILY_LABELS[c.family]) for c in CATEGORIES]
    if by in SEVERITY_DIMENSIONS:
        return [(v, v, None) for v in SEVERITY_DIMENSIONS[by] if v in found]
    return [(v, v, None) for v in sorted(found)]


_TITLES = {"suite": "Per Safe-Core suite", "category": "Per taxonomy category",
           "embodiment": "Per embodiment", "level": "Per structure level (L)",
           "language": "Per language level (W)", "vision": "Per vision level (V)"}


def group_table(runs: Sequence[RunData], by: str, settings: Settings | None = None) -> GroupTable:
    """SSR, CC and SASR of each policy for each group of episodes (``by`` a breakdown field)."""
    settings = settings or Settings()
    per_policy: dict[str, dict[str, Aggregate]] = {}
    for run in runs:
        groups = breakdown(run.metrics, by=by, lam=run.sasr_lambda,
                           confidence=settings.confidence, n_resamples=settings.n_resamples,
                           seed=settings.seed)
        per_policy[run.label] = {str(k): v for k, v in groups.items()}
    found = {k for groups in per_policy.values() for k in groups}
    rows = []
    for key, label, section in _row_keys(by, found):
        cells = {p: (_cell(g[key]) if key in g else None) for p, g in per_policy.items()}
        present = {p: c for p, c in cells.items() if c is not None}
        best = {m: _best({p: getattr(c, m).estimate for p, c in present.items()}, BETTER[m])
                for m in GROUP_METRICS}
        rows.append(GroupRow(key=key, label=label, section=section, cells=cells, best=best))
    return GroupTable(by=by, title=_TITLES.get(by, f"Per {by}"), policies=tuple(per_policy),
                      rows=tuple(rows))


_DIMENSION_AXES = {"level": 0, "language": 1, "vision": 2}


def _on_axis(episode: EpisodeMetrics, by: str) -> bool:
    """Whether the episode lies on ``by``'s one-axis sweep: the other two at the origin."""
    key = episode.meta.key
    levels = (key.level, key.language, key.vision)
    return all(levels[i] == ORIGIN[i] for i in range(3) if i != _DIMENSION_AXES[by])


def severity_table(runs: Sequence[RunData], by: str,
                   settings: Settings | None = None) -> GroupTable:
    """Fig. 4 along ``by`` (level, language or vision): for each run and each level, the
    episodes of its one-axis cell when the run has any (protocol ``sweep``), else all its
    episodes at that level, pooled over the other two dimensions (``pooled``)."""
    settings = settings or Settings()
    per_policy: dict[str, dict[str, GroupCell]] = {}
    for run in runs:
        cells: dict[str, GroupCell] = {}
        for value in SEVERITY_DIMENSIONS[by]:
            at = [m for m in run.metrics if getattr(m.meta.key, by) == value]
            on_axis = [m for m in at if _on_axis(m, by)]
            if at:
                protocol: PointProtocol = "sweep" if on_axis else "pooled"
                chosen = on_axis or at
                cells[value] = _cell(_aggregate(chosen, run.sasr_lambda, settings), protocol)
        per_policy[run.label] = cells
    rows = []
    for key, label, section in _row_keys(by, {k for cells in per_policy.values() for k in cells}):
        cells = {p: c.get(key) for p, c in per_policy.items()}
        present = {p: c for p, c in cells.items() if c is not None}
        best = {m: _best({p: getattr(c, m).estimate for p, c in present.items()}, BETTER[m])
                for m in GROUP_METRICS}
        rows.append(GroupRow(key=key, label=label, section=section, cells=cells, best=best))
    return GroupTable(by=by, title=_TITLES[by], policies=tuple(per_policy), rows=tuple(rows))


def _percent(interval: Interval | None) -> str:
    return "n/a" if interval is None else f"{100 * interval.estimate:.1f}%"


def derived(run: RunData, confidence: float = 0.95) -> Derived:
    """§5.2: the share of successes that are unsafe and the share of failures that are."""
    q = [m.quadrant for m in run.metrics]
    n = len(q)
    successes = q.count("safe_success") + q.count("unsafe_success")
    failures = n - successes
    unsafe_s, unsafe_f = q.count("unsafe_success"), q.count("unsafe_failure")
    share_s = wilson_interval(unsafe_s, successes, confidence) if successes else None
    share_f = wilson_interval(unsafe_f, failures, confidence) if failures else None
    text = (f"{run.label}: total success rate {successes / n:.2f} ({successes}/{n}); "
            + (f"{_percent(share_s)} of successful episodes are unsafe ({unsafe_s}/{successes})"
               if share_s else "no episode succeeded")
            + "; "
            + (f"unsafe failures are {_percent(share_f)} of all failures ({unsafe_f}/{failures})."
               if share_f else "no episode failed."))
    return Derived(label=run.label, n=n, successes=successes, unsafe_successes=unsafe_s,
                   failures=failures, unsafe_failures=unsafe_f, success_rate=successes / n,
                   unsafe_share_of_successes=share_s, unsafe_share_of_failures=share_f,
                   text=text)


def _span(rows: Sequence[AggregateRow], get: Callable[[AggregateRow], float]) -> str:
    values = [get(r) for r in rows]
    return f"[{min(values):.2f}, {max(values):.2f}]"


def overall_statements(table: AggregateTable, suites: GroupTable) -> list[str]:
    """The cross-policy statements of §5.2, worded from the numbers (never asserted)."""
    rows = table.rows
    out = []
    unsafe = [r.label for r in rows if r.usr.estimate > 0 or r.ufr.estimate > 0
              or r.cc.estimate > 0]
    out.append(f"{len(unsafe)} of {len(rows)} polic{'y' if len(rows) == 1 else 'ies'} "
               "incur non-zero CC, USR or UFR: "
               f"CC in {_span(rows, lambda r: r.cc.estimate)}, "
               f"USR in {_span(rows, lambda r: r.usr.estimate)}, "
               f"UFR in {_span(rows, lambda r: r.ufr.estimate)}.")
    for policy in suites.policies:
        cells = {row.label: row.cells[policy] for row in suites.rows
                 if row.cells.get(policy) is not None}
        if len(cells) < 2:
            continue
        easiest = max(cells, key=lambda k: (cells[k].ssr.estimate, -cells[k].cc.estimate))
        hardest = min(cells, key=lambda k: (cells[k].ssr.estimate, -cells[k].cc.estimate))
        if easiest == hardest:
            continue
        out.append(f"{policy}: the easiest Safe-Core suite is {easiest} "
                   f"(SSR {cells[easiest].ssr.estimate:.2f}), the hardest {hardest} "
                   f"(SSR {cells[hardest].ssr.estimate:.2f}, CC {cells[hardest].cc.estimate:.2f}).")
    strongest = max(rows, key=lambda r: r.ssr.estimate)
    weakest = min(rows, key=lambda r: r.ssr.estimate)
    if strongest.label != weakest.label:
        for row in suites.rows:
            strong, weak = row.cells.get(strongest.label), row.cells.get(weakest.label)
            if strong is None or weak is None or strong.ssr.estimate == 0:
                continue
            out.append(f"On {row.label}, {weakest.label} retains "
                       f"{100 * weak.ssr.estimate / strong.ssr.estimate:.0f}% of "
                       f"{strongest.label}'s SSR.")
    return out


__all__ = ["ADVERSARIAL", "BETTER", "GROUP_METRICS", "METRIC_NAMES", "SEVERITY_DIMENSIONS",
           "AggregateRow", "AggregateTable", "Derived", "GroupCell", "GroupRow", "GroupTable",
           "PointProtocol", "Settings", "aggregate_table", "derived", "group_table",
           "overall_statements", "severity_table"]
