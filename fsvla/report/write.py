"""Write a report's files into one folder::

    report/
      report.html        one self-contained page (figures embedded, sortable tables)
      report.md          the same in Markdown (figures linked from figures/)
      report.json        the report as data (every number, interval and count)
      tables/*.tex       booktabs tables, one per table
      figures/*.png|pdf|svg   landscape, diagnosis, margins, keyframes
      data/*.csv|parquet aggregates, breakdowns, §5.2 shares, every episode behind them

Each file is written whole to a temporary name and renamed, so a folder never holds a
half-written file.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from fsvla.report import html, latex, markdown
from fsvla.report.build import Report
from fsvla.report.data import RunData
from fsvla.report.export import all_records, to_csv
from fsvla.report.views import all_views

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FORMATS = ("html", "md", "json", "tex", "png", "pdf", "svg", "csv", "parquet")
DEFAULT_FORMATS = ("html", "md", "json", "tex", "png", "pdf", "csv")
FIGURE_CAPTIONS = {
    "landscape": "Safety–success landscape: SSR against CC per policy; bubble area is USR; "
                 "bars are the confidence intervals; the upper left is preferable.",
    "diagnosis": "Diagnosis under variation: SSR (solid, left axis) and CC (dashed, right "
                 "axis) against severity along L, W and V, one dimension at a time: filled "
                 "points come from the one-axis cells (the other two dimensions at L0/W0/V0, "
                 "as fsvla run --sweep plans them), hollow points, where a run has no such "
                 "cell, pool the episodes at that level over the other two dimensions; "
                 "adversarial settings (W3–W4, V4) shaded.",
    "keyframes": "Keyframes of the dissected episode.",
    "margins": "Time-aligned per-channel margins q_k(t) of the dissected episode, with the "
               "warning band [0, ε_k) and the hard threshold q = 0.",
}


def check_formats(formats: Iterable[str]) -> tuple[str, ...]:
    chosen = tuple(dict.fromkeys(f.strip().lower() for f in formats if f.strip()))
    unknown = [f for f in chosen if f not in FORMATS]
    if unknown or not chosen:
        raise ValueError(f"unknown format(s) {', '.join(map(repr, unknown)) or '(none)'}; "
                         f"choose among {', '.join(FORMATS)}")
    return chosen


def _write(path: Path, data: bytes | str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(raw)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def make_figures(report: Report) -> dict[str, Figure]:
    """The report's figures by key (raises FiguresUnavailable without matplotlib)."""
    from fsvla.report import figures

    made: dict[str, Figure | None] = {"landscape": figures.landscape(report),
                                      "diagnosis": figures.diagnosis(report)}
    if report.dissection is not None:
        made["keyframes"] = figures.keyframes(report.dissection)
        made["margins"] = figures.margins(report.dissection)
    return {k: f for k, f in made.items() if f is not None}


def write_report(report: Report, runs: Sequence[RunData], out_dir: Path,
                 formats: Sequence[str] = DEFAULT_FORMATS, *, figures: bool = True,
                 on_write: Callable[[Path], None] | None = None) -> list[Path]:
    """Write the chosen ``formats`` of ``report`` into ``out_dir``; returns the files."""
    chosen = check_formats(formats)
    out_dir = Path(out_dir)
    written: list[Path] = []

    def put(relative: str, data: bytes | str) -> None:
        path = _write(out_dir / relative, data)
        written.append(path)
        if on_write is not None:
            on_write(path)

    drawn = make_figures(report) if figures else {}
    if drawn:
        from fsvla.report.figures import render

        for fmt in ("png", "pdf", "svg"):
            if fmt in chosen or (fmt == "png" and "md" in chosen):
                for key, figure in drawn.items():
                    put(f"figures/{key}.{fmt}", render(figure, fmt))
    records = all_records(report, runs)
    if "csv" in chosen:
        for name, rows in records.items():
            if rows:
                put(f"data/{name}.csv", to_csv(rows))
    if "parquet" in chosen:
        from fsvla.report.export import to_parquet

        for name, rows in records.items():
            if rows:
                put(f"data/{name}.parquet", to_parquet(rows))
    if "tex" in chosen:
        for view in all_views(report):
            put(f"tables/{view.key}.tex", latex.table(view))
    if "json" in chosen:
        put("report.json", report.model_dump_json(indent=1) + "\n")
    note = None if figures else "Figures were not drawn (--no-figures)."
    if "md" in chosen:
        linked = {k: (FIGURE_CAPTIONS[k], f"figures/{k}.png") for k in drawn}
        put("report.md", markdown.page(report, linked))
    if "html" in chosen:
        from fsvla.report.figures import render

        embedded = {k: (FIGURE_CAPTIONS[k], render(f, "png", dpi=110)) for k, f in drawn.items()}
        put("report.html", html.page(report, embedded, records["episodes"], note))
    return written


__all__ = ["DEFAULT_FORMATS", "FIGURE_CAPTIONS", "FORMATS", "check_formats", "make_figures",
           "write_report"]
