"""Setting a held object into an open container (a pot, a bowl, a box whose lid stands
open) without the hand touching it: a Panda hand is 21 cm long across its fingers, wider
than a 19 cm pot's mouth, and coming down to put the object on the floor it lands on the
rim (a -300 N knock on the gripper). The careful hand comes down only until some piece
of the hand, or of the held object, would come within a margin of a piece of the
container beneath it; the object is let go there, over the floor of the cavity, and
drops the rest of the way.

The lowest height is found from the geometry, not by feeling for the rim: the hand's
and the held object's boxes are sampled at about 1 cm and each sample is moved straight
down onto the container's collision pieces (its wall pieces and its base). Among the
points the object's centre may be set over (inside the cavity, which is where the
``inside`` predicate looks for it) and a few turns of the hand about the vertical, the
one that lets the object go lowest is taken, and the descent is guarded: a touch of the
container stops it."""

from __future__ import annotations

from itertools import product

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_matrix, quat_to_matrix

from ..motion import Guard, Pose, Segment
from ..skills import (
    UP,
    Plan,
    attained,
    branch_for_path,
    carried_rotation,
    carrying_style,
    force_watched,
    free_speed,
    gentle,
    horizontal,
    load_reach,
    reach_ceiling,
    transit,
)
from ..style import Style
from ..world import World, box_distance

#: How far (m) any piece of the hand (the fingers also as they open to let go) stays above
#: the container's pieces beneath it, and how far beside them a piece counts as beneath.
HAND_CLEAR = 0.01
HAND_BESIDE = 0.005
#: How far (m) beside the container's pieces a piece of the held object counts as above
#: them. It is let go the style's release height above them, or, watched for force (a
#: fragile object), set down on them (a 3 mm drop of a 60 g cube lands with 15 N).
OBJECT_BESIDE = 0.004
#: Spacing (m) of the sample points on the hand's and the object's boxes.
SAMPLE = 0.01
#: Links of the arm within this distance (m) of the tool centre point count as the hand
#: (a Baxter's gripper base and wrist stand 10-15 cm above its fingertips).
HAND_RADIUS = 0.2
#: How far (m) from the cavity's wall the object's centre stays.
CENTRE_MARGIN = 0.01
#: The hand's turns about the vertical that are tried (rad), nearest to the grasp first.
TURNS = (0.0, np.pi / 6, -np.pi / 6, np.pi / 3, -np.pi / 3, np.pi / 2)
#: How far (m) each finger opens away from the object to let it go (a wide-open hand in
#: a narrow mouth would open onto the wall).
RELEASE_GAP = 0.008
#: How near (m) the TCP an object's box must be for the hand to hold it.
HELD_WITHIN = 0.02
#: Force (N) at which a touch of the container stops the descent, at most.
TOUCH_FORCE = 5.0


def _box_surface(lo: NDArray[np.float64], hi: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points on the surface of the box [lo, hi], about SAMPLE apart."""
    axes = [np.linspace(a, b, max(2, int(np.ceil((b - a) / SAMPLE)) + 1)) for a, b in zip(lo, hi)]
    grid = np.array(list(product(*axes)))
    on = np.any(np.isclose(grid, lo) | np.isclose(grid, hi), axis=1)
    return grid[on]


def hand_points(world: World, arm: str, gap: float = 0.0) -> NDArray[np.float64]:
    """Sample points (TCP frame, m) on the boxes of the arm's links near the TCP, as the
    hand is now, and the fingers' also where they are once each has opened ``gap`` (m)
    farther out along the closing axis (to let go)."""
    tcp = world.current_pose(arm)
    closing = world.finger_axis(arm)
    fingers = world.arm_spec(arm).gripper.finger_links
    points = []
    for link in world.kinematics(arm).link_names:
        try:
            found = world.link_points(arm, link)
        except StopIteration:  # a link of the robot that the arm's state does not pose
            continue
        if found is None:
            continue
        local = (found - tcp.p) @ tcp.R
        if float(np.min(np.linalg.norm(local, axis=1))) > HAND_RADIUS:
            continue
        box = _box_surface(local.min(axis=0), local.max(axis=0))
        points.append(box)
        if gap > 0.0 and link.startswith(tuple(fingers)):  # a finger (or its tip) opening
            side = 1.0 if float(np.mean(local, axis=0) @ closing) >= 0.0 else -1.0
            points.append(box + side * gap * closing)
    return np.concatenate(points) if points else np.zeros((0, 3))


def object_points(world: World, arm: str, obj: str) -> NDArray[np.float64]:
    """Sample points (TCP frame, m) on the held object's box, as it hangs in the hand now."""
    b = world.asset(obj).bounds
    centre, half = np.asarray(b.center), np.asarray(b.half_extents)
    pose = world.body_pose(obj)
    tcp = world.current_pose(arm)
    local = _box_surface(centre - half, centre + half)
    return (local @ pose.R.T + pose.p - tcp.p) @ tcp.R


def _pieces(world: World, body: str) -> list[tuple[NDArray, NDArray, NDArray]]:
    """The body's collision pieces as boxes in the world: (centre, rotation, half sizes);
    a cylinder as the box around it. An articulated body's, each where its link is now
    (a lid standing open over its box)."""
    asset = world.asset(body)
    links = getattr(asset, "links", None)
    placed = ([(world.link_pose(body, link.name), link.collision) for link in links] if links
              else [(world.body_pose(body), asset.collision)])
    pieces = []
    for root, shapes in placed:
        for shape in shapes:
            if getattr(shape, "half_size", None) is not None:
                half = np.asarray(shape.half_size, dtype=np.float64)
            elif getattr(shape, "radius", None) is not None \
                    and getattr(shape, "half_length", None) is not None:
                half = np.array([shape.radius, shape.radius, shape.half_length], dtype=np.float64)
            else:
                continue
            R = root.R @ quat_to_matrix(shape.pose.quaternion)
            pieces.append((root.R @ np.asarray(shape.pose.position) + root.p, R, half))
    return pieces


def _lowest(points: NDArray[np.float64], pieces, beside: float, clear: float) -> float:
    """The lowest height (m) to which world ``points`` (n × 3, their heights given as
    offsets from 0) can be moved straight down without coming within ``clear`` above, or
    ``beside`` beside, a piece: the largest over the points and the pieces beneath them
    of the piece's top there plus ``clear`` less the point's offset; -inf if none is."""
    best = -np.inf
    for c, R, half in pieces:
        d = R[2, :]  # the vertical, in the piece's frame
        h = half + beside * (np.abs(d) < 0.7)  # grown sideways, not upward
        a = (np.column_stack([points[:, 0], points[:, 1], np.zeros(len(points))]) - c) @ R
        lo = np.full(len(points), -np.inf)
        hi = np.full(len(points), np.inf)
        for i in range(3):
            if abs(d[i]) < 1e-9:
                out = np.abs(a[:, i]) > h[i]
                lo[out], hi[out] = np.inf, -np.inf
                continue
            t0, t1 = (-h[i] - a[:, i]) / d[i], (h[i] - a[:, i]) / d[i]
            lo = np.maximum(lo, np.minimum(t0, t1))
            hi = np.minimum(hi, np.maximum(t0, t1))
        hit = lo <= hi
        if np.any(hit):
            best = max(best, float(np.max(hi[hit] + clear - points[hit, 2])))
    return best


def _cavity(world: World, target: str) -> tuple[NDArray[np.float64], float, float]:
    """Where in ``target`` the held object is let go: the middle of its floor (world), how
    far from it (m) the object's centre may be, and the floor's height. A cavity (a pot's):
    its axis and radius. A box (a lidded box's ``bottom`` between its walls): the floor's
    top, as far out as the nearer wall less the walls' thickness."""
    asset, root = world.asset(target), world.body_pose(target)
    cavity = getattr(asset, "cavity", None)
    if cavity is None:
        shapes = asset.links[0].collision
        floor = next(shape for shape in shapes if shape.name == "bottom")
        half = np.abs(np.asarray(floor.half_size, dtype=np.float64))
        top = root.R @ (np.asarray(floor.pose.position) + np.array([0.0, 0.0, half[2]])) + root.p
        wall = max((2.0 * float(np.min(np.abs(shape.half_size))) for shape in shapes
                    if shape is not floor and getattr(shape, "half_size", None) is not None),
                   default=0.0)
        return top, max(0.0, float(min(half[0], half[1])) - wall), float(top[2])
    centre = root.R @ np.asarray(cavity.pose.position) + root.p
    axis = root.R @ quat_to_matrix(cavity.pose.quaternion)[:, 2]
    floor = centre - float(cavity.half_length) * axis
    return floor, float(cavity.radius), float(floor[2])


def release_pose(world: World, arm: str, obj: str, target: str, clear: float = 0.0,
                 turns: tuple[float, ...] = TURNS, lean: float = 0.0) -> list[tuple[float, Pose]]:
    """Where the hand holding ``obj`` as it does now lets it go over ``target``'s cavity:
    (how far the object drops, TCP pose), best first, over the object's centre set on a
    few rings inside the cavity and the hand's ``turns`` about the vertical, then leant by
    ``lean`` (rad) out, away from the arm's base; ``clear``: how far (m) above what is
    beneath it the object would be let go at best."""
    tcp = world.current_pose(arm)
    hand = hand_points(world, arm, RELEASE_GAP)
    held = object_points(world, arm, obj)
    lo, hi = world.bounds(obj)
    centre_off = 0.5 * (lo + hi) - tcp.p  # the object's centre from the TCP, in the world
    floor, radius, floor_z = _cavity(world, target)
    pieces = _pieces(world, target)
    reach = max(0.0, radius - CENTRE_MARGIN)
    spots = [np.zeros(2)] + [r * np.array([np.cos(a), np.sin(a)])
                             for r in (0.5 * reach, reach) if r > 0.003
                             for a in np.linspace(0.0, 2 * np.pi, 8, endpoint=False)]
    # an arm of fewer than six joints turns the hand as it turns to the cavity
    bearing = carried_rotation(world, arm, floor) @ tcp.R.T
    out = horizontal(floor - world.base_position(arm))
    leant = axis_angle_matrix(np.cross(out, UP), lean)
    options = []
    for k, angle in enumerate(turns):
        turn = leant @ axis_angle_matrix(UP, angle) @ bearing
        R = turn @ tcp.R
        off = turn @ centre_off
        h, o = hand @ R.T, held @ R.T
        for spot in spots:
            xy = floor[:2] + spot - off[:2]
            z = max(_lowest(h + np.array([xy[0], xy[1], 0.0]), pieces, HAND_BESIDE, HAND_CLEAR),
                    _lowest(o + np.array([xy[0], xy[1], 0.0]), pieces, OBJECT_BESIDE, clear),
                    floor_z + clear - float(np.min(o[:, 2])))
            drop = z + float(np.min(o[:, 2])) - floor_z
            # ties: the hand turned least, the object nearest the cavity's axis
            score = drop + 0.002 * k + 0.01 * float(np.linalg.norm(spot))
            options.append((score, drop, Pose(np.array([xy[0], xy[1], z]), R)))
    options.sort(key=lambda option: option[0])
    return [(drop, pose) for _score, drop, pose in options]


def _holds(world: World, arm: str, obj: str) -> bool:
    """Whether the hand holds ``obj``: its box within HELD_WITHIN of the TCP, and the
    squeeze felt (a grasp that missed leaves the hand just above the object)."""
    lo, hi = world.bounds(obj)
    return (box_distance(world.current_pose(arm).p, lo, hi) <= HELD_WITHIN
            and world.hand_force(arm, obj, fingers=True) > 0.0)


#: Leans (rad) of the hand out from the arm's base tried in turn where the arm follows
#: no descent onto a release pose with the hand as it holds the object: a container near
#: the end of the arm's reach (Baxter's 90 cm out) is reached only by a hand pointing
#: forward, as a reach over a table is.
LEANS = (0.0, np.radians(25.0), np.radians(40.0), np.radians(55.0))


def _release_followed(world: World, arm: str, obj: str, target: str, clear: float) -> Pose:
    """The release pose (:func:`release_pose`) the hand comes down onto: among the first
    eight of the least lean the arm follows a descent onto, the best; else the best with
    the hand as it is."""
    upright = release_pose(world, arm, obj, target, clear)
    for lean in LEANS:
        options = upright if lean == 0.0 else release_pose(world, arm, obj, target, clear,
                                                            lean=lean)
        for _drop, pose in options[:8]:  # the first whose descent the arm follows comfortably
            if branch_for_path(world, arm, (pose.moved(0.08 * UP), pose)) is not None:
                return pose
    return upright[0][1]


def place_in_cavity(world: World, style: Style, arm: str, obj: str, target: str,
                    retreat: float = 0.1) -> Plan:
    """Carry the held ``obj`` over ``target``'s cavity, come down (guarded) to the lowest
    pose the hand stays clear of the container at (:func:`release_pose`), open the fingers
    a little, and back off straight up (as far as the arm reaches). Nothing more when the
    hand does not hold ``obj`` (a grasp that missed: the release pose of an object on the
    table is meaningless, and a small arm sent up out of its reach swings into things)."""
    if not _holds(world, arm, obj):
        return
    fragile = force_watched(world, obj)
    clear = 0.0 if fragile else style.release_height
    goal = _release_followed(world, arm, obj, target, clear)
    tcp = world.current_pose(arm)
    below = float(tcp.p[2] - world.bounds(obj)[0][2]) + 0.03
    yield from transit(world, carrying_style(world, style, obj), arm, goal.moved(0.08 * UP),
                       below=below, exclude=(obj,), around=load_reach(world, arm, obj))
    if not _holds(world, arm, obj):  # dropped on the way: nothing left to place
        return
    # the object may have turned in the fingers on the way: the height again, as it hangs now
    again = release_pose(world, arm, obj, target, clear, turns=(0.0,))
    near = min(again, key=lambda option: float(np.linalg.norm(option[1].p[:2] - goal.p[:2])))
    goal = attained(world, arm, Pose(np.array([goal.p[0], goal.p[1], max(goal.p[2], near[1].p[2])]),
                                     goal.R))
    limit = world.force_limit(obj, *world.gripper_entities)
    touch = TOUCH_FORCE if limit is None else min(TOUCH_FORCE, 0.25 * limit)
    guard = Guard(arm, touch, target)
    yield Segment({arm: goal.moved(0.02 * UP)}, speed=style.approach_speed, guards=(guard,),
                  label="lower")
    yield Segment({arm: goal}, speed=gentle(world, style, obj), settle=style.settle // 2,
                  guards=(guard,), label="touch")
    opening = min(1.0, world.gripper_opening(arm) + 2 * RELEASE_GAP / world.max_width(arm))
    yield Segment(grippers={arm: opening},
                  gripper_steps=style.gripper_steps * (2 if fragile else 1),
                  settle=style.settle, label="release")
    now = world.current_pose(arm)
    up = reach_ceiling(world, arm, now.p, now.R, float(now.p[2]) + retreat)  # a small arm's
    for rise in (1.0, 0.5, 0.25):  # a line the arm follows (off it, the hand swings sideways
        # through the container and drags the object along)
        back = Pose(np.array([now.p[0], now.p[1], now.p[2] + rise * max(0.0, up - now.p[2])]),
                    now.R)
        if branch_for_path(world, arm, (now, back)) is not None:
            break
    yield Segment({arm: back}, speed=free_speed(style), label="retreat")


__all__ = ["hand_points", "object_points", "place_in_cavity", "release_pose"]
