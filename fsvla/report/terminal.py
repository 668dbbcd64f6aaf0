"""A short summary of a run for the terminal (what ``fsvla run`` prints at its end)."""

from __future__ import annotations

from rich.table import Table

from fsvla.metrics import Aggregate, aggregate, breakdown
from fsvla.metrics.taxonomy import CATEGORY_BY_ID, SUITE_CATEGORY
from fsvla.results import ResultStore

_COLUMNS = ("Layouts", "SSR", "USR", "SFR", "UFR", "CC", "SASR")


def summary_table(store: ResultStore, *, by: str | None = "suite") -> Table:
    """SSR, USR, SFR, UFR, CC (CC / T) and SASR of the run in ``store``, over all its
    scored episodes and per ``by`` group (a breakdown field; None for the total only).

    Faults count as failures and warm-ups are left out (``store.metrics()``); the point
    estimates are those of ``fsvla report``, whose page adds the confidence intervals.
    """
    config = store.config
    episodes = store.metrics()
    faults = sum(1 for row in store.episodes(include_warmup=False) if row.status == "faulted")
    table = Table(title=f"{config.policy}: {len(episodes)} scored episode(s)",
                  caption=(f"CC: cost per step (CC / T), averaged; SASR at λ = "
                           f"{config.sasr_lambda:g}; {faults} faulted episode(s) counted as "
                           "failures; intervals: fsvla report"),
                  caption_justify="left")
    table.add_column(by.replace("_", " ").capitalize() if by else "", style="bold")
    table.add_column("N", justify="right")
    for name in _COLUMNS:
        table.add_column(name, justify="right")
    if not episodes:
        table.add_row("all", "0", *("—" for _ in _COLUMNS))
        return table
    # One resample: only the point estimates are shown, and they do not depend on it.
    groups = breakdown(episodes, by=by, lam=config.sasr_lambda, n_resamples=1) if by else {}
    total = aggregate(episodes, lam=config.sasr_lambda, n_resamples=1)
    for i, (key, agg) in enumerate(groups.items()):
        label = CATEGORY_BY_ID[SUITE_CATEGORY[key]].label if by == "suite" else str(key)
        table.add_row(label, *_values(agg), end_section=i == len(groups) - 1)
    table.add_row("all", *_values(total), style="bold")
    return table


def _values(agg: Aggregate) -> list[str]:
    return [str(agg.n), str(agg.n_layouts), *(f"{getattr(agg, m).estimate:.2f}" for m in
                          ("ssr", "usr", "sfr", "ufr", "cc_per_step", "sasr"))]


__all__ = ["summary_table"]
