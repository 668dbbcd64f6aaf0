"""The simulator seam: what fsvla reads from a running scene and what it changes in its look.

The safety monitor (``fsvla.monitor``) reads a scene through :class:`MonitoredScene` and
the :class:`StepProbe` it makes; the experts (``fsvla.experts``) read it through
:class:`SceneState` and plan with an :class:`ArmModel`; the visual variation
(``fsvla.variation.apply``) changes pictures through :class:`SceneAppearance`. They depend
on these protocols only, never on a simulator, so a second back-end plugs in by
implementing them. ``fsvla.sim`` implements them for SAPIEN: :class:`fsvla.sim.BuiltScene`
is a :class:`MonitoredScene` (its probe a :class:`fsvla.sim.probe.Probe`) and a
:class:`SceneState` (its :meth:`arm_model` an :class:`fsvla.sim.kinematics.ArmKinematics`),
and ``BuiltScene.appearance()`` returns an :class:`fsvla.sim.appearance.SapienAppearance`.

The protocols live here, beside ``fsvla.sim`` rather than in it, because ``fsvla.sim`` is
the SAPIEN back-end: a consumer that imported them from there would name the back-end it
means to be free of. This module imports numpy alone.

Names are the scene spec's (bodies, articulated bodies' links and joints, zones, arms,
cameras). Poses are in the world (table) frame, quaternions (w, x, y, z) as everywhere in
fsvla (``fsvla.compiler.pose``). A pose read is anything with ``p`` and ``q``
(:class:`PoseReading`), in whatever float dtype the simulator keeps, so arithmetic on it is
the simulator's own numbers; :class:`WorldPose` is the plain one to build. :func:`pad_gap`
is the one measure of a gripper's shut fingers both sides compute on their hulls.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from fsvla.compiler.assets.model import Shape
    from fsvla.compiler.scene import SceneSpec
    from fsvla.embodiments.spec import ArmSpec
    from fsvla.monitor.contacts import ContactFilter
    from fsvla.monitor.state import WorldState as MonitorState

Color = tuple[float, ...]  # RGB or RGBA, linear, in [0, 1]
Undo = Callable[[], None]  # takes back the change that returned it


class PoseReading(Protocol):
    """A pose: ``p`` the position (3,), ``q`` the (w, x, y, z) quaternion (4,)."""

    @property
    def p(self) -> NDArray[np.floating]: ...

    @property
    def q(self) -> NDArray[np.floating]: ...


class WorldPose(NamedTuple):
    """A plain :class:`PoseReading`."""

    p: NDArray[np.floating]
    q: NDArray[np.floating]


# --- reading the state ------------------------------------------------------------------


@dataclass(frozen=True)
class IKResult:
    """An IK answer, checked by forward kinematics."""

    qpos: NDArray[np.float64]  # the arm's joints, in the spec's order
    converged: bool  # the solver's own verdict
    position_error: float  # metres, |FK(qpos) TCP - target|
    rotation_error: float  # radians, angle between FK(qpos) TCP and target orientation
    within_limits: bool  # every joint inside its URDF limits

    def ok(self, position_tol: float = 0.01, rotation_tol: float = 0.05) -> bool:
        return (
            self.within_limits
            and self.position_error <= position_tol
            and self.rotation_error <= rotation_tol
        )


class ArmModel(Protocol):
    """Forward and inverse kinematics of one arm, in the world frame; joints not the arm's
    stay where they are in the scene. Links are indexed by :attr:`link_names` (every link
    of the robot that carries the arm)."""

    @property
    def spec(self) -> ArmSpec: ...

    @property
    def limits(self) -> NDArray[np.float64]:
        """(n, 2) lower and upper limits of the arm's joints, in the spec's order."""
        ...

    @property
    def link_names(self) -> tuple[str, ...]: ...

    def tcp_pose(self, arm_q: Sequence[float] | None = None) -> PoseReading:
        """The TCP at arm joints ``arm_q`` (default: the current ones)."""
        ...

    def inverse(self, position: Sequence[float], orientation: Sequence[float],
                seed: Sequence[float] | None = None, restarts: int = 8,
                max_iterations: int = 500) -> IKResult:
        """Arm joints putting the TCP at ``position`` with ``orientation``, from ``seed``
        (default: home) and up to ``restarts`` more seeds, reproducibly."""
        ...

    def link_poses(self, arm_q: Sequence[float],
                   links: Sequence[int]) -> tuple[NDArray[np.floating], NDArray[np.floating]]:
        """Positions (n, 3) and quaternions (n, 4) of ``links`` at arm joints ``arm_q``."""
        ...

    def finger_points(self, fraction: float) -> NDArray[np.float64]:
        """World positions (n, 3), one per finger link, of the points that lie on the TCP
        when the gripper is closed, with it open by ``fraction`` (the arm as it is)."""
        ...

    def link_vertices(self, link: int) -> NDArray[np.float64] | None:
        """The vertices of a link's convex collision pieces in its own frame (None: none)."""
        ...


class SceneState(Protocol):
    """The state of a running scene, as the experts read it."""

    def body_pose(self, body: str) -> PoseReading:
        """A rigid body's pose, or an articulated body's root pose."""
        ...

    def link_pose(self, body: str, link: str) -> PoseReading:
        """A link of an articulated body."""
        ...

    def joint_position(self, body: str, joint: str) -> float:
        """A joint of an articulated body (rad or m)."""
        ...

    def arm_joints(self, arm: str) -> NDArray[np.float64]:
        """An arm's joint positions, in its spec's order."""
        ...

    def gripper_opening(self, arm: str) -> float:
        """How open an arm's gripper is: 0 closed, 1 open."""
        ...

    def tcp_pose(self, arm: str) -> PoseReading:
        """An arm's tool centre point."""
        ...

    def robot_link_pose(self, arm: str, link: str) -> PoseReading:
        """A link of the robot that carries ``arm``."""
        ...

    def arm_model(self, arm: str) -> ArmModel:
        """A new kinematic model of ``arm`` (callers keep it: it may be costly to make)."""
        ...

    def contact_force(self, arm: str, links: Sequence[str], other: str | None = None) -> float:
        """A force sensor on the hand: the largest net contact force (N) on one of ``arm``'s
        robot ``links`` at the last physics substep, from the scene's bodies (only from
        the body ``other`` when given); contacts between robot links are left out."""
        ...

    def contact_gap(self, arm: str, links: Sequence[str], other: str) -> float | None:
        """How far (m) the nearest of ``arm``'s robot ``links`` is from the body ``other``
        (negative: into it) where the simulator tracks the two as in contact, within its
        contact distance; None where they are farther apart. A proximity sensor on the
        fingers."""
        ...


# --- monitoring --------------------------------------------------------------------------


class StepProbe(Protocol):
    """Reads what the safety monitor needs of a running scene: contact forces folded over
    every physics substep of a control step, and a snapshot at its end. The monitor's
    contact gate sets :attr:`scan` and :attr:`read_last` before each control step."""

    scan: bool  # the coming control step's substeps scan the kept contact pairs
    read_last: bool  # its snapshot reads the last substep's kept contacts

    def reset(self) -> None:
        """Forget what was folded in, and re-read the state (after the scene's reset)."""
        ...

    def record_substep(self) -> None:
        """Fold the physics substep just taken into the control step's maxima."""
        ...

    def snapshot(self, step: int, time: float, *, contacts: bool = False) -> MonitorState:
        """The world now, with the maxima folded in since the last snapshot."""
        ...


class MonitoredScene(Protocol):
    """A running scene as the safety monitor reads it. Frames are named as in
    ``fsvla.monitor.state``: a body, ``"<body>:<link>"``, ``"@<robot>:<link>"``."""

    @property
    def spec(self) -> SceneSpec: ...

    def frames(self) -> Sequence[str]:
        """Every frame the scene has."""
        ...

    def frame_shapes(self, frame: str) -> list[Shape]:
        """A frame's collision shapes, in its own frame (the monitor's geometry of a robot
        link)."""
        ...

    def probe(self, timestep: float, *, pose_frames: Sequence[str], free_bodies: Sequence[str],
              torque_frames: Sequence[str], scan: ContactFilter, last: ContactFilter,
              joints: Mapping[str, tuple[str, str]],
              gravity: tuple[float, float, float]) -> StepProbe:
        """A probe that reads ``pose_frames``' poses, the net contact force (and, for
        ``torque_frames``, torque) of each free body in ``free_bodies`` from its velocity
        change, the contact pairs ``scan`` keeps at every substep and those ``last`` keeps
        at the last, and the joints ``joints`` maps (state name -> (body, joint); joints
        the body lacks are left out)."""
        ...


# --- changing the look ------------------------------------------------------------------


class Light(Protocol):
    """One light of the scene (the ambient light is :attr:`SceneAppearance.ambient`)."""

    @property
    def directional(self) -> bool: ...

    @property
    def color(self) -> Color: ...

    @color.setter
    def color(self, value: Color) -> None: ...

    @property
    def pose(self) -> PoseReading:
        """Where it is; a directional light shines along its +x."""
        ...

    @pose.setter
    def pose(self, value: PoseReading) -> None: ...


class Material(Protocol):
    """A surface material of a body's visual."""

    @property
    def base_color(self) -> Color:
        """RGBA."""
        ...

    @base_color.setter
    def base_color(self, value: Color) -> None: ...


class Camera(Protocol):
    """A camera: where it is, and how it projects (OpenCV conventions: x right, y down,
    z forward)."""

    @property
    def pose(self) -> PoseReading:
        """Its pose; it looks along its +x, +z up (only a world-mounted camera is moved)."""
        ...

    @pose.setter
    def pose(self, value: PoseReading) -> None: ...

    def move(self, offset: Sequence[float], yaw: float, pitch: float) -> None:
        """Shift it by ``offset`` (world) from where it is, and turn it in its own frame by
        ``yaw`` about its +z, then ``pitch`` about its +y (a pan and a tilt), composing in
        the simulator's own pose arithmetic (so a shifted view is the one it always gave)."""
        ...

    def intrinsic(self) -> NDArray[np.float64]:
        """3 × 3 intrinsic matrix (pixels)."""
        ...

    def extrinsic(self) -> NDArray[np.float64]:
        """3 × 4 world-to-camera matrix."""
        ...


class SceneAppearance(Protocol):
    """How a rendering scene looks, and the changes the visual variation makes to it.
    Nothing here may touch physics: an episode's states are the same whatever its look."""

    @property
    def ambient(self) -> Color:
        """The ambient light's RGB."""
        ...

    @ambient.setter
    def ambient(self, value: Color) -> None: ...

    def names(self) -> Sequence[str]:
        """The bodies, articulated bodies and zones that have a look here."""
        ...

    def lights(self) -> Sequence[Light]: ...

    def materials(self, name: str) -> Sequence[Material]:
        """Every material of the visuals of body or zone ``name`` (an articulated body's
        links' too)."""
        ...

    def camera(self, name: str) -> Camera: ...

    def paint(self, name: str, texture: NDArray[np.uint8], period: float) -> Undo:
        """Cover ``name``'s visuals with the RGBA ``texture``, projected from above, one
        repeat per ``period`` metres, its materials' other properties kept."""
        ...

    def add_occluder(self, name: str, pose: PoseReading, half_size: Sequence[float],
                     color: Color) -> Undo:
        """Add a box seen by the cameras and by nothing else (no collision, no mass)."""
        ...

    def add_patch(self, name: str, corners: NDArray[np.floating],
                  image: NDArray[np.uint8]) -> Undo:
        """Fix a flat quad showing the RGB(A) ``image`` to body or zone ``name`` (an
        articulated body's root), seen by the cameras and by nothing else (no collision,
        no mass): ``corners`` (4 × 3, in that body's frame) are where the image's top-left,
        top-right, bottom-right and bottom-left corners go; the image shows from the side
        its normal ``(c1 - c0) x (c0 - c3)`` points to. It moves with the body."""
        ...


def pad_gap(fingers: Sequence[NDArray[np.float64]], tcp: NDArray[np.float64],
            across: NDArray[np.float64], back: NDArray[np.float64], depth: float) -> float:
    """How far apart (m) the fingers' pads are across the closing axis ``across`` (unit):
    of each finger's hull ``fingers`` (world points), what lies within ``depth`` behind the
    TCP at ``tcp`` (``back``: unit, from the TCP back into the hand), each finger on the side
    of the TCP its pad lies on; 0 where the pads meet or one side has none."""
    sides: dict[bool, list[float]] = {True: [], False: []}
    for points in fingers:
        rel = np.asarray(points, dtype=np.float64) - tcp
        pads = rel[rel @ back < depth] @ across
        if len(pads):
            positive = float(np.mean(pads)) > 0.0
            sides[positive].append(float(np.min(pads)) if positive else float(np.max(pads)))
    if not sides[True] or not sides[False]:
        return 0.0
    return max(0.0, min(sides[True]) - max(sides[False]))


__all__ = ["ArmModel", "Camera", "Color", "IKResult", "Light", "Material", "MonitoredScene",
           "PoseReading", "SceneAppearance", "SceneState", "StepProbe", "Undo", "WorldPose",
           "pad_gap"]
