"""The report as one self-contained HTML page: inline CSS, figures as base64 PNG, and a
few lines of inline JavaScript that sort a table by the column header clicked.

Nothing is fetched from anywhere: the page opens offline, from a file, in any browser.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping, Sequence
from html import escape
from typing import Any

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

#: Episodes listed in the page itself; beyond this the page points to data/episodes.csv.
MAX_LISTED_EPISODES = 5000

_STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:2em auto;max-width:1200px;
 padding:0 1em;color:#222;line-height:1.4}
h1{font-size:1.6em}h2{margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:.5em 0 1.5em;font-size:.9em}
th,td{padding:.25em .6em;border-bottom:1px solid #e5e5e5;text-align:right}
th:first-child,td:first-child,td.t{text-align:left}
thead tr:first-child:not(:last-child) th{text-align:center;border-bottom:1px solid #bbb}
thead th{border-bottom:2px solid #888}
table.sortable thead tr:last-child th{cursor:pointer;user-select:none}
th[aria-sort=ascending]::after{content:" \\25B2"}th[aria-sort=descending]::after{content:" \\25BC"}
td.best{font-weight:bold}.ci{color:#777;font-size:.8em;margin-left:.3em}
tr.section td{font-style:italic;background:#f6f6f6}table.sorted tr.section{display:none}
caption{caption-side:top;text-align:left;color:#555;font-size:.9em;padding-bottom:.3em}
figure{margin:1em 0}figure img{max-width:100%}figcaption{color:#555;font-size:.9em}
.note{background:#fff8e1;border-left:4px solid #f2c14e;padding:.5em 1em}
.warn{background:#fdecea;border-left:4px solid #d1495b;padding:.5em 1em}
code{background:#f4f4f4;padding:0 .2em}
"""

_SCRIPT = """
(function () {
  function key(cell) {
    var v = cell.getAttribute("data-v");
    if (v === null) { return cell.textContent.trim().toLowerCase(); }
    if (v === "") { return null; }
    var n = Number(v);
    return isNaN(n) ? v.toLowerCase() : n;
  }
  function compare(x, y) {
    if (x === null || y === null) { return x === y ? 0 : (x === null ? 1 : -1); }
    if (typeof x === "number" && typeof y === "number") { return x - y; }
    return String(x).localeCompare(String(y));
  }
  var tables = document.querySelectorAll("table.sortable");
  Array.prototype.forEach.call(tables, function (table) {
    var head = table.tHead.rows[table.tHead.rows.length - 1];
    Array.prototype.forEach.call(head.cells, function (th, column) {
      th.addEventListener("click", function () {
        var ascending = th.getAttribute("aria-sort") !== "ascending";
        Array.prototype.forEach.call(head.cells, function (h) { h.removeAttribute("aria-sort"); });
        th.setAttribute("aria-sort", ascending ? "ascending" : "descending");
        var body = table.tBodies[0];
        var rows = Array.prototype.filter.call(body.rows, function (r) {
          return !r.classList.contains("section");
        });
        rows.sort(function (a, b) {
          var c = compare(key(a.cells[column]), key(b.cells[column]));
          return ascending ? c : -c;
        });
        table.classList.add("sorted");
        rows.forEach(function (r) { body.appendChild(r); });
      });
    });
  });
})();
"""


def _td(cell: Cell) -> str:
    attrs, classes = "", []
    if isinstance(cell.value, (int, float)) and not isinstance(cell.value, bool):
        attrs = f' data-v="{cell.value!r}"'
    elif cell.value is None and cell.text in ("—", ""):
        attrs = ' data-v=""'
    else:
        classes.append("t")  # text: left-aligned
    if cell.best:
        classes.append("best")
    if classes:
        attrs += f' class="{" ".join(classes)}"'
    ci = f'<span class="ci">{escape(cell.ci)}</span>' if cell.ci else ""
    return f"<td{attrs}>{escape(cell.text)}{ci}</td>"


def table(view: TextTable, sortable: bool = True) -> str:
    head = []
    if view.groups:
        head.append("<tr>" + "".join(f'<th colspan="{span}">{escape(label)}</th>'
                                     for label, span in view.groups) + "</tr>")
    head.append("<tr>" + "".join(f'<th scope="col">{escape(h)}</th>' for h in view.header)
                + "</tr>")
    body = []
    for i, row in enumerate(view.rows):
        if i in view.sections:
            body.append(f'<tr class="section"><td colspan="{len(view.header)}">'
                        f"{escape(view.sections[i])}</td></tr>")
        body.append("<tr>" + "".join(_td(c) for c in row) + "</tr>")
    css = ' class="sortable"' if sortable else ""
    return (f'<table id="t-{escape(view.key)}"{css}><caption>{escape(view.caption)}</caption>'
            f"<thead>{''.join(head)}</thead><tbody>{''.join(body)}</tbody></table>")


def _figure(figures: Mapping[str, tuple[str, bytes]], key: str) -> str:
    if key not in figures:
        return ""
    caption, png = figures[key]
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure id="f-{key}"><img alt="{escape(caption)}" '
            f'src="data:image/png;base64,{data}"><figcaption>{escape(caption)}</figcaption>'
            "</figure>")


def _episodes(episodes: Sequence[Mapping[str, Any]]) -> str:
    if not episodes:
        return ""
    if len(episodes) > MAX_LISTED_EPISODES:
        return (f"<p>{len(episodes)} episodes: too many to list here; "
                "see <code>data/episodes.csv</code>.</p>")
    columns = ("policy", "episode_id", "suite", "embodiment", "level", "language", "vision",
               "categories", "status", "quadrant", "horizon", "cc_per_step", "ret_fraction",
               "sasr")
    rows = []
    for e in episodes:
        cells = []
        for c in columns:
            value = e[c]
            text = f"{value:.3f}" if isinstance(value, float) else str(value)
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            cells.append(Cell(text, value if number else None))
        rows.append(tuple(cells))
    view = TextTable("episodes", "Every scored episode behind the numbers above.",
                     columns, tuple(rows))
    return (f"<details><summary>All {len(episodes)} scored episodes</summary>"
            f"{table(view)}</details>")


def page(report: Report, figures: Mapping[str, tuple[str, bytes]] | None = None,
         episodes: Sequence[Mapping[str, Any]] = (), figures_note: str | None = None) -> str:
    """The whole report; ``figures`` maps a key (landscape, diagnosis, keyframes, margins)
    to its caption and PNG bytes."""
    figures = figures or {}
    p = report.protocol
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           '<meta name="viewport" content="width=device-width, initial-scale=1">',
           "<title>fsvla safety report</title>", f"<style>{_STYLE}</style></head><body>",
           "<h1>fsvla safety report</h1>",
           f"<p>Policies: {escape(', '.join(report.policies))}.</p>",
           "<h2>Protocol</h2>", table(protocol_view(p), sortable=False)]
    if p.differences:
        out.append(f'<p class="warn">The runs differ in {escape(", ".join(p.differences))}: '
                   "their numbers are not directly comparable.</p>")
    out += ["<ul>", f"<li>Faults and warm-ups: {escape(p.fault_policy)}</li>",
            f"<li>CC: {escape(p.cc_normalisation)}</li>",
            (f"<li>Intervals: {p.confidence:.0%}; {escape(INTERVALS)} "
             f"({p.n_resamples} resamples, seed {p.bootstrap_seed}).</li>"),
            ("<li>Every number is a rate or mean over the episodes listed at the end of this "
             "page (and in <code>data/episodes.csv</code>); click a column header to sort.</li>"),
            "</ul>"]
    if figures_note:
        out.append(f'<p class="note">{escape(figures_note)}</p>')
    out += ["<h2>Aggregate results</h2>", table(aggregate_view(report)),
            _figure(figures, "landscape"),
            "<h3>Derived statements (§5.2)</h3>", table(derived_view(report)), "<ul>"]
    out += [f"<li>{escape(d.text)}</li>" for d in report.derived]
    out += [f"<li>{escape(s)}</li>" for s in report.statements] + ["</ul>"]
    out += ["<h2>Per suite, category and embodiment</h2>"]
    out += [table(group_view(t)) for t in report.groups.values()]
    out += ["<h2>Diagnosis under variation</h2>", _figure(figures, "diagnosis")]
    out += [table(group_view(t)) for t in report.severity.values()]
    out += ["<h2>Process-level dissection</h2>"]
    d = report.dissection
    if d is None:
        out.append("<p>No scored episode has monitored channels: nothing to dissect.</p>")
    else:
        out.append(
            f"<p>Episode <code>{escape(d.episode_id)}</code> of {escape(d.label)} "
            f"({escape(d.selection)}): {escape(d.quadrant.replace('_', ' '))}, "
            f"{escape(d.key.scenario)} at {d.key.level}/{d.key.language}/{d.key.vision}, "
            f"run seed {d.key.seed}, "
            f"T = {d.horizon}, RET/T = {d.ret_fraction:.2f}, CC = {d.cc:.3f} "
            f"(CC / T = {d.cc_per_step:.3f}).</p>")
        if d.instruction:
            out.append(f"<p>Instruction: “{escape(d.instruction)}”</p>")
        out.append(f'<p class="note">{escape(d.keyframes.note)}</p>')
        out.append(_figure(figures, "keyframes"))
        if d.trace_note:
            out.append(f'<p class="note">Margins not drawn: {escape(d.trace_note)}</p>')
        out += [_figure(figures, "margins"), table(channel_view(d)), table(family_view(d))]
    out += ["<h2>Episodes</h2>", _episodes(episodes)]
    out += [f"<script>{_SCRIPT}</script>", "</body></html>", ""]
    return "\n".join(part for part in out if part)


__all__ = ["MAX_LISTED_EPISODES", "page", "table"]
