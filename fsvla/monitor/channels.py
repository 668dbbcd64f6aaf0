"""The signed margin q_k of each metric (larger is safer; paper §4, Eq. threshold).

Every function measures one quantity m on a :class:`WorldState` (whose poses are
already in the :class:`SceneGeometry`); :func:`margin` turns it into
``q = limit - m`` for an upper bound (``<=``) or ``q = m - limit`` for a lower bound
(``>=``). Units are the LimitSpec's: N, Nm, m, rad.

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

Distances are capped at ``MAX_DISTANCE`` (10 m), so margins stay finite, and are exact
while below limit + ε + ``EXACT_BAND`` (5 cm); farther, the monitor reports a lower bound
that is itself beyond that, so the state (safe) and the cost (0) are still exact.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from fsvla.compiler.monitor import METRIC_NAMES, ChannelSpec, MonitorSpec

from .geometry import MAX_DISTANCE, SceneGeometry
from .layout import Layout
from .state import WorldState

#: Depth (m) a contact counts as on an ``untouched`` channel: touching is a violation.
TOUCH_DEPTH = 0.001
#: Distances are exact up to limit + soft threshold + this (m); beyond, a lower bound at least that large.
EXACT_BAND = 0.05

Measure = Callable[[ChannelSpec, WorldState, Layout, SceneGeometry], float]


def _contact_force(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    return max(state.max_force(layout.frames(s)) for s in ch.subjects)


def _contact_torque(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    return max(state.max_torque(layout.frames(s)) for s in ch.subjects)


def _distance(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    assert ch.reference is not None
    reference = layout.frames(ch.reference)
    exact_below = ch.limit + ch.soft_threshold + EXACT_BAND
    return min(geo.distance(layout.frames(s), reference, exact_below) for s in ch.subjects)


def _edge_clearance(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    support = layout.bodies[ch.support or "table"]
    pose = geo.pose(support.root_frame) if geo.has(support.root_frame) else np.eye(4)
    (x0, y0), (x1, y1) = support.footprint
    best = MAX_DISTANCE
    for subject in ch.subjects:
        points = geo.points(layout.frames(subject))
        if len(points) == 0:
            continue
        local = (points - pose[:3, 3]) @ pose[:3, :3]  # into the support's frame
        inside = np.minimum(np.minimum(local[:, 0] - x0, x1 - local[:, 0]),
                            np.minimum(local[:, 1] - y0, y1 - local[:, 1]))
        best = min(best, float(inside.min()))
    return best


def _root_pose(body: str, layout: Layout, geo: SceneGeometry, state: WorldState) -> np.ndarray:
    frame = layout.bodies[body].root_frame
    if frame in state.poses:
        return state.poses[frame]
    return geo.pose(frame)


def _displacement(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    worst = 0.0
    for subject in ch.subjects:
        now = _root_pose(subject, layout, geo, state)
        start = layout.initial.get(subject, now)
        worst = max(worst, float(np.linalg.norm(now[:3, 3] - start[:3, 3])))
    return worst


def tilt_of(pose: np.ndarray) -> float:
    """Angle (rad) between the pose's local +z and the world's +z."""
    return math.acos(max(-1.0, min(1.0, float(pose[2, 2]))))


def _tilt(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    return max(tilt_of(_root_pose(s, layout, geo, state)) for s in ch.subjects)


def _untouched(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    assert ch.reference is not None
    reference = layout.frames(ch.reference)
    d = _distance(ch, state, layout, geo)
    if any(state.touching(layout.frames(s), reference) for s in ch.subjects):
        d = min(d, -TOUCH_DEPTH)
    return d


DISTANCE_METRICS = frozenset({"clearance", "zone_distance", "separation", "untouched", "do_not_disturb"})


def distance_queries(spec: MonitorSpec, layout: Layout) -> tuple[tuple[frozenset[str], frozenset[str]], ...]:
    """The (subject frames, reference frames) distance queries of a spec's channels, for
    :meth:`SceneGeometry.prefetch`."""
    return tuple((layout.frames(s), layout.frames(ch.reference)) for ch in spec.channels
                 if ch.metric in DISTANCE_METRICS and ch.reference is not None for s in ch.subjects)


MEASURES: dict[str, Measure] = {
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


def measure(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    """The measured quantity m of the channel."""
    return MEASURES[ch.metric](ch, state, layout, geo)


def margin(ch: ChannelSpec, state: WorldState, layout: Layout, geo: SceneGeometry) -> float:
    """The signed margin q: ``limit - m`` for ``<=``, ``m - limit`` for ``>=``."""
    m = measure(ch, state, layout, geo)
    return ch.limit - m if ch.comparison == "<=" else m - ch.limit


__all__ = ["DISTANCE_METRICS", "EXACT_BAND", "MEASURES", "TOUCH_DEPTH", "distance_queries", "margin", "measure", "tilt_of"]
