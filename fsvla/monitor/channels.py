"""The signed margin q_k of each metric (larger is safer; paper §4, Eq. threshold).

:func:`compile_margin` resolves a channel's entities to frames once and returns a
function that measures one quantity m on a :class:`WorldState` (whose poses are already
in the :class:`SceneGeometry`) and turns it into ``q = limit - m`` for an upper bound
(``<=``) or ``q = m - limit`` for a lower bound (``>=``). Units are the LimitSpec's: N,
Nm, m, rad.

=================  ===========================================================================
metric             m
=================  ===========================================================================
contact_force      largest contact force on a subject over the step's substeps, per pair
                   (subject, anything outside the subject); 0 with no contact
contact_torque     the same for the contacts' torque about the subject frame's centre of mass
clearance          smallest signed FCL distance between a subject's and the reference's geometry
zone_distance      the same to a zone's region (a corridor: its walls)
separation         smallest signed distance between the link geometry of the two groups
edge_clearance     smallest distance from a subject's geometry (vertical projection) to the
                   support top's edge, negative where it overhangs
displacement       distance of the body's origin from where it was at reset
tilt               angle between the body's up axis and the world's +z
untouched          robot-to-X distance; at most -TOUCH_DEPTH when they were in contact in any
                   substep of the step
do_not_disturb     robot-to-X distance (inside a zone region or penetrating X: negative)
=================  ===========================================================================

A distance channel (``>=``) reports the step's end, or an incursion into the band (or past
the limit) at a physics substep of the step's interpolated motion (:mod:`.sweep`), so a
pass through a thin zone within one step is seen. Distances are capped at
``MAX_DISTANCE`` (10 m), so margins stay finite, and are exact
while below limit + ε + ``EXACT_BAND``; farther, the monitor reports a lower bound that
is itself beyond that, so every state, cost, exposure and violation is still exact: they
depend on q only where q < ε. ``EXACT_BAND`` is 0: exact FCL queries beyond the warning
band would only refine plotted margins, at most of the monitor's cost (docs/monitor.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from fsvla.compiler.monitor import METRIC_NAMES, ChannelSpec, MonitorSpec

from . import kernels
from .geometry import MAX_DISTANCE, SceneGeometry
from .layout import Layout
from .state import WorldState
from .sweep import swept_distance

#: Depth (m) a contact counts as on an ``untouched`` channel: touching is a violation.
TOUCH_DEPTH = 0.001
#: Distances are exact up to limit + soft threshold + this (m); beyond, a lower bound at least that large.
EXACT_BAND = 0.0

#: m of one channel, given the state and the posed geometry.
Measure = Callable[[WorldState, SceneGeometry], float]
#: Builds a channel's :data:`Measure` from its spec and the scene's layout.
MeasureFactory = Callable[[ChannelSpec, Layout], Measure]


def _contact_force(ch: ChannelSpec, layout: Layout) -> Measure:
    subjects = [layout.frames(s) for s in ch.subjects]
    return lambda state, geo: max(state.max_force(frames) for frames in subjects)


def _contact_torque(ch: ChannelSpec, layout: Layout) -> Measure:
    subjects = [layout.frames(s) for s in ch.subjects]
    return lambda state, geo: max(state.max_torque(frames) for frames in subjects)


def _distance(ch: ChannelSpec, layout: Layout) -> Measure:
    """The distance of the nearest subject to the reference for the control step: at its end,
    or the incursion into the band within it (:mod:`fsvla.monitor.sweep`)."""
    assert ch.reference is not None
    reference = layout.frames(ch.reference)
    subjects = [layout.frames(s) for s in ch.subjects]
    warn = ch.limit + ch.soft_threshold
    exact_below = warn + EXACT_BAND
    ends = [(-1, 0.0)] * len(subjects)  # per subject: (geometry step, distance at its end)

    def measure(state: WorldState, geo: SceneGeometry) -> float:
        best = MAX_DISTANCE
        for i, frames in enumerate(subjects):
            end = geo.distance(frames, reference, exact_below)
            step, before = ends[i]
            ends[i] = (geo.step, end)
            if ch.comparison == ">=":
                end = swept_distance(geo, frames, reference, end, before if step == geo.step - 1 else None,
                                     ch.limit, warn)
            best = min(best, end)
        return best

    return measure


def _edge_clearance(ch: ChannelSpec, layout: Layout) -> Measure:
    support = layout.bodies[ch.support or "table"]
    subjects = [layout.frames(s) for s in ch.subjects]
    (x0, y0), (x1, y1) = support.footprint
    moving = frozenset().union(*subjects, {support.root_frame})
    memo: list[tuple[SceneGeometry, int, float]] = []  # the last answer, while nothing moved

    def measure(state: WorldState, geo: SceneGeometry) -> float:
        version = geo.version(moving)
        if memo and memo[0][0] is geo and memo[0][1] == version:
            return memo[0][2]
        pose = geo.pose(support.root_frame) if geo.has(support.root_frame) else np.eye(4)
        best = MAX_DISTANCE
        for frames in subjects:
            for frame in frames:
                points = geo.local_points(frame)
                if points is not None and len(points):  # in the support's frame, to its footprint's nearest edge
                    best = min(best, kernels.inside_margin(points, geo.pose(frame), pose, x0, y0, x1, y1))
        memo[:] = [(geo, version, best)]
        return best

    return measure


def _root_pose(frame: str, geo: SceneGeometry, state: WorldState) -> np.ndarray:
    found = state.poses.get(frame)
    return geo.pose(frame) if found is None else found


def _displacement(ch: ChannelSpec, layout: Layout) -> Measure:
    roots = [(s, layout.bodies[s].root_frame) for s in ch.subjects]

    def measure(state: WorldState, geo: SceneGeometry) -> float:
        worst = 0.0
        for subject, frame in roots:
            now = _root_pose(frame, geo, state)
            start = layout.initial.get(subject, now)
            worst = max(worst, math.dist(now[:3, 3].tolist(), start[:3, 3].tolist()))
        return worst

    return measure


def tilt_of(pose: np.ndarray) -> float:
    """Angle (rad) between the pose's local +z and the world's +z."""
    return math.acos(max(-1.0, min(1.0, float(pose[2, 2]))))


def _tilt(ch: ChannelSpec, layout: Layout) -> Measure:
    roots = [layout.bodies[s].root_frame for s in ch.subjects]
    return lambda state, geo: max(tilt_of(_root_pose(frame, geo, state)) for frame in roots)


def _untouched(ch: ChannelSpec, layout: Layout) -> Measure:
    assert ch.reference is not None
    reference = layout.frames(ch.reference)
    subjects = [layout.frames(s) for s in ch.subjects]
    distance = _distance(ch, layout)

    def measure(state: WorldState, geo: SceneGeometry) -> float:
        d = distance(state, geo)
        if any(state.touching(frames, reference) for frames in subjects):
            d = min(d, -TOUCH_DEPTH)
        return d

    return measure


DISTANCE_METRICS = frozenset({"clearance", "zone_distance", "separation", "untouched", "do_not_disturb"})


def distance_queries(spec: MonitorSpec, layout: Layout) -> tuple[tuple[frozenset[str], frozenset[str]], ...]:
    """The (subject frames, reference frames) distance queries of a spec's channels, for
    :meth:`SceneGeometry.prefetch`."""
    return tuple((layout.frames(s), layout.frames(ch.reference)) for ch in spec.channels
                 if ch.metric in DISTANCE_METRICS and ch.reference is not None for s in ch.subjects)


MEASURES: dict[str, MeasureFactory] = {
    "contact_force": _contact_force,
    "contact_torque": _contact_torque,
    "clearance": _distance,
    "zone_distance": _distance,
    "separation": _distance,
    "edge_clearance": _edge_clearance,
    "displacement": _displacement,
    "tilt": _tilt,
    "untouched": _untouched,
    "do_not_disturb": _distance,
}
assert set(MEASURES) == set(METRIC_NAMES), "every MonitorSpec metric needs a measure"


def compile_measure(ch: ChannelSpec, layout: Layout) -> Measure:
    """The channel's measured quantity m, as a function of the state and the geometry."""
    return MEASURES[ch.metric](ch, layout)


def compile_margin(ch: ChannelSpec, layout: Layout) -> Measure:
    """The channel's signed margin q: ``limit - m`` for ``<=``, ``m - limit`` for ``>=``."""
    measure, limit = compile_measure(ch, layout), ch.limit
    if ch.comparison == "<=":
        return lambda state, geo: limit - measure(state, geo)
    return lambda state, geo: measure(state, geo) - limit


__all__ = ["DISTANCE_METRICS", "EXACT_BAND", "MEASURES", "TOUCH_DEPTH", "compile_margin", "compile_measure",
           "distance_queries", "tilt_of"]
