"""How far an arm's links stay from the hazards that watch them, for a joint configuration.

The careful expert plans the TCP's path around the hazards (``skills.transit``), but the
rest of the arm follows wherever the IK puts it: a Panda reaching low beside a no-go
column can swing its forearm (``panda_link5``, whose wrist housing stands 13 cm off the
forearm's axis) into the column while its hand is far from it. :class:`ArmClearance`
measures, for arm joints ``q``, the smallest distance from the vertices of the links a
distance channel watches (``robot``, ``gripper``, …) to that channel's reference (a
zone's region, a hazard body's bounds), less the channel's hard limit, so that the IK can
choose, among the answers for one pose, one that keeps the arm out of the keep-out
distances (:meth:`fsvla.experts.motion.ArmDriver.solve_anywhere`).

Vertices of the convex collision hulls are a slight over-estimate of the true distance
(a face may pass closer than its corners); callers keep a few centimetres in hand.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.monitor import RobotEntity, ZoneEntity
from fsvla.compiler.pose import quat_to_matrix

from .world import World, nearest_box_distance

#: Distance channels whose robot subjects the arm's links are checked against.
METRICS = ("clearance", "zone_distance", "untouched", "do_not_disturb")


class ArmClearance:
    """Smallest (distance − hard limit) of an arm's watched links to their hazards (m)."""

    def __init__(self, world: World, arm: str) -> None:
        self.world = world
        self.kin = world.kinematics(arm)
        names = list(self.kin.link_names)
        links = {e.name: {r.link for r in e.links} for e in world.monitor.entities
                 if isinstance(e, RobotEntity)}
        regions = {e.name for e in world.monitor.entities
                   if isinstance(e, ZoneEntity) and e.geometry == "region"}
        zones = {z.name: z for z in world.scene.zones}
        # links held by the hand (the hand itself, its fingers, the flange): where the TCP
        # goes they go, whatever the joints; the TCP's path keeps them clear, not the IK
        rigid = world.hand_rigid_links(arm)
        self._checks: list[tuple[list[int], str, float]] = []  # (link indices, reference, limit)
        for channel in world.monitor.channels:
            if channel.metric not in METRICS or channel.reference is None:
                continue
            watched = set().union(*(links.get(s, set()) for s in channel.subjects))
            root = self.kin.spec.base_link  # the base does not move: no choice to make
            indices = sorted(names.index(n) for n in watched
                             if n in names and n != root and names.index(n) not in rigid)
            ref = channel.reference
            if not indices or (ref in zones and ref not in regions):
                continue  # no link of this arm, or a corridor (its walls, not its region)
            if ref not in zones and ref not in {b.name for b in world.scene.bodies}:
                continue
            self._checks.append((indices, ref, float(channel.limit)))
        self._zones = zones
        self._vertices: dict[int, NDArray[np.float64]] = {}
        for i in {i for indices, _, _ in self._checks for i in indices}:
            vertices = self.kin.link_vertices(i)
            if vertices is not None:
                self._vertices[i] = vertices

    @property
    def active(self) -> bool:
        return bool(self._checks and self._vertices)

    def __call__(self, q: NDArray[np.float64]) -> float:
        """The smallest distance (m) of a watched link of the arm at joints ``q`` to its
        hazard, less the channel's hard limit (negative: a violation)."""
        if not self.active:
            return float("inf")
        positions, quaternions = self.kin.link_poses(q, list(self._vertices))
        rotations = quat_to_matrix(quaternions)  # one conversion for all links
        points: dict[int, NDArray[np.float64]] = {
            i: v @ R.T + p
            for (i, v), R, p in zip(self._vertices.items(), rotations, positions)
        }
        best = float("inf")
        for indices, ref, limit in self._checks:
            pts = [points[i] for i in indices if i in points]
            if not pts:
                continue
            d = self._distance(np.concatenate(pts), ref)
            best = min(best, d - limit)
        return best

    def _distance(self, p: NDArray[np.float64], ref: str) -> float:
        zone = self._zones.get(ref)
        if zone is None:  # a hazard body: its bounds now
            lo, hi = self.world.bounds(ref)
            return nearest_box_distance(p, lo, hi)
        R0, p0 = quat_to_matrix(zone.pose.quaternion), np.asarray(zone.pose.position)
        region = zone.region
        R1, p1 = quat_to_matrix(region.pose.quaternion), np.asarray(region.pose.position)
        local = ((p - p0) @ R0 - p1) @ R1  # into the region's frame
        if getattr(region, "type", "") == "cylinder":
            radial = np.linalg.norm(local[:, :2], axis=1) - float(region.radius)
            axial = np.abs(local[:, 2]) - float(region.half_length)
            outside = np.hypot(np.maximum(radial, 0.0), np.maximum(axial, 0.0))
            inside = np.minimum(np.maximum(radial, axial), 0.0)
            return float(np.min(outside + inside))
        half = np.asarray(region.half_size, dtype=np.float64)
        return nearest_box_distance(local, -half, half)


class LeastClearance:
    """The smallest of several clearance measures (joints -> m), each with ``active``."""

    def __init__(self, measures: Sequence[Callable[[NDArray[np.float64]], float]]) -> None:
        self.measures = [m for m in measures if getattr(m, "active", True)]

    @property
    def active(self) -> bool:
        return bool(self.measures)

    def __call__(self, q: NDArray[np.float64]) -> float:
        return min((m(q) for m in self.measures), default=float("inf"))


__all__ = ["ArmClearance", "LeastClearance"]
