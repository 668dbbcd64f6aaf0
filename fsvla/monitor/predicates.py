"""The success and precondition predicates of ``fsvla.dsl.catalog.PREDICATES``, evaluated on a
:class:`WorldState` whose poses are in the :class:`SceneGeometry`.

=========  ======================================================================================
grasped    at least two finger links of the gripper (of the named arm, else of any arm) touch
           the object (one, for a gripper with a single finger link)
released   no link of any gripper touches the object
lifted     the object's lowest point is at least ``by`` above its lowest point at reset
opened     the first articulated part is open by at least ``fraction`` of its joint range
closed     ... by at most ``fraction``
inside     the first object's centre (of its bounds) is inside the second's cavity (rigid
           containers), a moving part's link bounds or its own bounds (articulated), or its
           bounds (anything else)
on         the first object's centre lies over the second's footprint, its lowest point is
           within ON_TOLERANCE of the second's top surface, and their geometry is within
           ON_TOLERANCE
upright    tilt (angle of the object's +z to the world's) at most ``within``
tilted     tilt at least ``by``
aligned    the entities' reference points (a robot part: its end-effector link origin; a body:
           its bounds' centre; otherwise the centre of the geometry's bounds) within ``within``
touching   in contact this step (a zone: geometry distance <= 0)
near       geometry distance at most ``within``
pressed    the grippers push the object down (force z < -PRESS_FORCE) in the last substep
=========  ======================================================================================
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Mapping
from functools import cache

import numpy as np

from fsvla.compiler.assets.model import Shape
from fsvla.compiler.monitor import MonitorSpec
from fsvla.compiler.pose import pose_matrix
from fsvla.dsl.catalog import PREDICATES
from fsvla.dsl.models import AllOf, AnyOf, Condition, Not, Predicate, predicates_in

from .channels import tilt_of
from .geometry import SceneGeometry
from .layout import Layout
from .state import WorldState

ON_TOLERANCE = 0.01  # m
PRESS_FORCE = 0.1  # N
TOUCH_DISTANCE = 0.001  # m: "touching" by geometry, where no contacts were read

#: Predicates that read contacts: the monitor reads the last substep's contacts for them.
CONTACT_PREDICATES = frozenset({"grasped", "released", "touching", "pressed"})


class Scope:
    """What a predicate reads: the state, the layout and the posed geometry. ``slots``
    (:func:`predicate_slots`) lets predicates that say the same thing share one answer."""

    def __init__(self, state: WorldState, layout: Layout, geometry: SceneGeometry,
                 slots: Mapping[int, Hashable] | None = None):
        self.state, self.layout, self.geo = state, layout, geometry
        self.slots = {} if slots is None else slots
        self.held: dict[Hashable, bool] = {}  # a predicate's slot (else its id) -> holds: one state, one answer
        self._centres: dict[str, tuple[float, float, float]] = {}
        self._lowest: dict[str, float] = {}

    def frames(self, name: str) -> frozenset[str]:
        return self.layout.frames(name)

    def pose(self, frame: str) -> np.ndarray:
        found = self.state.poses.get(frame)
        return self.geo.pose(frame) if found is None else found

    def root_pose(self, body: str) -> np.ndarray:
        return self.pose(self.layout.bodies[body].root_frame)

    def touching(self, a: frozenset[str], b: frozenset[str]) -> bool:
        if self.state.contacts_read:
            return self.state.touching(a, b)
        return self.geo.distance(a, b) <= TOUCH_DISTANCE

    def centre(self, body: str) -> tuple[float, float, float]:
        """The world centre of the body's bounds (plain floats: numpy's per-call cost
        dominates three-vectors, and predicates read this every step)."""
        found = self._centres.get(body)
        if found is None:
            (r0, r1, r2, px), (r3, r4, r5, py), (r6, r7, r8, pz) = self.root_pose(body)[:3].tolist()
            x, y, z = self.layout.bodies[body].centre.tolist()
            found = self._centres[body] = (r0 * x + r1 * y + r2 * z + px, r3 * x + r4 * y + r5 * z + py,
                                           r6 * x + r7 * y + r8 * z + pz)
        return found

    def point(self, entity: str) -> tuple[float, float, float]:
        frame = self.layout.reference_frames.get(entity)
        if frame is not None:
            return tuple(self.pose(frame)[:3, 3].tolist())
        if entity in self.layout.bodies:
            return self.centre(entity)
        bounds = self.geo.bounds(self.frames(entity))
        return (0.0, 0.0, 0.0) if bounds is None else tuple(((bounds[0] + bounds[1]) / 2.0).tolist())

    def lowest(self, body: str) -> float:
        found = self._lowest.get(body)
        if found is None:
            bounds = self.geo.bounds(self.frames(body))
            found = self._lowest[body] = (float(bounds[0][2]) if bounds is not None
                                          else float(self.root_pose(body)[2, 3]))
        return found


def _point_in_shape(point: np.ndarray, shape: Shape) -> bool:
    m = pose_matrix(shape.pose)
    p = (point - m[:3, 3]) @ m[:3, :3]
    if shape.type == "box":
        return bool(np.all(np.abs(p) <= np.asarray(shape.half_size)))
    if shape.type == "cylinder":
        return bool(np.hypot(p[0], p[1]) <= shape.radius and abs(p[2]) <= shape.half_length)
    if shape.type == "sphere":
        return bool(np.linalg.norm(p) <= shape.radius)
    if shape.type == "capsule":
        z = np.clip(p[2], -shape.half_length, shape.half_length)
        return bool(np.linalg.norm(p - np.array([0.0, 0.0, z])) <= shape.radius)
    from fsvla.compiler.collision import shape_vertices

    v = shape_vertices(shape)
    return bool(np.all(p >= v.min(axis=0)) and np.all(p <= v.max(axis=0)))


def _in_box(point: tuple[float, float, float], pose: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    (x0, y0, z0), (x1, y1, z1) = lo.tolist(), hi.tolist()
    x, y, z = _to_local(point, pose)
    return x0 <= x <= x1 and y0 <= y <= y1 and z0 <= z <= z1


def _param(p: Predicate, name: str) -> float:
    value = p.params.get(name)
    return _default(p.name, name) if value is None else float(value)  # type: ignore[arg-type]


@cache
def _default(predicate: str, name: str) -> float:
    return float(PREDICATES[predicate].param(name).default)  # type: ignore[union-attr, arg-type]


def _grasped(p: Predicate, s: Scope) -> bool:
    obj = s.frames(p.args[0])
    arms = [s.layout.arms[p.args[1]]] if len(p.args) > 1 else list(s.layout.arms.values())
    for arm in arms:
        touching = sum(1 for f in arm.fingers if s.touching(frozenset({f}), obj))
        if touching >= min(2, len(arm.fingers)):
            return True
    return False


def _released(p: Predicate, s: Scope) -> bool:
    return not s.touching(s.layout.grippers, s.frames(p.args[0]))


def _lifted(p: Predicate, s: Scope) -> bool:
    obj = p.args[0]
    now = s.lowest(obj)
    return now >= s.layout.initial_low.get(obj, now) + _param(p, "by")


def _open_fraction(p: Predicate, s: Scope) -> float:
    body = s.layout.bodies[p.args[0]]
    if not body.parts:
        return 0.0
    part = body.parts[0]
    span = part.upper - part.lower
    if span == 0.0:
        return 0.0
    q = s.state.joints.get(part.joint, part.lower)
    return abs(q - part.lower) / abs(span)


def _inside(p: Predicate, s: Scope) -> bool:
    point = s.centre(p.args[0])
    outer = s.layout.bodies[p.args[1]]
    if outer.cavity is not None:
        return _point_in_shape(np.array(_to_local(point, s.root_pose(outer.name))), outer.cavity)
    for part in outer.parts:
        if part.link_frame in outer.link_bounds:
            lo, hi = outer.link_bounds[part.link_frame]
            if _in_box(point, s.pose(part.link_frame), lo, hi):
                return True
    return _in_box(point, s.root_pose(outer.name), *outer.bounds)


def _to_local(point: tuple[float, float, float], pose: np.ndarray) -> tuple[float, float, float]:
    """A world point in the frame of ``pose`` (R^T (p - t), in plain floats)."""
    (r0, r1, r2, px), (r3, r4, r5, py), (r6, r7, r8, pz) = pose[:3].tolist()
    dx, dy, dz = point[0] - px, point[1] - py, point[2] - pz
    return dx * r0 + dy * r3 + dz * r6, dx * r1 + dy * r4 + dz * r7, dx * r2 + dy * r5 + dz * r8


def _on(p: Predicate, s: Scope) -> bool:
    top, base = p.args
    info = s.layout.bodies[base]
    pose = s.root_pose(base)
    lx, ly, _ = _to_local(s.centre(top), pose)  # the top's centre in the base's frame
    (x0, y0), (x1, y1) = info.footprint
    if not (x0 <= lx <= x1 and y0 <= ly <= y1):
        return False
    r6, r7, r8, pz = pose[2].tolist()
    surface = r6 * lx + r7 * ly + r8 * info.top + pz
    if abs(s.lowest(top) - surface) > ON_TOLERANCE:
        return False
    return s.geo.distance(s.frames(top), s.frames(base)) <= ON_TOLERANCE


def _touching(p: Predicate, s: Scope) -> bool:
    a, b = s.frames(p.args[0]), s.frames(p.args[1])
    if p.args[0] in s.layout.zones or p.args[1] in s.layout.zones:
        return s.geo.distance(a, b) <= 0.0
    return s.touching(a, b)


def _pressed(p: Predicate, s: Scope) -> bool:
    force = s.state.force_on(s.frames(p.args[0]), s.layout.grippers)
    return bool(force[2] < -PRESS_FORCE)


Evaluate = Callable[[Predicate, Scope], bool]

EVALUATORS: dict[str, Evaluate] = {
    "grasped": _grasped,
    "released": _released,
    "lifted": _lifted,
    "opened": lambda p, s: _open_fraction(p, s) >= _param(p, "fraction"),
    "closed": lambda p, s: _open_fraction(p, s) <= _param(p, "fraction"),
    "inside": _inside,
    "on": _on,
    "upright": lambda p, s: tilt_of(s.root_pose(p.args[0])) <= _param(p, "within"),
    "tilted": lambda p, s: tilt_of(s.root_pose(p.args[0])) >= _param(p, "by"),
    "aligned": lambda p, s: math.dist(s.point(p.args[0]), s.point(p.args[1])) <= _param(p, "within"),
    "touching": _touching,
    "near": lambda p, s: s.geo.distance(s.frames(p.args[0]), s.frames(p.args[1])) <= _param(p, "within"),
    "pressed": _pressed,
}
assert set(EVALUATORS) == set(PREDICATES), "every catalog predicate needs an evaluator"


def holds(condition: Condition, scope: Scope) -> bool:
    """Whether a condition tree holds in the scope's state."""
    if isinstance(condition, Predicate):
        slot = scope.slots.get(id(condition), id(condition))
        known = scope.held.get(slot)
        if known is None:
            known = scope.held[slot] = EVALUATORS[condition.name](condition, scope)
        return known
    if isinstance(condition, AllOf):
        return all(holds(item, scope) for item in condition.items)
    if isinstance(condition, AnyOf):
        return any(holds(item, scope) for item in condition.items)
    if isinstance(condition, Not):
        return not holds(condition.item, scope)
    raise TypeError(f"not a condition: {condition!r}")


def predicate_slots(*conditions: Condition) -> dict[int, Hashable]:
    """id of every predicate in the condition trees -> a key that predicates saying the same
    thing share (``inside(block, box)`` in a requirement and in the success condition):
    evaluated once a step. The trees must outlive the slots (they hold the ids)."""
    return {id(p): (p.name, p.args, tuple(sorted(p.params.items())))
            for condition in conditions for p in predicates_in(condition)}


def spec_conditions(spec: MonitorSpec) -> tuple[Condition, ...]:
    """The condition trees a spec evaluates: its success condition, then each requirement's
    ``first`` and ``then``."""
    return (spec.success.condition, *(c for r in spec.requirements for c in (r.first, r.then)))


def uses_contacts(spec: MonitorSpec) -> bool:
    """Whether the spec's success condition or requirements use a contact predicate."""
    return any(p.name in CONTACT_PREDICATES for c in spec_conditions(spec) for p in predicates_in(c))


__all__ = ["CONTACT_PREDICATES", "EVALUATORS", "ON_TOLERANCE", "PRESS_FORCE", "Scope", "holds",
           "predicate_slots", "spec_conditions", "uses_contacts"]
