"""Lifting a hinged lid by its knob, along the knob's arc (the first step of inserting
into a lidded container)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix

from ..motion import Guard, Pose, Segment
from ..skills import UP, Plan, branch_for_path, free_speed, nearest_arm, transit
from ..style import Style
from ..world import World

#: Lid angle (rad) the careful expert lifts a lid to: past vertical, so that it falls
#: open onto its stop instead of shut when the hand leaves it.
LID_PAST_VERTICAL = np.deg2rad(95.0)


def lift_lid(world: World, style: Style, body: str, angle: float) -> Plan:
    """Lift a hinged lid by its knob from below: the closed fingers come horizontally
    under the knob's overhang (the hand upright, the fingers closing across the lid: a
    Panda cannot point a flat hand forward that low), then follow the knob's arc about the
    hinge, the hand turning with the lid, up to ``angle`` (rad); the hand then backs away
    (a lid left short of vertical falls shut). The hand is 21 cm tall that way: the knob
    must stand 11 cm or more above the table."""
    part, joint = world.part(body)
    link = world.link_pose(body, part.link)
    knob = world.shape(body, "knob", link=part.link)
    axis = world.body_pose(body).R @ np.asarray(joint.axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    span = joint.upper - joint.lower
    now = world.open_fraction(body) * span
    closed = axis_angle_matrix(axis, -now) @ link.R  # the lid frame when shut
    c, half = np.asarray(knob.pose.position), np.asarray(knob.half_size)
    # under the knob's front edge (the fingertips reach ~1 cm past the TCP), the closed
    # fingers' half thickness and a little more below it
    local = np.array([c[0] - half[0] - 0.002, c[1], c[2] - half[2] - 0.016])
    toward_hinge = -np.sign(c[0]) * np.array([1.0, 0.0, 0.0])  # the knob is at -x

    def pose_at(theta: float, near: np.ndarray | None = None) -> Pose:
        R = axis_angle_matrix(axis, theta) @ closed
        approach = R @ toward_hinge
        return Pose(link.p + R @ local, world.grasp_frame(arm, approach, R[:, 2], near=near))

    arm = nearest_arm(world, link.p + closed @ local)
    start = pose_at(now)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="fist")
    back_off = -0.06 * (start.R @ world.approach_axis(arm))
    arc: tuple[Pose, ...] = ()
    if style.avoid_hazards:
        # on an IK branch that follows the whole arc (others drive a wrist joint onto its
        # limit half way up: the hand leaves the arc and jams against the lid), the hand
        # turned either way about its approach (a fist is symmetric), each pose of the
        # arc the turn nearest the one before
        flipped = start.R @ axis_angle_matrix(world.approach_axis(arm), np.pi)
        options = [_chained(pose_at, now, angle, R0) for R0 in (start.R, flipped)]
        arc = next((a for a in options if branch_for_path(
            world, arm, (a[0].moved(back_off), *a)) is not None), options[0])
        start = arc[0]
    yield from transit(world, style, arm, start.moved(back_off), exclude=(body,), then=start,
                       follow=arc)
    yield Segment({arm: start}, speed=style.approach_speed * 0.5, label="under knob")
    speed = max(style.contact_speed * 4, 0.06) if style.avoid_hazards else style.approach_speed
    if style.avoid_hazards:
        # one smooth arc, one control step per segment (each segment eases in and out: a
        # chain of 8° chords stops and starts the hand under the lid, which rises off the
        # fingers and lands back on them, 30-60 N spikes)
        last = [start.R]

        def chained_at(theta: float) -> Pose:
            pose = pose_at(theta, last[0])
            last[0] = pose.R
            return pose

        yield from smooth_arc(world, style, arm, chained_at, now, angle, speed, "lift lid")
    else:
        steps = max(2, int(np.ceil((angle - now) / np.deg2rad(8.0))))
        for theta in np.linspace(now, angle, steps + 1)[1:]:
            yield Segment({arm: pose_at(float(theta))}, speed=speed, label="lift lid")
    yield Segment({}, settle=style.settle, label="hold lid")
    end = world.current_pose(arm)
    back = -(end.R @ world.approach_axis(arm))
    yield Segment({arm: end.moved(0.06 * back)}, speed=free_speed(style), label="leave lid")
    yield Segment({arm: end.moved(0.06 * back + 0.08 * UP)}, speed=free_speed(style),
                  label="up", settle=20)


def _chained(pose_at: Callable[..., Pose], start: float, end: float, near: np.ndarray,
             n: int = 12) -> tuple[Pose, ...]:
    """``pose_at(theta, near)`` at ``n`` angles from ``start`` to ``end``, each turned the
    way nearest the pose before (the first: nearest ``near``)."""
    poses = []
    for theta in np.linspace(start, end, n):
        poses.append(pose_at(float(theta), near))
        near = poses[-1].R
    return tuple(poses)


def smooth_arc(world: World, style: Style, arm: str, pose_at: Callable[[float], Pose],
               start: float, end: float, speed: float, label: str,
               guards: tuple[Guard, ...] = ()) -> Plan:
    """Follow ``pose_at(theta)`` from ``start`` to ``end`` without stopping: one segment per
    control step, the parameter eased in and out over the whole arc, the peak TCP speed
    ``speed`` and the peak turn rate within the style's angular speed; each segment
    ``guards``ed."""
    thetas = np.linspace(start, end, 50)
    points = np.array([pose_at(float(t)).p for t in thetas])
    length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
    duration = 1.5 * max(length / speed, abs(end - start) / (0.8 * style.angular_speed))
    n = max(2, int(np.ceil(duration / world.dt)))
    for i in range(1, n + 1):
        s = i / n
        theta = start + (end - start) * s * s * (3.0 - 2.0 * s)
        yield Segment({arm: pose_at(float(theta))}, speed=2.0 * speed, label=label,
                      guards=guards)


__all__ = ["LID_PAST_VERTICAL", "lift_lid", "smooth_arc"]
