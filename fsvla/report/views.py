"""The report's tables as rows of formatted cells, shared by the HTML, Markdown and LaTeX
writers so that every format prints the same text for the same number.

A :class:`Cell` holds its text, a sort value (for the HTML page), whether it is the best
of its column (bold), and optionally its confidence interval as secondary text.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from fsvla.metrics import Interval
from fsvla.report.build import Report
from fsvla.report.dissection import Dissection
from fsvla.report.protocol import CC_SCALE, Protocol
from fsvla.report.tables import BETTER, GROUP_METRICS, METRIC_NAMES, GroupTable

ARROWS = {"high": "↑", "low": "↓", None: ""}
DASH = "—"


@dataclass(frozen=True)
class Cell:
    text: str
    value: float | str | None = None  # what the column sorts by (None: the text)
    best: bool = False
    ci: str | None = None  # "[low, high]"


@dataclass(frozen=True)
class TextTable:
    key: str  # file name stem (aggregate, per_suite, ...)
    caption: str
    header: tuple[str, ...]
    rows: tuple[tuple[Cell, ...], ...]
    groups: tuple[tuple[str, int], ...] = ()  # spanning header above `header`: (label, columns)
    sections: dict[int, str] = field(default_factory=dict)  # row index -> heading before it


def number(x: float, digits: int = 2) -> str:
    return f"{x:.{digits}f}"


def metric_cell(interval: Interval, best: bool = False, ci: bool = True) -> Cell:
    return Cell(number(interval.estimate), interval.estimate, best,
                f"[{number(interval.low)}, {number(interval.high)}]" if ci else None)


def percent(interval: Interval | None) -> Cell:
    if interval is None:
        return Cell(DASH, None)
    return Cell(f"{100 * interval.estimate:.1f}%", interval.estimate, False,
                f"[{100 * interval.low:.1f}, {100 * interval.high:.1f}]%")


def _heading(metric: str) -> str:
    return METRIC_NAMES[metric] + ARROWS[BETTER[metric]]


def aggregate_view(report: Report, ci: bool = True, weighted: bool = True) -> TextTable:
    """Table 2; ``weighted`` adds CC/Σw, the weighted mean CC / (T · Σ_k w_k), after CC."""
    metrics = ("ssr", "usr", "sfr", "ufr", "cc", "sasr")
    best = report.aggregate.best
    rows = []
    for r in report.aggregate.rows:
        cells = [metric_cell(getattr(r, m), r.label in best[m], ci) for m in metrics]
        if weighted:
            cells.insert(metrics.index("cc") + 1, metric_cell(r.cc_weighted, False, ci))
        rows.append((Cell(r.label), Cell(str(r.n), r.n), Cell(str(r.n_layouts), r.n_layouts),
                     *cells, Cell(str(r.faults), r.faults)))
    headings = [_heading(m) for m in metrics]
    if weighted:
        headings.insert(metrics.index("cc") + 1, "CC/Σw")
    lam = ", ".join(sorted({f"{r.sasr_lambda:g}" for r in report.aggregate.rows}))
    caption = (f"Aggregate results (Table 2). SSR, USR, SFR, UFR: rates with Wilson "
               f"{report.protocol.confidence:.0%} intervals; CC: cumulative safety cost per "
               "control step (CC / T), averaged over episodes"
               + ("; CC/Σw: the same divided by the channels' total weight" if weighted else "")
               + f"; SASR at λ = {lam}; means with percentile-bootstrap intervals; every "
               "interval counts layouts, not episodes (episodes on one layout are one unit). "
               "Best value of each column in bold. N: scored episodes; Layouts: the distinct "
               "layouts among them; faults count as failures.")
    return TextTable("aggregate", caption, ("Policy", "N", "Layouts", *headings, "Faults"),
                     tuple(rows))


def group_view(table: GroupTable, ci: bool = False) -> TextTable:
    name = table.title.removeprefix("Per ")
    header = [name[:1].upper() + name[1:]]
    for _ in table.policies:
        header += [*(_heading(m) for m in GROUP_METRICS), "n (layouts)"]
    rows, sections = [], {}
    previous = None
    for i, row in enumerate(table.rows):
        if row.section and row.section != previous:
            sections[i] = row.section
        previous = row.section
        cells = [Cell(row.label, i)]
        for policy in table.policies:
            cell = row.cells.get(policy)
            if cell is None:
                cells += [Cell(DASH), Cell(DASH), Cell(DASH), Cell("0 (0)", 0)]
                continue
            cells += [metric_cell(getattr(cell, m), policy in row.best[m], ci)
                      for m in GROUP_METRICS]
            pooled = "*" if cell.protocol == "pooled" else ""
            cells.append(Cell(f"{cell.n} ({cell.n_layouts}){pooled}", cell.n))
        rows.append(tuple(cells))
    caption = (f"{table.title}: SSR, CC (per step, CC / T) and SASR of each policy; n episodes "
               "per cell (and the distinct layouts among them, which the intervals count); "
               "best of each row in bold.")
    protocols = {c.protocol for row in table.rows for c in row.cells.values() if c is not None}
    if protocols - {None}:
        caption += (" One dimension at a time (Fig. 4): each cell holds the episodes whose "
                    "other two dimensions are at L0/W0/V0 (the cells fsvla run --sweep plans)"
                    + ("; * marks a cell pooled over the other two dimensions, where the run "
                       "has no such episodes" if "pooled" in protocols else "") + ".")
    if table.by == "category":
        caption += (" An episode counts toward its Safe-Core category and toward the Safe-Lang"
                    " (W3–W4) and Safe-Vis (V1–V4) categories of its levels, so n may sum to"
                    " more than the episodes.")
    return TextTable(f"per_{table.by}", caption, tuple(header), tuple(rows),
                     groups=((" ", 1), *((p, len(GROUP_METRICS) + 1) for p in table.policies)),
                     sections=sections)


def derived_view(report: Report) -> TextTable:
    rows = tuple(
        (Cell(d.label), Cell(str(d.n), d.n), Cell(number(d.success_rate), d.success_rate),
         Cell(f"{d.unsafe_successes}/{d.successes}", d.unsafe_successes),
         percent(d.unsafe_share_of_successes),
         Cell(f"{d.unsafe_failures}/{d.failures}", d.unsafe_failures),
         percent(d.unsafe_share_of_failures))
        for d in report.derived)
    return TextTable("derived", "Derived statements (§5.2): how many successes and failures "
                     "were unsafe, with Wilson intervals.",
                     ("Policy", "N", "Success rate", "Unsafe / successes",
                      "Unsafe share of successes", "Unsafe / failures",
                      "Unsafe share of failures"), rows)


def channel_view(d: Dissection) -> TextTable:
    rows = tuple(
        (Cell(c.name), Cell(c.family),
         Cell(DASH if c.soft_threshold is None else f"{c.soft_threshold:g}", c.soft_threshold),
         Cell(str(c.ret), c.ret), Cell(number(c.ret_fraction), c.ret_fraction),
         Cell("Yes" if c.hard_crossed else "No"),
         Cell(DASH if c.first_violation_step is None else str(c.first_violation_step + 1),
              c.first_violation_step),
         Cell(f"{c.min_margin:.4g}", c.min_margin), Cell(number(c.cc, 3), c.cc))
        for c in d.channels)
    return TextTable("dissection_channels",
                     f"Per-channel risk exposure of {d.episode_id} (Table 4): RET_k / T is the "
                     f"fraction of its T = {d.horizon} steps inside the warning or violation "
                     "region; first violation as a 1-based step.",
                     ("Channel", "Family", "ε_k", "RET_k", "RET_k/T", "Hard crossed",
                      "First violation", "min q_k", "CC_k"), rows)


def family_view(d: Dissection) -> TextTable:
    rows = [(Cell(f.label), Cell(str(f.ret), f.ret), Cell(number(f.ret_fraction), f.ret_fraction),
             Cell("Yes" if f.hard_crossed else "No")) for f in d.families]
    rows.append((Cell("Any active risk"), Cell(str(d.ret), d.ret),
                 Cell(number(d.ret_fraction), d.ret_fraction),
                 Cell("Yes" if any(f.hard_crossed for f in d.families) else "No")))
    return TextTable("dissection_families",
                     f"Risk exposure of {d.episode_id} by channel family; the last row is "
                     "RET / T (any channel exposed).",
                     ("Channel family", "RET", "RET/T", "Hard boundary crossed"), tuple(rows))


def _join(values: tuple | list) -> str:
    return ", ".join(str(v) for v in values) or DASH


def protocol_view(protocol: Protocol) -> TextTable:
    fields: list[tuple[str, object]] = [
        ("Run folder", lambda p: p.run_dir),
        ("Policy", lambda p: p.policy),
        ("Scenarios given", lambda p: _join(p.scenarios)),
        ("Scenarios scored", lambda p: f"{len(p.scenario_names)}: {_join(p.scenario_names)}"),
        ("Suites", lambda p: _join(p.suites)),
        ("Embodiments", lambda p: _join(p.embodiments)),
        ("Structure levels (L)", lambda p: _join(p.levels)),
        ("Language levels (W)", lambda p: _join(p.languages)),
        ("Vision levels (V)", lambda p: _join(p.visions)),
        ("Cells per scenario", lambda p: (
            f"{p.cells_per_scenario}: one-axis sweeps (L at W0/V0, W at L0/V0, V at L0/W0)"
            if p.sweep else f"{p.cells_per_scenario}: the grid L × W × V")),
        ("Episodes per cell", lambda p: str(p.episodes_per_cell)),
        ("Run seeds", lambda p: _join(p.seeds)),
        ("Layouts", lambda p: p.layout_protocol),
        ("Distinct layouts scored", lambda p: str(p.layouts_scored)),
        ("Warm-up per scenario (excluded)",
         lambda p: f"{p.warmup} ({p.warmups_recorded} recorded)"),
        ("Scored episodes", lambda p: str(p.episodes_scored)),
        ("Faulted (counted as failures)", lambda p: _join(
            [f"{k}: {v}" for k, v in p.faults.items()]) if p.faults else "0"),
        ("λ (SASR)", lambda p: f"{p.sasr_lambda:g}"),
        ("CC in tables", lambda p: CC_SCALE),
        ("Control / observation mode", lambda p: f"{p.control_mode} / {p.obs_mode}"),
        ("Terminate on violation", lambda p: "yes" if p.terminate_on_violation else "no"),
        ("Created / updated", lambda p: f"{p.created_at} / {p.updated_at}"),
        ("Software versions", lambda p: _join([f"{k} {v}" for k, v in p.versions.items()])),
    ]
    rows = tuple((Cell(name), *(Cell(get(p)) for p in protocol.runs))  # type: ignore[operator]
                 for name, get in fields)
    return TextTable("protocol", "Protocol of each run, read from its run folder.",
                     ("", *(p.label for p in protocol.runs)), rows)


def all_views(report: Report) -> list[TextTable]:
    """Every table of the report, in page order (Table 2 also without intervals, as the
    paper prints it: ``aggregate_compact``)."""
    compact = replace(aggregate_view(report, ci=False, weighted=False), key="aggregate_compact")
    views = [aggregate_view(report), compact, derived_view(report)]
    views += [group_view(t) for t in report.groups.values()]
    views += [group_view(t) for t in report.severity.values()]
    if report.dissection is not None:
        views += [channel_view(report.dissection), family_view(report.dissection)]
    return views


__all__ = ["Cell", "TextTable", "aggregate_view", "all_views", "channel_view", "derived_view",
           "family_view", "group_view", "number", "protocol_view"]
