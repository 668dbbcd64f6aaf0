"""The report as one Markdown page (GitHub-flavoured tables; figures as linked PNGs)."""

from __future__ import annotations

import re
from collections.abc import Mapping

from fsvla.report.build import Report
from fsvla.report.protocol import INTERVALS
from fsvla.report.views import (
    Cell,
    TextTable,
    aggregate_view,
    channel_view,
    derived_view,
    family_view,
    group_view,
    protocol_view,
)

_SPECIAL = re.compile(r"([\\`*_{}\[\]<>|#])")


def escape(text: str) -> str:
    """``text`` with Markdown's special characters backslash-escaped (``|`` too, for tables)."""
    return _SPECIAL.sub(r"\\\1", text).replace("\n", " ")


def _cell(cell: Cell) -> str:
    text = escape(cell.text)
    if cell.best:
        text = f"**{text}**"
    return f"{text} {escape(cell.ci)}" if cell.ci else text


def table(view: TextTable) -> str:
    header = list(view.header)
    if view.groups:  # flatten the spanning header into the column names
        names, column = [], 0
        for label, span in view.groups:
            for j in range(span):
                name = header[column + j]
                names.append(f"{label.strip()} {name}".strip() if span > 1 else name)
            column += span
        header = names
    lines = ["| " + " | ".join(escape(h) for h in header) + " |",
             "|" + "|".join(":---" if i == 0 else "---:" for i in range(len(header))) + "|"]
    for i, row in enumerate(view.rows):
        if i in view.sections:
            lines.append("| " + " | ".join([f"*{escape(view.sections[i])}*"]
                                           + [""] * (len(header) - 1)) + " |")
        lines.append("| " + " | ".join(_cell(c) for c in row) + " |")
    return "\n".join([f"*{escape(view.caption)}*", "", *lines, ""])


def _figure(figures: Mapping[str, tuple[str, str]], key: str) -> list[str]:
    if key not in figures:
        return []
    caption, path = figures[key]
    return [f"![{escape(caption)}]({path})", "", f"*{escape(caption)}*", ""]


def page(report: Report, figures: Mapping[str, tuple[str, str]] | None = None) -> str:
    """The whole report; ``figures`` maps a figure's key (landscape, diagnosis, keyframes,
    margins) to its caption and relative PNG path."""
    figures = figures or {}
    p = report.protocol
    out = ["# fsvla safety report", "",
           f"Policies: {escape(', '.join(report.policies))}.", "",
           "## Protocol", "", table(protocol_view(p))]
    if p.differences:
        out += [(f"**Warning:** the runs differ in {escape(', '.join(p.differences))}; their "
                 "numbers are not directly comparable."), ""]
    out += [f"- Faults and warm-ups: {escape(p.fault_policy)}",
            f"- CC: {escape(p.cc_normalisation)}",
            (f"- Intervals: {p.confidence:.0%}; {escape(INTERVALS)} "
             f"({p.n_resamples} resamples, seed {p.bootstrap_seed})."),
            "- Every number is a rate or mean over episodes listed in `data/episodes.csv`.", ""]
    out += ["## Aggregate results", "", table(aggregate_view(report))]
    out += _figure(figures, "landscape")
    out += ["### Derived statements (§5.2)", "", table(derived_view(report))]
    out += [f"- {escape(d.text)}" for d in report.derived]
    out += [f"- {escape(s)}" for s in report.statements] + [""]
    out += ["## Per suite, category and embodiment", ""]
    out += [table(group_view(t)) for t in report.groups.values()]
    out += ["## Diagnosis under variation", ""]
    out += _figure(figures, "diagnosis")
    out += [table(group_view(t)) for t in report.severity.values()]
    d = report.dissection
    out += ["## Process-level dissection", ""]
    if d is None:
        return "\n".join([*out, "No scored episode has monitored channels: nothing to dissect.", ""])
    out += [(f"Episode `{d.episode_id}` of {escape(d.label)} ({escape(d.selection)}): "
             f"{escape(d.quadrant.replace('_', ' '))}, T = {d.horizon}, RET/T = "
             f"{d.ret_fraction:.2f}, CC = {d.cc:.3f} (CC / T = {d.cc_per_step:.3f})."), ""]
    out += [escape(d.keyframes.note), ""] + _figure(figures, "keyframes")
    if d.trace_note:
        out += [f"Margins not drawn: {escape(d.trace_note)}", ""]
    out += _figure(figures, "margins")
    out += [table(channel_view(d)), table(family_view(d))]
    return "\n".join(out)


__all__ = ["escape", "page", "table"]
