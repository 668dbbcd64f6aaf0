"""Which part of ``success`` a failed episode never achieved, and what happened instead.

A recorded episode stores its success condition's value per step, not its parts. To say
which conjunct never held, :func:`replay_success` replays the episode's recorded actions
in a fresh environment (as ``fsvla replay`` does: the same layout, the same physics, bit
for bit) and, at every control step, evaluates each top-level conjunct of the success
condition on the monitor's own world state and geometry (:mod:`fsvla.monitor.predicates`),
with one measurement per predicate to say what was observed instead:

==============  =================================================================
lifted          the most the object rose above where it started
opened, closed  the most (least) its first moving part opened, as a share of its range
upright         the least it tilted;  tilted: the most
near, touching  the smallest distance between the two
aligned         the smallest distance between their reference points
on, inside      where the object ended, from the other's centre (and whether it
                ended inside it)
grasped, ...    nothing beyond "never held"
==============  =================================================================

Replaying costs one episode's simulation (about a second state-only); ``fsvla validate``
does it for one failed careful-expert episode per scenario and level.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsvla.compiler.variants.errors import cm
from fsvla.dsl.models import Condition, Predicate

from .sources import conjuncts

RAD_TO_DEG = 180.0 / math.pi


@dataclass(frozen=True)
class ConjunctTrack:
    """One top-level conjunct over a replayed episode."""

    condition: Condition
    held: int  # steps at which it held
    observed: str | None  # what was measured instead (see the module doc), or None


@dataclass(frozen=True)
class SuccessReplay:
    """What the success condition's parts did in one episode."""

    episode_id: str
    steps: int
    control_dt: float  # s per control step
    conjuncts: tuple[ConjunctTrack, ...]
    longest_together: int  # the longest run of steps at which the whole condition held


def longest_run(values: Sequence[bool]) -> int:
    """The longest run of consecutive true values."""
    best = run = 0
    for value in values:
        run = run + 1 if value else 0
        best = max(best, run)
    return best


def replay_success(run_dir: Path, episode_id: str) -> SuccessReplay:
    """Replay ``episode_id`` of the run in ``run_dir`` and track its success conjuncts."""
    from .replay import Replay

    replay = Replay(run_dir, episode_id)
    watcher: Watcher | None = None
    for step in replay.steps():
        if watcher is None:
            evaluator = replay.env.monitor.evaluator
            watcher = Watcher(conjuncts(replay.env.monitor_spec.success.condition),
                              evaluator.layout, evaluator.geometry)
        watcher.observe(step.state)
    if watcher is None:
        raise ValueError(f"episode {episode_id} has no recorded step to replay")
    return SuccessReplay(episode_id=episode_id, steps=len(replay.record["actions"]),
                         control_dt=replay.control_dt, conjuncts=watcher.tracks(),
                         longest_together=longest_run(replay.record["success_values"]))


@dataclass
class _Tally:
    held: int = 0
    values: list[float] = field(default_factory=list)
    inside_at_end: bool = False


class Watcher:
    """Evaluates each conjunct on each observed state and keeps its measurements."""

    def __init__(self, parts: Sequence[Condition], layout: Any, geometry: Any) -> None:
        self.parts = tuple(parts)
        self.layout, self.geometry = layout, geometry
        self._tallies = [_Tally() for _ in self.parts]

    def observe(self, state: Any) -> None:
        """Call after the monitor evaluated ``state`` (its geometry is posed for it)."""
        from fsvla.monitor.predicates import Scope, holds

        scope = Scope(state, self.layout, self.geometry)
        for part, tally in zip(self.parts, self._tallies):
            tally.held += holds(part, scope)
            if isinstance(part, Predicate) and part.name in MEASURES:
                tally.values.append(MEASURES[part.name][0](part, scope))
                if part.name == "on" and part.args[1] in self.layout.bodies:
                    inside = Predicate(name="inside", args=part.args)
                    tally.inside_at_end = holds(inside, scope)

    def tracks(self) -> tuple[ConjunctTrack, ...]:
        found = []
        for part, tally in zip(self.parts, self._tallies):
            observed = None
            if isinstance(part, Predicate) and part.name in MEASURES and tally.values:
                observed = MEASURES[part.name][1](part, tally)
            found.append(ConjunctTrack(condition=part, held=tally.held, observed=observed))
        return tuple(found)


# --- the measurements -------------------------------------------------------------------------


def _param(p: Predicate, name: str) -> float:
    from fsvla.dsl.catalog import PREDICATES

    value = p.params.get(name)
    if value is None:
        value = PREDICATES[p.name].param(name).default  # type: ignore[union-attr]
    return float(value)  # type: ignore[arg-type]


def _rise(p: Predicate, s: Any) -> float:
    obj = p.args[0]
    now = s.lowest(obj)
    return now - s.layout.initial_low.get(obj, now)


def _open_fraction(p: Predicate, s: Any) -> float:
    body = s.layout.bodies[p.args[0]]
    if not body.parts or body.parts[0].upper == body.parts[0].lower:
        return 0.0
    part = body.parts[0]
    q = s.state.joints.get(part.joint, part.lower)
    return abs(q - part.lower) / abs(part.upper - part.lower)


def _tilt(p: Predicate, s: Any) -> float:
    from fsvla.monitor.channels import tilt_of

    return float(tilt_of(s.root_pose(p.args[0])))


def _distance(p: Predicate, s: Any) -> float:
    return float(s.geo.distance(s.frames(p.args[0]), s.frames(p.args[1])))


def _points(p: Predicate, s: Any) -> float:
    return math.dist(s.point(p.args[0]), s.point(p.args[1]))


def _offset(p: Predicate, s: Any) -> float:
    """How far the first object's centre is from the second's, across the table."""
    (ax, ay, _), (bx, by, _) = s.centre(p.args[0]), s.centre(p.args[1])
    return math.hypot(ax - bx, ay - by)


def _ended(p: Predicate, tally: _Tally) -> str:
    a, b = p.args
    if p.name == "on" and tally.inside_at_end:
        return f"`{a}` ended inside `{b}`"
    return f"`{a}` ended {cm(round(tally.values[-1], 3))} from the centre of `{b}`, across the table"


Measure = tuple[Callable[[Predicate, Any], float], Callable[[Predicate, _Tally], str]]

MEASURES: dict[str, Measure] = {
    "lifted": (_rise, lambda p, t: f"`{p.args[0]}` rose at most {cm(round(max(t.values), 3))} "
                                   f"(needs {cm(_param(p, 'by'))})"),
    "opened": (_open_fraction, lambda p, t: f"`{p.args[0]}` opened at most {max(t.values):.0%} "
                                            f"of its range (needs {_param(p, 'fraction'):.0%})"),
    "closed": (_open_fraction, lambda p, t: f"`{p.args[0]}` stayed at least {min(t.values):.0%} "
                                            f"open (needs at most {_param(p, 'fraction'):.0%})"),
    "upright": (_tilt, lambda p, t: f"`{p.args[0]}` tilted at least {min(t.values) * RAD_TO_DEG:.0f} "
                                    f"deg throughout (needs within {_param(p, 'within') * RAD_TO_DEG:.0f} deg)"),
    "tilted": (_tilt, lambda p, t: f"`{p.args[0]}` tilted at most {max(t.values) * RAD_TO_DEG:.0f} deg "
                                   f"(needs {_param(p, 'by') * RAD_TO_DEG:.0f} deg)"),
    "near": (_distance, lambda p, t: f"`{p.args[0]}` came no closer to `{p.args[1]}` than "
                                     f"{cm(round(min(t.values), 3))} (needs {cm(_param(p, 'within'))})"),
    "touching": (_distance, lambda p, t: f"`{p.args[0]}` came no closer to `{p.args[1]}` than "
                                         f"{cm(round(min(t.values), 3))}"),
    "aligned": (_points, lambda p, t: f"`{p.args[0]}` and `{p.args[1]}` came no closer than "
                                      f"{cm(round(min(t.values), 3))} (needs {cm(_param(p, 'within'))})"),
    "on": (_offset, _ended),
    "inside": (_offset, _ended),
}


__all__ = ["MEASURES", "ConjunctTrack", "SuccessReplay", "Watcher", "longest_run", "replay_success"]
