"""The short per-scenario table ``fsvla run`` ends with: rates and means with 95% CIs."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from fsvla.metrics.aggregate import Aggregate, aggregate, breakdown
from fsvla.results import ResultStore

#: Bootstrap resamples for the end-of-run table (reports use more if they like).
SUMMARY_RESAMPLES = 1000


@dataclass(frozen=True)
class SummaryRow:
    scenario: str  # "all" for the overall row
    episodes: int  # scored episodes (warm-ups out, faults in, as failures)
    faults: int
    metrics: Aggregate | None  # None without episodes


def summarize(store: ResultStore) -> list[SummaryRow]:
    """One row per scenario and an ``all`` row, from the store alone (faults counted as
    failures, warm-ups left out: ``ResultStore.metrics`` defaults)."""
    lam = store.config.sasr_lambda
    episodes = store.metrics()
    faults = Counter(row.key.scenario for row in store.episodes(include_warmup=False)
                     if row.status == "faulted")
    rows = [SummaryRow(scenario=str(name), episodes=value.n, faults=faults[str(name)],
                       metrics=value)
            for name, value in breakdown(episodes, by="scenario", lam=lam,
                                         n_resamples=SUMMARY_RESAMPLES).items()]
    overall = aggregate(episodes, lam=lam, n_resamples=SUMMARY_RESAMPLES) if episodes else None
    rows.append(SummaryRow(scenario="all", episodes=len(episodes),
                           faults=sum(faults.values()), metrics=overall))
    return rows


__all__ = ["SUMMARY_RESAMPLES", "SummaryRow", "summarize"]
