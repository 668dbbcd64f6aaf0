"""Safe initial states: what a layout must satisfy at t = 0 for a policy that holds still.

Every channel that the layout alone decides at t = 0 must start *safe*, outside its
warning band (q ≥ ε), so that exposure and cost measure the policy, not the layout:

- a distance an object keeps from an object or a zone (``keep OBJECT outside D warn W``,
  ``clearance(a, b) >= D warn W``): at least D + W, with :data:`START_SLACK` to spare so
  that a body settling under physics does not enter the band (:class:`Keep`);
- the edge clearance of an object (``edge_clearance(mug) >= D warn W``): every point of
  its geometry at least D + W (plus the slack) inside its support's top, measured as the
  monitor measures it (:func:`edge_points`, :func:`edge_margin`);
- channels whose value at rest is known from the scene alone: displacement, tilt and
  contact torque are 0, the contact force on a free rigid body is its weight m·g
  (:func:`static_start_failures`).

Robot parts are not judged here: the compiler has no robot geometry (the runtime reads
it from SAPIEN), so the env checks them at reset (``fsvla.monitor.start``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from fsvla.compiler.assets import ArticulatedAsset, RigidAsset
from fsvla.compiler.assets.geometry import shape_to_trimesh
from fsvla.dsl.models import Approach, Jitter, LimitSpec, Scenario, VariantRule
from numpy.typing import NDArray

from ..scene import Level, SceneSpec
from .errors import Infeasibility, VariantError, cm, describe_rule, quantity
from .layout import Draw, Layout
from .solids import link_frames

if TYPE_CHECKING:
    from .feasibility import Checker, Rejection

#: Room (m) a distance keeps beyond its warning band at t = 0: resting bodies settle by
#: less than a millimetre under physics, and must not settle into the band.
START_SLACK = 0.001
#: Rim points of a round shape for edge clearance: the monitor's sampling (``_POINT_SECTIONS``).
EDGE_SECTIONS = 12
#: The distance metrics whose t = 0 value the layout decides when subject and reference are bodies or zones.
DISTANCE_METRICS = frozenset({"clearance", "zone_distance"})


@dataclass(frozen=True)
class Keep:
    """A distance an object keeps at t = 0: from ``reference`` (an object or a zone), or,
    with no reference, from the edge of its support's top. ``distance`` is the hard limit
    and ``band`` its warning band ε; a pair an ``approach`` brings together with no limit
    on it keeps only ``distance`` 0 (``limit`` None, ``band`` 0): it must not touch."""

    subject: str
    reference: str | None
    distance: float
    limit: LimitSpec | None
    band: float = 0.0

    @property
    def safe(self) -> float:
        """The smallest distance that starts safe."""
        return self.distance + self.band + (START_SLACK if self.band > 0.0 else 0.0)

    def describe(self) -> str:
        """``limit 'stove' (6 cm, warn 4 cm)``."""
        if self.limit is None:
            return "no contact"
        return f"limit '{self.limit.name}' ({cm(self.distance)}, warn {cm(self.band)})"


def keeps_of(scenario: Scenario, approached: Iterable[tuple[str, str]]) -> list[Keep]:
    """The t = 0 distances of ``scenario``'s objects: every ``>=`` clearance or zone
    distance between an object and an object or zone, every edge clearance of an object,
    and "do not touch" for each (hazard, object) pair an ``approach`` brings together."""
    objects = {o.name for o in scenario.objects}
    names = objects | {z.name for z in scenario.zones}
    keeps = [Keep(obj, hazard, 0.0, None) for hazard, obj in sorted(set(approached))]
    for limit in scenario.limits:
        if limit.comparison != ">=":
            continue
        if limit.metric in DISTANCE_METRICS and limit.reference in names:
            keeps += [Keep(s, limit.reference, limit.limit, limit, limit.soft_threshold)
                      for s in limit.subjects if s in objects and s != limit.reference]
        elif limit.metric == "edge_clearance":
            keeps += [Keep(s, None, limit.limit, limit, limit.soft_threshold) for s in limit.subjects if s in objects]
    return keeps


# --- edge clearance --------------------------------------------------------------------------


def edge_points(asset: RigidAsset | ArticulatedAsset) -> NDArray[np.float64]:
    """Points of a body's collision geometry in its own frame (an articulated body with its
    joints at zero): the vertices of its pieces and the rims of round shapes, as the
    monitor samples them for ``edge_clearance``."""
    if isinstance(asset, RigidAsset):
        groups = [(asset.collision, np.eye(4))]
    else:
        frames = link_frames(asset)
        groups = [(link.collision, frames[link.name]) for link in asset.links if link.name in frames]
    points = [np.zeros((0, 3))]
    for shapes, frame in groups:
        for shape in shapes:  # a file mesh's hull: the same extreme points as its vertices
            local = np.asarray(shape_to_trimesh(shape, sections=EDGE_SECTIONS).vertices, dtype=np.float64)
            points.append(local @ frame[:3, :3].T + frame[:3, 3])
    return np.concatenate(points)


def edge_margin(points: NDArray[np.float64], xy: tuple[float, float], yaw: float,
                support_xy: tuple[float, float], support_yaw: float,
                footprint: tuple[tuple[float, float], tuple[float, float]]) -> float:
    """The smallest distance, in the support's x-y frame, from a point of ``points`` (of a
    body at ``xy`` turned by ``yaw``) to the edge of the support's ``footprint`` (its own
    frame): negative where a point overhangs."""
    c, s = math.cos(yaw), math.sin(yaw)
    wx = c * points[:, 0] - s * points[:, 1] + xy[0] - support_xy[0]
    wy = s * points[:, 0] + c * points[:, 1] + xy[1] - support_xy[1]
    c, s = math.cos(support_yaw), math.sin(support_yaw)
    x, y = c * wx + s * wy, -s * wx + c * wy
    (x0, y0), (x1, y1) = footprint
    return float(np.min(np.minimum(np.minimum(x - x0, x1 - x), np.minimum(y - y0, y1 - y)))) if len(x) else math.inf


# --- channels the scene alone decides -------------------------------------------------------


@dataclass(frozen=True)
class StartFailure:
    """A limit that no layout can start outside the warning band of, and why."""

    limit: LimitSpec
    cause: str  # a sentence: what the channel reads at rest against the band
    remedy: str


def static_start_failures(scenario: Scenario, scene: SceneSpec) -> list[StartFailure]:
    """Limits whose value at rest puts every layout in their warning band or past their hard
    limit: a displacement, tilt or contact torque limit below its band (those read 0 at
    rest), a contact force limit on a free rigid body less than its band above the body's
    weight (a body at rest reads m·g, its net contact force)."""
    g = float(np.linalg.norm(scene.physics.gravity))
    bodies = {b.name: b for b in scene.bodies}
    failures = []
    for limit in scenario.limits:
        if limit.comparison != "<=":
            continue
        if limit.metric in ("displacement", "tilt", "contact_torque") and limit.limit < limit.soft_threshold:
            at_rest = "0 Nm" if limit.metric == "contact_torque" else ("0 deg" if limit.metric == "tilt" else "0 cm")
            failures.append(StartFailure(
                limit, f"'{limit.name}' reads {at_rest} at rest, inside its warning band "
                       f"({quantity(limit.limit, limit.unit)}, warn {quantity(limit.soft_threshold, limit.unit)})",
                f"make the warning band of '{limit.name}' narrower than its limit "
                f"({quantity(limit.limit, limit.unit)})"))
        elif limit.metric == "contact_force":
            for subject in limit.subjects:
                body = bodies.get(subject)
                if body is None or body.is_static or not isinstance(body.asset, RigidAsset):
                    continue
                weight = body.asset.mass * g
                if limit.limit - weight < limit.soft_threshold:
                    failures.append(StartFailure(
                        limit, f"'{subject}' bears its weight, {weight:.3g} N, at rest, and '{limit.name}' "
                               f"({quantity(limit.limit, 'N')}, warn {quantity(limit.soft_threshold, 'N')}) "
                               f"is safe only below {limit.limit - limit.soft_threshold:.3g} N",
                        f"raise '{limit.name}' to at least {weight + limit.soft_threshold:.3g} N, or make "
                        f"'{subject}' lighter (now {body.asset.mass:.3g} kg)"))
                    break
    return failures


# --- the generator's safe-start checks -------------------------------------------------------


class SafeStart:
    """The generator's checks and wording for safe starts (mixed into ``Generator``, whose
    attributes these are): limits no layout starts safe with, approaches into a band."""

    scenario: Scenario
    varied: Scenario
    canonical: SceneSpec
    level: Level
    rules: list[tuple[Level, VariantRule]]
    tightened: dict[str, int]
    layout: Layout
    checker: Checker

    def _approach(self, draw: Draw, rule: Approach, index: int, distance: float) -> None: ...
    def _with_anchors(self, *names: str) -> set[str]: ...
    def _static_failure(self, lvl: Level, rule: VariantRule, why: str, label: str,
                        remedies: tuple[str, ...]) -> None: ...

    def start_checks(self) -> None:
        """Limits that no layout starts safe with (their value at rest is in the warning
        band): FSV601 on the ``tighten`` that made it so, else FSV603 on the limit."""
        failures = static_start_failures(self.varied, self.canonical)
        if not failures:
            return
        failure = failures[0]
        tighten = self.tightened.get(failure.limit.name)
        if tighten is not None:
            lvl, rule = self.rules[tighten]
            self._static_failure(lvl, rule, failure.cause, "starts in the warning band",
                                 (f"loosen `{describe_rule(rule, self.scenario)}`", failure.remedy))
        raise VariantError(Infeasibility(
            code="FSV603", level=self.level, source=failure.limit.source, label="starts in the warning band",
            message=f"the canonical layout of '{self.scenario.name}' is infeasible: {failure.cause}",
            remedies=(failure.remedy,)))

    def _static_approach_band(self, lvl: Level, rule: Approach, index: int) -> None:
        """An approach that leaves its pair inside a warning band in every layout: the
        pair's distance after the approach in the canonical layout, plus the most that
        the level's jitters can add, stays short of the safe distance."""
        slack = self._approach_slack(rule)
        for keep in self._approach_keeps(rule):
            after = self.checker.distance(keep, self._approached(rule, index, rule.distance))
            if after + slack >= keep.safe:
                continue
            room = self._approach_room(rule, index)
            jitter = f" (at most {cm(after + slack)} with the jitters)" if slack else ""
            violated = after + slack < keep.distance
            where = "past the hard limit" if violated else "inside the warning band"
            self._static_failure(
                lvl, rule, f"it leaves '{keep.subject}' {cm(after)} from '{keep.reference}'{jitter}, {where} "
                           f"of {keep.describe()}: it must start at least {cm(keep.safe)} away",
                "approach past the hard limit" if violated else "approach into the warning band",
                self._approach_remedies(rule, room))

    def _approach_keeps(self, rule: Approach) -> list[Keep]:
        """The limits on the pair an approach brings together."""
        pair = {rule.hazard, rule.toward}
        return [k for k in self.checker.keeps if k.limit is not None and {k.subject, k.reference} == pair]

    def _approached(self, rule: Approach, index: int, distance: float) -> Draw:
        """The canonical layout with only ``rule`` applied, by ``distance``."""
        draw = Draw()
        self._approach(draw, rule, index, distance)
        return draw

    def _approach_slack(self, rule: Approach) -> float:
        """How much the level's jitters can widen an approached pair's distance (a bound):
        the discs of the jitters that move either (directly, by an anchor or a support),
        how far their turns can carry the pair's geometry, and how much those move the
        approach's own direction."""
        movers = self._with_anchors(rule.hazard, rule.toward)
        frames = self.layout.frames(Draw())
        shift = 0.0
        for _, r in self.rules:
            if not isinstance(r, Jitter) or r.target not in movers:
                continue
            shift += r.distance
            if r.yaw > 0.0:
                t = frames[r.target]
                reach = max(math.hypot(frames[n].x - t.x, frames[n].y - t.y) + self.checker.radius(n)
                            for n in (rule.hazard, rule.toward) if r.target in self._with_anchors(n))
                shift += 2.0 * math.sin(min(r.yaw, math.pi) / 2.0) * reach
        h, o = frames[rule.hazard], frames[rule.toward]
        apart = math.hypot(o.x - h.x, o.y - h.y)
        turn = 2.0 if shift >= apart else min(2.0, 0.5 * math.pi * shift / apart)
        return shift + rule.distance * turn

    def _approach_room(self, rule: Approach, index: int) -> float:
        """The longest approach (to 1 mm) after which the canonical layout starts safe; 0
        when even the canonical layout does not."""
        keeps = self._approach_keeps(rule)

        def safe(distance: float) -> bool:
            draw = self._approached(rule, index, distance)
            return all(self.checker.distance(k, draw) >= k.safe for k in keeps)

        lo, hi = 0.0, rule.distance
        if safe(hi):
            return hi
        if not safe(lo):
            return 0.0
        while hi - lo > 1e-5:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if safe(mid) else (lo, mid)
        up = math.ceil(lo * 1000.0) / 1000.0  # a round number where it is safe
        return up if up <= rule.distance and safe(up) else math.floor(lo * 1000.0) / 1000.0

    def _approach_remedies(self, rule: Approach, room: float) -> tuple[str, ...]:
        place = f"place '{rule.hazard}' farther from '{rule.toward}' in the canonical layout"
        tightened = [self.rules[self.tightened[k.limit.name]][1] for k in self._approach_keeps(rule)
                     if k.limit is not None and k.limit.name in self.tightened]
        loosen = tuple(dict.fromkeys(f"loosen `{describe_rule(r, self.scenario)}`" for r in tightened))
        if room <= 0.0:
            return (place, *loosen)
        return (f"approach '{rule.hazard}' to '{rule.toward}' by at most {cm(room)} (now {cm(rule.distance)})",
                place, *loosen)

    def _keep_of(self, rejection: Rejection) -> Keep | None:
        """The limit's keep a hazard or warning-band rejection is about."""
        if rejection.reason not in ("hazard violated", "warning band") or rejection.limit is None:
            return None
        pair = rejection.entities + (None,) * (2 - len(rejection.entities))
        return next((k for k in self.checker.keeps if k.limit is not None and k.limit.name == rejection.limit
                     and (k.subject, k.reference) == pair), None)

    def start_notes(self, rejection: Rejection, remedies: tuple[str, ...], tighten: int | None
                    ) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Notes and remedies of a canonical layout that starts in a band or past a limit:
        how far the object is, from where it starts safe, and how far to move it."""
        keep = self._keep_of(rejection)
        if keep is None or keep.limit is None:
            return (), remedies
        now = self.checker.distance(keep, Draw())
        what = f"'{keep.reference}'" if keep.reference else "the edge of its support"
        notes = ((f"'{keep.subject}' starts {cm(now)} from {what}; {keep.describe()} (line "
                  f"{keep.limit.source.line}) starts safe from {cm(keep.safe)} on ({cm(START_SLACK)} to spare)"),)
        move = f"move '{keep.subject}' at least {cm(_up(keep.safe - now))} farther from {what}"
        return notes, ((move, *remedies[:1]) if tighten is not None else (move,))


def _up(metres: float) -> float:
    """``metres`` rounded up to the millimetre (a distance to move by, for remedies)."""
    return math.ceil(metres * 1000.0 - 1e-9) / 1000.0


__all__ = ["DISTANCE_METRICS", "EDGE_SECTIONS", "START_SLACK", "Keep", "SafeStart", "StartFailure", "edge_margin",
           "edge_points", "keeps_of", "static_start_failures"]
