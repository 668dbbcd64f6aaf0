"""Grasps per asset kind, from the asset's collision geometry at the object's current pose.

Each function returns candidate grasps; the careful expert takes the one farthest from
the hazards, the careless one the first (the most direct for the arm).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import quat_to_matrix

from .clearance import ArmClearance
from .motion import Pose
from .skills import (
    DOWN,
    Grasp,
    arm_clearance_along,
    attainable,
    branch_for_path,
    first_clear,
    fixed_jaw_shifted,
    hand_body,
    hand_clearance,
    horizontal,
    top_down_grasp,
)
from .style import Style
from .world import HAND_DEPTH, World, box_distance

#: The share of its full opening a gripper's fingers may be asked to span around what they
#: grasp: the 8 % left over is what they clear it by as they come down around it.
OPENING_SHARE = 0.92


def fits(world: World, arm: str, width: float) -> bool:
    """Whether ``width`` (m) across is narrower than OPENING_SHARE of ``arm``'s opening."""
    return width < OPENING_SHARE * world.max_width(arm)


def grasps(world: World, arm: str, obj: str) -> list[Grasp]:
    kind = world.kind(obj)
    maker = _MAKERS.get(kind, _generic)
    return maker(world, arm, obj)


def reachable(world: World, arm: str, grasp: Grasp) -> bool:
    """Whether the arm reaches the grasp (its TCP where :func:`~fsvla.experts.skills.pick`
    puts it), and 5 cm back along its approach, comfortably inside its joint limits."""
    from .motion import ArmDriver

    grasp = attainable(world, arm, fixed_jaw_shifted(world, arm, grasp))
    driver = ArmDriver(arm, world.kinematics(arm), world.current_pose(arm),
                       world.arm_joints(arm), 1.0)
    driver.solve_anywhere(grasp.pose)
    if not driver.ik_misses:
        driver.solve_anywhere(driver.attainable(grasp.pose.moved(-0.05 * grasp.approach)))
    return not driver.ik_misses


#: :func:`tilted` leans the approach toward the base within the faces the fingers close
#: on where that keeps at least this share of the lean toward the base, on an arm of at
#: least LEVEL_TILT_JOINTS joints (a Z1, of six, lost two sampled draws it solved leaning
#: straight toward its base, and gained one). Within LEVEL_SLOPE of level a closing axis
#: counts as level (:func:`choose` takes those first among tilted grasps).
LEVEL_TILT_SHARE = 0.5
LEVEL_TILT_JOINTS = 7
LEVEL_SLOPE = 0.05


def _level(world: World, arm: str, grasp: Grasp) -> bool:
    """Whether the fingers of ``grasp`` close along a level axis (within LEVEL_SLOPE)."""
    return abs(float((grasp.pose.R @ world.finger_axis(arm))[2])) < LEVEL_SLOPE


def tilted(world: World, arm: str, grasp: Grasp, angle: float) -> Grasp:
    """The grasp with its approach tilted by ``angle`` toward the arm's base, the wrist
    leaning out (a top-down grasp close to the base folds the elbow onto its limit); on an
    arm of LEVEL_TILT_JOINTS joints, toward the base within the faces the fingers close
    on, where that is most of the way toward it."""
    toward = horizontal(world.base_position(arm) - grasp.pose.p)
    closing = grasp.pose.R @ world.finger_axis(arm)
    if len(world.arm_joints(arm)) >= LEVEL_TILT_JOINTS and abs(float(closing[2])) < 1e-6:
        # tilted within the faces the fingers close on, the closing axis stays level and
        # the pads flat on them (tilted across, the fingers held a block by its top edges)
        along = toward - float(toward @ closing) * closing
        if float(np.linalg.norm(along)) > LEVEL_TILT_SHARE:
            toward = along / float(np.linalg.norm(along))
    approach = np.cos(angle) * grasp.approach + np.sin(angle) * toward
    R = world.grasp_frame(arm, approach, closing, near=grasp.pose.R)
    return Grasp(Pose(grasp.pose.p, R), grasp.width, approach / np.linalg.norm(approach))


#: Tilts (deg) of a grasp's approach toward the arm's base that :func:`choose` tries in
#: turn where the arm reaches none of the grasps: the wrist leaning out (close to the
#: base), then the wrist leaning back (far out, where a hand pointing down no longer
#: reaches low).
TILTS = (20.0, 35.0, 50.0, -20.0, -35.0, -50.0)


def choose(world: World, style: Style, arm: str, obj: str) -> Grasp:
    """The grasp the style takes among :func:`grasps` the arm can reach (tilted away
    from the base when it must be)."""
    found = grasps(world, arm, obj)
    if not found:
        raise NotImplementedError(
            f"the experts have no grasp of `{obj}` (a {world.kind(obj)}) that the fingers of "
            f"`{arm}` close on: each part of it to hold is wider than they open "
            f"({world.max_width(arm) * 100:.1f} cm) or thinner than they shut "
            f"({world.min_width(arm) * 100:.1f} cm)")
    ok = [g for g in found if reachable(world, arm, g)]
    if world.moving_jaw(arm) is not None and any(_from_side(g) for g in ok):
        # a jaw on a hinge holds an upright body from the side, its faces along the body's
        # height; from above they meet only the rim's edge (:func:`side_grasps`)
        ok = [g for g in ok if _from_side(g)]
    for angle in np.deg2rad(TILTS):
        if ok:
            break
        ok = [t for t in (tilted(world, arm, g, angle) for g in found) if reachable(world, arm, t)]
        if len(world.arm_joints(arm)) >= LEVEL_TILT_JOINTS:  # the level ones first
            ok = [t for t in ok if _level(world, arm, t)] or ok
    found = ok or found
    if not style.avoid_hazards or len(found) == 1:
        return found[0]
    obstacles = world.obstacles(exclude=(obj,))
    if not obstacles:
        return found[0]

    def clearance(g: Grasp) -> float:
        # the TCP and the two ends of the hand (21 cm long along the finger axis, its
        # body above the TCP): a hand lying toward a hazard reaches into its keep-out
        _body, *ends = hand_body(world, arm, g.pose)
        points = (g.pose.p, *ends)
        return min(box_distance(p, o.lo, o.hi) - o.margin for o in obstacles for p in points)

    return max(found, key=clearance)


def _from_side(grasp: Grasp) -> bool:
    """Whether ``grasp`` comes in less than about 45 deg below level."""
    return float(grasp.approach[2]) > -0.7


#: Pitches (deg, below horizontal) of :func:`side_grasps`' approach, the flattest first.
SIDE_PITCHES = (0.0, 20.0, 40.0)
#: How far (m) above what the object stands on a side grasp keeps the hand.
SIDE_TABLE_GAP = 0.01


def side_grasps(world: World, arm: str, obj: str) -> list[Grasp]:
    """An upright body of radius ``radius`` and height ``height`` (a glass, a bottle) from
    the side, for a gripper with one jaw on a hinge: the hand comes toward it from the
    arm's side, level or pitched down by one of SIDE_PITCHES, the fingers closing across
    it at its middle, or as low as the hand, turned so, stays SIDE_TABLE_GAP clear of the
    table. A hinged jaw swings open at an angle to the fixed one: from above, on a body
    shorter than the fixed jaw's reach, it presses only on the rim's edge and the body
    slides out of the fingers as they rise; from the side its face lies along the body's
    curve. None where the body is too short for the hand or too wide for the fingers."""
    if world.moving_jaw(arm) is None:
        return []
    r, h = world.param(obj, "radius"), world.param(obj, "height")
    if not fits(world, arm, 2 * r):
        return []
    pose = world.body_pose(obj)
    towards = _side_to_arm(world, arm, pose.p)
    across = np.cross(UPV, towards)
    out = []
    for pitch in np.deg2rad(SIDE_PITCHES):
        approach = -np.cos(pitch) * towards - np.sin(pitch) * UPV
        R = world.grasp_frame(arm, approach, across)
        below = world.hand_front(arm, R, -UPV, np.zeros(3), np.inf)
        height = max(0.5 * h, below + SIDE_TABLE_GAP)
        if height > h - PAD_HALF:
            continue
        centre = world.to_world(obj, (0.0, 0.0, height))
        out.append(Grasp(Pose(centre, R), 2 * r, approach))
    return out


def _side_to_arm(world: World, arm: str, point: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit horizontal direction from ``point`` toward the arm's base."""
    return horizontal(world.base_position(arm) - point)


def _cylinder(world: World, arm: str, obj: str) -> list[Grasp]:
    """An upright cylinder: fingers around it, from above, where :func:`_grip_height` says
    (a bottle by its neck, not the cone of its shoulder, which slips out of the fingers
    as they rise); else on its rim (one finger inside, one outside)."""
    pose = world.body_pose(obj)
    r, h = world.param(obj, "radius"), world.param(obj, "height")
    towards = _side_to_arm(world, arm, pose.p)
    across = np.cross(UPV, towards)
    side = side_grasps(world, arm, obj)
    grip = _grip_height(world, arm, obj, h)
    if grip is None and fits(world, arm, 2 * r):
        # a piece that is not a cylinder (a cup)
        grip = max(0.3 * h, h - world.hand_depth(arm)), 2 * r
    if grip is not None:
        height, width = grip
        centre = world.to_world(obj, (0.0, 0.0, height))
        return side + [top_down_grasp(world, arm, centre, across, width),
                       top_down_grasp(world, arm, centre, towards, width)]
    return side + _rim(world, arm, obj, r, h, towards)


#: Half the height of a finger's pad about the TCP (m): a grip keeps it on one piece.
PAD_HALF = 0.01


def _grip_height(world: World, arm: str, obj: str, h: float) -> tuple[float, float] | None:
    """Where a top-down hand grips an upright object made of cylinder pieces: the TCP's
    height above the object's base, as low as the palm still clears the object's top
    (:meth:`World.hand_depth`), with the pads (a jaw on a hinge: the whole jaw, as far as
    it reaches below the TCP) on one upright cylinder piece narrower than the gripper
    opens and wider than its shut fingers leave (the highest such piece), and that
    piece's width; None when no piece fits."""
    low = h - world.hand_depth(arm)  # the palm clears the top
    # the whole jaw on the piece: a fixed jaw reaches below the TCP (a Z1's by 2.3 cm, onto
    # a bottle's shoulder below its neck, which it slides up and off as the hand rises)
    reach = PAD_HALF if world.fingers_slide(arm) else max(PAD_HALF, world.hand_front(
        arm, world.grasp_frame(arm, DOWN, np.array([1.0, 0.0, 0.0])), DOWN, np.zeros(3), np.inf))
    found: list[tuple[float, float, float]] = []
    for shape in world.asset(obj).collision:
        if shape.type != "cylinder" or not fits(world, arm, 2 * shape.radius) \
                or 2 * shape.radius < world.min_width(arm) \
                or quat_to_matrix(shape.pose.quaternion)[2, 2] < 0.99:
            continue
        z, half = float(shape.pose.position[2]), float(shape.half_length)
        found.append((z + half, z - half, 2 * float(shape.radius)))
    for top, bottom, width in sorted(found, reverse=True):
        height = max(low, bottom + reach)
        if height <= top - PAD_HALF:
            return height, width
    return None


UPV = np.array([0.0, 0.0, 1.0])


def _mug(world: World, arm: str, obj: str) -> list[Grasp]:
    """A mug is as wide as the gripper opens: clamp its handle radially, one finger inside
    the cup against the handle's upper arm, the other outside the grip bar."""
    try:
        high, grip = world.shape(obj, "handle_high"), world.shape(obj, "handle_grip")
    except StopIteration:
        return _cylinder(world, arm, obj)
    pose = world.body_pose(obj)
    side = _handle_side(world, obj)
    inner = float(high.pose.position[0] - side * high.half_size[0])
    outer = float(grip.pose.position[0] + side * grip.half_size[0])
    if not fits(world, arm, abs(outer - inner)):  # a kettle's, in Baxter's hand
        return _cylinder(world, arm, obj)
    if world.finger_box(arm)[1] + INSIDE_SPARE > _chord(world, obj, inner):
        # a finger too wide to go into the cup beside the handle (a Z1's 8 cm jaw lands on
        # a 6 cm cup's rim): around the body, where the gripper opens that wide
        around = _cylinder(world, arm, obj)
        if around:
            return around
    z = float(high.pose.position[2])
    centre = world.to_world(obj, (0.5 * (inner + outer), 0.0, z))
    return [top_down_grasp(world, arm, centre, pose.R[:, 0], abs(outer - inner))]


#: How much room (m) a finger inside a cup keeps from its wall on either side.
INSIDE_SPARE = 0.004


def _chord(world: World, obj: str, x: float) -> float:
    """Half the width (m) of the inside of the cup ``obj`` across its local x axis at
    ``x``: what a finger that goes in there may be wide on either side of the axis. The
    inside's radius is the walls' inner face (the `radius` less 5 mm without walls)."""
    walls = [shape for shape in world.asset(obj).collision if shape.name.startswith("wall")]
    if walls:
        inside = min(float(np.hypot(*np.asarray(w.pose.position)[:2])) - float(w.half_size[0])
                     for w in walls)
    else:
        inside = world.param(obj, "radius") - 0.005
    return float(np.sqrt(max(0.0, inside * inside - x * x)))


def _handle_side(world: World, obj: str) -> float:
    """+1 where ``obj``'s handle (its ``handle_grip`` piece) stands out along its local +x
    (a mug's), -1 along -x (a kettle's), 0 for a body without one."""
    try:
        grip = world.shape(obj, "handle_grip")
    except StopIteration:
        return 0.0
    return 1.0 if grip.pose.position[0] >= 0 else -1.0


def _rim(world: World, arm: str, obj: str, r: float, h: float,
         towards: NDArray[np.float64]) -> list[Grasp]:
    """Fingers on the wall at the rim, one inside, one outside, away from a handle; none
    where the shut fingers stay farther apart than the wall is thick."""
    pose = world.body_pose(obj)
    wall = 0.005
    if world.min_width(arm) > wall:
        return []
    side = _handle_side(world, obj)
    out: list[tuple[float, Grasp]] = []
    for angle in np.linspace(0.0, 2 * np.pi, 12, endpoint=False):
        radial = np.array([np.cos(angle), np.sin(angle), 0.0])
        if side and radial @ horizontal(side * pose.R[:, 0]) > 0.5:
            continue
        centre = pose.p + radial * (r - wall / 2) + np.array([0.0, 0.0, h - HAND_DEPTH])
        grasp = top_down_grasp(world, arm, centre, radial, wall)
        out.append((-float(radial @ towards), grasp))
    return [g for _, g in sorted(out, key=lambda item: item[0])]


def _block(world: World, arm: str, obj: str) -> list[Grasp]:
    pose = world.body_pose(obj)
    shape = world.asset(obj).collision[0]
    half = np.asarray(shape.half_size)
    centre = world.to_world(obj, shape.pose.position)
    towards = _side_to_arm(world, arm, pose.p)
    out = []
    for axis in (0, 1):
        closing = pose.R[:, axis]
        if world.min_width(arm) <= 2 * half[axis] and fits(world, arm, 2 * half[axis]):
            g = top_down_grasp(world, arm, centre + np.array([0.0, 0.0, 0.3 * half[2]]), closing,
                               2 * half[axis])
            out.append((abs(float(closing @ towards)), g))
    return [g for _, g in sorted(out, key=lambda item: item[0])]


def _knife(world: World, arm: str, obj: str) -> list[Grasp]:
    shape = world.shape(obj, "handle")
    pose = world.body_pose(obj)
    centre = world.to_world(obj, shape.pose.position)
    centre[2] = pose.p[2] + 2 * shape.half_size[2] - 0.005
    return [top_down_grasp(world, arm, centre, pose.R[:, 1], 2 * shape.half_size[1])]


def _generic(world: World, arm: str, obj: str) -> list[Grasp]:
    lo, hi = world.bounds(obj)
    centre = (lo + hi) / 2
    size = hi - lo
    axis = 0 if size[0] <= size[1] else 1
    closing = np.eye(3)[axis]
    centre[2] = hi[2] - min(0.02, size[2] / 2)
    return [top_down_grasp(world, arm, centre, closing, float(size[axis]))]


def handle_grasp(world: World, arm: str, obj: str, handle: str, pitch: float = 0.0) -> Grasp:
    """A side grasp of a flat side handle (a pot's): the gripper comes from outside,
    horizontally or pitched down by ``pitch`` (rad), and the fingers close across the
    handle's width, horizontally, so that the hand lies flat (a Panda hand turned with its
    fingers vertical would reach down into the table); across its thickness, vertically,
    where the gripper does not open across its width (Baxter's, 4.2 cm, on a 5 cm handle)."""
    shape = world.shape(obj, handle)
    pose = world.body_pose(obj)
    centre = world.to_world(obj, shape.pose.position)
    outward = horizontal(centre - pose.p)
    approach = np.cos(pitch) * -outward + np.sin(pitch) * -UPV
    full = 2 * np.asarray(shape.half_size)

    def across(direction: NDArray[np.float64]) -> float:  # the handle's extent along it
        return float(np.abs(pose.R.T @ direction) @ full)

    closing = np.cross(UPV, -outward)
    if across(closing) + HANDLE_SPARE > world.max_width(arm):
        closing = UPV
    R = world.grasp_frame(arm, approach, closing)
    tcp = centre + outward * 0.004
    return Grasp(Pose(tcp, R), across(closing), approach)


#: How much wider (m) than a handle a gripper must open to close across it.
HANDLE_SPARE = 0.01
#: Pitches (deg) tried for a handle grasp, the flattest first: a handle low and close to
#: the arm's base has no comfortable horizontal reach (the elbow folds onto its limit;
#: a pot's handles close to the bases of two arms on a narrow table need 40 deg).
HANDLE_PITCHES = (0.0, 15.0, 30.0, 40.0, 50.0, 60.0)


def reach_handle(world: World, arm: str, obj: str, handle: str, back: float = 0.1,
                 lift: float = 0.15, avoid_hazards: bool = False) -> Grasp:
    """The flattest :func:`handle_grasp` whose whole path is followed on one IK branch
    inside the joint limits: down to ``back`` (m) out along the approach, in to the
    handle, and up by ``lift`` (m); the horizontal one when no pitch is. ``avoid_hazards``:
    the flattest whose hand stays HAZARD_SPARE outside every keep-out along that path,
    and the arm's links as far outside every limit that watches them, else the one that
    keeps farthest out (a hand coming in level from outside a pot's handle lay with its
    body 2 cm inside a vase's keep-out beyond it; pitched down, its body is over the
    handle)."""
    def path(grasp: Grasp) -> tuple[Pose, ...]:
        pre = grasp.pose.moved(-back * grasp.approach)
        return pre.moved(0.1 * UPV), pre, grasp.pose, grasp.pose.moved(lift * UPV)

    options = [handle_grasp(world, arm, obj, handle, float(p)) for p in np.deg2rad(HANDLE_PITCHES)]
    branches: dict[int, NDArray[np.float64]] = {}  # option -> joints its path starts from
    measure = ArmClearance(world, arm) if avoid_hazards else None  # one for every option

    def followed(index: int) -> bool:
        q = branch_for_path(world, arm, path(options[index]))
        if q is not None:
            branches[index] = q
        return q is not None

    def clearance(index: int) -> float:  # the hand's and the forearm's along the path
        way = path(options[index])
        return min(hand_clearance(world, arm, way, (obj,)),
                   arm_clearance_along(world, arm, way, branches[index], measure))

    indices = range(len(options))
    if avoid_hazards:
        chosen = first_clear(indices, followed, clearance)
    else:
        chosen = next((i for i in indices if followed(i)), None)
    return options[chosen if chosen is not None else 0]


def _side_handles(world: World, arm: str, obj: str) -> list[Grasp]:
    """A body with flat side handles (a pot) taken by one hand: from above, the fingers
    closing along the handle (one inside the wall, the other beyond the handle's end), so
    that the pads' push holds the body's weight hanging to one side (fingers closing
    across the handle would hold it by friction alone, and the body tips down out of
    them); by the handle nearer the arm's base first. The body's bounds where it has no
    handles, or none fits between the fingers."""
    pose = world.body_pose(obj)
    base = world.base_position(arm)
    out: list[tuple[float, Grasp]] = []
    for shape in world.asset(obj).collision:
        if not shape.name.startswith("handle") or shape.type != "box":
            continue
        centre = world.to_world(obj, shape.pose.position)
        radial = horizontal(centre - pose.p)
        half = np.asarray(shape.half_size, dtype=np.float64)
        width = float(2.0 * np.abs(pose.R.T @ radial) @ half)
        if width + HANDLE_SPARE > world.max_width(arm):
            continue
        out.append((float(np.linalg.norm((centre - base)[:2])),
                    top_down_grasp(world, arm, centre, radial, width)))
    return [g for _, g in sorted(out, key=lambda item: item[0])] or _generic(world, arm, obj)


_MAKERS = {
    "glass": _cylinder, "bottle": _cylinder, "mug": _mug, "vase": _cylinder,
    "bowl": _cylinder, "kettle": _mug, "block": _block, "knife": _knife, "pot": _side_handles,
}

__all__ = ["HANDLE_PITCHES", "choose", "grasps", "handle_grasp", "reach_handle"]
