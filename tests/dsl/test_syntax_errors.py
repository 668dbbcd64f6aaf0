"""Syntax errors: the catalogue is the test, plus a table of exact first diagnostics."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from fsvla.dsl.diagnostics import Diagnostic
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.parser import MAX_SYNTAX_ERRORS
from fsvla.dsl.syntax_errors import CATALOGUE


def loads(text: str):
    return ScenarioLoader().loads(text, "m.fsv")


def first(text: str) -> Diagnostic:
    result = loads(text)
    assert result.diagnostics, f"no diagnostic for {text!r}"
    assert result.scenario is None
    return result.diagnostics[0]


# ------------------------------------------------------------------ catalogue

CATALOGUE_EXAMPLES = [(kind.code, example) for kind in CATALOGUE for example in kind.examples]


@pytest.mark.parametrize(("code", "example"), CATALOGUE_EXAMPLES,
                         ids=[f"{c}-{i}" for i, (c, _) in enumerate(CATALOGUE_EXAMPLES)])
def test_catalogue_example_gives_its_code_first(code: str, example: str) -> None:
    assert first(example).code == code


def test_catalogue_codes_are_unique_and_documented() -> None:
    codes = [kind.code for kind in CATALOGUE]
    assert len(codes) == len(set(codes))
    assert all(re.fullmatch(r"FSV\d{3}", code) for code in codes)
    assert all(kind.summary and kind.examples for kind in CATALOGUE)


# --------------------------------------------------------- exact diagnostics

# (id, program, code, line, column, message, help or None when not asserted)
SYNTAX_CASES = [
    ("unit-spelled-out", "scenario s\n  horizon 20 sec\n",
     "FSV202", 2, 14, "unknown unit `sec`", "did you mean `s`?"),
    ("unit-no-close-match", "scenario s\n  horizon 20 fortnights\n",
     "FSV202", 2, 14, "unknown unit `fortnights`",
     "known units: `Hz`, `N`, `Nm`, `cm`, `deg`, `g`, `kg`, `m`, `mm`, `ms`, `rad`, `s`"),
    ("unit-plural", "scenario s\n  constrain contact_force(gripper) <= 30 newtons\n",
     "FSV202", 2, 42, "unknown unit `newtons`", "did you mean `N`?"),
    ("unit-did-you-mean", "scenario s\n  object pot: pot(radius=9 cms)\n",
     "FSV202", 2, 28, "unknown unit `cms`", "did you mean `cm`?"),
    ("unit-degs", "scenario s\n  object pot: pot() yaw 30 degs\n",
     "FSV202", 2, 28, "unknown unit `degs`", "did you mean `deg`?"),
    ("unknown-statement", "scenario s\n  objet pot: pot()\n",
     "FSV010", 2, 3, "unknown statement `objet`", "did you mean `object`?"),
    ("unknown-statement-2", "scenario s\n  suite force\n  sute force\n",
     "FSV010", 3, 3, "unknown statement `sute`", "did you mean `suite`?"),
    ("unclosed-paren", "scenario s\n  object pot: pot(radius=9 cm\n",
     "FSV007", 2, 18, "unclosed `(`", "close it with `)` on the same line; a statement never spans lines"),
    ("unclosed-outer-paren", "scenario s\n  success (lifted(pot) or released(pot)\n",
     "FSV007", 2, 11, "unclosed `(`", None),
    ("unclosed-vector", "scenario s\n  object pot: pot() at (1 cm, 2 cm\n",
     "FSV007", 2, 24, "unclosed `(`", None),
    ("unterminated-string", 'scenario s\n  instruction "Lift the pot\n',
     "FSV005", 2, 15, "unterminated string", None),
    ("indent-deeper", "scenario s\n  suite force\n     suite force\n",
     "FSV004", 3, 6, "unexpected indentation", None),
    ("dedent-to-nowhere", "scenario s\n    suite force\n  suite force\n",
     "FSV004", 3, 3, "indentation does not match any enclosing block",
     "indent it like the statements around it (the enclosing blocks use columns 0)"),
    ("not-indented", "scenario s\nsuite force\n",
     "FSV004", 2, 1, "expected an indented block", None),
    ("missing-colon", "scenario s\n  object pot pot()\n",
     "FSV008", 2, 14, "expected `:` after the declared name", None),
    ("trailing-junk", "scenario s\n  suite force extra\n",
     "FSV009", 2, 15, "unexpected `extra` after a complete statement",
     "remove it, or put it on a line of its own"),
    ("trailing-number", "scenario s\n  horizon 20 s 5\n",
     "FSV009", 2, 16, "unexpected `5` after a complete statement", None),
    ("bad-comparator", "scenario s\n  constrain contact_force(gripper) =< 30 N\n",
     "FSV009", 2, 36, "unexpected `=` after a complete statement",
     ("remove it, or put it on a line of its own; here the grammar expects `cost`, `warn`, "
      "`weight`, a comparison (`<=` or `>=`) or the end of the line")),
    ("empty-file", "", "FSV006", 1, 1, "empty scenario file", None),
    ("only-comments", "# nothing here\n\n# at all\n", "FSV006", 1, 1, "empty scenario file", None),
    ("no-scenario-header", "object pot: pot()\n",
     "FSV006", 1, 1, "a scenario file must start with `scenario NAME`", None),
    ("stray-character", "scenario s\n  suite force $\n",
     "FSV001", 2, 15, "unexpected character `$`", None),
    ("non-ascii-name", "scenario s\n  suite forcé\n",
     "FSV001", 2, 13, "unexpected character `é`", None),
    ("nul-in-text", "scenario s\n  suite \x00force\n",
     "FSV001", 2, 9, "unexpected character `U+0000`", None),
    ("incomplete-statement", "scenario s\n  suite\n",
     "FSV011", 2, 8, "incomplete statement", None),
    ("incomplete-placement", "scenario s\n  object pot: pot() at\n",
     "FSV011", 2, 23, "incomplete statement", None),
    ("end-of-file", "scenario s\n", "FSV003", 1, 11, "unexpected end of file", None),
    ("variant-level-colon", "scenario s\n  variants\n    L1 jitter pot 2 cm\n",
     "FSV002", 3, 8, "unexpected `jitter`", None),
    ("abstract-without-scenario", "abstract s\n  suite force\n",
     "FSV002", 1, 10, "unexpected `s`", None),
]


@pytest.mark.parametrize(("program", "code", "line", "column", "message", "help"),
                         [case[1:] for case in SYNTAX_CASES], ids=[case[0] for case in SYNTAX_CASES])
def test_first_syntax_diagnostic(program: str, code: str, line: int, column: int, message: str,
                                 help: str | None) -> None:
    diagnostic = first(program)
    assert (diagnostic.code, diagnostic.span.line, diagnostic.span.column, diagnostic.message) == (
        code, line, column, message)
    assert diagnostic.span.file == "m.fsv"
    assert diagnostic.is_error
    if help is not None:
        assert diagnostic.help == help


def test_unknown_unit_span_covers_the_word() -> None:
    span = first("scenario s\n  horizon 20 sec\n").span
    assert (span.line, span.column, span.end_line, span.end_column) == (2, 14, 2, 17)


def test_unterminated_string_span_runs_to_end_of_line() -> None:
    span = first('scenario s\n  instruction "Lift the pot\n').span
    assert (span.column, span.end_column) == (15, 28)


# ------------------------------------------------------------ file reading

def _load_bytes(tmp_path: Path, data: bytes) -> Diagnostic:
    path = tmp_path / "m.fsv"
    path.write_bytes(data)
    result = ScenarioLoader(display_root=tmp_path).load(path)
    assert result.scenario is None and len(result.diagnostics) == 1
    return result.diagnostics[0]


def test_binary_file_is_not_text(tmp_path: Path) -> None:
    diagnostic = _load_bytes(tmp_path, b"\x7fELF\x02\x01\x01\x00\x00\x00\x00\xff\xfe")
    assert (diagnostic.code, diagnostic.span.line, diagnostic.span.column, diagnostic.message) == (
        "FSV902", 1, 1, "not a text file")
    assert diagnostic.label == "contains NUL bytes"


def test_invalid_utf8_points_at_the_byte(tmp_path: Path) -> None:
    diagnostic = _load_bytes(tmp_path, b"scenario s\n  suite f\xffo\n")
    assert (diagnostic.code, diagnostic.span.line, diagnostic.span.column, diagnostic.message) == (
        "FSV902", 2, 10, "not valid UTF-8 text")


def test_byte_order_mark_is_ignored(tmp_path: Path) -> None:
    path = tmp_path / "m.fsv"
    path.write_bytes(b"\xef\xbb\xbfscenario s\n  suite force $\n")
    diagnostic = ScenarioLoader(display_root=tmp_path).load(path).diagnostics[0]
    assert (diagnostic.code, diagnostic.span.line, diagnostic.span.column) == ("FSV001", 2, 15)


def test_missing_file_and_folder(tmp_path: Path) -> None:
    loader = ScenarioLoader(display_root=tmp_path)
    missing = loader.load(tmp_path / "nope.fsv").diagnostics
    assert [(d.code, d.message, d.span.file) for d in missing] == [("FSV901", "file not found", "nope.fsv")]
    (tmp_path / "dir.fsv").mkdir()
    folder = loader.load(tmp_path / "dir.fsv").diagnostics
    assert [(d.code, d.message) for d in folder] == [("FSV901", "is a folder, not a file")]


# ---------------------------------------------------------- error recovery

def test_independent_syntax_errors_are_all_reported() -> None:
    program = (
        "scenario s\n"
        "  suite force extra\n"  # 2: trailing junk
        "  objet pot: pot()\n"  # 3: unknown statement
        "  horizon 20 sec\n"  # 4: unknown unit
        '  instruction "Lift the pot\n'  # 5: unterminated string
        "  object pot: pot(radius=9 cm\n"  # 6: unclosed parenthesis
        "  success lifted(pot) for 1 s\n"  # 7: fine
        "  object mug mug()\n"  # 8: missing colon
    )
    result = loads(program)
    assert result.scenario is None
    assert [(d.code, d.span.line, d.span.column) for d in result.diagnostics] == [
        ("FSV009", 2, 15), ("FSV010", 3, 3), ("FSV202", 4, 14), ("FSV005", 5, 15),
        ("FSV007", 6, 18), ("FSV008", 8, 14)]


def test_recovery_inside_blocks() -> None:
    program = (
        "scenario s\n"
        "  suite force\n"
        "  variants\n"
        "    L1 jitter pot 2 cm\n"  # 4: missing colon after the level
        "    L2: clutter 2 sec\n"  # 5: unknown unit
        "  language\n"
        "    W1 \"unterminated\n"  # 7: unterminated string
        "  hazard h: heat_zone(radius=5 cm)\n"
        "    keep gripper 3 cm\n"  # 9: missing `outside`
        "  horizon 20 s 5\n"  # 10: trailing junk
    )
    assert [(d.code, d.span.line) for d in loads(program).diagnostics] == [
        ("FSV002", 4), ("FSV202", 5), ("FSV005", 7), ("FSV002", 9), ("FSV009", 10)]


def test_recovery_is_bounded() -> None:
    program = "scenario s\n" + "  suite force extra\n" * (MAX_SYNTAX_ERRORS + 10)
    diagnostics = loads(program).diagnostics
    assert len(diagnostics) == MAX_SYNTAX_ERRORS
    assert [d.span.line for d in diagnostics] == list(range(2, MAX_SYNTAX_ERRORS + 2))


# ---------------------------------------------------- no parser internals

# lark's own terminal names, as lark would print them (`__ANON_3`, `$END`, `_NL`, `RPAR`, ...).
_RAW_NAMES = re.compile(r"__ANON|__anon|\$END|\b_?NL\b|\bRPAR\b|\bLPAR\b|_INDENT|_DEDENT|\bCOLON\b"
                        r"|\bCOMMA\b|\bEQUAL\b|\bUNIT\b|\bCOMPARATOR\b|\bRELATION\b|\bLIMIT_KIND\b"
                        r"|\bSCENARIO\b|\bABSTRACT\b")


_MORE_BROKEN = [
    "scenario s\n  object pot: pot(radius=)\n",
    "scenario s\n  object pot: pot(,)\n",
    "scenario s\n  object : pot()\n",
    "scenario s\n  task lift(pot))\n",
    "scenario s\n  require before lifted(pot)\n",
    "scenario s\n  require grasped(pot) lifted(pot)\n",
    "scenario s\n  success lifted(pot) for\n",
    "scenario s\n  success not\n",
    "scenario s\n  constrain c: contact_force(gripper) <= N\n",
    "scenario s\n  hazard h: heat_zone() left_of\n",
    "scenario s\n  hazard h: heat_zone()\n    keep outside 2 cm\n",
    "scenario s\n  language\n    W1: x\n",
    "scenario s\n  vision\n    V1 lighting()\n",
    "scenario s\n  remove\n",
    "scenario s extends\n  suite force\n",
    "scenario s\n  variants\n",
    "scenario s\n  variants\n    L1: jitter\n",
    "scenario s\n  instruction\n",
    "scenario s\n  suite force\n  )\n",
    "scenario scenario\n",
    "scenario s\n  embodiment 5\n",
]


@pytest.mark.parametrize("program", [c[1] for c in SYNTAX_CASES] + [e for _, e in CATALOGUE_EXAMPLES]
                         + _MORE_BROKEN)
def test_messages_never_show_parser_internals(program: str) -> None:
    diagnostics = loads(program).diagnostics
    assert diagnostics
    for diagnostic in diagnostics:
        for text in (diagnostic.message, diagnostic.label, diagnostic.help or "", *diagnostic.notes):
            assert not _RAW_NAMES.search(text), (program, text)


def test_every_terminal_has_a_readable_description() -> None:
    from fsvla.dsl.parser import build_parser
    from fsvla.dsl.syntax_errors import describe_terminal

    parser = build_parser()
    names = [t.name for t in parser.terminals] + ["_NL", "_INDENT", "_DEDENT", "$END"]
    for name in names:
        described = describe_terminal(name, parser)
        assert described and not _RAW_NAMES.search(described), (name, described)
