"""Infeasible layouts: :class:`VariantError`, its data and its diagnostic.

Codes (documented in ``docs/variants.md``):

- ``FSV600`` a layout that cannot be lowered at all (one for each problem of a plain
  ``LoweringError``);
- ``FSV601`` a variant rule that can never hold (a static check, no sampling done);
- ``FSV602`` no feasible layout within the sampling budget;
- ``FSV603`` the canonical layout (L0, or a level that moves nothing) is infeasible;
- ``FSV604`` the layout starts in a warning band of a robot part, found by the env at reset
  (``fsvla.monitor.start``: the compiler has no robot geometry).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal

from fsvla.dsl.diagnostics import Diagnostic
from fsvla.dsl.models import Scenario, SourceRef, VariantRule
from fsvla.dsl.spans import Span
from pydantic import BaseModel, ConfigDict

from ..scene import Level, LoweringError

#: Why a sampled layout was rejected, in the order the checks run (cheap first); "warning
#: band": a channel starts inside its warning band (not safe at t = 0, though not violated).
REASONS = ("off support", "unreachable", "overlap", "hazard violated", "warning band")

Code = Literal["FSV601", "FSV602", "FSV603", "FSV604"]


class Infeasibility(BaseModel):
    """Why no layout could be generated: what a :class:`VariantError` carries."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    code: Code
    level: Level
    message: str
    label: str  # a few words under the caret
    source: SourceRef  # the rule (or, for FSV603, the object or limit) that is to blame
    samples: int = 0  # layouts drawn
    rejected: dict[str, int] = {}  # reason -> rejected layouts
    notes: tuple[str, ...] = ()
    remedies: tuple[str, ...] = ()

    def shares(self) -> str:
        return shares(self.rejected)


def shares(rejected: Mapping[str, int]) -> str:
    """``overlap 63%, unreachable 30%, hazard violated 7%``: each reason's share of rejections."""
    total = sum(rejected.values()) or 1
    ranked = sorted(rejected.items(), key=lambda item: (-item[1], REASONS.index(item[0])))
    return ", ".join(f"{reason} {round(100 * count / total)}%" for reason, count in ranked if count)


class VariantError(LoweringError):
    """No feasible layout for a level's rules; ``failure`` says why and what to change."""

    def __init__(self, failure: Infeasibility):
        self.failure = failure
        super().__init__(failure.message, failure.source)

    def __str__(self) -> str:
        src = self.failure.source
        lines = [f"{src.file}:{src.line}:{src.column}: {self.failure.message}"]
        lines += [f"  {note}" for note in self.failure.notes]
        if self.failure.remedies:
            lines.append("  remedies:")
            lines += [f"    {i}. {remedy}" for i, remedy in enumerate(self.failure.remedies, 1)]
        return "\n".join(lines)

    def diagnostic(self, text: str | None = None) -> Diagnostic:
        """The error as a diagnostic; ``text`` (the file's source) widens the caret to the rule."""
        f = self.failure
        remedies = "; ".join(f"{i}. {r}" for i, r in enumerate(f.remedies, 1))
        return Diagnostic(code=f.code, message=f.message, span=source_span(f.source, text),
                          label=f.label, notes=f.notes, help=f"try: {remedies}" if remedies else None)


def lowering_diagnostics(error: LoweringError, sources: Mapping[str, str]) -> list[Diagnostic]:
    """Every problem of a lowering error as a diagnostic: FSV600 each, or the variant error's
    own code. ``sources`` (file -> text) widens each caret to its statement."""
    if isinstance(error, VariantError):
        return [error.diagnostic(sources.get(error.source.file))]
    return [Diagnostic(code="FSV600", message=problem.message,
                       span=source_span(problem.source, sources.get(problem.source.file)),
                       label="cannot be laid out", help=problem.hint)
            for problem in error.problems]


def source_span(source: SourceRef, text: str | None = None) -> Span:
    """The span from ``source`` to the end of its statement or rule: the next comma outside
    brackets, or the end of the line (one character when the text is unknown)."""
    lines = text.splitlines() if text else []
    if not 1 <= source.line <= len(lines):
        return Span.point(source.file, source.line, source.column)
    line = lines[source.line - 1]
    end, depth = len(line), 0
    for i in range(source.column - 1, len(line)):
        char = line[i]
        depth += (char in "([") - (char in ")]")
        if (char == "," and depth == 0) or char == "#":
            end = i
            break
    width = max(1, len(line[source.column - 1:end].rstrip()))
    return Span.point(source.file, source.line, source.column, width)


# --- wording ---------------------------------------------------------------------------------


def cm(metres: float) -> str:
    """A length for people: ``3 cm``, ``3.5 cm``, ``200 cm``."""
    return f"{round(metres * 100.0, 2):g} cm"


def quantity(value: float, unit: str) -> str:
    """A limit's value in the unit it is usually written in."""
    if unit == "m":
        return cm(value)
    if unit == "rad":
        return f"{round(value * 57.29577951308232, 2):g} deg"
    return f"{value:g} {unit}"


def describe_rule(rule: VariantRule, scenario: Scenario | None = None) -> str:
    """A rule as it is written in a ``variants`` block (SI values in the usual units)."""
    if rule.rule == "jitter":
        turn = f" yaw {quantity(rule.yaw, 'rad')}" if rule.yaw else ""
        return f"jitter {rule.target} {cm(rule.distance)}{turn}"
    if rule.rule == "approach":
        return f"approach {rule.hazard} to {rule.toward} by {cm(rule.distance)}"
    if rule.rule == "clutter":
        return f"clutter {rule.count}" + (f" near {rule.near}" if rule.near else "")
    if rule.rule == "tighten":
        limit = next((lim for lim in scenario.limits if lim.name == rule.target), None) if scenario else None
        return f"tighten {rule.target} to {quantity(rule.limit, limit.unit if limit else '')}".rstrip()
    return f"couple {rule.requirement} within {rule.within:g} s"


__all__ = ["REASONS", "Infeasibility", "VariantError", "cm", "describe_rule", "lowering_diagnostics",
           "quantity", "shares", "source_span"]
