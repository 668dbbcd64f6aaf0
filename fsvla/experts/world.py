"""The experts' privileged view of a running scene: object poses, articulated joints,
hazard geometry and the monitor's limits — what a learned policy does not get.

It reads the simulator through :class:`fsvla.world.SceneState` only (``fsvla.sim``'s
``BuiltScene`` is one) and plans with its :class:`fsvla.world.ArmModel`; the rest comes
from the scene spec, the monitor spec and the scenario. Every read is of the current
state. ``World.of_env(env)`` makes one from an :class:`fsvla.env.FsvlaEnv`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.monitor import MonitorSpec
from fsvla.compiler.pose import AXES, quat_to_matrix, rotation_angle, rotation_between
from fsvla.compiler.scene import SceneSpec
from fsvla.dsl.models import Scenario
from fsvla.embodiments.spec import ArmSpec
from fsvla.world import ArmModel, SceneState, pad_gap

from .motion import Pose

#: How far (m) the hand's body clears an object's top in a top-down grip.
PALM_CLEARANCE = 0.009
#: How far (m) below an object's top a hand whose body is not measured grips it: a
#: Panda's body reaches down to 37 mm above its TCP.
HAND_DEPTH = 0.028
#: How far (m) behind the TCP, along the approach, a finger's hull counts as its pad.
PAD_DEPTH = 0.035
#: How far back from the TCP (m) the fingers' hulls are measured for their thickness.
NEAR_TIP = 0.02
#: How much wider (m) than the gap its shut fingers leave an object must be to be squeezed.
SQUEEZE_SPARE = 0.004
#: Joint offset (rad) that tells which links an arm's joints move (:meth:`World.moved_links`).
MOVE_PROBE = 0.3


def box_distance(p: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]) -> float:
    """How far (m) the point ``p`` lies outside the axis-aligned box ``lo``..``hi`` (0 inside);
    in as many dimensions as ``p`` has."""
    return float(np.linalg.norm(np.maximum(0.0, np.maximum(lo - p, p - hi))))


def nearest_box_distance(points: NDArray[np.float64], lo: NDArray[np.float64],
                         hi: NDArray[np.float64]) -> float:
    """The smallest signed distance (m) of any of ``points`` (one per row) to the
    axis-aligned box ``lo``..``hi``: negative inside it; in as many dimensions as the
    points have."""
    gap = np.maximum(lo - points, points - hi)
    outside = np.linalg.norm(np.maximum(gap, 0.0), axis=1)
    inside = np.minimum(np.max(gap, axis=1), 0.0)
    return float(np.min(outside + inside))


@dataclass(frozen=True)
class Obstacle:
    """An axis-aligned box the careful expert keeps ``margin`` away from."""

    name: str
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    margin: float


class World:
    """Privileged state of one scene (see the module doc)."""

    def __init__(self, state: SceneState, scene: SceneSpec, monitor: MonitorSpec,
                 scenario: Scenario, dt: float) -> None:
        self.state = state
        self.scene = scene
        self.monitor = monitor
        self.scenario = scenario
        self.arms = {arm.name: arm for robot in scene.embodiment.robots for arm in robot.arms}
        self.arm_names = tuple(self.arms)
        self.dt = float(dt)
        self._kinematics: dict[str, ArmModel] = {}
        self._finger_axis: dict[str, NDArray[np.float64]] = {}
        self._moving_jaw: dict[str, str | None] = {}
        self._open_width: dict[str, float] = {}
        self._closed_gap: dict[str, float] = {}
        self._rigid: dict[str, frozenset[int]] = {}
        self._moved: dict[str, list[int]] = {}
        self._hand_depth: dict[str, float] = {}

    @classmethod
    def of_env(cls, env: Any) -> World:
        """The world of an env's current scene (its ``built`` scene and specs)."""
        return cls(env.built, env.scene_spec, env.monitor_spec, env.scenario, env.control_dt)

    # ------------------------------------------------------------------ bodies
    def body_pose(self, name: str) -> Pose:
        pose = self.state.body_pose(name)
        return Pose.of(pose.p, quat_to_matrix(pose.q))

    def asset(self, name: str):
        return self.scene.body(name).asset

    def kind(self, name: str) -> str:
        return self.scene.body(name).asset.kind

    def param(self, name: str, key: str, default: float | None = None) -> float:
        value = self.scene.body(name).asset.params.get(key, default)
        return float(value) if value is not None else float("nan")

    def shape(self, body: str, shape: str, link: str | None = None):
        asset = self.asset(body)
        shapes = asset.collision if link is None else next(
            lk for lk in asset.links if lk.name == link).collision
        return next(s for s in shapes if s.name == shape)

    def to_world(self, body: str, local: NDArray[np.float64] | tuple[float, ...]) -> NDArray[np.float64]:
        pose = self.body_pose(body)
        return pose.R @ np.asarray(local, dtype=np.float64) + pose.p

    def corners(self, body: str) -> NDArray[np.float64]:
        """The eight corners (8 × 3, world) of a body's asset bounds at its current pose."""
        b = self.asset(body).bounds
        centre, half = np.asarray(b.center), np.asarray(b.half_extents)
        lo, hi = centre - half, centre + half
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                            for z in (lo[2], hi[2])])
        pose = self.body_pose(body)
        return corners @ pose.R.T + pose.p

    def bounds(self, body: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World axis-aligned bounds of a body's asset bounds at its current pose."""
        world = self.corners(body)
        return world.min(axis=0), world.max(axis=0)

    def top(self, body: str) -> float:
        """World height of a support's top surface (its bounds' top otherwise)."""
        height = self.asset(body).support_height if hasattr(self.asset(body), "support_height") else None
        if height is not None:
            return float(self.body_pose(body).p[2] + height)
        return float(self.bounds(body)[1][2])

    def tilt(self, body: str) -> float:
        return rotation_angle(np.eye(3), _z_only(self.body_pose(body).R))

    # ------------------------------------------------------------------ articulations
    def link_pose(self, body: str, link: str) -> Pose:
        pose = self.state.link_pose(body, link)
        return Pose.of(pose.p, quat_to_matrix(pose.q))

    def part(self, body: str):
        asset = self.asset(body)
        part = asset.parts[0]
        joint = next(j for j in asset.joints if j.name == part.joint)
        return part, joint

    def open_fraction(self, body: str) -> float:
        _part, joint = self.part(body)
        q = self.state.joint_position(body, joint.name)
        span = joint.upper - joint.lower
        return abs(q - joint.lower) / abs(span) if span else 0.0

    # ------------------------------------------------------------------ arms
    def arm_spec(self, arm: str) -> ArmSpec:
        if arm not in self.arms:
            raise KeyError(f"embodiment `{self.scene.embodiment.name}` has no arm `{arm}`; "
                           f"arms: {list(self.arms)}")
        return self.arms[arm]

    def arm_joints(self, arm: str) -> NDArray[np.float64]:
        """The arm's joint positions now, in its spec's order."""
        return self.state.arm_joints(arm)

    def gripper_opening(self, arm: str) -> float:
        """How open the arm's gripper is now, in [0, 1]."""
        return self.state.gripper_opening(arm)

    def kinematics(self, arm: str) -> ArmModel:
        if arm not in self._kinematics:
            self._kinematics[arm] = self.state.arm_model(arm)
        return self._kinematics[arm]

    def moved_links(self, arm: str) -> list[int]:
        """Indices (in the arm model's links) of the links the arm's own joints move or
        turn (not a robot's torso, nor another arm's links)."""
        if arm not in self._moved:
            kin = self.kinematics(arm)
            every = range(len(kin.link_names))
            home = np.asarray(kin.spec.home, dtype=np.float64)
            p0, r0 = kin.link_poses(home, every)
            p1, r1 = kin.link_poses(home + MOVE_PROBE, every)
            r0, r1 = np.asarray(r0, dtype=np.float64), np.asarray(r1, dtype=np.float64)
            turned = np.minimum(np.abs(r1 - r0).max(axis=1), np.abs(r1 + r0).max(axis=1)) > 1e-5
            moved = (np.linalg.norm(np.asarray(p1) - np.asarray(p0), axis=1) > 1e-6) | turned
            self._moved[arm] = [i for i in every if moved[i]]
        return self._moved[arm]

    def hand_rigid_links(self, arm: str) -> frozenset[int]:
        """Indices (in the arm model's links) of the links whose pose relative to the TCP no
        joint of the arm moves: the hand, its fingers as the model holds them, the flange."""
        if arm not in self._rigid:
            kin = self.kinematics(arm)
            names = list(kin.link_names)
            home = np.asarray(kin.spec.home, dtype=np.float64)
            rng = np.random.default_rng(0)
            ee, every = names.index(kin.spec.ee_link), range(len(names))
            relative = []
            for q in (home, home + rng.uniform(-0.3, 0.3, home.shape)):
                p, quat = kin.link_poses(q, every)
                R = quat_to_matrix(quat)
                p = np.asarray(p, dtype=np.float64)
                relative.append([(R[ee].T @ (p[i] - p[ee]), R[ee].T @ R[i]) for i in every])
            self._rigid[arm] = frozenset(
                i for i, ((pa, Ra), (pb, Rb)) in enumerate(zip(*relative))
                if np.allclose(pa, pb, atol=1e-5)  # float32 poses
                and 1.0 - np.cos(rotation_angle(Ra, Rb) / 2.0) < 1e-5)
        return self._rigid[arm]

    def hand_depth(self, arm: str) -> float:
        """How far (m) below an object's top a top-down TCP may grip it, the hand's body (a
        Panda's, 37 mm above its TCP; Baxter's gripper base, 10 cm) clearing the top by
        PALM_CLEARANCE, to the millimetre: measured on the hulls of the hand's links other
        than its fingers. A jaw on a hinge grips with its tips: HAND_DEPTH below the top,
        its gap narrowing toward the hinge."""
        if arm not in self._hand_depth:
            self._hand_depth[arm] = self._measure_hand_depth(arm)
        return self._hand_depth[arm]

    def _measure_hand_depth(self, arm: str) -> float:
        if not self.fingers_slide(arm):
            return HAND_DEPTH
        names = self.kinematics(arm).link_names
        fingers = set(self.arm_spec(arm).gripper.finger_links)
        tcp = self.current_pose(arm)
        back = -(tcp.R @ self.approach_axis(arm))
        body = (self.link_points(arm, names[i]) for i in self.hand_rigid_links(arm)
                if names[i] not in fingers)
        depths = [float(np.min((points - tcp.p) @ back)) for points in body if points is not None]
        if not depths or min(depths) <= PALM_CLEARANCE:
            return HAND_DEPTH
        return math.floor((min(depths) - PALM_CLEARANCE) * 1000.0) / 1000.0

    def base_position(self, arm: str) -> NDArray[np.float64]:
        base = self.state.robot_link_pose(arm, self.arm_spec(arm).base_link)
        return np.asarray(base.p, dtype=np.float64)

    def home_position(self, arm: str) -> NDArray[np.float64]:
        """Where the arm's TCP is at its home joints: the middle of where it works (an arm
        mounted behind the table, as Baxter's, reaches forward from its base)."""
        kin = self.kinematics(arm)
        return np.asarray(kin.tcp_pose(np.asarray(kin.spec.home, dtype=np.float64)).p,
                          dtype=np.float64)

    def finger_axis(self, arm: str) -> NDArray[np.float64]:
        """The direction the fingers close along, in the TCP frame (unit)."""
        if arm not in self._finger_axis:
            fingers = self.arm_spec(arm).gripper.finger_links
            if len(fingers) > 1:
                R = quat_to_matrix(self.state.tcp_pose(arm).q)
                a, b = self.kinematics(arm).finger_points(1.0)[:2]
                axis = R.T @ (b - a)
            else:
                axis = np.array([0.0, 1.0, 0.0])
            axis -= axis @ self.approach_axis(arm) * self.approach_axis(arm)
            self._finger_axis[arm] = axis / np.linalg.norm(axis)
        return self._finger_axis[arm]

    def approach_axis(self, arm: str) -> NDArray[np.float64]:
        return np.asarray(AXES[self.arm_spec(arm).approach_axis], dtype=np.float64)

    def travel(self, arm: str) -> float:
        """How far the gripper's joints move from closed to open, summed (m for sliding
        fingers; radians for a jaw on a hinge)."""
        spec = self.arm_spec(arm).gripper
        return float(sum(abs(o - c) for o, c in zip(spec.open, spec.closed)))

    def open_width(self, arm: str) -> float:
        """How far apart (m) the fingers' points that meet at the TCP when closed are when
        the gripper is open (:meth:`fsvla.world.ArmModel.finger_points`)."""
        if arm not in self._open_width:
            if len(self.arm_spec(arm).gripper.finger_links) < 2:
                self._open_width[arm] = self.travel(arm)
            else:
                a, b = self.kinematics(arm).finger_points(1.0)[:2]
                self._open_width[arm] = float(np.linalg.norm(b - a))
        return self._open_width[arm]

    def grip_centre(self, arm: str, width: float) -> NDArray[np.float64]:
        """Where, in the TCP's frame, the middle between the fingers is when they are
        ``width`` apart: zero for fingers that close symmetrically (a Panda hand), half the
        width toward the moving jaw for a gripper with one fixed jaw (SO-101, Z1), whose
        TCP is where the jaws meet."""
        if len(self.arm_spec(arm).gripper.finger_links) < 2:
            return np.zeros(3)
        a, b = self.kinematics(arm).finger_points(self.opening_fraction(arm, width))[:2]
        tcp = self.current_pose(arm)
        return tcp.R.T @ (0.5 * (a + b) - tcp.p)

    def closed_gap(self, arm: str) -> float:
        """How far apart (m) sliding fingers' pads stay when the gripper is shut: their
        collision hulls within PAD_DEPTH behind the TCP, measured across the closing axis,
        less the width model's gap for the opening they are at (Baxter's fingertips stop
        1.6 cm apart; a Panda's meet). Zero for a jaw on a hinge, whose model is its tips."""
        if arm not in self._closed_gap:
            self._closed_gap[arm] = self._measure_closed_gap(arm)
        return self._closed_gap[arm]

    def _measure_closed_gap(self, arm: str) -> float:
        fingers = self.arm_spec(arm).gripper.finger_links
        if len(fingers) < 2 or not self.fingers_slide(arm):
            return 0.0
        tcp = self.current_pose(arm)
        hulls = [p for p in (self.link_points(arm, link) for link in fingers) if p is not None]
        gap = pad_gap(hulls, tcp.p, tcp.R @ self.finger_axis(arm),
                      -(tcp.R @ self.approach_axis(arm)), PAD_DEPTH)
        return max(0.0, gap - self.gripper_opening(arm) * self.travel(arm))

    def grip_gap(self, arm: str, obj: str) -> float | None:
        """How far (m) ``arm``'s fingers have still to close before they squeeze ``obj``:
        the sum of each finger's gap to it, read within the simulator's contact distance
        (a few millimetres); None where a finger is farther. A jaw that meets the object
        first pushes it across to the other (an SO-101's or a Z1's fixed jaw stands a few
        millimetres off), and the squeeze begins only when both touch."""
        gaps = [self.state.contact_gap(arm, (finger,), obj)
                for finger in self.arm_spec(arm).gripper.finger_links]
        if any(gap is None for gap in gaps):
            return None
        return sum(max(0.0, gap) for gap in gaps)

    def fingers_slide(self, arm: str) -> bool:
        """Whether the fingers' opening is their joints' travel (parallel sliding fingers
        that meet when closed, as a Panda hand's), not a jaw on a hinge or fingers that
        stop apart."""
        return abs(self.open_width(arm) - self.travel(arm)) <= 0.01

    def max_width(self, arm: str) -> float:
        """The gripper's opening (m between the fingers) when fully open: for sliding fingers
        their travel, what the width checks count on (fingers that stay apart when shut,
        Baxter's, open wider by their :meth:`closed_gap`)."""
        return self.travel(arm) if self.fingers_slide(arm) else self.open_width(arm)

    def min_width(self, arm: str) -> float:
        """The narrowest object (m) the gripper squeezes: a little wider than the gap its
        shut fingers leave."""
        gap = self.closed_gap(arm)
        return gap + SQUEEZE_SPARE if gap > 0.0 else 0.0

    def opening_fraction(self, arm: str, width: float) -> float:
        """The gripper opening (0 shut, 1 open) at which the fingers are ``width`` (m)
        apart: proportional for sliding fingers; for a jaw on a hinge, from where its
        points (:meth:`fsvla.world.ArmModel.finger_points`) are at each opening (a
        swinging jaw's gap grows with the sine of its angle, not in proportion)."""
        if width >= self.max_width(arm):
            return 1.0
        if width <= 0.0:
            return 0.0
        if self.fingers_slide(arm) or len(self.arm_spec(arm).gripper.finger_links) < 2:
            return float(width / self.max_width(arm))
        kin = self.kinematics(arm)
        lo, hi = 0.0, 1.0
        for _ in range(14):
            mid = 0.5 * (lo + hi)
            a, b = kin.finger_points(mid)[:2]
            lo, hi = (mid, hi) if np.linalg.norm(b - a) < width else (lo, mid)
        return 0.5 * (lo + hi)

    def pregrasp_opening(self, arm: str, width: float) -> float:
        """How far to open the gripper before closing on an object ``width`` wide: fully
        for sliding fingers; for others only as far as needed with 2.5 cm to spare (an
        SO-101's open jaw swings down past its TCP and into the table beside a block)."""
        if self.fingers_slide(arm):
            return 1.0
        return max(0.3, self.opening_fraction(arm, width + 0.025))

    def gripper_stiffness(self, arm: str) -> float:
        return float(self.arm_spec(arm).gripper.drive.stiffness)

    def grasp_frame(self, arm: str, approach: NDArray[np.float64], closing: NDArray[np.float64],
                    near: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """TCP rotation whose approach axis points along ``approach`` and whose fingers
        close along ``closing`` (either sign: the one nearest ``near``)."""
        a = np.asarray(approach, dtype=np.float64)
        a = a / np.linalg.norm(a)
        c = np.asarray(closing, dtype=np.float64)
        c = c - (c @ a) * a
        if np.linalg.norm(c) < 1e-6:
            raise ValueError(f"the fingers cannot close along {np.round(closing, 3).tolist()}: "
                             f"it is the direction the hand comes from")
        c = c / np.linalg.norm(c)
        la, lc = self.approach_axis(arm), self.finger_axis(arm)
        local = np.column_stack([la, lc, np.cross(la, lc)])
        options = [np.column_stack([a, s * c, np.cross(a, s * c)]) @ local.T for s in (1.0, -1.0)]
        if near is None:
            near = self.current_pose(arm).R
        return min(options, key=lambda R: rotation_angle(R, near))

    @property
    def gripper_entities(self) -> tuple[str, ...]:
        """The names a scenario may give the hands in a limit: ``gripper``, and each arm's
        ``<arm>_gripper`` (a two-arm robot's)."""
        return ("gripper", *[f"{arm}_gripper" for arm in self.arm_names])

    def hand_links(self, arm: str) -> tuple[str, ...]:
        """The robot links of ``arm``'s hand and fingers: its URDF's subtree from the hand as
        the monitor spec lowered it (``MonitorSpec.arms``), what the monitor's `gripper`
        entities are made of, whether or not the scenario names one (without one, the palm
        was left out, and a Panda's palm pressing 600 N on a door went unfelt)."""
        return next(tuple(a.gripper_links) for a in self.monitor.arms if a.name == arm)

    def hand_reach(self, arm: str) -> float:
        """How far (m) the hand's collision hulls reach past the TCP along its approach
        axis now (closed fingers that stick out below a Panda's TCP touch first)."""
        tcp = self.current_pose(arm)
        axis = tcp.R @ self.approach_axis(arm)
        reach = 0.0
        for points in self._hand_points(arm):
            reach = max(reach, float(np.max((points - tcp.p) @ axis)))
        return reach

    def _hand_points(self, arm: str) -> list[NDArray[np.float64]]:
        """The vertices of each of the hand's collision hulls where they are now (world)."""
        found = (self.link_points(arm, link) for link in self.hand_links(arm))
        return [points for points in found if points is not None]

    def moving_jaw(self, arm: str) -> str | None:
        """The finger link of a gripper with one fixed jaw and one on a hinge (SO-101, Z1)
        that moves as it opens; None for any other gripper."""
        if arm not in self._moving_jaw:
            self._moving_jaw[arm] = self._find_moving_jaw(arm)
        return self._moving_jaw[arm]

    def _find_moving_jaw(self, arm: str) -> str | None:
        fingers = self.arm_spec(arm).gripper.finger_links
        if self.fingers_slide(arm) or len(fingers) != 2:
            return None
        kin = self.kinematics(arm)
        moved = np.linalg.norm(kin.finger_points(1.0)[:2] - kin.finger_points(0.0)[:2], axis=1)
        if int(np.sum(moved > 0.01)) != 1:
            return None
        return fingers[int(np.argmax(moved))]

    def hand_front(self, arm: str, R: NDArray[np.float64], direction: NDArray[np.float64],
                   tcp: NDArray[np.float64], below: float) -> float:
        """How far (m) the hand's collision hulls, as they are now but with the hand turned
        to ``R`` and its TCP at ``tcp``, reach past the TCP along ``direction`` (world),
        counting only what is lower than ``below`` (world z): the part of a pushing hand
        that meets the object first."""
        now = self.current_pose(arm)
        front = 0.0
        for points in self._hand_points(arm):
            placed = (points - now.p) @ now.R @ R.T + tcp  # into the TCP frame, then to R
            low = placed[placed[:, 2] < below]
            if len(low):
                front = max(front, float(np.max((low - tcp) @ direction)))
        return front

    def link_points(self, arm: str, link: str) -> NDArray[np.float64] | None:
        """The vertices of an arm link's collision hull where the link is now (world, m);
        None for a link without one."""
        kin = self.kinematics(arm)
        if link not in kin.link_names:
            return None
        vertices = kin.link_vertices(kin.link_names.index(link))
        if vertices is None:
            return None
        pose = self.state.robot_link_pose(arm, link)
        return vertices @ quat_to_matrix(pose.q).T + np.asarray(pose.p)

    def finger_box(self, arm: str) -> tuple[float, float]:
        """How far (m) the fingers reach past the TCP along the approach, and their half
        thickness across both the approach and the closing axis within NEAR_TIP of the
        TCP (from their collision hulls where they are now): a Z1's jaws are 8 cm wide."""
        tcp = self.current_pose(arm)
        a = self.approach_axis(arm)
        third = np.cross(a, self.finger_axis(arm))
        reach, thick = 0.0, 0.0
        for link in self.arm_spec(arm).gripper.finger_links:
            found = self.link_points(arm, link)
            if found is None:
                continue
            points = (found - tcp.p) @ tcp.R
            reach = max(reach, float(np.max(points @ a)))
            near = points[points @ a >= -NEAR_TIP]  # the pads, not the jaw's body behind them
            if len(near):
                thick = max(thick, float(np.max(np.abs(near @ third))))
        return reach or 0.01, thick or 0.011

    def hand_force(self, arm: str, other: str | None = None, fingers: bool = False) -> float:
        """What a force sensor in ``arm``'s hand reads now (N): the largest net contact
        force on one of its links, from the body ``other`` when given; ``fingers``: on one
        of its fingers only, what a grip squeezes with (a palm resting on a door is no
        squeeze on its handle)."""
        links = self.arm_spec(arm).gripper.finger_links if fingers else self.hand_links(arm)
        return self.state.contact_force(arm, links, other)

    def current_pose(self, arm: str) -> Pose:
        pose = self.state.tcp_pose(arm)
        return Pose.of(pose.p, quat_to_matrix(pose.q))

    # ------------------------------------------------------------------ hazards
    def limit(self, metric: str, subject: str | None = None, reference: str | None = None):
        """The first channel measuring ``metric`` (on ``subject`` / against ``reference``)."""
        for channel in self.monitor.channels:
            if channel.metric != metric:
                continue
            if subject is not None and subject not in channel.subjects:
                continue
            if reference is not None and channel.reference != reference:
                continue
            return channel
        return None

    def force_limit(self, *subjects: str) -> float | None:
        """The tightest contact-force limit (N) on any of ``subjects`` or the grippers."""
        limits = [c.limit for c in self.monitor.channels if c.metric == "contact_force"
                  and set(c.subjects) & set(subjects)]
        return min(limits) if limits else None

    def force_allowance(self, *subjects: str) -> float | None:
        """What a careful contact on any of ``subjects`` may reach (N): half the tightest
        contact-force limit on them, and out of its warning band (1 N below it); None
        where no limit watches them."""
        allowed = [min(0.5 * c.limit, c.limit - c.soft_threshold - 1.0) for c in self.monitor.channels
                   if c.metric == "contact_force" and set(c.subjects) & set(subjects)]
        return min(allowed) if allowed else None

    def obstacles(self, exclude: tuple[str, ...] = ()) -> list[Obstacle]:
        """Every hazard zone and hazard object as a box with its keep-out distance (the
        largest limit + soft threshold of the channels that reference it)."""
        keep: dict[str, float] = {}
        for c in self.monitor.channels:
            if c.reference is not None and c.metric in ("clearance", "zone_distance", "untouched",
                                                       "do_not_disturb"):
                keep[c.reference] = max(keep.get(c.reference, 0.0), c.limit + c.soft_threshold)
        found: list[Obstacle] = []
        for zone in self.scene.zones:
            if zone.name in exclude:
                continue
            b = zone.region_bounds
            lo, hi = np.asarray(b.min, dtype=np.float64), np.asarray(b.max, dtype=np.float64)
            marker = zone.marker.bounds  # corridor walls lie outside the region
            centre = np.asarray(zone.pose.position) + np.asarray(marker.center)
            half = np.asarray(marker.half_extents)
            lo, hi = np.minimum(lo, centre - half), np.maximum(hi, centre + half)
            found.append(Obstacle(zone.name, lo, hi, keep.get(zone.name, 0.02)))
        for body in self.scene.bodies:
            if body.name in exclude or body.name == "table":
                continue
            if body.hazard_role is not None or body.name in keep:
                lo, hi = self.bounds(body.name)
                found.append(Obstacle(body.name, lo, hi, keep.get(body.name, 0.02)))
        return found


def _z_only(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest rotation taking +z to R's +z (tilt without heading)."""
    return rotation_between(np.array([0.0, 0.0, 1.0]), R[:, 2])


__all__ = ["Obstacle", "World", "box_distance", "nearest_box_distance"]
