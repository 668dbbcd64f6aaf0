"""push: slide the object over the table to the target with closed fingers."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..motion import Pose, Segment
from ..skills import (
    DOWN,
    UP,
    Plan,
    attained,
    branch_for_path,
    force_watched,
    horizontal,
    leaning_frame,
    nearest_arm,
    transit,
)
from ..style import Style
from ..world import World
from .common import retreat_home
from .detour import detour
from .lid import smooth_arc


def plan_push(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """Push ``object`` over the table to ``target``'s centre with closed fingers: in one
    straight push where the arm follows all of it with one turn of the hand; else in legs,
    the hand leaning out and turning with the direction to the base as it goes, each leg as
    far as the arm follows it and the next from where the object is then."""
    obj, target = roles["object"], roles["target"]
    arm = nearest_arm(world, world.body_pose(obj).p)
    # careful: around the keep-outs, through the points of a detour first
    way = detour(world, arm, obj, target) if style.avoid_hazards else None
    via = way.points if way is not None else []

    def aim() -> NDArray[np.float64]:
        """Where this leg pushes to: the next point of the detour not yet passed (reached,
        or the one after it in a clear line from where the object is), else the target."""
        here = world.body_pose(obj).p
        while via and (float(np.linalg.norm((via[0] - here)[:2])) < VIA_REACHED
                       or way.clear(here, via[1] if len(via) > 1 else world.body_pose(target).p)):
            via.pop(0)
        return via[0] if via else world.body_pose(target).p

    def arrived() -> bool:
        return not via and _gap(world, obj, target) < PUSH_GAP

    def aim_at(start: NDArray[np.float64], bounds) -> NDArray[np.float64]:
        """Where this leg's line ends: a point of the detour pushed to so that the object
        ends on it (the push ends STANDOFF short, and a round object's box across the
        line is wider than the object), else the target."""
        goal = aim()
        if not via:
            return goal
        direction = horizontal(goal - start)
        lo, hi = bounds
        over = _half_along(direction, bounds) - 0.5 * float(np.min((hi - lo)[:2]))
        return goal + (STANDOFF + over) * direction

    # the first leg is laid out, and the one turn for the whole push chosen, on the line at
    # 40 % of the object's height, where things are before the fingers close
    bounds = world.bounds(obj)
    start = world.body_pose(obj).p
    goal = aim_at(start, bounds)
    line, direction, travel = _push_line(world, obj, start, goal, bounds)
    R = _push_frame(world, arm, line, direction, travel)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="close")
    for leg in range(PUSH_LEGS + len(via)):
        if leg:
            bounds = world.bounds(obj)
            start = world.body_pose(obj).p
            goal = aim_at(start, bounds)
            line, direction, travel = _push_line(world, obj, start, goal, bounds)
            if travel < LEG_DONE or arrived():
                break
            R = _push_frame(world, arm, line, direction, travel)
        behind = _off_the_table(world, arm, line, bounds)  # measured on the shut hand
        route = None if R is not None else _push_route(world, arm, behind, direction, travel,
                                                         world.top(obj))
        if route is None:  # all the way with one turn (none followed at all: the first)
            if leg == 0 or R is not None:
                R = R if R is not None else _push_frames(world, arm, behind, direction)[0]
                yield from _push_straight(world, style, arm, obj, Pose(behind, R),
                                          travel * direction)
                moved = float(np.linalg.norm((world.body_pose(obj).p - start)[:2]))
                if moved >= LEG_DONE and not arrived():
                    # a round object slides off the line of the hand's face: pushed again
                    # from where it went, as the legs below are
                    yield from _back_off(world, style, arm, direction)
                    continue
            break
        planned, length, whole = route
        hover = attained(world, arm, planned(0.0).moved(HOVER * UP))
        leg = (hover, *_leg_poses(planned, length))
        yield from transit(world, style, arm, _above_leg(world, arm, planned(0.0), leg),
                           exclude=(obj,), follow=leg, then=leg[1])
        yield Segment({arm: hover}, speed=style.approach_speed, settle=style.settle,
                      label="hover")
        # the hand, leaning, stops off its command by a few millimetres, and far out by a
        # centimetre or more (the arm sags; the five-joint arm's IK holds the turn of the
        # hand before its place): the leg is commanded that much off, as measured at the
        # hover above its start, as a camera-guided arm corrects its reach
        error = hover.p - world.current_pose(arm).p
        error *= min(1.0, MAX_CORRECTION / max(float(np.linalg.norm(error)), 1e-9))

        def pose_at(s: float, planned=planned, error=error) -> Pose:
            return planned(s).moved(error)

        yield Segment({arm: pose_at(0.0)}, speed=style.approach_speed, label="down")
        yield from smooth_arc(world, style, arm, pose_at, 0.0, length,
                              _push_speed(world, style, obj), "push")
        yield Segment(settle=style.settle, label="push")
        moved = float(np.linalg.norm((world.body_pose(obj).p - start)[:2]))
        yield from _back_off(world, style, arm, direction)
        if (whole and arrived()) or moved < LEG_DONE:
            break
    yield from retreat_home(world, style, arm)


def _back_off(world: World, style: Style, arm: str, direction: NDArray[np.float64]) -> Plan:
    """Off the object before the next leg: back from it, then up."""
    end = world.current_pose(arm)
    yield Segment({arm: end.moved(-LEG_BACK * direction)}, speed=style.approach_speed,
                  label="back")
    yield Segment({arm: end.moved(-LEG_BACK * direction + 0.05 * UP)},
                  speed=style.approach_speed, label="up")


def _gap(world: World, obj: str, target: str) -> float:
    """How far apart (m) ``obj``'s and ``target``'s boxes are over the table."""
    (alo, ahi), (blo, bhi) = world.bounds(obj), world.bounds(target)
    apart = np.maximum(np.maximum(blo[:2] - ahi[:2], alo[:2] - bhi[:2]), 0.0)
    return float(np.linalg.norm(apart))


def _above_leg(world: World, arm: str, start: Pose, leg: tuple[Pose, ...]) -> Pose:
    """Where the hand comes down to a leg's ``start`` from: as high of ABOVE_LEG as an IK
    branch follows the line down and the whole ``leg`` from (a short arm leaning out holds
    its wrist within its limits only low), its rotation one the arm holds there."""
    highest = None
    for up in ABOVE_LEG:
        above = attained(world, arm, start.moved(up * UP))
        if branch_for_path(world, arm, (above, *leg)) is not None:
            return above
        highest = highest or above
    return highest


def _leg_poses(pose_at: Callable[[float], Pose], length: float) -> tuple[Pose, ...]:
    """The poses a leg goes through, every ROUTE_STEP at most, both ends included."""
    n = max(2, int(np.ceil(length / ROUTE_STEP)) + 1)
    return tuple(pose_at(float(s)) for s in np.linspace(0.0, length, n))


def _push_line(world: World, obj: str, start: NDArray[np.float64],
               goal: NDArray[np.float64], bounds: tuple[NDArray[np.float64], NDArray[np.float64]]
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Where the hand starts behind ``obj`` (TCP), at 40 % of its height (``bounds``), the
    push direction and its length."""
    direction = horizontal(goal - start)
    lo, hi = bounds
    reach = _half_along(direction, bounds) + STANDOFF
    height = lo[2] + 0.4 * (hi[2] - lo[2])
    behind = np.array([start[0], start[1], height]) - reach * direction
    return behind, direction, float(np.linalg.norm((goal - start)[:2]))


def _half_along(direction: NDArray[np.float64],
                bounds: tuple[NDArray[np.float64], NDArray[np.float64]]) -> float:
    """Half the extent (m) of the object's box ``bounds`` along ``direction`` over the
    table."""
    lo, hi = bounds
    return 0.5 * float(np.abs(direction[:2]) @ (hi - lo)[:2])


def _off_the_table(world: World, arm: str, point: NDArray[np.float64],
                   bounds: tuple[NDArray[np.float64], NDArray[np.float64]]) -> NDArray[np.float64]:
    """``point`` raised for a hand whose body reaches below its TCP (a Z1's), measured on
    the hand as it is, along its approach axis: up to 70 % of the object's height."""
    lo, hi = bounds
    lowest = lo[2] + world.hand_reach(arm) + TABLE_GAP
    if point[2] >= lowest:
        return point
    return point + (min(lowest, lo[2] + 0.7 * (hi[2] - lo[2])) - point[2]) * UP


def _push_straight(world: World, style: Style, arm: str, obj: str, behind: Pose,
                   push: NDArray[np.float64]) -> Plan:
    # a hand whose body reaches farther ahead of its TCP than the standoff (the Z1's jaws,
    # 8 cm wide) would come down onto the object: it starts that much farther back
    direction = push / np.linalg.norm(push)
    front = world.hand_front(arm, behind.R, direction, behind.p, world.top(obj))
    back = max(0.0, front + HAND_GAP - STANDOFF)
    behind, push = behind.moved(-back * direction), push + back * direction
    yield from transit(world, style, arm, behind.moved(0.08 * UP), exclude=(obj,))
    yield Segment({arm: behind}, speed=style.approach_speed, label="down")
    yield Segment({arm: behind.moved(push)}, speed=_push_speed(world, style, obj),
                  settle=style.settle, label="push")


def _push_speed(world: World, style: Style, obj: str) -> float:
    """Careful, on an object a force limit watches: contact speed (a rigid hand pushing at
    three times that chatters, with one-step spikes of ~60 N)."""
    return style.contact_speed * (1 if style.avoid_hazards and force_watched(world, obj) else 3)


def _push_frames(world: World, arm: str, behind: NDArray[np.float64],
                 direction: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """The hand pointing down, fingers closing across the push, then turned about the
    vertical; then tipped out from the base (a short arm reaches far only tipped out)."""
    across = np.cross(UP, direction)
    frames = [world.grasp_frame(arm, DOWN, np.cos(t) * across + np.sin(t) * direction)
              for t in np.deg2rad([0.0, 45.0, -45.0, 90.0])]
    return frames + [leaning_frame(world, arm, behind, float(t)) for t in np.deg2rad(LEANS)]


def _push_frame(world: World, arm: str, behind: NDArray[np.float64],
                direction: NDArray[np.float64], travel: float) -> NDArray[np.float64] | None:
    """The first of :func:`_push_frames` the arm holds along the whole push, None if none."""
    path = (behind, behind + travel * direction)
    for R in _push_frames(world, arm, behind, direction):
        if branch_for_path(world, arm, tuple(Pose(p, R) for p in path)) is not None:
            return R
    return None


def _push_route(world: World, arm: str, behind: NDArray[np.float64],
                direction: NDArray[np.float64], travel: float, top: float
                ) -> tuple[Callable[[float], Pose], float, bool] | None:
    """Where no one turn of the hand is held along the push (a five-joint arm turns its
    hand with the direction to its base; far out, it reaches low only leaning out): the
    hand leaning out by one of LEANS at each point, its fingers closing across the push
    (its thin side leads) or else level across the lean (its wrist may not roll that far;
    the fingers' side then leads, and the hand starts SIDE_STANDOFF farther back; farther
    still where its body reaches ahead of its TCP, :meth:`World.hand_front`, unless no
    branch follows the leg from there), and the
    longest share of the push (of LEG_SHARES) the arm follows that way. (pose at distance s
    along it, its length, whether it pushes all the way) or None."""
    def frames(lean: float, across: bool) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
        def frame_at(p: NDArray[np.float64]) -> NDArray[np.float64]:
            out = horizontal(p - world.base_position(arm))
            approach = np.cos(lean) * DOWN + np.sin(lean) * out
            closing = np.cross(approach, direction) if across else np.cross(UP, out)
            if np.linalg.norm(closing) < 1e-3:
                closing = np.cross(UP, out)
            return world.grasp_frame(arm, approach, closing / np.linalg.norm(closing))
        return frame_at

    def leg_from(back: float, frame_at) -> Callable[[float], Pose]:
        first = behind - back * direction
        return lambda s: Pose(first + s * direction, frame_at(first + s * direction))

    for share in LEG_SHARES:
        if share * travel < LEG_DONE:
            break
        for across in (True, False):
            for lean in np.deg2rad(LEANS):
                frame_at = frames(float(lean), across)
                plain = 0.0 if across else SIDE_STANDOFF
                # a hand whose body reaches ahead of its TCP (a jaw's side) starts that much
                # farther back, as a straight push does; else from the plain standoff
                front = world.hand_front(arm, frame_at(behind), direction, behind, top + TOP_GAP)
                for back in dict.fromkeys((max(plain, front + HAND_GAP - STANDOFF), plain)):
                    pose_at = leg_from(back, frame_at)
                    length = share * travel + back
                    if branch_for_path(world, arm, _leg_poses(pose_at, length)) is not None:
                        return pose_at, length, share == 1.0
    return None


#: The TCP starts STANDOFF (m) behind the object, and the front of the hand at least
#: HAND_GAP behind it.
STANDOFF = 0.02
HAND_GAP = 0.008
#: What of the hand up to TOP_GAP (m) above the object's top counts as ahead of the TCP
#: in a push in legs: a jaw just over the top meets its edge.
TOP_GAP = 0.01
#: How far (m) the lowest point of the pushing hand stays above the table.
TABLE_GAP = 0.008
#: Leans (deg) of the hand out from pointing down, tried in turn.
LEANS = (20.0, 40.0, 60.0, 80.0)
#: A push in legs: at most PUSH_LEGS of them, each the longest of LEG_SHARES of what is
#: left that the arm follows (checked every ROUTE_STEP, m); it stops once a leg moved the
#: object less than LEG_DONE (m), or less than that is left; between legs the hand backs
#: LEG_BACK (m) off the object and rises.
PUSH_LEGS = 4
LEG_SHARES = (1.0, 0.75, 0.5, 0.3, 0.15)
ROUTE_STEP = 0.03
LEG_DONE = 0.01
LEG_BACK = 0.02
#: A point of a detour is passed once the object's centre is this close to it (m).
VIA_REACHED = 0.03
#: A push goes on, in another leg, while the object's box is farther than this (m) from
#: the target's (the hand's face, not a gripper, steers a round object off its line).
PUSH_GAP = 0.01
#: Where a leg's hand stops above its start (m) to measure how far off its command it is,
#: and the most (m) a leg's commands are moved to make up for it.
HOVER = 0.03
#: Heights (m) above a leg's start the hand comes down from, the highest first.
ABOVE_LEG = (0.08, 0.06, 0.045)
MAX_CORRECTION = 0.02
#: How much farther back (m) a hand whose fingers close along the push starts.
SIDE_STANDOFF = 0.02

__all__ = ["plan_push"]
