"""Three renderings of diagnostics: full (rustc/ruff style), concise, and JSON."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence

from rich.text import Text

from .diagnostics import Diagnostic, Severity
from .spans import Span

_SEVERITY_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "bold yellow"}


def render_full(diagnostic: Diagnostic, sources: Mapping[str, str]) -> Text:
    """A diagnostic as a header, the source line with a caret under the span, and help."""
    span = diagnostic.span
    gutter = len(str(max([span.line] + [r.span.line for r in diagnostic.related])))
    pad = " " * gutter
    out = Text()
    out.append(diagnostic.severity.value, _SEVERITY_STYLE[diagnostic.severity])
    out.append(f"[{diagnostic.code}]", _SEVERITY_STYLE[diagnostic.severity])
    out.append(f": {diagnostic.message}\n", "bold")
    out.append(f"{pad}--> ", "bold blue")
    out.append(f"{span}\n")
    _snippet(out, span, diagnostic.label, "^", _SEVERITY_STYLE[diagnostic.severity], sources, gutter)
    for related in diagnostic.related:
        if related.span.file != span.file:
            out.append(f"{pad}::: ", "bold blue")
            out.append(f"{related.span}\n")
        _snippet(out, related.span, related.message, "-", "bold blue", sources, gutter)
    for note in diagnostic.notes:
        out.append(f"{pad} = ", "bold blue")
        out.append("note", "bold")
        out.append(f": {note}\n")
    if diagnostic.help:
        out.append("help", "bold cyan")
        out.append(f": {diagnostic.help}\n")
    return out


def _snippet(out: Text, span: Span, label: str, marker: str, style: str,
             sources: Mapping[str, str], gutter: int) -> None:
    lines = sources.get(span.file, "").splitlines()
    pad = " " * gutter
    out.append(f"{pad} |\n", "bold blue")
    if not 1 <= span.line <= len(lines):
        if label:
            out.append(f"{pad} = ", "bold blue")
            out.append(f"{label}\n")
        return
    source_line = _printable(lines[span.line - 1])
    out.append(f"{span.line:>{gutter}} | ", "bold blue")
    out.append(source_line + "\n")
    start = min(max(span.column, 1), len(source_line) + 1)
    end = span.end_column if span.end_line == span.line else len(source_line) + 1
    width = max(1, min(end, len(source_line) + 1) - start)
    out.append(f"{pad} | ", "bold blue")
    out.append(" " * (start - 1) + marker * width + (f" {label}" if label else ""), style)
    out.append("\n")


def _printable(line: str, limit: int = 200) -> str:
    line = line.replace("\t", " ")
    line = "".join(ch if ch.isprintable() else "\N{REPLACEMENT CHARACTER}" for ch in line)
    return line if len(line) <= limit else line[:limit] + "…"


def render_concise(diagnostic: Diagnostic) -> str:
    """``file:line:col: CODE message`` for editors and CI logs."""
    text = f"{diagnostic.span}: {diagnostic.code} {diagnostic.message}"
    if diagnostic.severity is Severity.WARNING:
        text += " (warning)"
    if diagnostic.help:
        text += f" ({diagnostic.help})"
    return text


def render_json(diagnostics: Sequence[Diagnostic]) -> str:
    """Every diagnostic as a JSON object, in a list."""
    return json.dumps([d.model_dump(mode="json") for d in diagnostics], indent=2)


def summary_line(errors: int, warnings: int, files: int) -> str:
    def plural(n: int, word: str) -> str:
        return f"{n} {word}{'' if n == 1 else 's'}"

    if errors == 0 and warnings == 0:
        return f"{plural(files, 'file')} checked: no problems"
    return f"{plural(files, 'file')} checked: {plural(errors, 'error')}, {plural(warnings, 'warning')}"
