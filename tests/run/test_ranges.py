"""The level and seed options of ``fsvla run``: what parses, and the exact errors."""

from __future__ import annotations

import pytest

from fsvla.run import RangeError, parse_languages, parse_levels, parse_seeds, parse_visions

PARSES = [
    (parse_levels, "L0,L1,L2", ("L0", "L1", "L2")),
    (parse_levels, "L2,L0", ("L0", "L2")),
    (parse_levels, "L0-L2", ("L0", "L1", "L2")),
    (parse_levels, " l1 ", ("L1",)),
    (parse_languages, "W0-W4", ("W0", "W1", "W2", "W3", "W4")),
    (parse_languages, "W3,W0,W3", ("W0", "W3")),
    (parse_visions, "V0-V2,V4", ("V0", "V1", "V2", "V4")),
    (parse_visions, "V3-V3", ("V3",)),
    (parse_seeds, "3", (0, 1, 2)),
    (parse_seeds, "0-2,7", (0, 1, 2, 7)),
    (parse_seeds, "5,3,5", (5, 3)),
    (parse_seeds, "7-7", (7,)),
]

# The catalogue of errors: (parser, value, token, message).
ERRORS = [
    (parse_levels, "", "", "--levels: expected levels such as L0,L2 or L0-L2, got nothing"),
    (parse_levels, "L0,,L2", "", "--levels: empty item in 'L0,,L2' (e.g. L0,L2 or L0-L2)"),
    (parse_levels, "L0,L3", "L3",
     "--levels: 'L3' is not one of L0 to L2 (e.g. L0,L2 or L0-L2), in 'L0,L3'"),
    (parse_languages, "W0-W5", "W5",
     "--language: 'W5' is not one of W0 to W4 (e.g. W0-W4 or W0,W3), in 'W0-W5'"),
    (parse_languages, "V0", "V0",
     "--language: 'V0' is not one of W0 to W4 (e.g. W0-W4 or W0,W3), in 'V0'"),
    (parse_languages, "W4-W1", "W4-W1", "--language: range 'W4-W1' runs backwards: write W1-W4"),
    (parse_visions, "V0-", "V0-",
     "--vision: 'V0-' is not one of V0 to V4 (e.g. V0-V2,V4), in 'V0-'"),
    (parse_visions, "V0-V2,Vx", "Vx",
     "--vision: 'Vx' is not one of V0 to V4 (e.g. V0-V2,V4), in 'V0-V2,Vx'"),
    (parse_seeds, "0", "0", "--seeds: a seed count must be 1 to 10000, got 0"),
    (parse_seeds, "a", "a",
     ("--seeds: 'a' is not a seed or seed range: expected a count such as 3, or seeds such as "
     "0-2,7, in 'a'")),
    (parse_seeds, "3-1", "3-1", "--seeds: range '3-1' runs backwards: write 1-3"),
    (parse_seeds, "0-2,-1", "-1",
     ("--seeds: '-1' is not a seed or seed range: expected a count such as 3, or seeds such as "
     "0-2,7, in '0-2,-1'")),
]


@pytest.mark.parametrize(("parse", "text", "expected"), PARSES)
def test_parses(parse, text: str, expected: tuple) -> None:
    assert parse(text) == expected


@pytest.mark.parametrize(("parse", "text", "token", "message"), ERRORS)
def test_errors_name_the_option_and_the_token(parse, text: str, token: str, message: str) -> None:
    with pytest.raises(RangeError) as caught:
        parse(text)
    assert str(caught.value) == message
    assert (caught.value.text, caught.value.token) == (text, token)


def test_option_name_is_the_callers() -> None:
    with pytest.raises(RangeError, match=r"^--language-levels: "):
        parse_languages("W9", option="--language-levels")
