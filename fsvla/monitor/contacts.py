"""What contact data the monitor reads, and when it can skip reading them.

:func:`contact_plan` derives, from the force and ``untouched`` channels, which free
bodies get a velocity-based net force (and torque) every substep and which contact pairs
the per-substep scan keeps; :func:`predicate_filter` the pairs the contact predicates
read at a step's last substep. :class:`ContactGate` turns a scan off for the next
control step while no robot link is within :data:`CONTACT_GATE` of a body its pairs
could touch (see ``fsvla.sim.probe``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fsvla.compiler.monitor import MonitorSpec
from fsvla.compiler.scene import SceneSpec
from fsvla.dsl.models import predicates_in

from . import kernels
from .geometry import SceneGeometry
from .layout import Layout
from .predicates import CONTACT_PREDICATES, spec_conditions

#: Broad-phase distance (m) within which robot links' contacts are scanned.
CONTACT_GATE = 0.1
FORCE_METRICS = frozenset({"contact_force", "contact_torque"})


def _robot_of(frame: str | None) -> str | None:
    return frame.split(":", 1)[0] if frame and frame.startswith("@") else None


@dataclass(frozen=True)
class ContactFilter:
    """Which contact pairs a reading keeps."""

    any_pair: frozenset[str] = frozenset()  # frames whose every contact counts
    robot_pairs: frozenset[str] = frozenset()  # frames whose contacts with a robot link count

    def __bool__(self) -> bool:
        return bool(self.any_pair or self.robot_pairs)

    @property
    def frames(self) -> frozenset[str]:
        """The frames one of which every kept pair involves."""
        return self.any_pair | self.robot_pairs

    def wants(self, f0: str | None, f1: str | None) -> bool:
        if f0 in self.any_pair or f1 in self.any_pair:
            r0 = _robot_of(f0)
            return r0 is None or r0 != _robot_of(f1)  # not a robot's own links
        return ((f0 in self.robot_pairs and f1 is not None and f1[0] == "@")
                or (f1 in self.robot_pairs and f0 is not None and f0[0] == "@"))


def contact_plan(spec: MonitorSpec, layout: Layout, scene_spec: SceneSpec) -> tuple[
        set[str], set[str], ContactFilter]:
    """(free bodies, torque frames, per-substep filter) the force and untouched channels need."""
    static = {b.name for b in scene_spec.bodies if b.is_static}
    free, torque, any_pair, robot_pairs = set(), set(), set(), set()
    for ch in spec.channels:
        if ch.metric in FORCE_METRICS:
            for subject in ch.subjects:
                frames = layout.frames(subject)
                if ch.metric == "contact_torque":
                    torque |= frames
                body = layout.bodies.get(subject)
                if body is not None and not body.articulated and subject not in static:
                    free |= frames
                    robot_pairs |= frames
                else:
                    any_pair |= frames
        elif ch.metric == "untouched" and ch.reference in layout.bodies:
            robot_pairs |= layout.frames(ch.reference)
    return free, torque, ContactFilter(any_pair=frozenset(any_pair), robot_pairs=frozenset(robot_pairs))


def predicate_filter(spec: MonitorSpec, layout: Layout) -> ContactFilter:
    """The last-substep contacts the contact predicates read."""
    any_pair, robot_pairs = set(), set()
    for p in (p for c in spec_conditions(spec) for p in predicates_in(c) if p.name in CONTACT_PREDICATES):
        bodies = [a for a in p.args if a in layout.bodies]
        for a in bodies:
            robot_pairs.update(layout.frames(a))
        if p.name == "touching" and len(bodies) == 2:
            any_pair.update(layout.frames(bodies[0]))
    return ContactFilter(any_pair=frozenset(any_pair), robot_pairs=frozenset(robot_pairs))


class ContactGate:
    """Whether the per-substep scan and the predicates' contact reading can find anything
    in the next control step: robot-link pieces against body pieces within
    :data:`CONTACT_GATE`, tested first on frame bounds (a frame's bounds hold its pieces',
    so far frames rule their pieces out) and on pieces only where a frame is near, in one
    compiled pass (``kernels.contact_gate``). A filter that counts every contact of a
    non-robot frame is never gated."""

    def __init__(self, geometry: SceneGeometry, scan: ContactFilter, last: ContactFilter):
        self.geometry = geometry
        robot = frozenset(f for f in geometry.frames if f.startswith("@"))
        self.rows, self.cols = robot, frozenset(f for f in geometry.frames if not f.startswith(("@", "zone:")))
        ia, ib = geometry.pieces(self.rows), geometry.pieces(self.cols)
        robot_any = frozenset(f for f in scan.any_pair if f.startswith("@"))
        self.scan_always = bool(scan.any_pair - robot_any) or (bool(scan) and not len(ia))
        self.last_always = bool(last.any_pair) or (bool(last) and not len(ia))
        self.wants_scan, self.wants_last = bool(scan), bool(last)
        # Frame level: every robot link against the bodies the scan or the predicates
        # watch, and the robot links whose every contact counts against every body.
        index = geometry.frame_indices
        rows_all, cols_all = index(self.rows), index(self.cols)
        scan_cols = np.isin(cols_all, index(scan.robot_pairs)) & self.wants_scan
        last_cols = np.isin(cols_all, index(last.robot_pairs)) & self.wants_last
        cols = scan_cols | last_cols
        scan_rows = rows_all[np.isin(rows_all, index(robot_any))] if self.wants_scan else rows_all[:0]
        piece_scan_rows = ia[np.isin(ia, geometry.pieces(robot_any))] if self.wants_scan else ia[:0]
        self._plan = (rows_all, cols_all[cols], scan_rows, scan_cols[cols], last_cols[cols], cols_all,
                      ia, ib, piece_scan_rows,
                      np.isin(ib, geometry.pieces(scan.robot_pairs)) & self.wants_scan,
                      np.isin(ib, geometry.pieces(last.robot_pairs)) & self.wants_last)
        self._answer: tuple[int, tuple[bool, bool]] | None = None

    def update(self) -> tuple[bool, bool]:
        """(scan substeps, read the last substep's contacts) for the next control step."""
        geometry = self.geometry
        if self._answer is not None and self._answer[0] == geometry.moves:
            return self._answer[1]  # nothing moved
        scan, last = self.scan_always, self.last_always
        check_scan, check_last = not scan and self.wants_scan, not last and self.wants_last
        if (check_scan or check_last) and len(self._plan[0]):
            verdict = kernels.contact_gate(*geometry.boxes, *self._plan, check_scan, check_last, CONTACT_GATE)
            scan, last = scan or bool(verdict & 1), last or bool(verdict & 2)
        self._answer = (geometry.moves, (scan, last))
        return scan, last


__all__ = ["CONTACT_GATE", "FORCE_METRICS", "ContactFilter", "ContactGate", "contact_plan",
           "predicate_filter"]
