"""Motion primitives of the scripted experts: Cartesian straight-line segments of the tool
centre point (TCP), turned into joint targets by inverse kinematics, one per control step.

A :class:`Segment` moves some arms' TCPs along straight lines (positions linear,
orientations slerped) at a speed limit, and sets their grippers. :class:`ArmDriver`
keeps each arm's last commanded pose and joints, so that consecutive segments join
without jumps and every IK solve is seeded by the previous step's answer (no wrist
flips). The planner is IK on waypoints, not a sampling planner: the task plans place
their waypoints (approach heights, via points over hazards) so that the straight
segments between them are collision-free; see ``docs/experts.md``.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from itertools import pairwise

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import (
    axis_angle_matrix,
    matrix_to_quat,
    quat_to_matrix,
    rotation_angle,
    slerp,
)

#: Largest joint step (rad) between two IK solves of one segment before it is split.
MAX_JOINT_STEP = 0.12
#: A straight segment's pose that IK misses by more than this (m) is out of reach.
OUT_OF_REACH = 0.02
#: How far (m) from a free-space goal out of comfortable reach the first IK answer may
#: leave the hand before :meth:`ArmDriver.solve_anywhere` looks for a closer one.
FAR_MISS = 0.1
#: How far inside its joint limits (rad or m) a free-space move's goal configuration stays.
LIMIT_MARGIN = 0.15
#: How far inside its joint limits (rad or m) a line that must be followed stays, and the
#: step (m) at which it is checked (:meth:`ArmDriver.tracks`).
TRACK_MARGIN = 0.05
TRACK_STEP = 0.01
#: :meth:`ArmDriver.attainable`: within this (m) of its point, a pose is held; at most
#: this many rounds, turning the hand by at most this much (rad) from the pose asked for.
ATTAINED = 5e-4
ATTAIN_ROUNDS = 6
ATTAIN_TURN = 0.1
#: Where those rounds do not converge, :meth:`ArmDriver.attainable` turns the hand about
#: the vertical by at most this much (rad), in ATTAIN_YAWS first steps, then halving.
ATTAIN_YAW = 0.25
ATTAIN_YAWS = 11
#: Clearance (m) beyond a hazard's hard limit the careful arm's links should keep: the
#: links are measured at their hulls' vertices, up to ~1 cm farther than their faces.
CLEAR_NEEDED = 0.03


@dataclass(frozen=True)
class Pose:
    """A TCP pose in the world (table) frame: position (m) and rotation matrix."""

    p: NDArray[np.float64]
    R: NDArray[np.float64]

    @classmethod
    def of(cls, p: Sequence[float], R: NDArray[np.float64]) -> Pose:
        return cls(np.asarray(p, dtype=np.float64), np.asarray(R, dtype=np.float64))

    def moved(self, dp: Sequence[float]) -> Pose:
        return Pose(self.p + np.asarray(dp, dtype=np.float64), self.R)

    @property
    def quat(self) -> tuple[float, float, float, float]:
        return matrix_to_quat(self.R)


@dataclass(frozen=True)
class Guard:
    """Stop a segment's motion (its TCP moves and gripper ramp) once ``arm``'s hand feels
    ``force`` N, from contact with the body ``other`` when given, as a real arm's wrist
    sensor ends a move-until-contact; the arm then holds where it was commanded last."""

    arm: str
    force: float
    other: str | None = None
    #: hold the arm's measured joints after a stop (a move, whose command leads the arm
    #: and would push on as it catches up); else the last command (a grip)
    hold_measured: bool = True
    #: a hold keeps this fraction of the command's lead on the arm (a move) or on the
    #: fingers (a grip), so that the hand keeps pushing with about that fraction of the
    #: force it felt (a press must go on pressing; a grip must go on holding)
    keep_lead: float = 0.5
    #: read the fingers only (a grip's squeeze), not the whole hand (a move's touch)
    fingers: bool = False


@dataclass
class Segment:
    """Move the named arms to ``targets`` in a straight line at ``speed`` (m/s), then set
    their grippers (``grippers``, opening in [0, 1]) over ``gripper_steps`` steps, then
    wait ``settle`` steps. Arms not named hold their pose; ``grippers`` may name arms
    that do not move."""

    targets: dict[str, Pose] = field(default_factory=dict)
    speed: float = 0.1
    grippers: dict[str, float] = field(default_factory=dict)
    gripper_steps: int = 0
    settle: int = 0
    label: str = ""
    joint_space: bool = False  # free-space move: interpolate joints to the IK of the target
    branch_of: dict[str, Pose] = field(default_factory=dict)  # joint_space: end on the IK
    # branch that also reaches these poses (the grasp below a hover point)
    joints: dict[str, NDArray[np.float64]] = field(default_factory=dict)  # joint_space: the
    # end joints the plan chose (a branch that follows a path after it), instead of IK
    #: move until these forces are felt (checked every step); an arm whose guard is felt
    #: stops, the others go on until theirs are (two hands closing on one pot together)
    guards: tuple[Guard, ...] = ()


class ArmDriver:
    """One arm's commanded state (TCP pose, joints, gripper) and its IK."""

    def __init__(self, name: str, kinematics, pose: Pose, qpos: NDArray[np.float64],
                 gripper: float) -> None:
        self.name = name
        self.kin = kinematics
        self.pose = pose
        self.q = np.asarray(qpos, dtype=np.float64)
        self.gripper = float(gripper)
        self.ik_misses = 0
        #: joints -> the arm's distance to the hazards watching it, less their hard limits
        #: (m; the careful expert's :class:`~fsvla.experts.clearance.ArmClearance`), and
        #: how much a free-space move's goal should keep along the line that follows it
        self.clearance: Callable[[NDArray[np.float64]], float] | None = None
        self.clear_needed = CLEAR_NEEDED

    def solve_anywhere(self, pose: Pose, branch_of: Pose | None = None) -> NDArray[np.float64]:
        """Joints for ``pose`` on any IK branch (the seeded one when it is within the
        limits, else the nearest of several restarts): the end of a joint-space move.
        With ``branch_of``, on the branch of that pose's comfortable answer."""
        if branch_of is not None:
            q_branch = self.solve_anywhere(branch_of)
            result = self.kin.inverse(tuple(pose.p), pose.quat, seed=q_branch, restarts=0,
                                      max_iterations=300)
            first = np.asarray(result.qpos, dtype=np.float64)
            clear = self.line_clearance(first, pose, branch_of) \
                if self._comfortable(result) else None
            if clear is not None and clear >= self.clear_needed:
                return first
            # a branch from which the straight line on to ``branch_of`` can be followed
            # (one that merely reaches both ends may lose the line in between: a hand
            # pulling a drawer toward the base folds the wrist onto its joint-5 limit), and
            # with an arm-clearance check, the one whose links stay farthest from hazards
            extra = [first] if self._comfortable(result) else []
            if self.clearance is not None:
                turned = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.swivel(
                    branch_of, q_branch), restarts=0, max_iterations=300)
                if self._comfortable(turned):
                    extra.append(np.asarray(turned.qpos, dtype=np.float64))
            other = self.branch_that_tracks(pose, branch_of, extra)
            if other is not None and clear is not None:  # another branch only if clearer
                better = self.line_clearance(other, pose, branch_of)
                return other if better is not None and better > clear + 0.005 else first
            if other is not None:
                return other
            if self._comfortable(result):
                return first
        result = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=0,
                                  max_iterations=300)
        if not self._comfortable(result):
            best, tried = None, [result]
            for seed in (self.q, self.kin.spec.home, *self._seeds()):
                r = self.kin.inverse(tuple(pose.p), pose.quat, seed=seed, restarts=0)
                tried.append(r)
                if self._comfortable(r) and (
                        best is None or _jump(r, self.q) < _jump(best, self.q)):
                    best = r
            # none near home: seeds spread over the whole joint range before giving up (a
            # top-down grasp close to the base has comfortable answers far from home)
            for seed in (self._wide_seeds() if best is None else ()):
                r = self.kin.inverse(tuple(pose.p), pose.quat, seed=seed, restarts=0)
                tried.append(r)
                if self._comfortable(r) and (
                        best is None or _jump(r, self.q) < _jump(best, self.q)):
                    best = r
            if best is None:  # out of comfortable reach: the first answer, clipped to the
                self.ik_misses += 1  # limits, unless that leaves the hand far off (by a
                first = self._clip(result.qpos)  # metre: joints far outside them); then the
                if self._miss(first, pose) <= FAR_MISS:  # answer that comes closest
                    return first
                return min((self._clip(r.qpos) for r in tried), key=lambda q: self._miss(q, pose))
            result = best
        return self._clip(result.qpos)

    def attainable(self, pose: Pose) -> Pose:
        """``pose`` turned, by a degree or two, to a rotation the arm holds at its point;
        ``pose`` itself for an arm of six joints or more, or where none is found within
        ATTAIN_TURN. An arm of fewer cannot turn its hand every way at a point, and the
        solver's answer then gives up position rather than turn (an SO-101's grasp
        leaning out, 35 cm from its base, ended 1.3 cm beside the block). Each round
        takes the rotation the answer holds, and as far again beyond it (half the miss
        went each round without; with it, one or two rounds reach a tenth of a
        millimetre)."""
        if len(self.q) >= 6:
            return pose
        q, R = copy.copy(self).solve_anywhere(pose), pose.R
        for _ in range(ATTAIN_ROUNDS):
            tcp = self.kin.tcp_pose(q)
            if float(np.linalg.norm(np.asarray(tcp.p) - pose.p)) < ATTAINED:
                return Pose(pose.p, R) if rotation_angle(R, pose.R) <= ATTAIN_TURN else pose
            R = slerp(R, quat_to_matrix(tcp.q), 2.0)
            q = np.asarray(self.kin.inverse(tuple(pose.p), matrix_to_quat(R), seed=q, restarts=0,
                                            max_iterations=300).qpos, dtype=np.float64)
        return self._yawed(pose, q)

    def _yawed(self, pose: Pose, seed: NDArray[np.float64]) -> Pose:
        """``pose`` turned about the vertical by the least miss within ATTAIN_YAW, where
        that is held (within ATTAINED of its point); else ``pose``. An arm of five joints
        whose TCP sits off its wrist's roll axis holds a hand pointing level or pitched
        down, fingers closing level, only a few degrees off the line from its base (an
        SO-101's, 34 cm out: 6 degrees), which the rounds above close on only slowly."""
        misses: dict[float, float] = {}

        def turned(yaw: float) -> NDArray[np.float64]:
            return axis_angle_matrix(np.array([0.0, 0.0, 1.0]), yaw) @ pose.R

        def miss(yaw: float) -> float:
            if yaw not in misses:
                answer = self.kin.inverse(tuple(pose.p), matrix_to_quat(turned(yaw)), seed=seed,
                                          restarts=0, max_iterations=300)
                q = np.asarray(answer.qpos, dtype=np.float64)
                misses[yaw] = float(np.linalg.norm(np.asarray(self.kin.tcp_pose(q).p) - pose.p))
            return misses[yaw]

        yaws = [float(y) for y in np.linspace(-ATTAIN_YAW, ATTAIN_YAW, ATTAIN_YAWS)]
        step = yaws[1] - yaws[0]
        best = min(yaws, key=miss)
        while step > 1e-3:  # down to a twentieth of a degree
            step /= 2
            best = min((best - step, best, best + step), key=miss)
        return Pose(pose.p, turned(best)) if miss(best) < ATTAINED else pose

    def _clip(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.clip(np.asarray(q, dtype=np.float64), self.kin.limits[:, 0], self.kin.limits[:, 1])

    def _miss(self, q: NDArray[np.float64], pose: Pose) -> float:
        """How far the TCP at joints ``q`` is from ``pose`` (m; 1 cm per 0.1 rad of turn),
        with a centimetre per radian that the joints move from the last command."""
        tcp = self.kin.tcp_pose(q)
        return (float(np.linalg.norm(np.asarray(tcp.p) - pose.p))
                + 0.1 * rotation_angle(quat_to_matrix(tcp.q), pose.R)
                + 0.01 * float(np.max(np.abs(q - self.q))))

    def tracks(self, q: NDArray[np.float64], start: Pose, end: Pose) -> bool:
        """Whether the straight line from ``start`` (at joints ``q``) to ``end`` is solved
        at every step on ``q``'s branch, at least TRACK_MARGIN inside the joint limits."""
        return self.line_clearance(q, start, end, check=False) is not None

    def line_clearance(self, q: NDArray[np.float64], start: Pose, end: Pose,
                       check: bool = True) -> float | None:
        """None unless the straight line from ``start`` (at joints ``q``) to ``end`` is
        solved at every step on ``q``'s branch, at least TRACK_MARGIN inside the joint
        limits; else the arm's smallest :attr:`clearance` along it (inf without one)."""
        trial = copy.copy(self)
        trial.q, trial.pose, trial.ik_misses = np.asarray(q, dtype=np.float64), start, 0
        lo, hi = self.kin.limits[:, 0] + TRACK_MARGIN, self.kin.limits[:, 1] - TRACK_MARGIN
        n = max(1, int(np.ceil(float(np.linalg.norm(end.p - start.p)) / TRACK_STEP)),
                int(np.ceil(rotation_angle(start.R, end.R) / (10 * TRACK_STEP))))
        measure = self.clearance if check else None
        clear = float("inf") if measure is None else measure(trial.q)
        for i in range(1, n + 1):
            s = i / n
            q_i = trial.solve(Pose(start.p + s * (end.p - start.p), slerp(start.R, end.R, s)))
            if trial.ik_misses or np.any(q_i < lo) or np.any(q_i > hi):
                return None
            trial.q = q_i
            if measure is not None:
                clear = min(clear, measure(q_i))
        return clear

    def branch_that_tracks(self, pose: Pose, branch_of: Pose,
                           extra: Sequence[NDArray[np.float64]] = ()) -> NDArray[np.float64] | None:
        """Comfortable joints for ``pose`` from which the line to ``branch_of`` is followed
        (:meth:`line_clearance`): the nearest the present joints of those in ``extra`` whose
        arm stays clear of the hazards by ``clear_needed``; else, among them and the answers
        from several seeds, the clearest, then the nearest; None if none is followed."""
        best: NDArray[np.float64] | None = None
        best_key: tuple[float, float] | None = None

        def consider(q: NDArray[np.float64]) -> None:
            nonlocal best, best_key
            jump = float(np.max(np.abs(q - self.q)))
            if best_key is not None and best_key[0] >= self.clear_needed and jump >= -best_key[1]:
                return  # one clear enough and nearer is already found
            clear = self.line_clearance(q, pose, branch_of)
            if clear is None:
                return
            key = (round(min(clear, self.clear_needed), 3), -jump)
            if best_key is None or key > best_key:
                best, best_key = q, key

        for q in extra:  # on the branch the plan was on: kept when clear enough
            consider(q)
        if best_key is not None and best_key[0] >= self.clear_needed:
            return best
        for seed in (self.q, self.kin.spec.home, *self._seeds()):
            rb = self.kin.inverse(tuple(branch_of.p), branch_of.quat, seed=seed, restarts=0,
                                  max_iterations=300)
            if not self._comfortable(rb):
                continue
            r = self.kin.inverse(tuple(pose.p), pose.quat, seed=rb.qpos, restarts=0,
                                 max_iterations=300)
            if self._comfortable(r):
                consider(np.asarray(r.qpos, dtype=np.float64))
        return best

    def swivel(self, pose: Pose, q: NDArray[np.float64], steps: int = 40,
               step: float = 0.08) -> NDArray[np.float64]:
        """Joints for ``pose`` turned from ``q`` about the arm's self-motion (the elbow's
        swivel of a 7-joint arm, the hand held still) to where :attr:`clearance` first
        reaches ``clear_needed`` and a little more, or is largest; ``q`` without a
        clearance measure."""
        if self.clearance is None:
            return q
        # a little more than needed: the line that follows drifts back part of the way
        enough = self.clear_needed + 0.015
        best, best_clear = np.asarray(q, dtype=np.float64), self.clearance(q)
        if best_clear >= enough:
            return best
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        for sign in (1.0, -1.0):
            cur, prev = np.asarray(q, dtype=np.float64), None
            for _ in range(steps):
                n = self._null(cur)
                if n is None:
                    break
                direction = sign * n if prev is None else (n if n @ prev >= 0 else -n)
                prev = direction
                r = self.kin.inverse(tuple(pose.p), pose.quat, seed=cur + step * direction,
                                     restarts=0, max_iterations=100)
                q_next = np.asarray(r.qpos, dtype=np.float64)
                if (not r.ok(position_tol=2e-3, rotation_tol=2e-2) or np.any(q_next < lo)
                        or np.any(q_next > hi)):
                    break
                cur = q_next
                clear = self.clearance(cur)
                if clear > best_clear + 1e-4:
                    best, best_clear = cur, clear
                    if clear >= enough:
                        break
        return best

    def _null(self, q: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """A unit joint direction that moves the TCP least (the Jacobian's null space)."""
        if len(q) < 7:
            return None
        base = self.kin.tcp_pose(q)
        p0, R0 = np.asarray(base.p), quat_to_matrix(base.q)
        J = np.zeros((6, len(q)))
        h = 1e-4
        for j in range(len(q)):
            dq = np.array(q, dtype=np.float64)
            dq[j] += h
            moved = self.kin.tcp_pose(dq)
            rel = R0.T @ quat_to_matrix(moved.q)
            J[:3, j] = (np.asarray(moved.p) - p0) / h
            J[3:, j] = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0],
                                 rel[1, 0] - rel[0, 1]]) / (2 * h)
        _, _, vt = np.linalg.svd(J)
        return vt[-1] / np.linalg.norm(vt[-1])

    def _comfortable(self, result) -> bool:
        """An exact answer at least LIMIT_MARGIN inside every joint limit (a Panda whose
        elbow is folded to its limit hits its own shoulder)."""
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        return bool(result.ok(position_tol=2e-3, rotation_tol=2e-2)
                    and np.all(result.qpos >= lo) and np.all(result.qpos <= hi))

    def _seeds(self) -> list[NDArray[np.float64]]:
        rng = np.random.default_rng(0)
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        home = np.asarray(self.kin.spec.home, dtype=np.float64)
        return [np.clip(home + rng.normal(0.0, 0.6, home.shape), lo, hi) for _ in range(16)]

    def _wide_seeds(self) -> list[NDArray[np.float64]]:
        rng = np.random.default_rng(1)
        lo, hi = self.kin.limits[:, 0] + LIMIT_MARGIN, self.kin.limits[:, 1] - LIMIT_MARGIN
        return [rng.uniform(lo, hi) for _ in range(48)]

    def solve(self, pose: Pose) -> NDArray[np.float64]:
        """Joints for ``pose``, seeded by the last command; the closest answer if none is
        exact (counted in ``ik_misses``)."""
        result = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=0,
                                  max_iterations=200)
        if not result.ok(position_tol=2e-3, rotation_tol=2e-2):
            retry = self.kin.inverse(tuple(pose.p), pose.quat, seed=self.q, restarts=6)
            # along a straight segment, never jump to another IK branch
            if _jump(retry, self.q) < MAX_JOINT_STEP and _rank(retry, self.q) < _rank(result, self.q):
                result = retry
            if not result.ok(position_tol=5e-3, rotation_tol=5e-2):
                self.ik_misses += 1
                # a pose well out of reach: the closest answer the solver wandered to may
                # be a swing across the workspace in one control step; stay where it is
                if result.position_error > OUT_OF_REACH and _jump(result, self.q) > MAX_JOINT_STEP:
                    return self.q.copy()
        return np.clip(result.qpos, self.kin.limits[:, 0], self.kin.limits[:, 1])


def _jump(result, seed: NDArray[np.float64]) -> float:
    return float(np.max(np.abs(result.qpos - seed)))


def _rank(result, seed: NDArray[np.float64]) -> tuple[bool, float]:
    jump = float(np.max(np.abs(result.qpos - seed)))
    return (not result.ok(position_tol=5e-3, rotation_tol=5e-2),
            result.position_error + 0.1 * result.rotation_error + 0.01 * jump)


@dataclass(frozen=True)
class Step:
    """One control step's command for every arm: joints, TCP pose and gripper."""

    q: dict[str, NDArray[np.float64]]
    pose: dict[str, Pose]
    gripper: dict[str, float]
    label: str = ""
    guards: tuple[Guard, ...] = ()  # read the hands' forces before this step; stop if felt


def expand(segment: Segment, drivers: Mapping[str, ArmDriver], dt: float,
           angular_speed: float) -> list[Step]:
    """The per-step commands of ``segment``; updates the drivers' commanded state."""
    steps: list[Step] = []
    n = 1
    for name, target in segment.targets.items():
        d = drivers[name]
        dist = float(np.linalg.norm(target.p - d.pose.p))
        turn = rotation_angle(d.pose.R, target.R)
        n = max(n, int(np.ceil(dist / max(segment.speed * dt, 1e-6))),
                int(np.ceil(turn / max(angular_speed * dt, 1e-6))))
    if segment.targets and segment.joint_space and not segment.joints and _straight_line_ok(
            segment, drivers, dt, angular_speed):
        segment = replace(segment, joint_space=False, branch_of={}, joints={})
    if segment.targets and segment.joint_space:
        q0 = {name: drivers[name].q.copy() for name in segment.targets}
        q1 = {name: np.asarray(segment.joints[name], dtype=np.float64) if name in segment.joints
              else drivers[name].solve_anywhere(t, segment.branch_of.get(name))
              for name, t in segment.targets.items()}
        paths = {name: _joint_path(drivers[name].kin, q0[name], q1[name]) for name in q0}
        n = max(n, max(int(np.ceil(path.length / (angular_speed * dt))) for path in paths.values()))
        for i in range(1, n + 1):
            s = _ease(i / n)
            for name in segment.targets:
                d = drivers[name]
                d.q = paths[name].at(s)
                tcp = d.kin.tcp_pose(d.q)
                d.pose = Pose.of(tcp.p, quat_to_matrix(tcp.q))
            steps.append(_snapshot(drivers, segment.label))
    elif segment.targets:
        starts = {name: drivers[name].pose for name in segment.targets}
        for i in range(1, n + 1):
            s = _ease(i / n)
            for name, target in segment.targets.items():
                a = starts[name]
                pose = Pose(a.p + s * (target.p - a.p), slerp(a.R, target.R, s))
                d = drivers[name]
                q = d.solve(pose)
                d.pose, d.q = pose, q
            steps.append(_snapshot(drivers, segment.label))
    if segment.grippers:
        k = max(1, segment.gripper_steps)
        starts_g = {name: drivers[name].gripper for name in segment.grippers}
        for i in range(1, k + 1):
            for name, g in segment.grippers.items():
                drivers[name].gripper = starts_g[name] + (g - starts_g[name]) * i / k
            steps.append(_snapshot(drivers, segment.label))
    if segment.guards:
        steps = [replace(step, guards=segment.guards) for step in steps]
    for _ in range(segment.settle):
        steps.append(_snapshot(drivers, segment.label))
    return steps


def _straight_line_ok(segment: Segment, drivers: Mapping[str, ArmDriver], dt: float,
                      angular_speed: float) -> bool:
    """Whether a free-space segment can be a Cartesian straight line on the current IK
    branch (every step solved, comfortably inside the limits at its end)."""
    import copy

    trial = {name: copy.copy(d) for name, d in drivers.items()}
    for d in trial.values():
        d.ik_misses = 0
    straight = Segment(segment.targets, segment.speed, label=segment.label)
    steps = expand(straight, trial, dt, angular_speed)
    for name in segment.targets:
        d = trial[name]
        lo = d.kin.limits[:, 0] + LIMIT_MARGIN
        hi = d.kin.limits[:, 1] - LIMIT_MARGIN
        if d.ik_misses or np.any(d.q < lo) or np.any(d.q > hi):
            return False
        if d.clearance is not None and steps:
            # the arm's links must not cross a hard limit on the way that they are clear
            # of at both ends (a seven-joint arm's elbow swings as the hand goes across)
            ends = min(d.clearance(drivers[name].q), d.clearance(d.q))
            if min(d.clearance(step.q[name]) for step in steps) < min(0.0, ends) - CROSS_SLACK:
                return False
        branch = segment.branch_of.get(name)
        if branch is not None:  # the straight line on to the next pose must be followed,
            clear = d.line_clearance(d.q, d.pose, branch)  # the arm clear of the hazards
            if clear is None:
                return False
            if clear < d.clear_needed:  # unless no other branch is clearer
                other = copy.copy(drivers[name]).solve_anywhere(segment.targets[name], branch)
                alternative = d.line_clearance(other, segment.targets[name], branch)
                if alternative is not None and alternative > clear + 0.005:
                    return False
    return True


#: How far (m) past a hard limit a free-space straight line may take the arm's links
#: (its clearance measure) before the move goes in joint space instead.
CROSS_SLACK = 0.001
#: How far (m) a joint-space move may take the TCP below the lower of its two ends, and
#: how high above the table (z = 0) it must stay, before it goes by way of the arm's home:
#: an arm changing IK branch may swing its hand down into the table on the straight line
#: between the two joint vectors.
DIP = 0.02
FLOOR = 0.03
#: Joint configurations checked along each straight piece of a joint-space move.
DIP_SAMPLES = 24


@dataclass(frozen=True)
class JointPath:
    """A joint-space move: straight lines between joint waypoints, walked by the largest
    joint's travel (rad or m)."""

    waypoints: tuple[NDArray[np.float64], ...]

    @property
    def length(self) -> float:
        return float(sum(np.max(np.abs(b - a)) for a, b in pairwise(self.waypoints)))

    def at(self, s: float) -> NDArray[np.float64]:
        """The joints a fraction ``s`` (0-1) of the way along."""
        total = self.length
        if total <= 0.0:
            return self.waypoints[-1].copy()
        left = s * total
        for a, b in pairwise(self.waypoints):
            piece = float(np.max(np.abs(b - a)))
            if left <= piece or b is self.waypoints[-1]:
                return a + min(1.0, left / piece if piece > 0 else 1.0) * (b - a)
            left -= piece
        return self.waypoints[-1].copy()


def _lowest_tcp(kin, a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """The TCP's lowest height (m) on the joint-space line from ``a`` to ``b``."""
    return min(float(kin.tcp_pose(a + s * (b - a)).p[2])
               for s in np.linspace(0.0, 1.0, DIP_SAMPLES))


def _joint_path(kin, q0: NDArray[np.float64], q1: NDArray[np.float64]) -> JointPath:
    """The straight joint-space move from ``q0`` to ``q1``, or, where it takes the TCP more
    than DIP below both ends and lower than FLOOR, the move by way of the arm's home
    configuration when that keeps the TCP higher."""
    floor = min(float(kin.tcp_pose(q0).p[2]), float(kin.tcp_pose(q1).p[2])) - DIP
    direct = _lowest_tcp(kin, q0, q1)
    if direct >= min(floor, FLOOR):
        return JointPath((q0, q1))
    home = np.clip(np.asarray(kin.spec.home, dtype=np.float64), kin.limits[:, 0], kin.limits[:, 1])
    via = min(_lowest_tcp(kin, q0, home), _lowest_tcp(kin, home, q1))
    return JointPath((q0, home, q1)) if via > direct + DIP else JointPath((q0, q1))


def _ease(s: float) -> float:
    """Smooth start and stop (cubic ease in/out) along a segment."""
    return s * s * (3.0 - 2.0 * s)


def _snapshot(drivers: Mapping[str, ArmDriver], label: str) -> Step:
    return Step(q={n: d.q.copy() for n, d in drivers.items()},
                pose={n: d.pose for n, d in drivers.items()},
                gripper={n: d.gripper for n, d in drivers.items()}, label=label)


__all__ = ["ArmDriver", "Guard", "Pose", "Segment", "Step", "expand"]
