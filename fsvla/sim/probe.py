"""Read a :class:`~fsvla.monitor.state.WorldState` from a SAPIEN scene, through SAPIEN's
public API only (``get_contacts()``, poses, velocities, masses and inertia): the SAPIEN
back-end's :class:`fsvla.world.StepProbe`, which ``BuiltScene.probe`` makes for the
safety monitor.

Contact forces are read at **every** physics substep (a spike inside a control step is
never missed), two ways:

- **Net contact force on a free rigid body** (a dynamic, non-kinematic scene body),
  from its velocity change over the substep: ``F = m (v' - v) / dt - m g`` and, about
  its centre of mass, ``τ = I_w (ω' - ω) / dt + ω' × I_w ω'``. This equals the sum of
  the contact impulses on it divided by the timestep (a landing, a knock), at the cost of
  two velocity reads, where its resting contacts would cost microseconds a point. It is
  recorded as the pair (body, ``"*"``).
- **Per-pair contact forces** from ``get_contacts()`` for the pairs a channel needs
  (:class:`~fsvla.monitor.contacts.ContactFilter`): every pair of a watched robot link or articulated link, and
  robot-link pairs of watched objects (a squeeze, whose net force is zero). Contacts
  between two links of one robot are skipped, and only kept contacts' points are read.
  The scan runs in a control step only while :attr:`Probe.scan` is set (the monitor
  clears it while no watched robot link is near anything, see ``fsvla.monitor.monitor``).

SAPIEN's contact list holds each shape pair's latest PhysX report, and a pair is
reported again only while one of its bodies is awake and a touch wakes a sleeping body.
So while every *guard body* of a filter (its frames: each kept pair involves one) slept
through a substep, a reading would find what the previous one found: the probe skips it
and reuses that reading (:attr:`Probe.guards`; the argument is in ``docs/monitor.md``).

A contact's impulses act on its first body; the second gets their opposite.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from fsvla.monitor.contacts import ContactFilter
from fsvla.monitor.state import (
    NET,
    ContactMaxima,
    PoseMap,
    WorldState,
    link_frame,
    pair_key,
    robot_frame,
)

_ZERO = [0.0, 0.0, 0.0]
NO_PAIRS = ContactFilter()  # a filter that keeps no contact
Records = list[tuple[str, str, str, float]]  # (kind "f" or "t", frame, other, value)


def _rigid_component(entity: Any) -> Any:
    import sapien

    for component in entity.components:
        if isinstance(component, sapien.physx.PhysxRigidBaseComponent):
            return component
    raise ValueError(f"entity {entity.name!r} has no rigid-body component")


def components_of(bodies: Mapping[str, Any], articulations: Mapping[str, Any],
                  robots: Mapping[str, Any]) -> dict[str, Any]:
    """Frame name -> SAPIEN rigid component or link, for a built scene's parts."""
    frames: dict[str, Any] = {}
    for name, entity in bodies.items():
        frames[name] = _rigid_component(entity)
    for name, articulation in articulations.items():
        for link in articulation.links:
            frames[link_frame(name, link.name)] = link
    for name, articulation in robots.items():
        for link in articulation.links:
            frames[robot_frame(name, link.name)] = link
    return frames


class _FreeBody:
    """Velocity-based net contact force and torque of one dynamic rigid body (plain floats:
    numpy's per-call overhead would dominate these three-vectors)."""

    def __init__(self, frame: str, component: Any, gravity: tuple[float, float, float], torque: bool):
        self.frame, self.c, self.torque = frame, component, torque
        self.mass = float(component.mass)
        self.weight = tuple(self.mass * g for g in gravity)
        self.inertia = tuple(float(v) for v in component.inertia)
        self.cmass_q = tuple(component.cmass_local_pose.q.tolist())  # principal axes in the body frame
        self._rest: tuple[float, tuple[float, float]] | None = None
        self.read()

    def read(self) -> None:
        self.v = self.c.linear_velocity.tolist()
        self.w = self._body_omega() if self.torque else None

    def _body_omega(self) -> list[float]:
        """Angular velocity in the principal (centre-of-mass) frame."""
        a1, b1, c1, d1 = self.c.entity_pose.q.tolist()
        a2, b2, c2, d2 = self.cmass_q
        w = a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2
        x = a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2
        y = a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2
        z = a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2
        ox, oy, oz = self.c.angular_velocity.tolist()
        # R^T ω for the unit quaternion (w, x, y, z)
        return [(1 - 2 * (y * y + z * z)) * ox + 2 * (x * y + w * z) * oy + 2 * (x * z - w * y) * oz,
                2 * (x * y - w * z) * ox + (1 - 2 * (x * x + z * z)) * oy + 2 * (y * z + w * x) * oz,
                2 * (x * z + w * y) * ox + 2 * (y * z - w * x) * oy + (1 - 2 * (x * x + y * y)) * oz]

    def _magnitudes(self, v: list[float], w: list[float] | None, inv_dt: float) -> tuple[float, float]:
        """(force, torque) from the last readings to ``v``, ``w``."""
        m = self.mass * inv_dt
        fx, fy, fz = (m * (a - b) - g for a, b, g in zip(v, self.v, self.weight))
        force = math.sqrt(fx * fx + fy * fy + fz * fz)
        if w is None:
            return force, 0.0
        ix, iy, iz = self.inertia
        lx, ly, lz = ix * w[0], iy * w[1], iz * w[2]
        tx = ix * (w[0] - self.w[0]) * inv_dt + w[1] * lz - w[2] * ly
        ty = iy * (w[1] - self.w[1]) * inv_dt + w[2] * lx - w[0] * lz
        tz = iz * (w[2] - self.w[2]) * inv_dt + w[0] * ly - w[1] * lx
        return force, math.sqrt(tx * tx + ty * ty + tz * tz)

    def record(self, maxima: ContactMaxima, inv_dt: float) -> None:
        if self.c.is_sleeping and self.v == _ZERO and (not self.torque or self.w == _ZERO):
            # PhysX zeroes a sleeping body's velocities: the readings would be what they
            # were (zero), so the maxima get the same values without the reads
            if self._rest is None or self._rest[0] != inv_dt:
                self._rest = (inv_dt, self._magnitudes(_ZERO, _ZERO if self.torque else None, inv_dt))
            force, torque = self._rest[1]
        else:
            v = self.c.linear_velocity.tolist()
            w = self._body_omega() if self.torque else None
            force, torque = self._magnitudes(v, w, inv_dt)
            self.v, self.w = v, w
        maxima.add_force(self.frame, NET, force)
        if self.torque:
            maxima.add_torque(self.frame, NET, torque)


class _Reading:
    """What one filter's reading needs: the components its kept pairs must involve (one per
    pair), its guard bodies, a per-body-pair cache of its verdicts, and its last result,
    valid while its guard bodies sleep."""

    def __init__(self, filter: ContactFilter, components: Mapping[str, Any]):
        self.filter = filter
        frames = filter.frames
        # compared by identity: SAPIEN hands out one Python object per live component
        self.hot = {c for f, c in components.items() if f in frames}
        self.plans: dict[tuple[int, int], Any] = {}  # (id(body0), id(body1)) -> plan or None
        self.guard = _guard(frames, components)
        self.memo: Any = None  # the last reading's result
        self.slept = False  # every guard body asleep since the memo was taken

    def forget(self) -> None:
        self.memo, self.slept = None, False

    def asleep(self, guards: bool) -> bool:
        """Whether the guard bodies sleep now (False with the guards off or without guards)."""
        return guards and _asleep(self.guard)


class Probe:
    """Reads contact forces per substep and a snapshot per control step.

    ``scan`` and ``read_last`` say whether the coming control step's substeps scan
    contacts and whether its snapshot reads the last substep's contacts (the monitor's
    contact gate sets them); ``guards`` lets sleeping guard bodies spare readings."""

    def __init__(self, scene: Any, timestep: float, components: Mapping[str, Any], *,
                 pose_frames: Iterable[str] = (), free_bodies: Iterable[str] = (),
                 torque_frames: Iterable[str] = (), scan: ContactFilter = NO_PAIRS,
                 last: ContactFilter = NO_PAIRS,
                 joints: Mapping[str, tuple[Any, int]] | None = None,
                 gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)):
        self._physx = getattr(scene, "physx_system", scene)
        self._inv_dt = 1.0 / float(timestep)
        self.components = dict(components)
        self._frame_of = {id(c): f for f, c in self.components.items()}
        pose_frames = [f for f in pose_frames if f in self.components]
        self._pose_names = tuple(pose_frames)
        self._pose_index = {f: i for i, f in enumerate(self._pose_names)}
        self._pose_components = [self.components[f] for f in pose_frames]
        self._torque = frozenset(torque_frames)
        g = (float(gravity[0]), float(gravity[1]), float(gravity[2]))
        self._free = [_FreeBody(f, self.components[f], g, f in self._torque) for f in free_bodies
                      if f in self.components]
        self._joints = dict(joints or {})  # "<body>:<joint>" -> (articulation, qpos index)
        self._scan_reading = _Reading(scan, self.components)
        self._last_reading = _Reading(last, self.components)
        self._scan_counted = False  # the scan's memo is in this control step's maxima
        self.maxima = ContactMaxima()  # this control step's so far
        self.scan = True
        self.read_last = True
        self.guards = True

    @property
    def records_substeps(self) -> bool:
        """Whether substeps are read at all (free bodies or a scan filter)."""
        return bool(self._free) or bool(self._scan_reading.filter)

    def reset(self) -> None:
        """Forget the maxima and re-read velocities (after the scene was reset)."""
        self.maxima.clear()
        self._scan_reading.forget()
        self._last_reading.forget()
        for body in self._free:
            body.read()

    def record_substep(self) -> None:
        """Fold the physics step just taken into the control step's maxima."""
        inv_dt = self._inv_dt
        for body in self._free:
            body.record(self.maxima, inv_dt)
        scan, last = self._scan_reading, self._last_reading
        if self.scan and scan.filter:
            was, scan.slept = scan.slept, scan.asleep(self.guards)
            if was and scan.slept and scan.memo is not None:
                # every contact the scan keeps touches a guard body, and a body asleep all
                # through the substep had no contact reported: the scan would read what the
                # last one read, which is in the maxima unless this control step just began
                if not self._scan_counted:
                    self._replay(scan.memo)
            else:
                scan.memo = self._read_scan(inv_dt)
            self._scan_counted = True
        else:
            scan.forget()
        if self.read_last and last.filter:
            # the last-substep reading stays valid only while its guards sleep all along
            last.slept = last.slept and last.asleep(self.guards)
        else:
            last.forget()

    def _replay(self, records: Records) -> None:
        for kind, a, b, value in records:
            if kind == "f":
                self.maxima.add_force(a, b, value)
            else:
                self.maxima.add_torque(a, b, value)

    def _frames(self, b0: Any, b1: Any, filter: ContactFilter) -> tuple[str, str] | None:
        """The frames of a contact's bodies when ``filter`` keeps the pair, else None."""
        f0, f1 = self._frame_of.get(id(b0)), self._frame_of.get(id(b1))
        if not filter.wants(f0, f1):
            return None
        return f0 or f"?{b0.entity.name}", f1 or f"?{b1.entity.name}"

    def _scan_plan(self, b0: Any, b1: Any) -> tuple[tuple[str, str], float, bool, bool] | None:
        """(pair_key of the frames, +1 if the contact's first body is the key's first frame
        else -1, torque on body 0, torque on body 1) of a contact pair the scan keeps."""
        reading = self._scan_reading
        if b0 not in reading.hot and b1 not in reading.hot:
            return None
        frames = self._frames(b0, b1, reading.filter)
        if frames is None:
            return None
        f0, f1 = frames
        pair = pair_key(f0, f1)
        return pair, 1.0 if pair[0] == f0 else -1.0, f0 in self._torque, f1 in self._torque

    def _read_scan(self, inv_dt: float) -> Records:
        """Fold the kept contacts of the substep into the maxima; returns what it folded in.
        A frame pair's force is the sum over its contacts (one per pair of collision
        shapes: a finger on a glass of 16 wall pieces touches several), as its torque is.
        A point's position is read only where its impulse is not zero (most points of a
        grip lie within the contact offset and carry none)."""
        plans = self._scan_reading.plans
        forces: dict[tuple[str, str], list[float]] = {}  # pair_key (a, b): impulse on a by b
        torques: dict[tuple[str, str], list[float]] = {}  # (frame, other): angular impulse on frame
        centres: dict[int, list[float]] = {}  # torque bodies' mass centres, this substep
        for contact in self._physx.get_contacts():
            b0, b1 = contact.bodies
            key = (id(b0), id(b1))
            plan = plans.get(key, False)
            if plan is False:
                plan = plans[key] = self._scan_plan(b0, b1)
            if plan is None:
                continue
            pair, sign, torque0, torque1 = plan
            total = forces.get(pair)
            if total is None:
                total = forces[pair] = [0.0, 0.0, 0.0]
            for point in contact.points:
                impulse = point.impulse.tolist()
                ix, iy, iz = impulse
                if not (ix or iy or iz):
                    continue
                total[0] += sign * ix
                total[1] += sign * iy
                total[2] += sign * iz
                if torque0 or torque1:
                    position = point.position.tolist()
                    f0, f1 = pair if sign > 0 else pair[::-1]
                    if torque0:
                        _add_moment(torques, (f0, f1), _centre(centres, b0), position, impulse, 1.0)
                    if torque1:
                        _add_moment(torques, (f1, f0), _centre(centres, b1), position, impulse, -1.0)
        records: Records = []
        for kind, totals, add in (("f", forces, self.maxima.add_force), ("t", torques, self.maxima.add_torque)):
            for (a, b), (x, y, z) in totals.items():
                value = math.sqrt(x * x + y * y + z * z) * inv_dt
                if value > 0.0:
                    add(a, b, value)
                    records.append((kind, a, b, value))
        return records

    def last_contacts(self) -> dict[tuple[str, str], np.ndarray]:
        """Force on the first frame by the second, for the kept contacts of the last
        substep (a pair in contact with no force is there, as a zero). Reused from the
        last reading while its guard bodies slept through every substep since."""
        last = self._last_reading
        if last.slept and last.memo is not None and self.guards:
            return {k: v.copy() for k, v in last.memo.items()}
        forces = self._read_last()
        last.slept = last.asleep(self.guards)
        last.memo = {k: v.copy() for k, v in forces.items()}
        return forces

    def _read_last(self) -> dict[tuple[str, str], np.ndarray]:
        totals: dict[tuple[str, str], list[float]] = {}
        inv_dt = self._inv_dt
        last = self._last_reading
        plans, hot, filter = last.plans, last.hot, last.filter
        for contact in self._physx.get_contacts():
            b0, b1 = contact.bodies
            key = (id(b0), id(b1))
            frames = plans.get(key, False)
            if frames is False:
                frames = plans[key] = self._frames(b0, b1, filter) if b0 in hot or b1 in hot else None
            if frames is None:
                continue
            f0, f1 = frames
            x, y, z = _impulse(contact.points)
            for ordered, sign in (((f0, f1), inv_dt), ((f1, f0), -inv_dt)):
                total = totals.get(ordered)
                if total is None:
                    total = totals[ordered] = [0.0, 0.0, 0.0]
                total[0] += sign * x
                total[1] += sign * y
                total[2] += sign * z
        return {k: np.array(v) for k, v in totals.items()}

    def poses(self) -> PoseMap:
        """The pose frames' world poses now."""
        if not self._pose_components:
            return PoseMap((), np.zeros((0, 4, 4), dtype=np.float32))
        return PoseMap(self._pose_names, np.array([c.entity_pose.to_transformation_matrix()
                                                   for c in self._pose_components]), self._pose_index)

    def snapshot(self, step: int, time: float, *, contacts: bool = False) -> WorldState:
        """The world now, with the maxima recorded since the last snapshot (which are then
        cleared); ``contacts`` also reads the last substep's kept contact forces."""
        qpos: dict[int, Any] = {}
        joints = {}
        for k, (a, i) in self._joints.items():
            q = qpos.get(id(a))
            if q is None:
                q = qpos[id(a)] = a.get_qpos()
            joints[k] = float(q[i])
        maxima, self.maxima = self.maxima, ContactMaxima()  # the state takes this step's maxima
        self._scan_counted = False
        last = self.last_contacts() if contacts and self.read_last else {}
        return WorldState(step=step, time=time, poses=self.poses(), joints=joints, contact_force=maxima.force,
                          contact_torque=maxima.torque, last_contacts=last,
                          contacts_read=contacts or self.records_substeps)


def _sleep_flag(component: Any) -> str | None:
    """The attribute that says whether a component is asleep: ``is_sleeping`` (a dynamic
    rigid body), ``sleeping`` (an articulation link); None for a static body, and for a
    kinematic one (a touch does not wake it)."""
    if getattr(component, "kinematic", False):
        return None
    kind = type(component)
    for name in ("is_sleeping", "sleeping"):
        if hasattr(kind, name):
            return name
    return None


def _guard(frames: frozenset[str], components: Mapping[str, Any]) -> tuple[tuple[Any, str], ...] | None:
    """The components of ``frames`` with the attribute that says whether each sleeps, or
    None when one of them is static or kinematic (never put to sleep by a touch's absence)
    or not in the scene."""
    if not frames or any(f not in components for f in frames):
        return None
    flags = [(components[f], _sleep_flag(components[f])) for f in sorted(frames)]
    return None if any(flag is None for _, flag in flags) else tuple(flags)  # type: ignore[misc]


def _asleep(guard: tuple[tuple[Any, str], ...] | None) -> bool:
    """Whether every guard body is asleep (False without guards)."""
    if not guard:
        return False
    for component, flag in guard:
        if not getattr(component, flag):
            return False
    return True


def _impulse(points: Any) -> tuple[float, float, float]:
    """Total impulse of a contact's points (plain floats: numpy's per-call overhead would
    dominate a handful of three-vectors)."""
    x = y = z = 0.0
    for p in points:
        a, b, c = p.impulse.tolist()
        x, y, z = x + a, y + b, z + c
    return x, y, z


def _centre(centres: dict[int, list[float]], body: Any) -> list[float]:
    """A body's mass centre, read once per substep into ``centres``."""
    centre = centres.get(id(body))
    if centre is None:
        centre = centres[id(body)] = (body.entity_pose * body.cmass_local_pose).p.tolist()
    return centre


def _add_moment(torques: dict[tuple[str, str], list[float]], key: tuple[str, str], centre: list[float],
                position: list[float], impulse: list[float], sign: float) -> None:
    """Add to ``torques[key]`` the moment about ``centre`` of ``sign`` × ``impulse`` at ``position``."""
    moment = torques.get(key)
    if moment is None:
        moment = torques[key] = [0.0, 0.0, 0.0]
    ix, iy, iz = impulse
    rx, ry, rz = position[0] - centre[0], position[1] - centre[1], position[2] - centre[2]
    moment[0] += sign * (ry * iz - rz * iy)
    moment[1] += sign * (rz * ix - rx * iz)
    moment[2] += sign * (rx * iy - ry * ix)


__all__ = ["Probe", "components_of"]
