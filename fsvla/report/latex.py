"""LaTeX tables (booktabs) from the report's views: every text escaped, every group balanced.

Each table is a ``table`` float with caption and label (``tab:fsvla-<key>``), to
``\\input`` into a paper with ``\\usepackage{booktabs}`` in its preamble. Best values are
``\\textbf``; confidence intervals, where a table has them, follow in ``\\scriptsize``.
"""

from __future__ import annotations

import re

from fsvla.report.views import Cell, TextTable

_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
            "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
            "^": r"\textasciicircum{}", "<": r"\textless{}", ">": r"\textgreater{}",
            "|": r"\textbar{}"}
_UNICODE = {"↑": r"$\uparrow$", "↓": r"$\downarrow$", "—": "---", "–": "--",
            "λ": r"$\lambda$", "ε": r"$\epsilon$", "§": r"\S{}", "→": r"$\rightarrow$",
            "×": r"$\times$", "Σ": r"$\Sigma$", "·": r"$\cdot$", "≈": r"$\approx$"}
_LABEL = re.compile(r"[^A-Za-z0-9-]+")  # what a \label keeps of a table's key
_PATTERN = re.compile("|".join(re.escape(c) for c in [*_SPECIAL, *_UNICODE]))


def escape(text: str) -> str:
    """``text`` as LaTeX source that prints it: specials escaped, a few symbols as math."""
    return _PATTERN.sub(lambda m: _SPECIAL.get(m.group(), _UNICODE.get(m.group(), "")), text)


def _cell(cell: Cell) -> str:
    text = escape(cell.text)
    if cell.best:
        text = rf"\textbf{{{text}}}"
    if cell.ci:
        text += rf" {{\scriptsize {escape(cell.ci)}}}"
    return text


def table(view: TextTable) -> str:
    """One view as a booktabs ``table`` float."""
    width = len(view.header)
    lines = [r"\begin{table}[t]", r"\centering",
             rf"\caption{{{escape(view.caption)}}}",
             rf"\label{{tab:fsvla-{_LABEL.sub('-', view.key)}}}",
             r"\small",
             rf"\begin{{tabular}}{{@{{}}l{'c' * (width - 1)}@{{}}}}", r"\toprule"]
    if view.groups:
        spans, rules, column = [], [], 1
        for label, span in view.groups:
            spans.append(escape(label) if span == 1 else
                         rf"\multicolumn{{{span}}}{{c}}{{{escape(label)}}}")
            if span > 1 or label.strip():
                rules.append(rf"\cmidrule(lr){{{column}-{column + span - 1}}}")
            column += span
        lines += [" & ".join(spans) + r" \\", "".join(rules)]
    lines.append(" & ".join(escape(h) for h in view.header) + r" \\")
    lines.append(r"\midrule")
    for i, row in enumerate(view.rows):
        if i in view.sections:
            if i:
                lines.append(r"\midrule")
            lines.append(rf"\multicolumn{{{width}}}{{@{{}}l}}{{\emph{{{escape(view.sections[i])}}}}} \\")
        lines.append(" & ".join(_cell(c) for c in row) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", r"\end{table}", ""]
    return "\n".join(lines)


__all__ = ["escape", "table"]
