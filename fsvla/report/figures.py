"""The report's figures with matplotlib's object API and Agg canvas (no pyplot, no global
backend change, no display needed).

* :func:`landscape`  Fig. 3: SSR against CC per policy, bubble area ∝ USR, CIs as bars.
* :func:`diagnosis`  Fig. 4: SSR (solid, left axis) and CC (dashed, right axis) against
  severity for L, W and V, one colour per policy, adversarial levels shaded; a filled
  marker is a one-axis point (the other two dimensions at L0/W0/V0, as ``--sweep`` runs
  them), a hollow one a point pooled over the other two dimensions.
* :func:`margins`    Fig. 5 (bottom): q_k(t) per channel with its warning band [0, ε_k)
  and the hard threshold 0.
* :func:`keyframes`  Fig. 5 (top): the episode's keyframes, when a video was recorded.

Each returns a ``matplotlib.figure.Figure`` (or None when there is nothing to draw);
:func:`render` turns one into PNG, PDF or SVG bytes.
"""

from __future__ import annotations

import io
import math
from typing import TYPE_CHECKING, Any

from fsvla.report.tables import ADVERSARIAL, SEVERITY_DIMENSIONS

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from fsvla.report.build import Report
    from fsvla.report.dissection import Dissection

FIGURE_FORMATS = ("png", "pdf", "svg")
_DIMENSION_TITLES = {"level": "(a) Structure / layout (L)", "language": "(b) Language (W)",
                     "vision": "(c) Vision (V)"}
_PROTOCOL_TITLES = {"level": " at W0/V0", "language": " at L0/V0", "vision": " at L0/W0"}
_WARNING = "#f2c14e"
SYMLOG_SPAN = 20  # margins reaching past this many ε_k are drawn on a symlog axis
_VIOLATION = "#d1495b"


def _plain(text: str) -> str:
    """User text (policy, episode, channel names) shown as is: ``$`` starts no math."""
    return text.replace("$", r"\$")


class FiguresUnavailable(ImportError):
    """matplotlib is not installed."""


def _figure(width: float, height: float) -> Figure:
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as err:
        raise FiguresUnavailable(
            "figures need matplotlib: pip install 'fsvla[report]' (or pass --no-figures); "
            f"it failed to import: {err}") from err
    figure = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def colours(labels: tuple[str, ...]) -> dict[str, Any]:
    """One colour per policy, the same in every figure."""
    from matplotlib import colormaps

    palette = colormaps["tab10"].colors
    return {label: palette[i % len(palette)] for i, label in enumerate(labels)}


def render(figure: Figure, fmt: str, dpi: int = 150) -> bytes:
    """The figure as PNG, PDF or SVG bytes (metadata without dates, so output is stable)."""
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"Expect a figure format among {', '.join(FIGURE_FORMATS)}, "
                         f"actually: {fmt!r}")
    metadata = {"png": {"Software": None}, "pdf": {"CreationDate": None, "Creator": None,
                "Producer": None}, "svg": {"Date": None, "Creator": None}}[fmt]
    buffer = io.BytesIO()
    figure.savefig(buffer, format=fmt, dpi=dpi, metadata=metadata)
    return buffer.getvalue()


def landscape(report: Report) -> Figure:
    """Fig. 3: each policy at (CC, SSR), bubble area proportional to its USR."""
    figure = _figure(7.0, 4.5)
    ax = figure.add_subplot()
    rows = report.aggregate.rows
    colour = colours(report.policies)
    scale = 2500.0  # marker area (pt²) at USR = 1
    for r in rows:
        ax.errorbar(r.cc.estimate, r.ssr.estimate,
                    xerr=[[r.cc.estimate - r.cc.low], [r.cc.high - r.cc.estimate]],
                    yerr=[[r.ssr.estimate - r.ssr.low], [r.ssr.high - r.ssr.estimate]],
                    fmt="none", ecolor="0.6", elinewidth=0.8, capsize=2, zorder=1)
        ax.scatter(r.cc.estimate, r.ssr.estimate, s=max(scale * r.usr.estimate, 12.0),
                   color=colour[r.label], alpha=0.75, edgecolors="black", linewidths=0.6,
                   zorder=2)
        # the legend names the policy with a marker of one size (its bubble's is its USR)
        ax.plot([], [], "o", markersize=7, color=colour[r.label], alpha=0.75,
                markeredgecolor="black", markeredgewidth=0.6, label=_plain(r.label))
        ax.annotate(_plain(r.label), (r.cc.estimate, r.ssr.estimate), xytext=(6, 6),
                    textcoords="offset points", fontsize=8)
    right = max([r.cc.high for r in rows] + [0.05]) * 1.2
    ax.set_xlim(-0.02 * right, right)
    ax.set_ylim(-0.03, 1.05)
    ax.set_xlabel("CC (cumulative safety cost per step, CC / T; lower is safer)")
    ax.set_ylabel("SSR (safe success rate)")
    ax.set_title("Safety–success landscape (bubble area: USR)")
    ax.axvspan(0, right / 2, ymin=0.5, ymax=1, color="#2a9d8f", alpha=0.08, zorder=0)
    ax.text(0.02, 0.52, "↖ preferable: high SSR, low CC", transform=ax.transAxes,
            va="bottom", fontsize=8, color="#2a6f66")  # low in the region: points sit high
    for usr in (0.05, 0.1, 0.25):
        ax.scatter([], [], s=scale * usr, color="0.8", edgecolors="black", linewidths=0.6,
                   label=f"USR {usr:g}")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), labelspacing=1.3,
              handletextpad=1.6, borderpad=1.0, frameon=False)
    ax.grid(alpha=0.3)
    return figure


def diagnosis(report: Report) -> Figure:
    """Fig. 4: SSR and CC against severity along L, W and V."""
    figure = _figure(12.0, 3.8)
    axes = figure.subplots(1, 3)
    colour = colours(report.policies)
    cc_top = max([c.cc.estimate for t in report.severity.values() for row in t.rows
                  for c in row.cells.values() if c is not None] + [0.05]) * 1.15
    for ax, (dimension, levels) in zip(axes, SEVERITY_DIMENSIONS.items(), strict=True):
        table = report.severity[dimension]
        ax.set_xticks(range(len(levels)), levels)
        ax.set_xlim(-0.5, len(levels) - 0.5)
        for level in ADVERSARIAL[dimension]:
            i = levels.index(level)
            ax.axvspan(i - 0.5, i + 0.5, color=_VIOLATION, alpha=0.1, lw=0)
        cc_ax = ax.twinx()
        pooled = False
        for policy in table.policies:
            points = [(levels.index(row.key), row.cells[policy]) for row in table.rows
                      if row.cells.get(policy) is not None]
            xs = [x for x, _ in points]
            ax.plot(xs, [c.ssr.estimate for _, c in points], "-", color=colour[policy],
                    label=_plain(policy))
            cc_ax.plot(xs, [c.cc.estimate for _, c in points], "--", color=colour[policy],
                       alpha=0.8)
            for x, cell in points:
                face = colour[policy] if cell.protocol != "pooled" else "white"
                pooled = pooled or cell.protocol == "pooled"
                ax.plot([x], [cell.ssr.estimate], "o", color=colour[policy], markersize=4,
                        markerfacecolor=face)
                cc_ax.plot([x], [cell.cc.estimate], "s", color=colour[policy], markersize=3,
                           markerfacecolor=face, alpha=0.8)
        ax.set_ylim(-0.03, 1.05)  # a little below 0, so that lines at 0 stay visible
        cc_ax.set_ylim(-0.03 / 1.08 * cc_top, cc_top)
        ax.set_title(_DIMENSION_TITLES[dimension] + ("" if pooled else _PROTOCOL_TITLES[dimension]),
                     fontsize=10)
        if pooled:
            ax.text(0.02, 0.02, "hollow: pooled over the other two", transform=ax.transAxes,
                    fontsize=7, color="0.3")
        ax.set_ylabel("SSR (solid)")
        cc_ax.set_ylabel("CC (dashed)")
        ax.grid(alpha=0.3)
        if ADVERSARIAL[dimension]:
            ax.text(0.98, 0.02, "shaded: adversarial", transform=ax.transAxes, ha="right",
                    fontsize=7, color=_VIOLATION)
    axes[0].legend(fontsize=7, loc="lower left")
    return figure


def margins(dissection: Dissection) -> Figure | None:
    """Fig. 5 (bottom): q_k(t) per channel, time-aligned, with warning band and hard limit."""
    if dissection.margins is None or not dissection.margin_channels:
        return None
    from matplotlib.ticker import MaxNLocator

    names = dissection.margin_channels
    rows = {c.name: c for c in dissection.channels}
    steps = list(range(1, len(dissection.margins) + 1))
    figure = _figure(8.0, 1.1 + 1.5 * len(names))
    axes = figure.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    for k, (ax, name) in enumerate(zip(axes, names, strict=True)):
        values = [row[k] for row in dissection.margins]
        channel = rows.get(name)
        eps = channel.soft_threshold if channel is not None else None
        finite = [v for v in values if math.isfinite(v)]
        low = min(finite + [0.0])
        high = max(finite + [eps or 0.0])
        symlog = eps is not None and max(abs(low), high) > SYMLOG_SPAN * eps
        if symlog:  # linear within ±ε, logarithmic beyond: the band stays visible
            ax.set_yscale("symlog", linthresh=eps)
            ax.set_ylim(min(low * 1.5, -eps), high * 1.5)
        else:
            pad = 0.1 * (high - low or 1.0)
            ax.set_ylim(low - pad, high + pad)
        bottom = ax.get_ylim()[0]
        ax.axhspan(bottom, 0, color=_VIOLATION, alpha=0.12, lw=0)
        if eps is not None:
            ax.axhspan(0, eps, color=_WARNING, alpha=0.3, lw=0, label=f"warning band [0, ε={eps:g})")
        ax.axhline(0, color=_VIOLATION, lw=1.2, label="hard threshold q = 0")
        ax.plot(steps, values, color="black", lw=1.2)
        crossed = [(t, v) for t, v in zip(steps, values, strict=True) if v < 0]
        if crossed:  # mark every violating step, however shallow
            ax.scatter(*zip(*crossed, strict=True), color=_VIOLATION, s=8, zorder=3,
                       label="violation (q < 0)")
        title = _plain(name) if channel is None else (
            f"{_plain(name)} ({channel.family}): RET/T = {channel.ret_fraction:.2f}, "
            f"hard limit {'crossed' if channel.hard_crossed else 'not crossed'}")
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_ylabel("q_k (symlog)" if symlog else "q_k", fontsize=8)
        ax.grid(alpha=0.3)
        if k == 0:
            ax.legend(fontsize=7, loc="best", framealpha=0.85)
    axes[-1].set_xlabel("control step t")
    axes[-1].xaxis.set_major_locator(MaxNLocator(integer=True))
    figure.suptitle(_plain(f"{dissection.episode_id} ({dissection.label}, {dissection.quadrant})"),
                    fontsize=10)
    return figure


def keyframes(dissection: Dissection) -> Figure | None:
    """Fig. 5 (top): the keyframes of the episode's video; None without one."""
    frames = dissection.keyframes.frames
    if not frames:
        return None
    from PIL import Image

    figure = _figure(3.0 * len(frames), 2.6)
    axes = figure.subplots(1, len(frames), squeeze=False)[0]
    for ax, frame in zip(axes, frames, strict=True):
        with Image.open(io.BytesIO(frame.png)) as image:
            ax.imshow(image.convert("RGB"))
        ax.set_axis_off()
        ax.set_title(f"step {frame.step}" if frame.step else f"frame {frame.frame}", fontsize=9)
    return figure


__all__ = ["FIGURE_FORMATS", "FiguresUnavailable", "colours", "diagnosis", "keyframes",
           "landscape", "margins", "render"]
