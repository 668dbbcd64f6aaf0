"""Where in the ``.fsv`` text a validate diagnostic points.

The IR keeps a :class:`~fsvla.dsl.models.SourceRef` on objects, zones, limits and
requirements; the success condition keeps none, so :func:`success_spans` reads it back
from the syntax tree of the file that states it (the scenario's own, else the nearest
base it extends), one span per top-level conjunct.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from fsvla.dsl import ast
from fsvla.dsl.models import AllOf, Condition, Scenario, SourceRef
from fsvla.dsl.spans import Span


@dataclass(frozen=True)
class Located:
    """A checked scenario with the text of every file it was read from (display path ->
    text), so diagnostics on it can be rendered."""

    path: str  # the display path of its file
    scenario: Scenario
    sources: Mapping[str, str]

    def span(self, source: SourceRef) -> Span:
        """From ``source`` to the end of its line (a comment and trailing blanks left out):
        the statement or clause written there, with its values."""
        lines = self.sources.get(source.file, "").splitlines()
        if not 1 <= source.line <= len(lines):
            return Span.point(source.file, source.line, source.column)
        line = lines[source.line - 1]
        end = line.find("#", source.column - 1)
        text = line[source.column - 1:end if end >= 0 else len(line)].rstrip()
        return Span.point(source.file, source.line, source.column, max(1, len(text)))


def conjuncts(condition: Condition) -> tuple[Condition, ...]:
    """The top-level conjuncts of a condition: ``a and b and c`` -> (a, b, c) however the
    ``and`` nests; anything else is one conjunct."""
    if isinstance(condition, AllOf):
        return tuple(item for part in condition.items for item in conjuncts(part))
    return (condition,)


def _ast_conjuncts(condition: ast.Condition) -> tuple[ast.Condition, ...]:
    if isinstance(condition, ast.AllOf):
        return tuple(item for part in condition.items for item in _ast_conjuncts(part))
    return (condition,)


def success_statement(located: Located) -> ast.SuccessDecl | None:
    """The ``success`` statement the scenario took: its own, else the nearest base's."""
    from fsvla.dsl.build import build_ast
    from fsvla.dsl.parser import parse_tree

    scenario = located.scenario
    for file in (scenario.source.file, *scenario.lineage):
        text = located.sources.get(file)
        if text is None:
            continue
        tree, _ = parse_tree(text, file)
        if tree is None:
            continue
        decl = build_ast(tree, file)
        found = [s for s in decl.statements if isinstance(s, ast.SuccessDecl)]
        if found:
            return found[-1]
    return None


def success_spans(located: Located) -> tuple[Span, tuple[Span, ...]]:
    """The span of the ``success`` statement and one span per top-level conjunct of the
    scenario's success condition (each the statement's span when they cannot be paired)."""
    wanted = conjuncts(located.scenario.success.condition)
    statement = success_statement(located)
    if statement is None:
        whole = located.span(located.scenario.source)
        return whole, (whole,) * len(wanted)
    written = _ast_conjuncts(statement.condition)
    if len(written) != len(wanted):
        return statement.span, (statement.span,) * len(wanted)
    return statement.span, tuple(c.span for c in written)


def span_text(span: Span, sources: Mapping[str, str]) -> str | None:
    """The text a one-line span covers, or None."""
    lines = sources.get(span.file, "").splitlines()
    if span.line != span.end_line or not 1 <= span.line <= len(lines):
        return None
    return lines[span.line - 1][span.column - 1:span.end_column - 1] or None


__all__ = ["Located", "conjuncts", "span_text", "success_spans", "success_statement"]
