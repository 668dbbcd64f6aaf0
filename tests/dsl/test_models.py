"""Helpers on the IR models."""

from __future__ import annotations

import pytest
from fsvla.dsl.models import AllOf, AnyOf, Not, Predicate, predicates_in


def test_predicates_in_walks_the_tree_left_to_right():
    a, b, c, d = (Predicate(name=n, args=("x",)) for n in ("grasped", "lifted", "released", "on"))
    tree = AllOf(items=(a, AnyOf(items=(Not(item=b), c)), d))
    assert [p.name for p in predicates_in(tree)] == ["grasped", "lifted", "released", "on"]
    assert list(predicates_in(a)) == [a]


def test_predicates_in_rejects_what_is_not_a_condition():
    with pytest.raises(TypeError, match="not a condition"):
        list(predicates_in("grasped(x)"))  # type: ignore[arg-type]
