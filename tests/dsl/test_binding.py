"""Task roles and asset parameters are bound by one binder, so they fail the same way."""

from __future__ import annotations

import pytest

from .conftest import BASE


@pytest.mark.parametrize(("old", "new", "message", "first", "again"), [
    ("task lift(pot)", "task lift(object=pot, object=pot)", "role `object` is given twice", 13, 25),
    ("pot(radius=9 cm)", "pot(radius=9 cm, radius=8 cm)", "`radius` is given twice", 19, 32),
])
def test_a_slot_given_twice_points_at_the_first(load_text, old, new, message, first, again) -> None:
    diagnostic = load_text(BASE.replace(old, new)).diagnostics[0]
    assert (diagnostic.code, diagnostic.message, diagnostic.span.column) == ("FSV208", message, again)
    assert [(r.span.column, r.message) for r in diagnostic.related] == [(first, "first given here")]


@pytest.mark.parametrize(("old", "new", "code"), [
    ("task lift(pot)", "task lift(object=pott, object=pot)", "FSV101"),
    ("pot(radius=9 cm)", "pot(radius=90 cm, radius=8 cm)", "FSV204"),
])
def test_a_rejected_value_still_counts_as_given(load_text, old, new, code) -> None:
    assert [d.code for d in load_text(BASE.replace(old, new)).diagnostics] == [code, "FSV208"]


def test_positional_values_fill_roles_and_parameters_in_order(load_text) -> None:
    result = load_text(BASE.replace("task lift(pot)", "task pick_place(pot, target=pot)")
                       .replace("pot(radius=9 cm)", "pot(9 cm, height=10 cm)"))
    assert result.ok, [d.message for d in result.diagnostics]
    assert result.scenario.task.roles == {"object": "pot", "target": "pot"}
    assert result.scenario.objects[1].params["radius"] == pytest.approx(0.09)
