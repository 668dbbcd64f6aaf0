"""Read a :class:`~fsvla.monitor.state.WorldState` from a SAPIEN scene.

Python access to SAPIEN's contact points costs microseconds per point, and a resting
object made of convex pieces has a dozen contacts with the table in every substep, so
the probe reads forces two ways, both at **every** physics substep (a spike inside a
control step is never missed):

- **Net contact force on a free rigid body** (a dynamic, non-kinematic scene body),
  from its velocity change over the substep: ``F = m (v' - v) / dt - m g`` and, about
  its centre of mass, ``τ = I_w (ω' - ω) / dt + ω' × I_w ω'``. This equals the sum of
  the contact impulses on it divided by the timestep (a landing, a knock), at the cost of
  two velocity reads. It is recorded as the pair (body, ``"*"``).
- **Per-pair contact forces** from ``scene.get_contacts()`` for the pairs a channel
  needs (:class:`ContactFilter`): every pair of a watched robot link or articulated
  link, and robot-link pairs of watched objects (a squeeze, whose net force is zero).
  Contacts between two links of one robot are skipped. The scan runs in a control step
  only while :attr:`Probe.scan` is set (the monitor clears it while no watched robot
  link is near anything, see ``fsvla.monitor.monitor``).

SAPIEN's contact list holds each shape pair's latest PhysX report, and a pair is
reported again only while one of its bodies is awake and a touch wakes a sleeping body.
So while every *guard body* of a filter (its frames: each kept pair involves one) slept
through a substep, a reading would find what the previous one found: the probe skips it
and reuses that reading (:attr:`Probe.guards`; the argument is in ``docs/monitor.md``).

A contact's impulses act on its first body; the second gets their opposite.

Both readings run natively where they can (``fsvla.monitor.native``: one call a substep
instead of Python objects per contact point); this module's Python loops are the
fallback and the reference the native reader is tested against.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .native import FreeBodySpec, NativeReader, NativeSnapshot, NativeUnavailable, native_library
from .state import NET, ContactMaxima, PoseMap, WorldState, link_frame, pair_key, robot_frame

log = logging.getLogger(__name__)

_ZERO = [0.0, 0.0, 0.0]


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


def _robot_of(frame: str | None) -> str | None:
    return frame.split(":", 1)[0] if frame and frame.startswith("@") else None


@dataclass(frozen=True)
class ContactFilter:
    """Which contact pairs the per-substep scan folds into the maxima."""

    any_pair: frozenset[str] = frozenset()  # frames whose every contact counts
    robot_pairs: frozenset[str] = frozenset()  # frames whose contacts with a robot link count

    def __bool__(self) -> bool:
        return bool(self.any_pair or self.robot_pairs)

    def wants(self, f0: str | None, f1: str | None) -> bool:
        if f0 in self.any_pair or f1 in self.any_pair:
            r0 = _robot_of(f0)
            return r0 is None or r0 != _robot_of(f1)  # not a robot's own links
        return ((f0 in self.robot_pairs and f1 is not None and f1[0] == "@")
                or (f1 in self.robot_pairs and f0 is not None and f0[0] == "@"))


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

    def _magnitudes(self, v: list[float], w: list[float] | None, inv_dt: float) -> tuple[float, float]:
        """(force, torque) of :meth:`record` for readings ``v``, ``w`` equal to the last ones."""
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

    def record(self, maxima: ContactMaxima, inv_dt: float) -> None:
        if self.c.is_sleeping and self.v == _ZERO and (not self.torque or self.w == _ZERO):
            # PhysX zeroes a sleeping body's velocities: the readings would be what they
            # were (zero), so the maxima get the same values without the reads
            if self._rest is None or self._rest[0] != inv_dt:
                self._rest = (inv_dt, self._magnitudes(_ZERO, _ZERO if self.torque else None, inv_dt))
            force, torque = self._rest[1]
            maxima.add_force(self.frame, NET, force)
            if self.torque:
                maxima.add_torque(self.frame, NET, torque)
            return
        v = self.c.linear_velocity.tolist()
        m = self.mass * inv_dt
        fx, fy, fz = (m * (a - b) - g for a, b, g in zip(v, self.v, self.weight))
        self.v = v
        maxima.add_force(self.frame, NET, math.sqrt(fx * fx + fy * fy + fz * fz))
        if self.torque:
            w = self._body_omega()
            ix, iy, iz = self.inertia
            lx, ly, lz = ix * w[0], iy * w[1], iz * w[2]
            tx = ix * (w[0] - self.w[0]) * inv_dt + w[1] * lz - w[2] * ly
            ty = iy * (w[1] - self.w[1]) * inv_dt + w[2] * lx - w[0] * lz
            tz = iz * (w[2] - self.w[2]) * inv_dt + w[0] * ly - w[1] * lx
            self.w = w
            maxima.add_torque(self.frame, NET, math.sqrt(tx * tx + ty * ty + tz * tz))


class Probe:
    """Reads contact forces per substep and a snapshot per control step."""

    def __init__(self, scene: Any, timestep: float, components: Mapping[str, Any], *,
                 pose_frames: Iterable[str] = (), free_bodies: Iterable[str] = (),
                 torque_frames: Iterable[str] = (), scan: ContactFilter = ContactFilter(),
                 last: ContactFilter = ContactFilter(),
                 joints: Mapping[str, tuple[Any, int]] | None = None,
                 gravity: tuple[float, float, float] = (0.0, 0.0, -9.81), native: bool = True):
        self._scene = scene
        self._physx = getattr(scene, "physx_system", scene)
        self._dt = float(timestep)
        self.components = dict(components)
        self._frame_of = {id(c): f for f, c in self.components.items()}
        self._pose_frames = [(f, self.components[f]) for f in pose_frames if f in self.components]
        self._pose_names = tuple(f for f, _ in self._pose_frames)
        self._pose_index = {f: i for i, f in enumerate(self._pose_names)}
        self._pose_components = [c for _, c in self._pose_frames]
        self._torque = frozenset(torque_frames)
        g = (float(gravity[0]), float(gravity[1]), float(gravity[2]))
        self._free = [_FreeBody(f, self.components[f], g, f in self._torque) for f in free_bodies
                      if f in self.components]
        self._filter = scan
        self._last = last
        self._joints = dict(joints or {})  # "<body>:<joint>" -> (articulation, qpos index)
        self.maxima = ContactMaxima()
        # (id(body0), id(body1)) -> the scan's plan for the pair if it keeps it (_scan_plan),
        # or the last-substep reading's frames, else None; the bodies are the components
        # above and the scene's other bodies, alive as long as it
        self._scan_pairs: dict[tuple[int, int], tuple[str, str, bool, bool] | None] = {}
        self._last_pairs: dict[tuple[int, int], tuple[str, str] | None] = {}
        self._scan_hot, self._last_hot = self._hot(scan), self._hot(last)
        self._scan_guard, self._last_guard = self._guard(scan), self._guard(last)
        # What the last reading found, valid while every guard body sleeps (see _asleep):
        # the scan's (kind, frame, other, value) records, and the last-substep forces.
        self._scan_memo: list[tuple[str, str, str, float]] | None = None
        self._scan_memo_counted = False  # its records are in this control step's maxima
        self._last_memo: dict[tuple[str, str], np.ndarray] | None = None
        self._scan_slept = self._last_slept = False  # guards asleep after the previous substep
        self._scan_on = True
        self.read_last = True  # snapshot(contacts=True) reads the last substep's contacts
        self.guards = True  # sleeping guard bodies spare the scans (off: every reading is taken)
        self._native_scan, self._native_last, self._native_snapshot = (
            self._native_parts(g) if native else (None, None, None))
        self._fold_native = self._native_fold()

    @property
    def scan(self) -> bool:
        """Whether the per-substep pair scan runs."""
        return self._scan_on

    @scan.setter
    def scan(self, on: bool) -> None:
        if on != self._scan_on:
            self._scan_on = on
            self._fold_native = self._native_fold()

    @property
    def _scanning(self) -> bool:
        """Whether this control step's substeps fold kept pairs (the scan is on and keeps some)."""
        return self._scan_on and bool(self._filter)

    def _native_fold(self) -> Callable[[], None] | None:
        """The native reader's fold of one substep with this probe's arguments bound (it runs
        25 times a control step: no Python between the call and the reader)."""
        if self._native_scan is None:
            return None
        return self._native_scan.folder(1.0 / self._dt, self._scanning)

    def _native_parts(self, gravity: tuple[float, float, float]) -> tuple[
            NativeReader | None, NativeReader | None, NativeSnapshot | None]:
        """(substep reader, last-substep reader, the snapshot's reading of poses and of
        both readers) in native code, or Nones."""
        library = native_library()
        if library is None:
            return None, None, None
        try:  # the C++ pointers once, for all three
            system = library.system(self._physx)
            pointers = {f: library.component(c) for f, c in self.components.items()}
            free = [FreeBodySpec(b.frame, b.c, b.torque, gravity) for b in self._free]
            scan = NativeReader(library, system, pointers, any_pair=self._filter.any_pair,
                                robot_pairs=self._filter.robot_pairs, torque=self._torque, free_bodies=free)
            last = NativeReader(library, system, pointers, any_pair=self._last.any_pair,
                                robot_pairs=self._last.robot_pairs) if self._last else None
            snapshot = NativeSnapshot(library, scan, last, [pointers[f] for f in self._pose_names])
        except NativeUnavailable as error:
            log.info("reading this scene's contacts in Python: %s", error)
            return None, None, None
        return scan, last, snapshot

    @property
    def native(self) -> bool:
        """Whether contacts are read by the native reader."""
        return self._native_scan is not None

    @property
    def records_substeps(self) -> bool:
        return bool(self._free) or bool(self._filter)

    def maxima_so_far(self) -> ContactMaxima:
        """The maxima recorded since the last snapshot (a copy; the snapshot takes them)."""
        maxima = ContactMaxima(dict(self.maxima.force), dict(self.maxima.torque))
        if self._native_scan is not None:
            self._native_scan.take(maxima, clear=False)
        return maxima

    def frame_of(self, component: Any) -> str:
        return self._frame_of.get(id(component)) or f"?{component.entity.name}"

    def reset(self) -> None:
        """Forget the maxima and re-read velocities (after the scene was reset)."""
        self.maxima.clear()
        self._scan_memo = self._last_memo = None
        self._scan_slept = self._last_slept = False
        if self._native_scan is not None:
            self._native_scan.reset()
        else:
            for body in self._free:
                body.read()

    def substep_recorder(self) -> Callable[[], None] | None:
        """What to call after each physics substep of the coming control step, in place of
        :meth:`record_substep`: the native fold itself (no Python in between), or None
        when the native fold would do nothing (no free body, no scan this step)."""
        if self._fold_native is None:
            return self.record_substep
        if not self._free and not self._scanning:
            return None
        return self._fold_native

    def record_substep(self) -> None:
        """Fold the physics step just taken into the control step's maxima."""
        if self._fold_native is not None:
            self._fold_native()
            return
        inv_dt = 1.0 / self._dt
        for body in self._free:
            body.record(self.maxima, inv_dt)
        if self._scanning:
            slept = self._scan_slept
            self._scan_slept = asleep = self.guards and _asleep(self._scan_guard)
            if slept and asleep and self._scan_memo is not None:
                # every contact a scan keeps touches a guard body, and a body asleep all
                # through the substep had no contact reported: the scan would read the
                # same contacts as the last one
                if not self._scan_memo_counted:
                    self._replay(self._scan_memo)
            else:
                self._scan_memo = self._scan(inv_dt)
            self._scan_memo_counted = True
        else:
            self._scan_memo, self._scan_slept = None, False
        if self.read_last and self._last:
            # the last-substep reading may be reused only if its guards slept all along
            self._last_slept = self._last_slept and self.guards and _asleep(self._last_guard)
        else:
            self._last_memo, self._last_slept = None, False

    def _pair(self, b0: Any, b1: Any, wants: Any) -> tuple[str, str] | None:
        """The frames of a contact's bodies when ``wants`` keeps the pair, else None."""
        f0, f1 = self._frame_of.get(id(b0)), self._frame_of.get(id(b1))
        if not wants(f0, f1):
            return None
        return f0 or f"?{b0.entity.name}", f1 or f"?{b1.entity.name}"

    def _guard(self, filter: ContactFilter) -> tuple[tuple[Any, str], ...] | None:
        """Components every kept pair involves whose sleep can be read (free rigid bodies,
        links), or None when one of them is static (never asleep) or not in the scene."""
        if not self.guards_possible(filter):
            return None
        return tuple((self.components[f], _sleep_flag(self.components[f]))
                     for f in sorted(filter.any_pair | filter.robot_pairs))

    def guards_possible(self, filter: ContactFilter) -> bool:
        """Whether the sleep of the filter's bodies can spare its readings."""
        frames = filter.any_pair | filter.robot_pairs
        if not frames or any(f not in self.components for f in frames):
            return False
        return all(_sleep_flag(self.components[f]) is not None for f in frames)

    def _replay(self, records: list[tuple[str, str, str, float]]) -> None:
        maxima = self.maxima
        for kind, a, b, value in records:
            if kind == "f":
                maxima.add_force(a, b, value)
            else:
                maxima.add_torque(a, b, value)

    def _hot(self, filter: ContactFilter) -> set[Any]:
        """The components a kept pair must involve (one side is in the filter), compared by
        identity (SAPIEN hands out one Python object per live component)."""
        frames = filter.any_pair | filter.robot_pairs
        return {c for f, c in self.components.items() if f in frames}

    def _scan(self, inv_dt: float) -> list[tuple[str, str, str, float]]:
        """Fold the wanted contacts into the maxima; returns what it folded in. A frame
        pair's force is the sum over its contacts (one per pair of collision shapes: a
        finger on a glass of 16 wall pieces touches several), as its torque is."""
        cache, hot = self._scan_pairs, self._scan_hot
        forces: dict[tuple[str, str], list[float]] = {}  # pair_key (a, b): impulse on a by b
        torques: dict[tuple[str, str], list[float]] = {}  # (frame, other): angular impulse on frame
        centres: dict[int, tuple[float, float, float]] = {}  # torque bodies' mass centres, this substep
        for contact in self._contacts():
            b0, b1 = contact.bodies
            key = (id(b0), id(b1))
            plan = cache.get(key, False)
            if plan is False:  # identity: a component's wrapper is unique
                plan = cache[key] = self._scan_plan(b0, b1) if b0 in hot or b1 in hot else None
            if plan is None:
                continue
            pair, sign, torque0, torque1 = plan
            points = contact.points
            impulses = [p.impulse.tolist() for p in points]
            total = forces.get(pair)
            if total is None:
                total = forces[pair] = [0.0, 0.0, 0.0]
            for x, y, z in impulses:
                total[0] += sign * x
                total[1] += sign * y
                total[2] += sign * z
            if torque0 or torque1:
                positions = [p.position.tolist() for p in points]
                f0, f1 = pair if sign > 0 else pair[::-1]
                for wanted, body, frame, other, on in ((torque0, b0, f0, f1, 1.0), (torque1, b1, f1, f0, -1.0)):
                    if wanted:
                        centre = centres.get(id(body))
                        if centre is None:
                            centre = centres[id(body)] = _mass_centre(body)
                        moment = torques.get((frame, other))
                        if moment is None:
                            moment = torques[(frame, other)] = [0.0, 0.0, 0.0]
                        _add_moment(moment, impulses, positions, centre, on)
        return self._fold(forces, torques, inv_dt)

    def _fold(self, forces: dict[tuple[str, str], list[float]], torques: dict[tuple[str, str], list[float]],
              inv_dt: float) -> list[tuple[str, str, str, float]]:
        """Fold a substep's per-pair impulses and angular impulses into the maxima, as
        forces and torques; returns what it folded in."""
        maxima, records = self.maxima, []
        for kind, totals, add in (("f", forces, maxima.add_force), ("t", torques, maxima.add_torque)):
            for (a, b), (x, y, z) in totals.items():
                value = math.sqrt(x * x + y * y + z * z) * inv_dt
                if value > 0.0:
                    add(a, b, value)
                    records.append((kind, a, b, value))
        return records

    def _scan_plan(self, b0: Any, b1: Any) -> tuple[tuple[str, str], float, bool, bool] | None:
        """(pair_key of the frames, +1 if the contact's first body is the key's first frame
        else -1, torque on body 0, torque on body 1) of a contact pair the scan keeps."""
        frames = self._pair(b0, b1, self._filter.wants)
        if frames is None:
            return None
        f0, f1 = frames
        pair = pair_key(f0, f1)
        return pair, 1.0 if pair[0] == f0 else -1.0, f0 in self._torque, f1 in self._torque

    def _contacts(self) -> list[Any]:
        return self._physx.get_contacts()

    def last_contacts(self) -> dict[tuple[str, str], np.ndarray]:
        """Force on the first frame by the second, for the wanted contacts of the last
        substep. Reused from the last reading while its guard bodies slept through every
        substep since (their contacts were not reported again)."""
        if self._native_last is not None:
            return self._native_last.read(1.0 / self._dt)
        if self._last_slept and self._last_memo is not None and self.guards:
            return {k: v.copy() for k, v in self._last_memo.items()}
        forces = self._read_last()
        self._last_slept = self.guards and _asleep(self._last_guard)
        self._last_memo = {k: v.copy() for k, v in forces.items()}
        return forces

    def _read_last(self) -> dict[tuple[str, str], np.ndarray]:
        totals: dict[tuple[str, str], list[float]] = {}
        inv_dt = 1.0 / self._dt
        cache, hot, wants = self._last_pairs, self._last_hot, self._last.wants
        for contact in self._contacts():
            b0, b1 = contact.bodies
            key = (id(b0), id(b1))
            frames = cache.get(key, False)
            if frames is False:
                frames = cache[key] = self._pair(b0, b1, wants) if b0 in hot or b1 in hot else None
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
        if not self._pose_frames:
            return PoseMap((), np.zeros((0, 4, 4), dtype=np.float32))
        return PoseMap(self._pose_names, np.array([c.entity_pose.to_transformation_matrix()
                                                   for c in self._pose_components]), self._pose_index)

    def snapshot(self, step: int, time: float, *, contacts: bool = False) -> WorldState:
        """The world now, with the maxima recorded since the last snapshot (which are then
        cleared); ``contacts`` also reads the last substep's wanted contact forces."""
        qpos: dict[int, Any] = {}
        joints = {}
        for k, (a, i) in self._joints.items():
            q = qpos.get(id(a))
            if q is None:
                q = qpos[id(a)] = a.get_qpos()
            joints[k] = float(q[i])
        maxima, self.maxima = self.maxima, ContactMaxima()  # the state takes this step's maxima
        read_last = contacts and self.read_last
        if self._native_snapshot is not None:  # poses, maxima and last contacts in one call
            stack, last = self._native_snapshot.take(maxima, read_last, 1.0 / self._dt)
            poses = PoseMap(self._pose_names, stack, self._pose_index)
        else:
            poses, last = self.poses(), self.last_contacts() if read_last else {}
        self._scan_memo_counted = False
        return WorldState(step=step, time=time, poses=poses, joints=joints, contact_force=maxima.force,
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


def _mass_centre(body: Any) -> tuple[float, float, float]:
    return tuple((body.entity_pose * body.cmass_local_pose).p.tolist())


def _add_moment(moment: list[float], impulses: list[list[float]], positions: list[list[float]],
                centre: tuple[float, float, float], sign: float) -> None:
    """Add the moment about ``centre`` of ``sign`` × the impulses at their positions."""
    cx, cy, cz = centre
    for (ix, iy, iz), (px, py, pz) in zip(impulses, positions):
        rx, ry, rz = px - cx, py - cy, pz - cz
        moment[0] += sign * (ry * iz - rz * iy)
        moment[1] += sign * (rz * ix - rx * iz)
        moment[2] += sign * (rx * iy - ry * ix)


__all__ = ["NET", "ContactFilter", "Probe", "components_of"]
