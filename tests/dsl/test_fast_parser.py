"""The one-pass parser (dsl/lalr.py) must agree with lark's on every text it accepts.

It reuses lark's tables but its own loop; a lark upgrade or a grammar change that it
does not reproduce must show up here, not as a wrong AST in a user's scenario."""

from __future__ import annotations

import pytest
from fsvla.dsl import lalr
from fsvla.dsl.build import build_ast
from fsvla.dsl.parser import parse_tree
from hypothesis import HealthCheck, given, settings

from .test_fuzz import TEXTS, mutated


def _lark(text: str):  # noqa: ANN202
    tree, diagnostics = parse_tree(text, "t.fsv")
    return (None if tree is None else build_ast(tree, "t.fsv")), diagnostics


def _agree(text: str) -> bool:
    """Whether the fast path accepted ``text``; asserts it agrees with lark when it did."""
    text = text if text.endswith("\n") else text + "\n"
    try:
        fast = lalr.parse(text, "t.fsv")
    except lalr.Unparsed:
        return False
    slow, diagnostics = _lark(text)
    assert slow is not None and not diagnostics, "the fast path accepted a text lark rejects"
    assert repr(fast) == repr(slow)
    assert fast == slow
    return True


@pytest.mark.parametrize("index", range(len(TEXTS)))
def test_every_builtin_scenario_takes_the_fast_path_and_agrees(index: int) -> None:
    assert _agree(TEXTS[index])


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def test_mutated_texts_agree_whenever_the_fast_path_accepts(text: str) -> None:
    _agree(text)
