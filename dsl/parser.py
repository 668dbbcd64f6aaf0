"""Text to parse tree: the cached LALR parser and error recovery.

A syntax error ends lark's parse, but an author wants every problem of a file at
once. After each error the parser blanks the offending statement (and the block
indented under it) and parses again, up to a bound; positions are unchanged
because blanked characters become spaces.
"""

from __future__ import annotations

from collections.abc import Iterator
from functools import lru_cache

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedInput
from lark.indenter import Indenter

from ..resources import grammar_path
from .diagnostics import Diagnostic
from .syntax_errors import IndentationFault, diagnose_indentation, diagnose_syntax_error

MAX_SYNTAX_ERRORS = 20


class FsvIndenter(Indenter):
    """Turns leading whitespace into _INDENT/_DEDENT tokens placed on the indented line."""

    NL_type = "_NL"
    OPEN_PAREN_types: list[str] = []
    CLOSE_PAREN_types: list[str] = []
    INDENT_type = "_INDENT"
    DEDENT_type = "_DEDENT"
    tab_len = 8

    def handle_NL(self, token: Token) -> Iterator[Token]:
        yield token
        indent_str = token.rsplit("\n", 1)[1]
        indent = indent_str.count(" ") + indent_str.count("\t") * self.tab_len
        line, column = token.end_line, token.end_column
        if indent > self.indent_level[-1]:
            self.indent_level.append(indent)
            yield _token_at(self.INDENT_type, indent_str, token, line, column)
            return
        while indent < self.indent_level[-1]:
            self.indent_level.pop()
            yield _token_at(self.DEDENT_type, indent_str, token, line, column)
        if indent != self.indent_level[-1]:
            raise IndentationFault(line, column, indent, tuple(self.indent_level))


def _token_at(kind: str, value: str, borrow: Token, line: int, column: int) -> Token:
    token = Token.new_borrow_pos(kind, value, borrow)
    token.line, token.column, token.end_line, token.end_column = line, column, line, column + 1
    return token


@lru_cache(maxsize=1)
def grammar_text() -> str:
    return grammar_path().read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def build_parser() -> Lark:
    """The one LALR parser of the language; built once per process."""
    return Lark(grammar_text(), parser="lalr", postlex=FsvIndenter(),
                propagate_positions=True, maybe_placeholders=True, cache=True)


def parse_tree(text: str, file: str) -> tuple[Tree | None, list[Diagnostic]]:
    """Parse ``text``; returns the tree (None when any syntax error was found) and diagnostics."""
    parser = build_parser()
    diagnostics: list[Diagnostic] = []
    current = text if text.endswith("\n") else text + "\n"
    blanked: set[int] = set()
    for _ in range(MAX_SYNTAX_ERRORS):
        try:
            tree = parser.parse(current)
        except IndentationFault as fault:
            diagnostic = diagnose_indentation(fault, file)
        except UnexpectedInput as error:
            diagnostic = diagnose_syntax_error(error, current, file, parser)
        else:
            return (tree if not diagnostics else None), diagnostics
        line = diagnostic.span.line
        if line in blanked:
            break
        diagnostics.append(diagnostic)
        blanked.add(line)
        recovered = _replace_statement(current, line, blank=diagnostic.code == "FSV004")
        if recovered is None:
            break
        current = recovered
    return None, diagnostics


# A valid line for each kind of block, put in place of a statement with a syntax
# error so that parsing can go on and find the errors after it.
_PLACEHOLDERS = {"variants": "L9: clutter 0", "language": 'W9: ""', "vision": "V9: x()",
                 "hazard": "keep x outside 0"}


def _replace_statement(text: str, line: int, blank: bool = False) -> str | None:
    """Replace line ``line`` with a placeholder statement (or spaces, when ``blank``) and
    blank the lines indented under it.

    Returns None when the line cannot be replaced (it is outside every block).
    """
    lines = text.split("\n")
    index = line - 1
    if not 0 <= index < len(lines):
        return None
    base = _indent_of(lines[index])
    if base == 0 or not lines[index].strip():
        return None
    block = _enclosing_block(lines, index, base)
    lines[index] = " " * base + ("" if blank else _PLACEHOLDERS.get(block, "remove _"))
    for follow in range(index + 1, len(lines)):
        stripped = lines[follow].strip()
        if not stripped or stripped.startswith("#"):
            continue
        if _indent_of(lines[follow]) <= base:
            break
        lines[follow] = " " * len(lines[follow])
    return "\n".join(lines)


def _enclosing_block(lines: list[str], index: int, indent: int) -> str:
    for previous in range(index - 1, -1, -1):
        stripped = lines[previous].strip()
        if stripped and not stripped.startswith("#") and _indent_of(lines[previous]) < indent:
            return stripped.split()[0].rstrip(":")
    return ""


def _indent_of(line: str) -> int:
    return len(line) - len(line.lstrip(" \t"))
