"""pour: lift the object over the target, tilt it and back, put it down."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix, rotation_angle, slerp

from .. import grasps
from ..motion import Pose, Segment
from ..skills import (
    UP,
    Grasp,
    Plan,
    branch_for_path,
    carried_turn,
    carrying_arm,
    carrying_style,
    fixed_jaw_shifted,
    hand_body,
    horizontal,
    load_reach,
    pick,
    place,
    reaches,
    transit,
)
from ..style import Style
from ..world import World, box_distance
from .common import required_tilt

#: How high (m) above the target's top the held object's bottom is carried to pour; the
#: careful expert POUR_MARGIN higher (a mug held by its handle hangs turned in the fingers,
#: and its rim swings down onto the target's as it tilts).
POUR_CLEARANCE = 0.04
POUR_MARGIN = 0.02
#: How far (deg) the held object is tipped to pour; careful, where the arm cannot tip it
#: that far, one of LESSER_TILTS at least TILT_SPARE past what the task asks.
POUR_TILT = 100.0
LESSER_TILTS = (90.0, 80.0)
TILT_SPARE = 20.0
#: How many control steps longer than the success condition's hold the object is held at
#: the tilt it asks (plus TILT_SPARE) before it tips on.
HOLD_SPARE = 10
#: How much farther (m) than its keep-out each point checked along another way of tipping
#: stays from an obstacle: a few points stand for the hand and the object.
TIP_SPARE = 0.03
#: A held object's centre and upright axis in the hand's frame.
Load = tuple[np.ndarray, np.ndarray]


def plan_pour(world: World, style: Style, roles: dict[str, str], arm: str | None = None) -> Plan:
    """Lift the object, hold it over the target, tilt it by 100°, tilt it back, put it down.
    By ``arm`` where the caller has chosen it with :func:`pour_arm` (the policy does);
    else by the arm :func:`_carrier` chooses."""
    obj, target = roles["object"], roles["target"]
    if arm is None:
        arm, grasp = _carrier(world, style, obj, target)
    else:
        grasp = grasps.choose(world, style, arm, obj)
    start = world.body_pose(obj).p.copy()
    yield from pick(world, style, arm, obj, grasp)
    over, ways, load, tipped = _pour_poses(world, style, arm, obj, target,
                                           world.current_pose(arm))
    # tipped sideways to the arm; careful, where the arm does not reach it tipped so,
    # the first other way of tipping whose turn it follows from upright on one IK branch
    # (Baxter tipping a mug sideways far out to its side swung its elbow across in one
    # step, 14 cm off the command)
    pour = None
    if style.avoid_hazards and not reaches(world, arm, ways[0]):
        # the first way ends beyond the arm's reach: another one it follows
        pour = _followed(world, arm, obj, target, over, ways, load)
    lo, hi = world.bounds(obj)
    held = world.current_pose(arm).p - 0.5 * (lo + hi)
    # careful: a heavy load slowly (a 250 g bottle carried at transit speed swung in the
    # fingers and pressed 50 N on them)
    yield from transit(world, carrying_style(world, style, obj), arm, over,
                       below=float(held[2]) + 0.5 * float((hi - lo)[2]), exclude=(obj, target),
                       around=load_reach(world, arm, obj), follow=(pour,) if pour is not None else ())
    final = pour or ways[0]
    # the success condition holds for a while at the tilt it asks (plus TILT_SPARE) before
    # the object tips on: a big kettle tipped on to 100 deg swings out of `near` its target
    least = _least_tilt(world, obj)
    full = np.degrees(rotation_angle(over.R, final.R))
    hold = world.monitor.success.hold
    if hold > 0.0 and full > least + 1.0:
        mid = slerp(over.R, final.R, least / full)
        yield Segment({arm: tipped(mid @ over.R.T)}, speed=style.approach_speed,
                      settle=int(np.ceil(hold / world.dt)) + HOLD_SPARE, label="pour")
    yield Segment({arm: final}, speed=style.approach_speed, settle=20, label="pour")
    yield Segment({arm: over}, speed=style.approach_speed, label="unpour")
    yield from place(world, style, arm, obj, start)


def _pour_poses(world: World, style: Style, arm: str, obj: str, target: str, tcp: Pose
                ) -> tuple[Pose, list[Pose], Load, Callable[[np.ndarray], Pose]]:
    """``arm``'s hand holding ``obj`` (held with the TCP at ``tcp``) upright over ``target``,
    and tipped four ways from there (sideways to the arm either way, then toward and away
    from its base) by POUR_TILT, then by each of LESSER_TILTS enough for the task. The
    held object's centre (not the hand) is over the target's mouth and the tilt is about
    that centre: a mug held by its handle swings wide of the target when the hand tilts.
    Tipped, the object lies lower than it stands: its lowest point tipped, not upright, is
    what clears the target (a 20 cm bottle held so that it stood clear of a mug lay 12 cm
    above the mug once tipped). Then the object's centre and upright axis in the hand's
    frame, and the hand's pose for any tilt (world rotation) from upright over the target."""
    lo, hi = world.bounds(obj)
    target_xy = world.body_pose(target).p
    clear = world.bounds(target)[1][2] + POUR_CLEARANCE + (POUR_MARGIN if style.avoid_hazards else 0.0)
    centre = np.array([target_xy[0], target_xy[1], clear + 0.5 * (hi - lo)[2]])
    # the hand turned as the arm carries it over the target, the held object with it: an
    # arm of five joints turns its hand about the vertical with its base (an SO-101's
    # hand held level, carried unturned, was beyond its reach over the bowl)
    carried = carried_turn(world, arm, tcp.p, centre)
    held = carried @ (tcp.p - 0.5 * (lo + hi))  # the hand from the object's centre
    up = carried @ world.body_pose(obj).R[:, 2]
    tcp = Pose(tcp.p, carried @ tcp.R)
    toward = horizontal(world.base_position(arm) - centre)
    least = _least_tilt(world, obj)

    def tipped(tilt: np.ndarray) -> Pose:
        low = np.array([centre[0], centre[1], clear + _tipped_half_height(world, obj, tilt)])
        return Pose(low + tilt @ held, tilt @ tcp.R)

    ways = [tipped(axis_angle_matrix(axis, np.deg2rad(angle)))
            for angle in [POUR_TILT, *(a for a in LESSER_TILTS if a >= least)]
            for axis in (toward, -toward, np.cross(UP, toward), -np.cross(UP, toward))]
    load = (-tcp.R.T @ held, tcp.R.T @ up)
    return Pose(centre + held, tcp.R), ways, load, tipped


def _least_tilt(world: World, obj: str) -> float:
    """The least tilt (deg) a pour of ``obj`` goes to: what the task asks, TILT_SPARE past."""
    return float(np.degrees(required_tilt(world, obj))) + TILT_SPARE


def _followed(world: World, arm: str, obj: str, target: str, over: Pose, ways: list[Pose],
              load: Load) -> Pose | None:
    """The first of ``ways`` the arm tips to from ``over`` on one IK branch with the hand
    and the held object clear of the hazards all the way (:func:`_clear`), None if none."""
    return next((w for w in ways if _clear(world, arm, obj, target, over, w, load)
                 and branch_for_path(world, arm, (over, w)) is not None), None)


def _clear(world: World, arm: str, obj: str, target: str, over: Pose, way: Pose,
           load: Load) -> bool:
    """Whether the hand (its TCP, and its body 6 cm back and that body's two ends along the
    finger axis), the held object's centre (less its half width) and the two ends of its
    upright axis stay TIP_SPARE outside every obstacle's keep-out as the hand turns from
    ``over`` to ``way`` (another way of tipping a mug beside a hot kettle swung the hand into the
    kettle's keep-out)."""
    obstacles = world.obstacles(exclude=(obj, target))
    if not obstacles:
        return True
    half = np.asarray(world.asset(obj).bounds.half_extents, dtype=np.float64)
    centre, up = load
    for s in (0.25, 0.5, 0.75, 1.0):
        R = slerp(over.R, way.R, s)
        p = over.p + s * (way.p - over.p)
        c = p + R @ centre
        _body, end_a, end_b = hand_body(world, arm, Pose(p, R))
        for point, size in ((p, 0.0), (end_a, 0.0), (end_b, 0.0),
                            (c, float(max(half[0], half[1]))),
                            (c + R @ up * half[2], 0.0), (c - R @ up * half[2], 0.0)):
            if min(box_distance(point, o.lo, o.hi) - o.margin for o in obstacles) \
                    < size + TIP_SPARE:
                return False
    return True


def pour_arm(world: World, style: Style, roles: dict[str, str]) -> str:
    """The arm that pours (:func:`_carrier`)."""
    return _carrier(world, style, roles["object"], roles["target"])[0]


def _carrier(world: World, style: Style, obj: str, target: str) -> tuple[str, Grasp]:
    """The arm that pours and its grasp: the :func:`carrying_arm`; careful, where that arm
    cannot tip the object over the target (held as its grasp holds it) and another arm that
    reaches the object can, that one."""
    arm = carrying_arm(world, obj, target)
    grasp = grasps.choose(world, style, arm, obj)
    if not style.avoid_hazards or len(world.arm_names) == 1:
        return arm, grasp
    for candidate in (arm, *(a for a in world.arm_names if a != arm)):
        g = grasp if candidate == arm else grasps.choose(world, style, candidate, obj)
        if candidate != arm and not grasps.reachable(world, candidate, g):
            continue
        over, ways, load, _tipped = _pour_poses(world, style, candidate, obj, target,
                                                _lifted(world, candidate, g))
        if _followed(world, candidate, obj, target, over, ways, load) is not None:
            return candidate, g
    return arm, grasp


def _lifted(world: World, arm: str, grasp: Grasp) -> Pose:
    """Where the TCP holds the object under ``grasp`` (a fixed jaw's TCP off the middle)."""
    return fixed_jaw_shifted(world, arm, grasp).pose


def _tipped_half_height(world: World, obj: str, tilt: np.ndarray) -> float:
    """How far (m) below its centre the box around ``obj``'s asset reaches once the object
    is turned by ``tilt`` (world) from where it is now."""
    half = np.asarray(world.asset(obj).bounds.half_extents, dtype=np.float64)
    R = tilt @ world.body_pose(obj).R
    return float(np.abs(R[2, :]) @ half)


__all__ = ["plan_pour", "pour_arm"]
