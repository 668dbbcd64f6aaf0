"""How far apart two arms' links are, for joint configurations of both: what a
``separation`` limit between two arms (or their grippers) measures, so that a two-arm plan
can choose where the hands meet, and the joints they meet with, before it moves.

The monitor measures the smallest signed distance between the link geometry of two robot
entities (``fsvla.monitor.channels``). :class:`ArmGap` does the same on the arms' models:
each watched link's collision shapes, read from the scene and made FCL geometry as the
monitor reads and makes them (``MonitoredScene.frame_shapes``,
:func:`fsvla.compiler.collision.fcl_geometry`), posed by the arm's forward kinematics.
The fingers stay as open as they are now (the arm joints do not move them relative to
the hand). It also checks an ``aligned`` a requirement asks of the two arms' reference
points.
"""

from __future__ import annotations

import fcl
import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.collision import fcl_geometry, signed_distance
from fsvla.compiler.monitor import RobotEntity
from fsvla.compiler.pose import pose_matrix, quat_to_matrix
from fsvla.dsl.models import predicates_in
from fsvla.monitor.state import robot_frame

from ..world import World


class ArmGap:
    """Smallest (distance − (limit + warning band)) between the links of arms ``a`` and
    ``b`` over the ``separation`` channels that watch the two (m); +inf where no such
    limit watches them (:attr:`watched`)."""

    def __init__(self, world: World, a: str, b: str) -> None:
        self.world = world
        self.arms = (a, b)
        self.kin = {arm: world.kinematics(arm) for arm in self.arms}
        robot_of = {arm.name: robot.name for robot in world.scene.embodiment.robots
                    for arm in robot.arms}
        entities = {e.name: e for e in world.monitor.entities if isinstance(e, RobotEntity)}
        owner = {arm: self._moved_links(arm) for arm in self.arms}

        def moves(links, arm: str) -> bool:
            return any(link.robot == robot_of[arm] and link.link in owner[arm] for link in links)

        #: (links of a, links of b, hard limit, warning band) per separation channel
        self._checks: list[tuple[list[int], list[int], float, float]] = []
        #: (arm, link index) -> the link's collision pieces: (FCL geometry, pose in the link)
        self._geometry: dict[tuple[str, int], list[tuple[fcl.CollisionGeometry,
                                                          NDArray[np.float64]]]] = {}
        for channel in world.monitor.channels:
            if channel.metric != "separation" or channel.reference not in entities:
                continue
            groups = []
            for name in (*channel.subjects, channel.reference):
                entity = entities.get(name)
                groups.append([] if entity is None else list(entity.links))
            first = [link for group in groups[:-1] for link in group]
            second = groups[-1]
            a_first = self._of(first, a, robot_of, owner)
            b_second = self._of(second, b, robot_of, owner)
            a_second = self._of(second, a, robot_of, owner)
            b_first = self._of(first, b, robot_of, owner)
            limit, band = float(channel.limit), float(channel.soft_threshold)
            # the side each arm plays: the group whose links it moves (a robot's static
            # links, a mount on its torso, belong to either side)
            if moves(first, a) and moves(second, b):
                self._checks.append((a_first, b_second, limit, band))
            elif moves(second, a) and moves(first, b):
                self._checks.append((a_second, b_first, limit, band))
            elif a_first and b_second:
                self._checks.append((a_first, b_second, limit, band))
            elif a_second and b_first:
                self._checks.append((a_second, b_first, limit, band))
        #: aligned(x, y, within=d) that a requirement asks of the two arms' reference
        #: points: (link index in a's model, link index in b's model, d)
        self._aligned: list[tuple[int, int, float]] = []
        refs = {}
        for name, entity in entities.items():
            link = entity.reference_link
            for arm in self.arms:
                if link is not None and link.robot == robot_of[arm] and self._of(
                        [link], arm, robot_of, owner):
                    refs[name] = (arm, list(self.kin[arm].link_names).index(link.link))
        for req in world.monitor.requirements:
            for p in predicates_in(req.first):
                if p.name != "aligned" or len(p.args) < 2:
                    continue
                x, y = refs.get(p.args[0]), refs.get(p.args[1])
                if x is None or y is None or x[0] == y[0]:
                    continue
                ia, ib = (x[1], y[1]) if x[0] == a else (y[1], x[1])
                self._aligned.append((ia, ib, float(p.params.get("within", 0.05))))
        for side, arm in enumerate(self.arms):
            names = self.kin[arm].link_names
            for i in {i for check in self._checks for i in check[side]}:
                # the monitor's own pieces: the scene's shapes of the link, as FCL geometry
                shapes = world.state.frame_shapes(robot_frame(robot_of[arm], names[i]))
                pieces = [(fcl_geometry(shape), pose_matrix(shape.pose)) for shape in shapes]
                if pieces:
                    self._geometry[(arm, i)] = pieces

    @property
    def asks_aligned(self) -> bool:
        """Whether a requirement asks the two arms' parts to come within a distance."""
        return bool(self._aligned)

    @property
    def separated(self) -> bool:
        """Whether a separation limit watches the two arms."""
        return bool(self._checks)

    @property
    def watched(self) -> bool:
        """Whether a separation limit, or a required alignment, watches the two arms."""
        return bool(self._checks or self._aligned)

    def _moved_links(self, arm: str) -> set[str]:
        """Names of the links the arm's own joints move (and its hand's frame)."""
        kin = self.kin[arm]
        names = list(kin.link_names)
        return {names[i] for i in self.world.moved_links(arm)} | {kin.spec.ee_link}

    def _of(self, links, arm: str, robot_of: dict[str, str],
            owner: dict[str, set[str]]) -> list[int]:
        """The indices, in ``arm``'s model, of those of ``links`` that ``arm`` carries (its
        robot's links its joints move, and its static links that no other arm moves)."""
        names = list(self.kin[arm].link_names)
        # by name: each arm's model numbers the robot's links its own way
        others = set().union(*(owner[o] for o in self.arms if o != arm
                               and robot_of[o] == robot_of[arm]))
        out = []
        for link in links:
            if link.robot != robot_of[arm] or link.link not in names:
                continue
            if link.link in owner[arm] or link.link not in others:
                out.append(names.index(link.link))
        return sorted(set(out))

    def _objects(self, arm: str, q: NDArray[np.float64], links: list[int]) -> list:
        kin = self.kin[arm]
        ps, quats = kin.link_poses(np.asarray(q, dtype=np.float64), links)
        out = []
        for i, p, quat in zip(links, ps, quats, strict=True):
            link = np.eye(4)
            link[:3, :3] = quat_to_matrix(np.asarray(quat, dtype=np.float64))
            link[:3, 3] = p
            for geometry, local in self._geometry.get((arm, i), ()):
                m = link @ local
                out.append(fcl.CollisionObject(geometry, fcl.Transform(
                    np.ascontiguousarray(m[:3, :3]), np.ascontiguousarray(m[:3, 3]))))
        return out

    def margin(self, qa: NDArray[np.float64], qb: NDArray[np.float64],
               band: bool = True) -> float:
        """Smallest distance less (limit + warning band) over the channels, for arm ``a``
        at joints ``qa`` and arm ``b`` at ``qb`` (m); less the hard limit alone without
        ``band``; +inf with no separation limit."""
        best = float("inf")
        for ia, ib, limit, warn in self._checks:
            need = limit + warn if band else limit
            left, right = self._objects(self.arms[0], qa, ia), self._objects(self.arms[1], qb, ib)
            for x in left:
                for y in right:
                    best = min(best, signed_distance(x, y) - need)
        return best

    def aligned(self, qa: NDArray[np.float64], qb: NDArray[np.float64],
                slack: float = 0.005) -> bool:
        """Whether every ``aligned`` a requirement asks of the two arms holds, ``slack`` (m)
        to spare, with arm ``a`` at ``qa`` and ``b`` at ``qb``."""
        for ia, ib, within in self._aligned:
            pa = np.asarray(self.kin[self.arms[0]].link_poses(qa, [ia])[0][0], dtype=np.float64)
            pb = np.asarray(self.kin[self.arms[1]].link_poses(qb, [ib])[0][0], dtype=np.float64)
            if float(np.linalg.norm(pa - pb)) > within - slack:
                return False
        return True

    def along(self, qa0: NDArray[np.float64], qa1: NDArray[np.float64],
              qb0: NDArray[np.float64], qb1: NDArray[np.float64], samples: int = 8) -> float:
        """The smallest :meth:`margin` along joint-space lines of both arms at once
        (``qa0`` to ``qa1`` and ``qb0`` to ``qb1``), at ``samples`` + 1 points."""
        return min(self.margin(qa0 + s * (qa1 - qa0), qb0 + s * (qb1 - qb0))
                   for s in np.linspace(0.0, 1.0, samples + 1))


class OtherArmClearance:
    """How far an arm's links, at joints ``q``, stay from another arm of the robot where
    that one stands now, less the hard limit of the ``separation`` channels that watch the
    two (m; +inf where none does): a clearance measure the IK chooses its answers by
    (:class:`fsvla.experts.clearance.ArmClearance` is the one for hazards), so that an arm
    working alone does not swing its elbow into the idle one."""

    def __init__(self, world: World, arm: str, other: str) -> None:
        self.world = world
        self.other = other
        self.gap = ArmGap(world, arm, other)

    @property
    def active(self) -> bool:
        return self.gap.separated

    def __call__(self, q: NDArray[np.float64]) -> float:
        return self.gap.margin(q, self.world.arm_joints(self.other), band=False)


__all__ = ["ArmGap", "OtherArmClearance"]
