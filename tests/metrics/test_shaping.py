"""Shaping functions g_k on the normalised incursion depth d / ε."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fsvla.dsl.catalog import SHAPINGS as DSL_SHAPINGS
from fsvla.metrics.shaping import SHAPINGS, incursion_depth, shape, soft_cost


def test_names_match_the_language():
    assert SHAPINGS == ("linear", "quadratic", "exponential", "step")
    assert SHAPINGS == DSL_SHAPINGS


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        # x =         0    0.5               1              2
        ("linear", [0.0, 0.5, 1.0, 2.0]),
        ("quadratic", [0.0, 0.25, 1.0, 4.0]),
        ("exponential", [0.0, math.e**0.5 - 1, math.e - 1, math.e**2 - 1]),
        ("step", [0.0, 1.0, 1.0, 1.0]),
    ],
)
def test_values_at_hand_picked_depths(name, expected):
    assert shape(name, [0.0, 0.5, 1.0, 2.0]) == pytest.approx(expected, rel=1e-12, abs=0)


def test_soft_cost_normalises_depth_by_the_soft_threshold():
    # ε = 8 N; margins 10 (safe), 8 (exactly ε: safe), 6 (d=2 -> x=0.25), 0 (x=1), -4 (x=1.5)
    q = [10.0, 8.0, 6.0, 0.0, -4.0]
    assert incursion_depth(q, 8.0).tolist() == [0.0, 0.0, 2.0, 8.0, 12.0]
    assert soft_cost(q, 8.0, "linear").tolist() == [0.0, 0.0, 0.25, 1.0, 1.5]
    assert soft_cost(q, 8.0, "quadratic").tolist() == [0.0, 0.0, 0.0625, 1.0, 2.25]
    assert soft_cost(q, 8.0, "step").tolist() == [0.0, 0.0, 1.0, 1.0, 1.0]


def test_cost_is_unit_free():
    # the same incursion in cm and in m costs the same
    assert soft_cost([1.0], 4.0, "quadratic") == pytest.approx(soft_cost([0.01], 0.04, "quadratic"))


def test_step_is_one_for_any_positive_depth():
    assert shape("step", [1e-300, 5e-324]).tolist() == [1.0, 1.0]


def test_unknown_shaping_is_named():
    with pytest.raises(ValueError, match="unknown shaping 'cubic'; expected one of linear"):
        shape("cubic", [0.0])


def test_negative_depth_and_bad_threshold_are_rejected():
    with pytest.raises(ValueError, match=">= 0"):
        shape("linear", [-0.1])
    with pytest.raises(ValueError, match="positive, actually: 0.0"):
        soft_cost([1.0], 0.0, "linear")


depths = st.floats(min_value=0.0, max_value=50.0, allow_nan=False)


@pytest.mark.parametrize("name", SHAPINGS)
@given(a=depths, b=depths)
def test_monotone_nonnegative_and_zero_at_zero(name, a, b):
    lo, hi = sorted((a, b))
    g_lo, g_hi = shape(name, [lo, hi])
    assert 0.0 <= g_lo <= g_hi
    assert shape(name, [0.0])[0] == 0.0
