"""What the task plans share: the Panda hand's measures, the fraction a part must open
to, where a held object is set down (the careful place point, checked against the arm's
reach), and the retreat at the end of a task."""

from __future__ import annotations

import numpy as np

from fsvla.dsl.catalog import PREDICATES
from fsvla.dsl.models import predicates_in

from ..motion import Pose, Segment
from ..skills import (
    HAND_HALF_LENGTH,
    REACH_SLACK,
    UP,
    Plan,
    branch_for_path,
    clear_height,
    free_speed,
    held_offset,
    horizontal,
)
from ..style import Style
from ..world import World, box_distance

#: Half the thickness of a Panda hand across its finger axis (m).
HAND_HALF_WIDTH = 0.032

#: Height of the hand's lowest point above its TCP (m), pointing down.
HAND_BOTTOM = 0.037

#: How far a drawer's handle stands proud of its front (m).
HANDLE_DEPTH = 0.02


#: The force (N) a careful push stops at where no contact-force limit watches it.
PUSH_FORCE = 25.0


def push_force(world: World, arm: str, body: str) -> float:
    """What a careful push of ``body`` stops at: PUSH_FORCE, or half of the tightest
    contact-force limit on the hand or the body and out of its warning band, at least 3 N."""
    allowed = world.force_allowance("gripper", f"{arm}_gripper", body)
    return max(3.0, PUSH_FORCE if allowed is None else min(PUSH_FORCE, allowed))


def required_fraction(world: World, body: str) -> float:
    """The largest ``opened(body, fraction=f)`` any requirement asks for (0 when none does)."""
    return _largest(_requirement_conditions(world), "opened", body, "fraction", 0.5)


def success_fraction(world: World, body: str) -> float:
    """The largest ``opened(body, fraction=f)`` the success condition asks for (0 when it
    does not)."""
    return _largest([world.monitor.success.condition], "opened", body, "fraction", 0.5)


def required_lift(world: World, obj: str) -> float:
    """The largest ``lifted(obj, by=h)`` (m) the success condition or a requirement asks for
    (0 when none does)."""
    conditions = [world.monitor.success.condition, *_requirement_conditions(world)]
    return _largest(conditions, "lifted", obj, "by", 0.05)


def required_tilt(world: World, obj: str) -> float:
    """The largest ``tilted(obj, by=a)`` (rad) the success condition or a requirement asks
    for (0 when none does)."""
    conditions = [world.monitor.success.condition, *_requirement_conditions(world)]
    by = PREDICATES["tilted"].param("by").default
    return _largest(conditions, "tilted", obj, "by", float(by))  # type: ignore[arg-type]


def _requirement_conditions(world: World) -> list:
    return [cond for req in world.monitor.requirements for cond in (req.first, req.then)]


def _largest(conditions: list, predicate: str, subject: str, key: str, default: float) -> float:
    """The largest ``key`` parameter (``default`` where not given) of the ``predicate``
    calls on ``subject`` in ``conditions``; 0 when there is none."""
    return max([0.0, *(float(p.params.get(key, default)) for cond in conditions
                       for p in predicates_in(cond) if p.name == predicate and p.args[0] == subject)])


def place_point(world: World, style: Style, obj: str, target: str,
                arm: str | None = None) -> np.ndarray:
    """Where on ``target``'s top the object's bottom centre goes: the footprint's centre,
    or (careful) the footprint point farthest from the hazards; with ``arm`` (holding
    ``obj``), careful, only among the points where the hand it holds the object with
    stays comfortably inside the arm's joint limits (a shelf at the edge of the reach:
    an arm stretched onto its elbow limit sags and presses the object into the shelf),
    the carry there ending inside the arm's reach (:func:`_reaches_place`); failing that,
    among those reached from 8 cm above."""
    asset = world.asset(target)
    pose = world.body_pose(target)
    (x0, y0), (x1, y1) = asset.footprint.min_xy, asset.footprint.max_xy
    lo, hi = world.bounds(obj)
    r = 0.5 * max(hi[0] - lo[0], hi[1] - lo[1]) + 0.015
    top = world.top(target)
    candidates = [np.array([(x0 + x1) / 2, (y0 + y1) / 2])]
    if style.avoid_hazards:
        xs = np.linspace(x0 + r, x1 - r, 5) if x1 - x0 > 2 * r else [(x0 + x1) / 2]
        ys = np.linspace(y0 + r, y1 - r, 5) if y1 - y0 > 2 * r else [(y0 + y1) / 2]
        candidates += [np.array([x, y]) for x in xs for y in ys]
    obstacles = world.obstacles(exclude=(obj, target))

    def score(c: np.ndarray) -> float:
        p = pose.R[:2, :2] @ c + pose.p[:2]
        d = [box_distance(p, o.lo[:2], o.hi[:2]) - o.margin for o in obstacles]
        return min(min(d, default=1.0), 0.04) - 0.05 * float(np.linalg.norm(c - candidates[0]))

    best = max(candidates, key=score) if style.avoid_hazards else candidates[0]
    if style.avoid_hazards and arm is not None:
        ranked = sorted(candidates, key=score, reverse=True)

        def bottom(c: np.ndarray) -> np.ndarray:
            return np.array([*(pose.R[:2, :2] @ c + pose.p[:2]), top])

        best = next((c for c in ranked if _reaches_place(world, style, arm, obj, bottom(c))),
                    None)
        if best is None:  # none the carry comes down onto surely: one it reaches at all
            best = next((c for c in ranked if _reaches_from_above(world, arm, obj, bottom(c))),
                        ranked[0])
    xy = pose.R[:2, :2] @ best + pose.p[:2]
    return np.array([xy[0], xy[1], top])


def _set_down_pose(world: World, arm: str, obj: str, bottom: np.ndarray) -> Pose:
    """The TCP pose that sets the held ``obj`` down at ``bottom``, the hand as it is now."""
    tcp = world.current_pose(arm)
    return Pose(bottom + tcp.R @ held_offset(world, arm, obj), tcp.R)


def _reaches_from_above(world: World, arm: str, obj: str, bottom: np.ndarray) -> bool:
    """Whether the hand holding ``obj`` as it does now can come straight down from 8 cm
    above onto the pose that sets it down at ``bottom``, inside the arm's joint limits
    (:func:`branch_for_path`)."""
    goal = _set_down_pose(world, arm, obj, bottom)
    return branch_for_path(world, arm, (goal.moved(0.08 * UP), goal)) is not None


def _reaches_place(world: World, style: Style, arm: str, obj: str, bottom: np.ndarray) -> bool:
    """Whether the hand holding ``obj`` as it does now comes straight down onto the pose
    that sets it down at ``bottom`` (:func:`_reaches_from_above`), and the carry that
    brings it there, at :func:`transit`'s clear height above that pose, ends inside the
    arm's reach (:func:`_within_reach`). Far from the base, a carry over a tall hazard
    otherwise ends with the arm at full stretch, and the line down from there may
    straighten the elbow onto its limit and set the object short of its place."""
    if not _reaches_from_above(world, arm, obj, bottom):
        return False
    tcp = world.current_pose(arm)
    goal = _set_down_pose(world, arm, obj, bottom)
    above = goal.moved(0.08 * UP)
    below = float(goal.p[2] - bottom[2]) + 0.03  # how far the load hangs under the TCP
    height = max(clear_height(world, style, tcp.p, above.p, below, (obj,)), above.p[2] + 0.05)
    return _within_reach(world, arm, Pose(np.array([above.p[0], above.p[1], height]), above.R))



def _within_reach(world: World, arm: str, pose: Pose) -> bool:
    """Whether ``pose`` lies REACH_SLACK inside the arm's reach: the same hand REACH_SLACK
    farther from the base is still solved comfortably. At full stretch (a Panda's elbow at
    -0.47 rad, its two offset links in line) a line that brings the hand nearer has two
    answers, the elbow bending, or straightening onto its -0.07 limit, and which one the
    driver takes depends on the last digits of its joints."""
    out = horizontal(pose.p - world.base_position(arm))
    return branch_for_path(world, arm, (Pose(pose.p + REACH_SLACK * out, pose.R),)) is not None


def retreat_home(world: World, style: Style, arm: str) -> Plan:
    pose = world.current_pose(arm)
    yield Segment({arm: pose.moved(0.08 * UP)}, speed=free_speed(style), label="clear")


__all__ = ["HANDLE_DEPTH", "HAND_BOTTOM", "HAND_HALF_LENGTH", "HAND_HALF_WIDTH", "REACH_SLACK", "place_point", "required_fraction",
           "required_lift", "required_tilt", "retreat_home", "success_fraction"]
