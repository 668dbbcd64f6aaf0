"""Syntax errors in the words of the language, not of the parser.

lark reports an unexpected token with the set of terminals it would have
accepted (`__ANON_3`, `$END`, `_NL`, ...). This module turns that into a
diagnostic an author can act on: an unknown unit after a number, an unknown
statement keyword, an unclosed parenthesis, a stray indent. ``CATALOGUE`` lists
every syntax error code with example programs; the tests walk it, so the
catalogue of errors is also their test.
"""

from __future__ import annotations

from dataclasses import dataclass

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from .diagnostics import Diagnostic, did_you_mean
from .spans import Span
from .units import UNITS

STATEMENTS = ("suite", "task", "embodiment", "instruction", "horizon", "object", "hazard",
              "constrain", "watch", "require", "success", "remove", "variants", "language",
              "vision")
_BLOCK_HEADERS = "`scenario`, `hazard`, `variants`, `language` or `vision`"


class IndentationFault(Exception):
    """A line dedented to a column that no enclosing block uses."""

    def __init__(self, line: int, column: int, indent: int, levels: tuple[int, ...]):
        super().__init__(f"line {line}: dedent to column {indent}")
        self.line, self.column, self.indent, self.levels = line, column, indent, levels


@dataclass(frozen=True)
class SyntaxErrorKind:
    code: str
    summary: str
    examples: tuple[str, ...]  # whole programs that raise exactly this code first


CATALOGUE: tuple[SyntaxErrorKind, ...] = (
    SyntaxErrorKind("FSV001", "a character that is not part of the language",
                    ("scenario s\n  suite force $\n",)),
    SyntaxErrorKind("FSV002", "a token where the grammar expects something else",
                    ("scenario s\n  object pot: pot() at 5 cm\n",)),
    SyntaxErrorKind("FSV003", "the file ends in the middle of a construct",
                    ("scenario s\n",)),
    SyntaxErrorKind("FSV004", "indentation that does not match the block structure",
                    ("scenario s\n  suite force\n     suite force\n",
                     "scenario s\nsuite force\n",
                     "scenario s\n    suite force\n  suite force\n")),
    SyntaxErrorKind("FSV005", "a string with no closing quote on its line",
                    ('scenario s\n  instruction "Lift the pot\n',)),
    SyntaxErrorKind("FSV006", "a file that does not start with `scenario NAME`",
                    ("", "# only a comment\n", "object pot: pot()\n")),
    SyntaxErrorKind("FSV007", "a parenthesis left open at the end of its line",
                    ("scenario s\n  object pot: pot(radius=9 cm\n",)),
    SyntaxErrorKind("FSV008", "a missing `:` between a declared name and its definition",
                    ("scenario s\n  object pot pot()\n",)),
    SyntaxErrorKind("FSV009", "more words after a complete statement",
                    ("scenario s\n  suite force extra\n",)),
    SyntaxErrorKind("FSV010", "a line that starts with an unknown statement keyword",
                    ("scenario s\n  objet pot: pot()\n",)),
    SyntaxErrorKind("FSV011", "a statement that ends before it is complete",
                    ("scenario s\n  suite\n", "scenario s\n  object pot: pot() at\n")),
    SyntaxErrorKind("FSV202", "a number followed by a word that is not a unit",
                    ("scenario s\n  horizon 20 sec\n",)),
)

_TERMINAL_WORDS = {
    "NAME": "a name",
    "NUMBER": "a number",
    "STRING": 'a quoted string ("...")',
    "UNIT": "a unit",
    "_NL": "the end of the line",
    "_INDENT": "an indented block",
    "_DEDENT": "the end of the block",
    "$END": "the end of the file",
    "COMPARATOR": "a comparison (`<=` or `>=`)",
    "RELATION": "`left_of`, `right_of`, `in_front_of` or `behind`",
    "LIMIT_KIND": "`constrain` or `watch`",
    "ABSTRACT": "`abstract`",
}


def describe_terminal(name: str, parser: Lark) -> str:
    if name in _TERMINAL_WORDS:
        return _TERMINAL_WORDS[name]
    try:
        pattern = parser.get_terminal(name).pattern
    except KeyError:
        return name.lower()
    if isinstance(pattern, PatternStr):
        return f"`{pattern.value}`"
    return name.lower()


def describe_expected(expected: set[str], parser: Lark, limit: int = 8) -> str:
    words = sorted({describe_terminal(name, parser) for name in expected})
    if len(words) > limit:
        words = words[:limit] + ["..."]
    if len(words) == 1:
        return words[0]
    return ", ".join(words[:-1]) + " or " + words[-1]


def describe_token(token: Token) -> str:
    if token.type == "$END":
        return "the end of the file"
    if token.type == "_NL":
        return "the end of the line"
    if token.type == "_INDENT":
        return "an indented line"
    if token.type == "_DEDENT":
        return "the end of the block"
    return f"`{token.value}`"


def diagnose_indentation(fault: IndentationFault, file: str) -> Diagnostic:
    levels = ", ".join(str(level) for level in fault.levels)
    return Diagnostic(
        code="FSV004", message="indentation does not match any enclosing block",
        span=Span.point(file, fault.line, max(1, fault.column)),
        label=f"this line is indented by {fault.indent} columns",
        help=f"indent it like the statements around it (the enclosing blocks use columns {levels})",
    )


def diagnose_syntax_error(error: UnexpectedInput, text: str, file: str, parser: Lark) -> Diagnostic:
    if isinstance(error, UnexpectedCharacters):
        return _unexpected_character(error, text, file)
    if isinstance(error, UnexpectedToken):
        return _unexpected_token(error, text, file, parser)
    if isinstance(error, UnexpectedEOF):  # only raised by Earley parsers; kept for safety
        return _end_of_file(text, file, "the file ends here")
    line = getattr(error, "line", 1) or 1
    column = getattr(error, "column", 1) or 1
    return Diagnostic(code="FSV002", message="syntax error", span=Span.point(file, line, column))


def _unexpected_character(error: UnexpectedCharacters, text: str, file: str) -> Diagnostic:
    span = Span.point(file, error.line, error.column)
    char = error.char
    if char == '"':
        line_text = text.split("\n")[error.line - 1]
        width = max(1, len(line_text) - error.column + 1)
        return Diagnostic(code="FSV005", message="unterminated string",
                          span=Span.point(file, error.line, error.column, width),
                          label="this string has no closing `\"`",
                          help='close the string on the same line; write a quote inside a string as `\\"`')
    shown = char if char.isprintable() and not char.isspace() else f"U+{ord(char):04X}"
    return Diagnostic(code="FSV001", message=f"unexpected character `{shown}`", span=span,
                      label="not part of the language",
                      help="comments start with `#`; names use letters, digits and `_`")


def _unexpected_token(error: UnexpectedToken, text: str, file: str, parser: Lark) -> Diagnostic:
    token = error.token
    expected = _acceptable(error)
    previous = error.token_history[-1] if error.token_history else None
    if token.type == "$END":
        if not _has_content(text):
            return Diagnostic(code="FSV006", message="empty scenario file",
                              span=Span.point(file, 1, 1), label="nothing to read",
                              help="a scenario file starts with `scenario NAME` and indented statements under it")
        return _end_of_file(text, file, f"expected {describe_expected(expected, parser)}")
    span = _token_span(token, file)
    found = describe_token(token)

    if _is_first_token(text, token) and token.type not in ("SCENARIO", "ABSTRACT"):
        return Diagnostic(code="FSV006", message="a scenario file must start with `scenario NAME`",
                          span=span, label=f"found {found}",
                          help="begin the file with `scenario my_scenario`, then indent its statements")
    if previous is not None and previous.type == "NUMBER" and "UNIT" in expected and token.type == "NAME":
        return Diagnostic(code="FSV202", message=f"unknown unit `{token.value}`", span=span,
                          label="not a unit",
                          help=_unit_help(token.value))
    if token.type == "_INDENT":
        return Diagnostic(code="FSV004", message="unexpected indentation", span=span,
                          label="this line is indented deeper than the statement above",
                          help=f"only the lines under {_BLOCK_HEADERS} are indented")
    if "_INDENT" in expected and len(expected) == 1:
        return Diagnostic(code="FSV004", message="expected an indented block", span=span,
                          label=f"found {found}",
                          help="indent the statements that belong to the line above")
    if token.type == "_NL" and "RPAR" in expected:
        return _unclosed_parenthesis(text, file, token)
    statement_keywords = {name.lower() for name in expected} & set(STATEMENTS)
    if token.type == "NAME" and len(statement_keywords) >= 5:
        return Diagnostic(code="FSV010", message=f"unknown statement `{token.value}`", span=span,
                          label="not a statement",
                          help=did_you_mean(token.value, STATEMENTS, "statements"))
    if expected == {"COLON"} and token.type == "NAME":
        return Diagnostic(code="FSV008", message="expected `:` after the declared name", span=span,
                          label=f"found {found}",
                          help="declare a name as `object NAME: asset(...)` or `hazard NAME: kind(...)`")
    if token.type in ("_NL", "_DEDENT"):
        return Diagnostic(code="FSV011", message="incomplete statement", span=span,
                          label=f"expected {describe_expected(expected, parser)}")
    if "_NL" in expected:
        return Diagnostic(code="FSV009", message=f"unexpected {found} after a complete statement",
                          span=span, label="the statement already ended before this",
                          help=f"remove it, or put it on a line of its own; here the grammar expects "
                               f"{describe_expected(expected, parser)}"
                          if expected - {"_NL"} else "remove it, or put it on a line of its own")
    return Diagnostic(code="FSV002", message=f"unexpected {found}", span=span,
                      label=f"expected {describe_expected(expected, parser)}")


# Units as people write them out, for the "did you mean" of an unknown unit.
_UNIT_WORDS = {"sec": "s", "second": "s", "meter": "m", "metre": "m", "newton": "N", "nm": "Nm",
               "degree": "deg", "radian": "rad", "gram": "g", "kilogram": "kg", "hz": "Hz"}


def _unit_help(word: str) -> str | None:
    singular = word[:-1] if word.endswith("s") and len(word) > 1 else word
    for candidate in (word, singular, word.lower(), singular.lower()):
        if candidate in UNITS and candidate != word:
            return f"did you mean `{candidate}`?"
        if candidate in _UNIT_WORDS:
            return f"did you mean `{_UNIT_WORDS[candidate]}`?"
    return did_you_mean(word, UNITS, "units")


def _acceptable(error: UnexpectedToken) -> set[str]:
    """The terminals the parser could take here (lark's own set may include ones the lexer allowed)."""
    interactive = getattr(error, "interactive_parser", None)
    if interactive is not None:
        try:
            return set(interactive.accepts())
        except Exception:  # noqa: BLE001 - fall back to lark's own set
            pass
    return set(error.expected)


def _is_first_token(text: str, token: Token) -> bool:
    for number, line in enumerate(text.split("\n"), start=1):
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            return token.line == number and token.column == len(line) - len(line.lstrip()) + 1
    return True


def _token_span(token: Token, file: str) -> Span:
    line = token.line or 1
    column = token.column or 1
    if token.type in ("_NL", "_DEDENT", "_INDENT"):
        return Span.point(file, line, column)
    end_column = token.end_column if token.end_line == line and token.end_column else column + 1
    return Span(file=file, line=line, column=column, end_line=line, end_column=max(end_column, column + 1))


def _end_of_file(text: str, file: str, label: str) -> Diagnostic:
    lines = text.rstrip("\n").split("\n")
    line = len(lines)
    return Diagnostic(code="FSV003", message="unexpected end of file",
                      span=Span.point(file, line, len(lines[-1]) + 1), label=label)


def _unclosed_parenthesis(text: str, file: str, token: Token) -> Diagnostic:
    line_text = text.split("\n")[token.line - 1]
    depth_stack: list[int] = []
    in_string = False
    for index, char in enumerate(line_text):
        if char == '"':
            in_string = not in_string
        elif char == "#" and not in_string:
            break
        elif char == "(" and not in_string:
            depth_stack.append(index)
        elif char == ")" and not in_string and depth_stack:
            depth_stack.pop()
    column = (depth_stack[-1] + 1) if depth_stack else token.column
    return Diagnostic(code="FSV007", message="unclosed `(`", span=Span.point(file, token.line, column),
                      label="this parenthesis is never closed",
                      help="close it with `)` on the same line; a statement never spans lines")


def _has_content(text: str) -> bool:
    return any(line.strip() and not line.strip().startswith("#") for line in text.split("\n"))
