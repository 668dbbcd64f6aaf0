"""Diagnostics: the structured errors and warnings of the language front-end.

Every problem found in a scenario is a :class:`Diagnostic` with a stable code
(documented in docs/language.md), the span it concerns, a message, a label for
the caret, and optionally a help line, notes and related spans ("first defined
here"). Checks collect diagnostics into a :class:`DiagnosticSink` rather than
raising at the first one, so an author sees every problem in one run.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from enum import Enum

from pydantic import BaseModel, ConfigDict, Field

from .spans import Span


class Severity(str, Enum):
    ERROR = "error"
    WARNING = "warning"


class Related(BaseModel):
    """A second place that explains the diagnostic, such as an earlier definition."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    span: Span
    message: str


class Diagnostic(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")

    code: str
    severity: Severity = Severity.ERROR
    message: str
    span: Span
    label: str = ""
    help: str | None = None
    notes: tuple[str, ...] = ()
    related: tuple[Related, ...] = ()

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def sort_key(self) -> tuple[str, int, int, str]:
        return (self.span.file, self.span.line, self.span.column, self.code)


class FsvError(Exception):
    """Raised by the public API when a scenario has errors; carries all of them."""

    def __init__(self, diagnostics: Iterable[Diagnostic]):
        self.diagnostics = tuple(diagnostics)
        first = self.diagnostics[0] if self.diagnostics else None
        summary = f"{first.span}: {first.code} {first.message}" if first else "invalid scenario"
        more = len(self.diagnostics) - 1
        super().__init__(summary + (f" (and {more} more)" if more > 0 else ""))


class DiagnosticSink(BaseModel):
    """Collects diagnostics; stops recording past ``limit`` errors."""

    limit: int = 200
    items: list[Diagnostic] = Field(default_factory=list)
    dropped: int = 0

    def add(self, diagnostic: Diagnostic) -> None:
        if diagnostic in self.items:
            return
        if len(self.items) >= self.limit:
            self.dropped += 1
            return
        self.items.append(diagnostic)

    def error(self, code: str, message: str, span: Span, label: str = "", *,
              help: str | None = None, notes: Iterable[str] = (),
              related: Iterable[Related] = ()) -> None:
        self.add(Diagnostic(code=code, message=message, span=span, label=label, help=help,
                            notes=tuple(notes), related=tuple(related)))

    def warning(self, code: str, message: str, span: Span, label: str = "", *,
                help: str | None = None, notes: Iterable[str] = ()) -> None:
        self.add(Diagnostic(code=code, severity=Severity.WARNING, message=message, span=span,
                            label=label, help=help, notes=tuple(notes)))

    @property
    def has_errors(self) -> bool:
        return any(d.is_error for d in self.items)

    def sorted(self) -> list[Diagnostic]:
        return sorted(self.items, key=Diagnostic.sort_key)


def suggest(word: str, candidates: Iterable[str]) -> str | None:
    """The closest candidate to a misspelt ``word``, or None when nothing is close."""
    matches = difflib.get_close_matches(word, list(candidates), n=1, cutoff=0.6)
    return matches[0] if matches else None


def did_you_mean(word: str, candidates: Iterable[str], what: str = "") -> str | None:
    """A help line: "did you mean `x`?" or, with no close match, the list of choices."""
    candidates = sorted(set(candidates))
    best = suggest(word, candidates)
    if best is not None:
        return f"did you mean `{best}`?"
    if not candidates:
        return None
    listing = ", ".join(f"`{c}`" for c in candidates[:12])
    if len(candidates) > 12:
        listing += f" and {len(candidates) - 12} more"
    return f"known {what or 'names'}: {listing}"
