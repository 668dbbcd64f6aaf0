"""Safe initial states where the compiler cannot see them: the robot at its home pose.

The compiler makes every layout start outside the warning bands that the layout decides
(``fsvla.compiler.variants.start``). Robot parts it cannot judge: their geometry is the
URDF's meshes as SAPIEN cooks them, and the compiler never imports SAPIEN. So the env
evaluates the monitor on the scene right after reset — the robot at home, every body
where the layout put it — and :func:`start_error` turns a channel found in its warning
band (or past its hard limit) there into a layout error, FSV604, on the line to change:

- the last rule of the level that moved the object or zone the robot part is measured
  against (an ``approach`` before a ``jitter``), directly or through its anchor or support;
- at L0, or where no rule moved it, the line that places it;
- robot against robot (``separation``: the embodiment places both arms), the ``tighten``
  that made the limit stricter at this level, else the limit's own line.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsvla.compiler.monitor import ChannelSpec
from fsvla.compiler.scene import Level
from fsvla.compiler.variants import Infeasibility, VariantError, describe_rule, rules_of
from fsvla.compiler.variants.errors import quantity
from fsvla.dsl.models import Approach, Jitter, Scenario, SourceRef, Tighten, VariantRule


def start_error(scenario: Scenario, level: Level, seed: int,
                exposures: Sequence[tuple[ChannelSpec, float]]) -> VariantError | None:
    """The error for the channels found in their band at t = 0, or None when there are none
    (``scenario``: the layout's, its ``tighten`` rules applied; ``exposures``: each channel
    with its margin at t = 0, as ``Evaluator.start_exposures`` gives them)."""
    if not exposures:
        return None
    channel, margin = min(exposures, key=lambda e: e[1] / e[0].soft_threshold)
    source, remedies = _blame(scenario, level, channel)
    violated = margin < 0.0
    unit = channel.unit
    state = "past the hard limit" if violated else "inside the warning band"
    others = [c.name for c, _ in exposures if c is not channel]
    return VariantError(Infeasibility(
        code="FSV604", level=level, source=source,
        label="past the hard limit at reset" if violated else "in the warning band at reset",
        message=(f"the {level} layout of '{scenario.name}' (seed {seed}) does not start safe: with the robot at "
                 f"home, '{channel.name}' starts {state} (margin {quantity(margin, unit)}; limit "
                 f"{quantity(channel.limit, unit)}, warn {quantity(channel.soft_threshold, unit)})"),
        notes=(f"also in a band at reset: {', '.join(repr(n) for n in others)}",) if others else (),
        remedies=remedies))


def _blame(scenario: Scenario, level: Level, channel: ChannelSpec) -> tuple[SourceRef, tuple[str, ...]]:
    """Where to point for a channel in its band at reset, and what to change there."""
    rules = rules_of(scenario, level)
    placed = [n for n in (channel.reference, *channel.subjects) if n is not None and _placement(scenario, n)]
    robot = next((n for n in (*channel.subjects, channel.reference) if n is not None and n not in placed), "robot")
    for name in placed:
        movers = [rule for _, rule in rules if _moves(scenario, rule, name)]
        if movers:
            rule = next((r for r in reversed(movers) if isinstance(r, Approach)), movers[-1])
            return rule.source, ((f"change `{describe_rule(rule, scenario)}` so that '{name}' stays farther "
                                 f"from the robot's '{robot}'"),
                                 f"place '{name}' farther from the robot's '{robot}' in the canonical layout")
    if placed:
        name = placed[0]
        return _placement(scenario, name).source, (f"place '{name}' farther from the robot's '{robot}'",)  # type: ignore[union-attr]
    tighten = next((r for _, r in rules if isinstance(r, Tighten) and r.target == channel.name), None)
    if tighten is not None:
        return tighten.source, (f"loosen `{describe_rule(tighten, scenario)}`",)
    return channel.source, ((f"loosen '{channel.name}' or narrow its warning band: the embodiment's home pose "
                            "starts inside it"),)


def _placement(scenario: Scenario, name: str):  # -> ObjectSpec | ZoneSpec | None
    return scenario.object(name) or next((z for z in scenario.zones if z.name == name), None)


def _moves(scenario: Scenario, rule: VariantRule, name: str) -> bool:
    """Whether ``rule`` moves ``name``: itself, or its anchor or support, transitively."""
    target = rule.target if isinstance(rule, Jitter) else rule.hazard if isinstance(rule, Approach) else None
    seen: set[str] = set()
    while name and name not in seen:
        if name == target:
            return True
        seen.add(name)
        spec = _placement(scenario, name)
        if spec is None:
            return False
        relation = spec.placement.relation
        anchor = relation.anchor if relation is not None else None
        if anchor is not None and anchor not in seen and _moves(scenario, rule, anchor):
            return True
        name = spec.placement.support
    return False


__all__ = ["start_error"]
