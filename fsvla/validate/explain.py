"""Why a verdict failed, as diagnostics on the ``.fsv`` line that causes it.

Everything here reads recorded episodes: their rows (quadrant, per-channel minimum
margins and first violation steps), their per-step traces (the hold-still start) and,
for a success condition that never held, a replay's :class:`~.conjuncts.SuccessReplay`.
Nothing here runs the simulator.

A channel's observed value is read back from its margin: ``limit - q`` for an upper
bound (``<=``), ``limit + q`` for a lower bound (``>=``), in the limit's unit; a level's
``tighten`` rules are applied to the limits first, so the value is compared with the
limit the episode ran under.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from fsvla.compiler.variants.errors import quantity
from fsvla.dsl.diagnostics import Diagnostic, Severity
from fsvla.dsl.models import LimitSpec, Scenario, SourceRef

from . import codes
from .conjuncts import SuccessReplay
from .sources import Located, span_text, success_spans
from .verdicts import Verdict


@dataclass(frozen=True)
class Channel:
    """A monitored channel as the scenario states it at one level."""

    name: str
    source: SourceRef
    text: str  # `contact_force(gripper) <= 20 N`, or `require both_hands`
    comparison: str | None = None  # None: a temporal requirement
    metric: str = ""  # contact_force, clearance, ...; "" for a requirement
    limit: float = 0.0
    unit: str = ""
    soft_threshold: float = 0.0

    def value(self, margin: float) -> float:
        """The measured value behind a margin."""
        return self.limit - margin if self.comparison == "<=" else self.limit + margin

    def show(self, value: float) -> str:
        return quantity(round(value, 3) if self.unit == "m" else round(value, 2), self.unit)


def channels_at(scenario: Scenario, level: str) -> dict[str, Channel]:
    """The scenario's channels by trace name, with the level's tightened limits."""
    from fsvla.compiler.variants.generate import rules_of, vary_limits

    varied = vary_limits(scenario, rules_of(scenario, level))  # type: ignore[arg-type]
    found: dict[str, Channel] = {}
    for limit in varied.limits:
        found[limit.name] = Channel(
            name=limit.name, source=limit.source, text=limit_text(limit),
            comparison=limit.comparison, metric=limit.metric, limit=limit.limit, unit=limit.unit,
            soft_threshold=limit.soft_threshold)
    for req in varied.requirements:
        name = req.name if req.name not in found else f"{req.name} (require)"
        found[name] = Channel(name=name, source=req.source, text=f"require {req.name}")
    return found


def channel_text(limit: LimitSpec) -> str:
    """``contact_force(gripper)``, ``clearance(gripper, vase)``."""
    names = (*limit.subjects, *((limit.reference,) if limit.reference else ()))
    return f"{limit.metric}({', '.join(names)})"


def limit_text(limit: LimitSpec) -> str:
    """A limit as it reads: ``contact_force(gripper) <= 20 N``, ``keep gripper, mug outside
    5 cm of stove``, ``untouched(vase)``."""
    shown = quantity(limit.limit, limit.unit)
    if limit.origin == "hazard":
        return f"keep {', '.join(limit.subjects)} outside {shown} of {limit.reference}"
    if limit.metric in ("untouched", "do_not_disturb"):
        return f"{limit.metric}({limit.reference})"
    return f"{channel_text(limit)} {limit.comparison} {shown}"


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


# --- crossed limits (careful expert, holding still) -----------------------------------------


def violation_diagnostics(located: Located, level: str, rows: Sequence[Any], *,
                          code: str, who: str,
                          pressed: Callable[[Any, str], str | None] | None = None
                          ) -> list[Diagnostic]:
    """One diagnostic per channel crossed in ``rows``, on the channel's line, with the worst
    value observed and where; for a crossed ``contact_force`` limit, what ``pressed``
    (given the worst episode's row and the channel's name) says pressed on its subject."""
    channels = channels_at(located.scenario, level)
    crossed: dict[str, list[tuple[Any, Any]]] = {}
    for row in rows:
        for metrics in row.channels or ():
            if metrics.hard_crossed:
                crossed.setdefault(metrics.name, []).append((row, metrics))
    found = []
    for name, hits in crossed.items():
        channel = channels.get(name)
        if channel is None:
            continue
        row, worst = min(hits, key=lambda hit: hit[1].min_margin)
        step = worst.first_violation_step
        where = f"{row.episode_id}" + (f", from step {step}" if step is not None else "")
        if channel.comparison is None:
            message = (f"{who} broke the requirement `{name}` at {level}: its second condition "
                       "began to hold before its first had held")
            label = "broken"
        else:
            observed = channel.show(channel.value(worst.min_margin))
            message = (f"{who} crossed `{name}` at {level}: {observed} observed, against "
                       f"`{channel.text}`")
            label = f"{observed} observed"
        notes = [f"crossed in {len(hits)} of {_plural(len(rows), 'episode')}; worst: {where}"]
        if pressed is not None and channel.metric == "contact_force":
            contact = pressed(row, name)
            if contact is not None:
                notes.append(contact)
        found.append(Diagnostic(code=code, message=message, span=located.span(channel.source),
                                label=label, notes=tuple(notes)))
    return found


# --- faults -----------------------------------------------------------------------------------


def fault_diagnostics(located: Located, level: str, rows: Sequence[Any], *, code: str,
                      who: str) -> list[Diagnostic]:
    """One diagnostic per fault reason among ``rows``: on the line that declares the first
    of the scenario's objects the fault's detail names in backticks (an expert that cannot
    reach a lid's arc names the box), else on the scenario's line."""
    by_reason: dict[str, list[Any]] = {}
    for row in rows:
        if row.status == "faulted":
            by_reason.setdefault(row.failure_reason or "fault", []).append(row)
    found = []
    for reason, faulted in by_reason.items():
        first = faulted[0]
        detail = (first.failure_detail or "").strip().splitlines()
        named = _named_object(located.scenario, detail[0] if detail else "")
        found.append(Diagnostic(
            code=code, message=f"{_plural(len(faulted), 'episode')} of {who} at {level} "
                               f"ended in a fault: {reason}",
            span=located.span(named.source if named is not None else located.scenario.source),
            label=reason,
            notes=(f"{first.episode_id}: {detail[0] if detail else reason}",),
            help="replay it with `fsvla replay` to see where it fails"))
    return found


def _named_object(scenario: Scenario, text: str) -> Any:
    """The first of ``scenario``'s objects ``text`` names in backticks, or None."""
    for name in re.findall(r"`([A-Za-z_][A-Za-z0-9_]*)`", text):
        found = scenario.object(name)
        if found is not None:
            return found
    return None


# --- holding still ----------------------------------------------------------------------------


def start_diagnostics(located: Located, level: str, rows: Sequence[Any],
                      traces: Mapping[str, Mapping[str, Any]]) -> list[Diagnostic]:
    """Why holding still is not safe: channels in their warning band at the first step
    (FSV720), or entering it later (FSV722); crossings and faults have their own codes."""
    channels = channels_at(located.scenario, level)
    at_start: dict[str, tuple[Any, float]] = {}
    later: dict[str, tuple[Any, int, float]] = {}
    for row in rows:
        trace = traces.get(row.episode_id)
        if trace is None or not trace.get("margins"):
            continue
        names = [c["name"] for c in trace["channels"]]
        bands = [c["soft_threshold"] for c in trace["channels"]]
        first = trace["margins"][0]
        for k, name in enumerate(names):
            if 0.0 <= first[k] < bands[k]:
                at_start.setdefault(name, (row, first[k]))
                continue
            step = next((t for t, margins in enumerate(trace["margins"], start=1)
                         if 0.0 <= margins[k] < bands[k]), None)
            if step is not None and name not in at_start:
                later.setdefault(name, (row, step, trace["margins"][step - 1][k]))
    found = []
    for name, (row, margin) in at_start.items():
        channel = channels.get(name)
        if channel is not None:
            found.append(_band(located, level, channel, row, margin, codes.START_WARNING,
                               "at the start"))
    for name, (row, step, margin) in later.items():
        channel = channels.get(name)
        if channel is not None and name not in at_start:
            found.append(_band(located, level, channel, row, margin, codes.HOLD_EXPOSURE,
                               f"from step {step} on, while the robot holds still"))
    return found


def done_at_rest_diagnostics(located: Located, level: str, rows: Sequence[Any]) -> list[Diagnostic]:
    """FSV724 on the ``success`` statement when it held in a hold-still episode: the task
    is done before the robot moves (a `close` of a part that starts shut, an object that
    starts where it must go)."""
    done = [r for r in rows if r.success is True]
    if not done:
        return []
    statement, _spans = success_spans(located)
    return [Diagnostic(
        code=codes.DONE_AT_REST, severity=Severity.ERROR,
        message=f"`success` held at {level} while the robot held still, in "
                f"{len(done)} of {_plural(len(rows), 'episode')}: nothing has to be done to succeed",
        span=statement, label="holds at rest", notes=(f"in {done[0].episode_id} (hold-still)",),
        help="start the scene away from the goal: e.g. `open=0.8` on the part a `close` task "
             "shuts, or the object off the place it must reach")]


def _band(located: Located, level: str, channel: Channel, row: Any, margin: float, code: str,
          when: str) -> Diagnostic:
    if channel.comparison is None:
        message = f"the requirement `{channel.name}` is in its warning band {when} at {level}"
        label = "in its warning band"
    else:
        observed = channel.show(channel.value(margin))
        edge = channel.show(channel.value(channel.soft_threshold))
        side = "below" if channel.comparison == "<=" else "above"
        message = (f"`{channel.name}` is in its warning band {when} at {level}: {observed} "
                   f"observed; safe {side} {edge}")
        label = f"{observed} observed"
    return Diagnostic(code=code, message=message, span=located.span(channel.source), label=label,
                      notes=(f"in {row.episode_id} (hold-still)",),
                      help="move the objects or hazards apart at L0, or narrow the `warn` band, "
                           "so that a robot that does nothing costs nothing")


# --- the careless expert ----------------------------------------------------------------------


def careless_diagnostic(located: Located, verdict: Verdict, rows: Sequence[Any]) -> Diagnostic:
    """The careless expert ends unsafe too rarely: on the scenario's line, with how close it
    came to each limit."""
    channels = channels_at(located.scenario, verdict.level)
    closest: dict[str, float] = {}
    for row in rows:
        for metrics in row.channels or ():
            closest[metrics.name] = min(closest.get(metrics.name, float("inf")), metrics.min_margin)
    notes = []
    for name, margin in sorted(closest.items(), key=lambda item: _depth(channels, *item))[:3]:
        channel = channels.get(name)
        if channel is None or channel.comparison is None:
            continue
        notes.append(f"closest to `{channel.text}`: {channel.show(channel.value(margin))} "
                     f"(margin {channel.show(margin)})")
    return Diagnostic(
        code=codes.NOT_HAZARDOUS,
        message=f"the careless expert ended unsafe in {verdict.count} of "
                f"{_plural(verdict.episodes, 'episode')} at {verdict.level} (needs at least "
                f"{verdict.needed:.0%}): the hazard barely threatens a careless policy",
        span=located.span(located.scenario.source), label="not hazardous enough",
        notes=tuple(notes),
        help="bring the hazard onto the task's path (`approach` it to the object), or tighten "
             "the limits the task presses against")


def _depth(channels: Mapping[str, Channel], name: str, margin: float) -> float:
    channel = channels.get(name)
    band = channel.soft_threshold if channel is not None and channel.soft_threshold > 0 else 1.0
    return margin / band


# --- the success condition --------------------------------------------------------------------


def success_diagnostics(located: Located, level: str, replay: SuccessReplay,
                        failed: int, episodes: int) -> list[Diagnostic]:
    """FSV710 on each conjunct of ``success`` that never held in the replayed episode, or
    FSV711 on the statement when each held but never all together for the hold time."""
    statement, spans = success_spans(located)
    where = (f"in {replay.episode_id}, replayed ({failed} of {_plural(episodes, 'episode')} "
             "failed)")
    found = []
    for track, span in zip(replay.conjuncts, spans):
        if track.held:
            continue
        text = span_text(span, located.sources) or "this condition"
        observed = f": {track.observed}" if track.observed else ""
        found.append(Diagnostic(
            code=codes.NEVER_HELD, severity=Severity.ERROR,
            message=f"the careful expert never made `{text}` hold at {level}{observed}",
            span=span, label="never held", notes=(where,),
            help="check that the task can make it true where the objects are (`fsvla preview`)"))
    if found or not replay.conjuncts:
        return found
    hold = located.scenario.success.hold
    longest = replay.longest_together * replay.control_dt
    return [Diagnostic(
        code=codes.NEVER_TOGETHER,
        message=f"every part of `success` held at some step at {level}, but never all together "
                f"for {hold:g} s (longest {longest:.2f} s)",
        span=statement, label="never held long enough", notes=(where,),
        help="the careful expert may undo one part while doing the next; shorten `for`, or "
             "check the success condition's parts agree")]


__all__ = ["Channel", "careless_diagnostic", "channel_text", "channels_at", "done_at_rest_diagnostics",
           "fault_diagnostics", "limit_text",
           "start_diagnostics", "success_diagnostics", "violation_diagnostics"]
