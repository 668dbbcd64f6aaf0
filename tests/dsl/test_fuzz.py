"""Fuzzing the front-end: broken input always gives diagnostics inside the text, never an exception."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from fsvla.dsl.diagnostics import Diagnostic
from fsvla.dsl.loader import MAX_FILE_BYTES, LoadResult, ScenarioLoader
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
TEXTS = [p.read_text(encoding="utf-8") for p in sorted(SCENARIOS.rglob("*.fsv"))]
_RAW_NAMES = re.compile(r"__ANON|\$END|\b_NL\b|\bRPAR\b|\bLPAR\b|_INDENT|_DEDENT")

_CHARS = st.one_of(st.sampled_from(list(" \t\n():,=\"#<>-.0123456789abcxyzNm\\\x00é€\u200b\ufeff\r")),
                   st.characters())


@st.composite
def mutated(draw) -> str:
    text = draw(st.sampled_from(TEXTS))
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["delete_token", "duplicate_token", "swap_tokens", "delete_char",
                                     "insert_char", "replace_char", "truncate"]))
        if kind.endswith("token") or kind == "swap_tokens":
            tokens = re.split(r"(\s+)", text)
            words = [i for i, t in enumerate(tokens) if t and not t.isspace()]
            if not words:
                continue
            i = draw(st.sampled_from(words))
            if kind == "delete_token":
                tokens[i] = ""
            elif kind == "duplicate_token":
                tokens[i] = tokens[i] + " " + tokens[i]
            else:
                j = draw(st.sampled_from(words))
                tokens[i], tokens[j] = tokens[j], tokens[i]
            text = "".join(tokens)
        elif kind == "truncate":
            text = text[: draw(st.integers(0, len(text)))]
        else:
            at = draw(st.integers(0, max(0, len(text) - 1)))
            char = draw(_CHARS)
            if kind == "delete_char":
                text = text[:at] + text[at + 1:]
            elif kind == "insert_char":
                text = text[:at] + char + text[at:]
            else:
                text = text[:at] + char + text[at + 1:]
    return text


def check_result(text: str, result: LoadResult) -> None:
    assert isinstance(result, LoadResult)
    line_count = len(text.split("\n"))
    for diagnostic in result.diagnostics:
        assert isinstance(diagnostic, Diagnostic)
        assert 1 <= diagnostic.span.line <= line_count + 1, (diagnostic, line_count)
        assert diagnostic.span.column >= 1
        assert diagnostic.span.end_line >= diagnostic.span.line
        assert re.fullmatch(r"FSV\d{3}", diagnostic.code)
        assert diagnostic.code != "FSV999", diagnostic  # the checker's own internal error
        shown = diagnostic.message + diagnostic.label + (diagnostic.help or "")
        leaked = {m.group(0) for m in _RAW_NAMES.finditer(shown)} - {m.group(0) for m in _RAW_NAMES.finditer(text)}
        assert not leaked, (leaked, diagnostic)  # a parser-internal name the author did not write
    if result.scenario is None and not result.abstract:
        assert result.errors, "no IR and no error to say why"


def _run(text: str) -> None:
    check_result(text, ScenarioLoader().loads(text, "m.fsv"))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def test_mutated_scenarios_give_diagnostics(text: str) -> None:
    _run(text)


@pytest.mark.slow
@settings(max_examples=int(os.environ.get("FSVLA_FUZZ_EXAMPLES", "5000")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def test_mutated_scenarios_give_diagnostics_many(text: str) -> None:
    _run(text)


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=400))
def test_arbitrary_text(text: str) -> None:
    _run(text)


def test_huge_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "huge.fsv"
    path.write_text("scenario s\n" + "  suite force\n" * (2_000_000 // 14), encoding="utf-8")
    assert path.stat().st_size > MAX_FILE_BYTES
    result = ScenarioLoader(display_root=tmp_path).load(path)
    assert [(d.code, d.span.line, d.span.column) for d in result.diagnostics] == [("FSV903", 1, 1)]
    assert result.diagnostics[0].message.startswith("file too large (")


def test_random_bytes_file(tmp_path: Path) -> None:
    import random

    generator = random.Random(1234)
    for index in range(20):
        data = bytes(generator.randrange(256) for _ in range(generator.randrange(1, 4000)))
        path = tmp_path / f"r{index}.fsv"
        path.write_bytes(data)
        result = ScenarioLoader(display_root=tmp_path).load(path)
        assert result.scenario is None
        assert result.diagnostics and result.diagnostics[0].code in ("FSV902", "FSV001", "FSV006")
        check_result(data.decode("utf-8", "replace"), result)


def test_long_lines_and_deep_nesting() -> None:
    _run("scenario s\n  success " + "(" * 5000 + "lifted(pot)" + ")" * 5000 + "\n")
    _run("scenario s\n  success " + " and ".join(["lifted(pot)"] * 3000) + "\n")
    _run("scenario s\n" + "  " * 3000 + "suite force\n")


@pytest.mark.parametrize("escape", [r"\N", r"\x4", r"\u12", r"\q", r"\\", r"\"", "\\\t"])
def test_any_backslash_escape_in_a_string(escape: str) -> None:
    text = f'scenario s\n  instruction "a{escape}b"\n  extends_me_not x\n'
    _run(text)
    _run(f'scenario s extends "x{escape}.fsv"\n  suite force\n')


def test_a_lone_surrogate_in_a_string_gives_a_result() -> None:
    """A str given to loads() may hold a lone surrogate (hypothesis found one in a comment)."""
    text = "#\ud800 " + TEXTS[0]
    _run(text)
    _run(TEXTS[0].replace("pot", "p\ud800t", 1))
