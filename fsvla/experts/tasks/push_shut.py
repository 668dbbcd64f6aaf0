"""Pushing a hinged panel (a lid, a door) shut with the closed hand, holding nothing: the
hand rests on the panel's outer face and follows the face's arc about the hinge down to
shut. It needs no knob or handle the fingers fit, and no grip an arm of five joints
cannot turn to: the hand may lean on the face at any angle, and the angle changes evenly
along the arc (pointing down the face of a lid standing open, down onto the shut one).

A lid standing past upright is pushed over it from behind and then down; one heavy
enough to overcome its hinge's friction falls the rest of the way ahead of the hand.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix

from ..motion import Guard, Pose, Segment
from ..skills import (
    UP,
    Plan,
    attained,
    branch_for_path,
    first_clear,
    free_speed,
    hand_clearance,
    nearest_arm,
    transit,
)
from ..style import Style
from ..world import World
from .common import push_force
from .hinge import Hinge, hinge
from .lid import smooth_arc

#: Where along the panel (a fraction of its reach from the hinge) the hand pushes: well
#: inside the free edge, where a door's handle or a lid's knob stands.
PUSH_REACH = 0.65
#: The hand's leans on the face (deg, from pointing straight into it toward pointing
#: along it at the hinge) a push is drawn from, at its start and at its end.
LEANS = (90.0, 60.0, 30.0, 0.0, -30.0)
#: How far (m) from the face the hand waits before it moves onto it.
STANDOFF = 0.05
#: How many poses along the arc are checked for one IK branch that follows them.
ARC_POSES = 12
#: How far (m) the hand backs off the shut panel before it rises.
BACK_OFF = 0.03


@dataclass(frozen=True)
class Face:
    """The face of a hinged panel a push shuts it by, in the panel's link frame: the
    point pushed, the face's outward normal there, and the direction along the panel
    away from the hinge."""

    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    outward: NDArray[np.float64]
    edge: NDArray[np.float64]  # the free edge, on the face, across from the point


def pushed_face(world: World, body: str) -> Face:
    """The face of ``body``'s hinged `panel` that a push shuts it by: the side that trails
    as the panel turns shut (a lid's top, a door's front), PUSH_REACH of the way from
    the hinge to the free edge, mid-way along the hinge."""
    part, _joint = world.part(body)
    panel = world.shape(body, "panel", link=part.link)
    h = hinge(world, body)
    along = h.closed.T @ h.axis  # the hinge axis in the panel's frame
    half = np.abs(np.asarray(panel.half_size, dtype=np.float64))
    centre = np.asarray(panel.pose.position, dtype=np.float64)
    thin = np.eye(3)[int(np.argmin(half))]
    # the link's origin is on the hinge: the panel's centre lies out from it
    outward = centre - (centre @ thin) * thin - (centre @ along) * along
    outward /= float(np.linalg.norm(outward))
    # shutting turns the panel negatively about the hinge: a point out along `outward`
    # moves along -(along x outward), so the face whose normal is along x outward trails
    normal = np.cross(along, outward)
    normal = thin * np.sign(float(normal @ thin))
    reach = float(centre @ outward + np.abs(half) @ np.abs(outward))
    root = centre - (centre @ outward) * outward + normal * float(np.abs(half) @ np.abs(normal))
    return Face(root + PUSH_REACH * reach * outward, normal, outward, root + reach * outward)


def push_shut(world: World, style: Style, body: str, angle: float,
              unreachable: Callable[[], Plan] | None = None, instead_of: str = "") -> Plan:
    """Close the fingers, bring the hand onto the panel's pushed face (:func:`pushed_face`)
    from STANDOFF out, follow the face's arc down to ``angle`` (rad) and back away.
    Careful: the hand's lean on the face changes evenly from one of LEANS at the start to
    one at the end, the first pair (the least change first) whose whole arc one IK branch
    follows with the hand clear of the keep-outs (:func:`_first_followed`; none followed:
    ``unreachable`` instead, or say so), at twice contact speed, each step guarded;
    careless: pointing straight down the face all along, at approach speed.
    ``instead_of``: what was tried first, for the error that says none of it is done."""
    h = hinge(world, body)
    face = pushed_face(world, body)
    arm = nearest_arm(world, h.at(face.point, h.now))
    # the fist first: the hand's poses on the face are measured on its shut fingers (a
    # push no arm follows hands over to ``unreachable``, which opens them as it needs)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="fist")
    leans = [(np.deg2rad(a), np.deg2rad(b)) for a in LEANS for b in LEANS]
    leans.sort(key=lambda pair: abs(pair[0] - pair[1]))
    pose_at = _pushing(world, arm, h, face, *leans[0], False)
    if style.avoid_hazards:
        found = _first_followed(world, arm, body, h, face, leans, angle)
        if found is None and unreachable is not None:
            yield from unreachable()
            return
        if found is None:
            raise NotImplementedError(
                f"the careful expert cannot push `{body}` shut from {np.degrees(h.now):.0f}°: "
                f"no IK branch of `{arm}` follows its face's arc with the hand on it "
                f"(out of the arm's reach){instead_of and f'; {instead_of}'}")
        pose_at = found
    start = pose_at(h.now)
    off = STANDOFF * _normal_at(h, face, h.now)
    top = max(float(h.at(face.edge, h.now)[2]), start.p[2])
    above = start.moved(off)
    above = Pose(np.array([above.p[0], above.p[1], max(above.p[2], top + STANDOFF)]), start.R)
    arc = tuple(pose_at(float(t)) for t in np.linspace(h.now, angle, ARC_POSES))
    yield from transit(world, style, arm, above, exclude=(body,), then=start.moved(off),
                       follow=arc)
    yield Segment({arm: start.moved(off)}, speed=style.approach_speed, label="to face")
    yield Segment({arm: start}, speed=style.approach_speed * 0.5, label="onto face")
    if style.avoid_hazards:
        # slowly (a rigid hand on a free-swinging door chatters: 50 N spikes at 6 cm/s)
        # and guarded, as a drawer's push
        yield from smooth_arc(world, style, arm, pose_at, h.now, angle,
                              2 * style.contact_speed, "push shut",
                              guards=(Guard(arm, push_force(world, arm, body), body),))
    else:
        steps = max(2, int(np.ceil(abs(angle - h.now) / np.deg2rad(8.0))))
        for theta in np.linspace(h.now, angle, steps + 1)[1:]:
            yield Segment({arm: pose_at(float(theta))}, speed=style.approach_speed,
                          label="push shut")
    yield Segment({}, settle=style.settle, label="hold shut")
    end = world.current_pose(arm)
    away = BACK_OFF * _normal_at(h, face, angle)
    yield Segment({arm: end.moved(away)}, speed=free_speed(style), label="off face")
    yield Segment({arm: end.moved(away + 0.08 * UP)}, speed=free_speed(style), label="up",
                  settle=20)


def _normal_at(h: Hinge, face: Face, theta: float) -> NDArray[np.float64]:
    """The pushed face's outward normal (world) with the panel at ``theta``."""
    return axis_angle_matrix(h.axis, theta) @ h.closed @ face.normal


def _pushing(world: World, arm: str, h: Hinge, face: Face, lean_a: float, lean_b: float,
             flip: bool) -> Callable[[float], Pose]:
    """The TCP at each panel angle with the closed hand on the face, leaning ``lean_a``
    (rad) at the present angle and ``lean_b`` shut, evenly between: the hand's approach
    from pointing into the face (0) toward pointing along it at the hinge (90 deg), its
    fingers closing along the hinge (``flip``: the hand turned half a turn about its
    approach). The TCP stands off the face as far as the hand's hulls reach past it."""
    span = h.now if h.now > 0 else 1.0
    cache: dict[float, Pose] = {}

    def pose_at(theta: float) -> Pose:
        if theta in cache:
            return cache[theta]
        s = float(np.clip(1.0 - theta / span, 0.0, 1.0))
        lean = lean_a + s * (lean_b - lean_a)
        frame = axis_angle_matrix(h.axis, theta) @ h.closed
        normal, outward = frame @ face.normal, frame @ face.outward
        approach = -(np.cos(lean) * normal + np.sin(lean) * outward)
        R = _frame(world, arm, approach, -h.axis if flip else h.axis)
        point = h.at(face.point, theta)
        pose = Pose(point + normal * world.hand_front(arm, R, -normal, np.zeros(3), np.inf), R)
        if len(world.arm_joints(arm)) < 6:  # turned to what a five-joint arm holds there
            R = attained(world, arm, pose).R
            pose = Pose(point + normal * world.hand_front(arm, R, -normal, np.zeros(3), np.inf), R)
        cache[theta] = pose
        return pose

    return pose_at


def _frame(world: World, arm: str, approach: NDArray[np.float64],
           closing: NDArray[np.float64]) -> NDArray[np.float64]:
    """The TCP rotation pointing along ``approach`` with the fingers closing along
    ``closing`` (perpendicular to it), that sign."""
    la, lc = world.approach_axis(arm), world.finger_axis(arm)
    a = approach / float(np.linalg.norm(approach))
    c = closing - (closing @ a) * a
    c /= float(np.linalg.norm(c))
    return np.column_stack([a, c, np.cross(a, c)]) @ np.column_stack([la, lc, np.cross(la, lc)]).T


def _first_followed(world: World, arm: str, body: str, h: Hinge, face: Face,
                    leans: list[tuple[float, float]], angle: float,
                    ) -> Callable[[float], Pose] | None:
    """The first push (its leans, least change first, and the hand's turn) whose arc one
    IK branch follows with the hand HAZARD_SPARE outside every keep-out, from STANDOFF
    off the face to where it backs off after; where none keeps that, the followed one
    that stays farthest out (:func:`first_clear`); None where none is followed."""
    off = STANDOFF * _normal_at(h, face, h.now)
    away = BACK_OFF * _normal_at(h, face, angle)

    def path(pose_at: Callable[[float], Pose]) -> tuple[Pose, ...]:
        arc = tuple(pose_at(float(t)) for t in np.linspace(h.now, angle, ARC_POSES))
        return (arc[0].moved(off), *arc, arc[-1].moved(away))

    def followed(pose_at: Callable[[float], Pose]) -> bool:
        return branch_for_path(world, arm, path(pose_at)[:-1]) is not None

    options = (_pushing(world, arm, h, face, lean_a, lean_b, flip)
               for lean_a, lean_b in leans for flip in (False, True))
    return first_clear(options, followed, lambda o: hand_clearance(world, arm, path(o), (body,)))


__all__ = ["Face", "push_shut", "pushed_face"]
