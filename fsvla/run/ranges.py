"""Parse the ``fsvla run`` options that name benchmark levels and seeds.

``--levels L0,L2``, ``--language W0-W4``, ``--vision V0-V2,V4``: comma-separated items,
each a level or an inclusive range of levels; case-insensitive; the result is sorted
and free of repeats, so ``L2,L0`` and ``L0,L2`` name the same run. ``--seeds 3`` is a
count (seeds 0, 1, 2); ``--seeds 0-2,7`` lists seeds (a single explicit seed is ``7-7``).
A bad value raises :class:`RangeError`, whose message names the option and the token.
"""

from __future__ import annotations

import re

_LEVEL = re.compile(r"^([A-Za-z])(\d+)$")
_MAX_SEEDS = 10_000


class RangeError(ValueError):
    """An option value that does not parse; ``str()`` is the message for the user."""

    def __init__(self, option: str, text: str, token: str, reason: str) -> None:
        self.option = option
        self.text = text
        self.token = token
        self.reason = reason
        super().__init__(f"{option}: {reason}")


def parse_levels(text: str, option: str = "--levels") -> tuple[str, ...]:
    """``L0,L2`` -> ("L0", "L2"); ``L0-L2`` -> ("L0", "L1", "L2")."""
    return parse_level_range(text, prefix="L", count=3, option=option, example="L0,L2 or L0-L2")


def parse_languages(text: str, option: str = "--language") -> tuple[str, ...]:
    """``W0-W4`` -> ("W0", ..., "W4"); ``W0,W3`` -> ("W0", "W3")."""
    return parse_level_range(text, prefix="W", count=5, option=option, example="W0-W4 or W0,W3")


def parse_visions(text: str, option: str = "--vision") -> tuple[str, ...]:
    """``V0-V2,V4`` -> ("V0", "V1", "V2", "V4")."""
    return parse_level_range(text, prefix="V", count=5, option=option, example="V0-V2,V4")


def parse_level_range(text: str, *, prefix: str, count: int, option: str,
                      example: str) -> tuple[str, ...]:
    """Levels ``<prefix>0`` .. ``<prefix><count-1>`` named by ``text``, sorted, no repeats."""
    if not text.strip():
        raise RangeError(option, text, "", f"expected levels such as {example}, got nothing")
    ranks: set[int] = set()
    for item in text.split(","):
        token = item.strip()
        if not token:
            raise RangeError(option, text, token, f"empty item in {text!r} (e.g. {example})")
        first, dash, last = token.partition("-")
        low = _rank(first, token, prefix, count, option, text, example)
        high = _rank(last, token, prefix, count, option, text, example) if dash else low
        if high < low:
            raise RangeError(option, text, token, f"range {token!r} runs backwards: "
                             f"write {prefix}{high}-{prefix}{low}")
        ranks.update(range(low, high + 1))
    return tuple(f"{prefix}{rank}" for rank in sorted(ranks))


def _rank(part: str, token: str, prefix: str, count: int, option: str, text: str,
          example: str) -> int:
    match = _LEVEL.match(part.strip())
    if match is None or match.group(1).upper() != prefix or int(match.group(2)) >= count:
        shown = part.strip() or token
        raise RangeError(option, text, shown, f"{shown!r} is not one of {prefix}0 to "
                         f"{prefix}{count - 1} (e.g. {example}), in {text!r}")
    return int(match.group(2))


def parse_seeds(text: str, option: str = "--seeds") -> tuple[int, ...]:
    """``3`` -> (0, 1, 2) (a count); ``0-2,7`` -> (0, 1, 2, 7) (explicit seeds, in order)."""
    stripped = text.strip()
    if stripped.isdigit():
        count = int(stripped)
        if not 1 <= count <= _MAX_SEEDS:
            raise RangeError(option, text, stripped, f"a seed count must be 1 to {_MAX_SEEDS}, "
                             f"got {count}")
        return tuple(range(count))
    seeds: list[int] = []
    for item in text.split(","):
        token = item.strip()
        first, dash, last = token.partition("-")
        if not (first.isdigit() and dash and last.isdigit()) and not (
                "," in text and token.isdigit()):
            raise RangeError(option, text, token, f"{token!r} is not a seed or seed range: "
                             f"expected a count such as 3, or seeds such as 0-2,7, in {text!r}")
        low, high = (int(first), int(last)) if dash else (int(token), int(token))
        if high < low:
            raise RangeError(option, text, token, f"range {token!r} runs backwards: "
                             f"write {high}-{low}")
        seeds.extend(range(low, high + 1))
        if len(seeds) > _MAX_SEEDS:
            raise RangeError(option, text, token, f"more than {_MAX_SEEDS} seeds in {text!r}")
    return tuple(dict.fromkeys(seeds))


__all__ = ["RangeError", "parse_languages", "parse_level_range", "parse_levels", "parse_seeds",
           "parse_visions"]
