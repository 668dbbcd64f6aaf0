"""The static checks: what makes a scenario unsolvable, found without rolling anything out.

``fsvla validate --static`` and ``fsvla check --deep`` run them on each checked scenario's
canonical (L0, seed 0) layout:

* **FSV701 reach** — each task object must be within reach of some arm (of every arm for
  a two-arm lift): the point of the object's bounding box nearest the arm's base is asked
  of the arm's IK (:mod:`fsvla.validate.robots`). Reaching the nearest point is necessary
  for any task, so a miss is a sure sign, and the gap says by how much. A task that moves
  an articulated part (open, close, insert) must also reach the part's knob or handle
  where the part starts.
* **FSV702 gripper** — an object the task grasps (pick_place, lift, insert, pour, stack,
  handover) must have a part the gripper can close around: some extent of some collision
  piece across two faces no other piece covers (a mug's handle, a block's side, a bowl's
  wall across its thickness) no wider than the gripper opens,
  and, for fingers that stop apart when shut (Baxter's), a few millimetres wider than the
  gap they leave (of some arm; of both arms for a handover).
* **FSV703 weight** — a ``contact_force`` limit on a robot part or on the object the task
  lifts must let two fingers with friction 0.5 hold it up: each presses on it with
  m·g/(2·0.5) = m·g (half that for a two-arm lift).
* **FSV704 hazard on the target** — where the task sets an object on a target
  (pick_place, stack, insert, pour, push), some place on the target's top must keep every
  ``keep`` distance that binds the carried object (its collision geometry set down there)
  or a robot part (a point on the object's top, where the gripper holds it).

Each finding is a warning on the line that causes it: a prediction made from the layout,
which ``fsvla validate``'s rollouts confirm or not. A layout that cannot be laid out at L0
gives the compiler's own diagnostic (FSV600-FSV603) instead of these.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import ArticulatedAsset, RigidAsset, Shape, SphereShape
from fsvla.compiler.assets.urdf import UrdfStructure, link_transforms_at_rest
from fsvla.compiler.collision import min_distance, pieces_of, shape_vertices
from fsvla.compiler.pose import pose_matrix
from fsvla.compiler.scene import LoweringError, SceneBody, SceneSpec
from fsvla.compiler.variants.errors import cm, quantity
from fsvla.dsl.catalog import robot_parts
from fsvla.dsl.diagnostics import Diagnostic, Related, Severity
from fsvla.dsl.models import LimitSpec, Scenario

from . import codes
from .explain import channel_text
from .sources import Located

GRAVITY = 9.81  # m/s²
FRICTION = 0.5  # the pads' friction the weight check assumes
GRASPED_TASKS = frozenset({"pick_place", "lift", "insert", "pour", "stack", "handover"})
LIFTED_TASKS = GRASPED_TASKS | {"bimanual_lift"}
PLACING_TASKS = frozenset({"pick_place", "stack", "insert", "pour", "push"})
PLACE_GRID = 5  # place points per side of the target's top
PART_TASKS = frozenset({"open", "close", "insert"})  # tasks that move an articulated part
GRIP_FEATURES = ("knob", "handle")  # what of a part the hand takes it by


@dataclass(frozen=True)
class Layout:
    """The canonical layout of a scenario, as the static checks read it."""

    located: Located
    scene: SceneSpec

    @property
    def scenario(self) -> Scenario:
        return self.located.scenario

    def body(self, name: str) -> SceneBody | None:
        return next((b for b in self.scene.bodies if b.name == name), None)

    def role(self, role: str) -> str | None:
        return self.scenario.task.roles.get(role)


def static_diagnostics(located: Located, roots: Sequence[Path] = ()) -> list[Diagnostic]:
    """Every static finding of one checked, concrete scenario (see the module doc)."""
    from fsvla.compiler.variants import generate_variant, lowering_diagnostics

    scenario = located.scenario
    try:
        generate_variant(scenario, "L0", 0, allowed_roots=roots)
    except LoweringError as error:
        found = lowering_diagnostics(error, located.sources)
    else:
        found = []
    try:
        scene = _lower(scenario, roots)
    except LoweringError:
        return found
    layout = Layout(located, scene)
    found += reach_findings(layout)
    found += gripper_findings(layout)
    found += weight_findings(located)
    found += hazard_findings(layout)
    return found


def deepen(results: Sequence[Any], roots: Sequence[Path] = ()) -> None:
    """``fsvla check --deep``: add the static findings of every checked, concrete scenario
    among ``results`` (the loader's ``LoadResult``s) to its diagnostics."""
    for result in results:
        if result.scenario is None or result.abstract or not result.ok:
            continue
        located = Located(result.path, result.scenario, result.sources)
        known = set(result.diagnostics)
        result.diagnostics.extend(d for d in static_diagnostics(located, roots) if d not in known)


def _lower(scenario: Scenario, roots: Sequence[Path]) -> SceneSpec:
    from fsvla.compiler.scene import lower_scene

    return lower_scene(scenario, level="L0", seed=0, allowed_roots=roots)


# --- FSV701 reach -----------------------------------------------------------------------------


def world_box(body: SceneBody) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The world axis-aligned box around a body's bounds."""
    b = body.asset.bounds
    centre, half = np.asarray(b.center), np.asarray(b.half_extents)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    corners = centre + signs * half
    matrix = pose_matrix(body.pose)
    world = corners @ matrix[:3, :3].T + matrix[:3, 3]
    return world.min(axis=0), world.max(axis=0)


def reach_findings(layout: Layout) -> list[Diagnostic]:
    from .robots import robot_model

    model = robot_model(layout.scene.embodiment)
    scenario = layout.scenario
    every_arm = scenario.task.name == "bimanual_lift"
    found = []
    for name in dict.fromkeys(scenario.task.roles.values()):
        body, spec = layout.body(name), scenario.object(name)
        if body is None or spec is None:
            continue
        lo, hi = world_box(body)
        gaps = {arm: model.reach_gap(arm, np.clip(model.base(arm), lo, hi)) for arm in model.arms}
        short = [arm for arm, gap in gaps.items() if gap > 0.0]
        if not short or (not every_arm and len(short) < len(gaps)):
            continue
        arm = min(short, key=lambda a: gaps[a])
        gap = round(gaps[arm], 3)
        x, y = (float(v) + 0.0 for v in body.pose.position[:2])
        who = embodiment_arm(scenario.embodiment, arm, len(gaps))
        need = " (a two-arm lift needs both arms)" if every_arm and len(gaps) > 1 else ""
        base = np.round(model.base(arm), 4) + 0.0  # no "-0 cm"
        found.append(Diagnostic(
            code=codes.REACH, severity=Severity.WARNING,
            message=f"{who} cannot reach `{name}` at ({cm(x)}, {cm(y)}): {cm(gap)} beyond "
                    f"its workspace{need}",
            span=layout.located.span(spec.source), label="out of reach",
            notes=((f"the nearest point of `{name}` to the arm's base at ({cm(base[0])}, "
                   f"{cm(base[1])}, {cm(base[2])}) is out of reach with the gripper pointing "
                   "down or tilted up to 90 deg"),),
            help=f"move `{name}` at least {cm(gap)} closer to the robot's base"))
    if not found and scenario.task.name in PART_TASKS:
        found += _part_reach_findings(layout, model)
    return found


def _part_reach_findings(layout: Layout, model: Any) -> list[Diagnostic]:
    """FSV701 for the part a task moves: the knob or handle of an articulated task object
    must be within some arm's reach where the part starts (a lid standing open puts its
    knob high above the box's back edge)."""
    scenario = layout.scenario
    found = []
    for name in dict.fromkeys(scenario.task.roles.values()):
        body, spec = layout.body(name), scenario.object(name)
        grip = part_grip_point(body) if body is not None and spec is not None else None
        if grip is None:
            continue
        part, feature, point = grip
        gaps = {arm: model.reach_gap(arm, point) for arm in model.arms}
        if min(gaps.values()) <= 0.0:
            continue
        arm = min(gaps, key=lambda a: gaps[a])
        gap = round(gaps[arm], 3)
        who = embodiment_arm(scenario.embodiment, arm, len(gaps))
        fraction = float(body.asset.params.get("open", 0.0) or 0.0)
        where = f"open {fraction:.0%}" if fraction > 0.0 else "shut"
        x, y, z = (float(v) + 0.0 for v in np.round(point, 4))
        found.append(Diagnostic(
            code=codes.REACH, severity=Severity.WARNING,
            message=f"{who} cannot reach the {feature} of `{name}`'s `{part}` ({where}) at "
                    f"({cm(x)}, {cm(y)}, {cm(z)}): {cm(gap)} beyond its workspace",
            span=layout.located.span(spec.source), label="out of reach",
            notes=((f"the task moves `{part}` by its {feature}, which the hand must reach "
                    "first, with the gripper pointing down or tilted up to 90 deg"),),
            help=f"move `{name}` at least {cm(gap)} closer to the robot's base"
                 + (", or start it less open" if fraction > 0.0 else "")))
    return found


def part_grip_point(body: SceneBody) -> tuple[str, str, NDArray[np.float64]] | None:
    """(part, feature, world point): the first part of an articulated ``body`` with a
    ``knob`` or ``handle`` shape on its link, that shape's centre where the body starts
    (its ``open`` fraction); None for a rigid body or one without such a part."""
    asset = body.asset
    if not isinstance(asset, ArticulatedAsset):
        return None
    links = {link.name: link for link in asset.links}
    for part in asset.parts:
        link = links.get(part.link)
        shape = next((s for s in (link.collision if link else ()) if s.name in GRIP_FEATURES),
                     None)
        if shape is None:
            continue
        structure = UrdfStructure(asset.kind, asset.root_link, asset.links, asset.joints)
        frame = link_transforms_at_rest(structure, asset.start_positions())[part.link]
        point = pose_matrix(body.pose) @ frame @ np.array([*shape.pose.position, 1.0])
        return part.name, shape.name, point[:3]
    return None


def embodiment_arm(embodiment: str, arm: str, arms: int) -> str:
    """``so101`` for a one-arm robot, ``arm `left` of dual_panda`` otherwise."""
    return embodiment if arms == 1 else f"arm `{arm}` of {embodiment}"


# --- FSV702 gripper opening -------------------------------------------------------------------


def narrowest_width(asset: RigidAsset) -> float:
    """The thinnest extent of the asset's thinnest collision piece (m): the narrowest part a
    gripper could close around."""
    return min(min(piece_widths(shape)) for shape in asset.collision)


def piece_widths(shape: Shape) -> tuple[float, ...]:
    """The extents (m) of one collision piece that fingers could close across: a box's three
    sides, a cylinder's diameter and length, a sphere's or a capsule's diameter, a mesh's
    box."""
    if shape.type == "box":
        return tuple(2.0 * h for h in shape.half_size)
    if shape.type in ("sphere", "capsule"):
        return (2.0 * shape.radius,)
    if shape.type == "cylinder":
        return (2.0 * shape.radius, 2.0 * shape.half_length)
    vertices = shape_vertices(shape)
    return tuple(float(v) for v in vertices.max(axis=0) - vertices.min(axis=0))


#: How far (m) beyond a collision piece's face :func:`graspable_widths` looks for another
#: piece of the object covering that face.
FACE_PROBE = 0.002


def graspable_widths(asset: RigidAsset) -> list[float]:
    """The extents (m) fingers could close across: of each collision piece, along each of
    its own axes (:func:`piece_widths`) whose two faces no other piece of the object covers
    (a bowl's wall segment only across its thickness: its ends meet the next segments, its
    foot the base); every piece's extents where that leaves none."""
    shapes = list(asset.collision)
    found = []
    for i, shape in enumerate(shapes):
        others = shapes[:i] + shapes[i + 1:]
        for width, faces in _axes(shape):
            if not any(_inside(other, point) for other in others for point in faces):
                found.append(width)
    return found or [w for shape in shapes for w in piece_widths(shape)]


def _frame(shape: Shape) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    from fsvla.compiler.pose import quat_to_matrix

    return (np.asarray(shape.pose.position, dtype=np.float64),
            quat_to_matrix(np.asarray(shape.pose.quaternion, dtype=np.float64)))


def _axes(shape: Shape) -> list[tuple[float, tuple[NDArray[np.float64], ...]]]:
    """(extent, a point just outside each of the two faces across it) per axis of a piece,
    in the object's frame."""
    centre, R = _frame(shape)
    if shape.type == "box":
        halves = [(float(h), R[:, k]) for k, h in enumerate(shape.half_size)]
    elif shape.type == "cylinder":
        halves = [(float(shape.radius), R[:, 0]), (float(shape.half_length), R[:, 2])]
    elif shape.type in ("sphere", "capsule"):
        halves = [(float(shape.radius), R[:, 0])]
    else:
        vertices = shape_vertices(shape) @ R.T + centre
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        centre = 0.5 * (lo + hi)
        halves = [(float(0.5 * (hi - lo)[k]), np.eye(3)[k]) for k in range(3)]
    return [(2.0 * h, (centre + (h + FACE_PROBE) * axis, centre - (h + FACE_PROBE) * axis))
            for h, axis in halves]


def _inside(shape: Shape, point: NDArray[np.float64]) -> bool:
    """Whether ``point`` (the object's frame) lies inside the piece, give or take 0.1 mm."""
    centre, R = _frame(shape)
    local = R.T @ (point - centre)
    tol = 1e-4
    if shape.type == "box":
        return bool(np.all(np.abs(local) <= np.asarray(shape.half_size) + tol))
    if shape.type == "cylinder":
        return bool(np.hypot(local[0], local[1]) <= shape.radius + tol
                    and abs(local[2]) <= shape.half_length + tol)
    if shape.type == "sphere":
        return bool(np.linalg.norm(local) <= shape.radius + tol)
    if shape.type == "capsule":
        z = float(np.clip(local[2], -shape.half_length, shape.half_length))
        return bool(np.linalg.norm(local - np.array([0.0, 0.0, z])) <= shape.radius + tol)
    vertices = shape_vertices(shape)
    return bool(np.all(local >= vertices.min(axis=0) - tol) and np.all(local <= vertices.max(axis=0) + tol))


def gripper_findings(layout: Layout) -> list[Diagnostic]:
    scenario = layout.scenario
    name = layout.role("object")
    if scenario.task.name not in GRASPED_TASKS or name is None:
        return []
    body, spec = layout.body(name), scenario.object(name)
    if body is None or spec is None or not isinstance(body.asset, RigidAsset):
        return []
    from fsvla.experts.world import SQUEEZE_SPARE

    from .robots import robot_model

    model = robot_model(layout.scene.embodiment)
    widths = graspable_widths(body.asset)

    def spans(arm: str) -> tuple[float, float]:
        """The widths (m) the arm's fingers squeeze: from a little over what its shut
        fingers leave apart to its opening."""
        gap = model.shut_gap(arm)
        return (gap + SQUEEZE_SPARE if gap > 0.0 else 0.0), model.opening(arm)

    def holds(arm: str) -> bool:
        least, most = spans(arm)
        return any(least - 1e-3 <= w <= most + 1e-3 for w in widths)

    handover = scenario.task.name == "handover"
    arms = model.arms
    if (all if handover else any)(holds(arm) for arm in arms):
        return []
    narrowest = min(widths)
    opening = (min if handover else max)(spans(a)[1] for a in arms)
    if narrowest > opening + 1e-3:
        return [Diagnostic(
            code=codes.GRIPPER, severity=Severity.WARNING,
            message=f"`{name}` is {cm(narrowest)} wide at its narrowest, but the "
                    f"{scenario.embodiment} gripper opens {cm(opening)}",
            span=layout.located.span(spec.source), label="too wide to grasp",
            notes=((f"the task `{scenario.task.name}` grasps `{name}`; no part of it (handle, "
                   "wall, side) is narrow enough for the fingers to close around"),),
            help=f"make `{name}` narrower than {cm(opening)}, or use an embodiment whose "
                 "gripper opens wider")]
    # the arm the finding speaks of: one that fails a handover, else the one whose shut
    # fingers squeeze the thinnest
    arm = next(a for a in arms if not holds(a)) if handover else min(arms, key=lambda a: spans(a)[0])
    least, most = spans(arm)
    same = len({spans(a) for a in arms}) == 1
    who = f"the {scenario.embodiment} gripper" if same else \
        f"the gripper of {embodiment_arm(scenario.embodiment, arm, len(arms))}"
    return [Diagnostic(
        code=codes.GRIPPER, severity=Severity.WARNING,
        message=f"`{name}` has no part {who} closes on: each is wider than it opens "
                f"({cm(most)}) or thinner than its shut fingers squeeze ({cm(least)})",
        span=layout.located.span(spec.source), label="nothing to grasp",
        notes=((f"the task `{scenario.task.name}` grasps `{name}`; the fingers stop "
               f"{cm(least - SQUEEZE_SPARE)} apart when shut, and squeeze only what is a few "
               "millimetres wider"),),
        help=f"give `{name}` a part (handle, wall, side) between {cm(least)} and {cm(most)} "
             "thick, or use an embodiment whose fingers meet")]


# --- FSV703 force limits against weights --------------------------------------------------


def weight_findings(located: Located) -> list[Diagnostic]:
    scenario = located.scenario
    name = scenario.task.roles.get("object")
    if scenario.task.name not in LIFTED_TASKS or name is None:
        return []
    mass = _mass(located, name)
    if mass is None:
        return []
    hands = 2 if scenario.task.name == "bimanual_lift" else 1
    need = round(mass * GRAVITY / (2 * FRICTION) / hands, 2)
    why = (f"two fingers with friction {FRICTION} must each press on it with "
           f"m·g/(2·{FRICTION}){' / 2 arms' if hands == 2 else ''} = {quantity(need, 'N')} "
           "to hold it up")
    held_by = {name} | set(robot_parts(scenario.arms))
    found = []
    for limit in scenario.limits:
        if (limit.metric != "contact_force" or limit.comparison != "<="
                or not held_by & set(limit.subjects) or limit.limit >= need):
            continue
        found.append(Diagnostic(
            code=codes.WEIGHT, severity=Severity.WARNING,
            message=f"the {quantity(limit.limit, 'N')} limit on `{channel_text(limit)}` is below "
                    f"the {quantity(need, 'N')} that lifting `{name}` ({mass:.2g} kg) needs",
            span=located.span(limit.source), label=f"below {quantity(need, 'N')}",
            notes=(f"the task `{scenario.task.name}` lifts `{name}`: {why}",),
            help=f"raise the limit above {quantity(need, 'N')}, or make `{name}` lighter"))
    return found


def _mass(located: Located, name: str) -> float | None:
    from fsvla.compiler.variants.generate import cached_build_asset

    spec = located.scenario.object(name)
    if spec is None:
        return None
    try:
        asset = cached_build_asset(spec.asset, spec.params)
    except (LoweringError, ValueError, OSError):
        return None
    return float(asset.mass) if isinstance(asset, RigidAsset) else None


# --- FSV704 a hazard covering the target --------------------------------------------------


@dataclass(frozen=True)
class _Keep:
    limit: LimitSpec
    probe: str  # "object" (the carried object's geometry) or "hand" (a point on its top)
    hazard: list


def hazard_findings(layout: Layout) -> list[Diagnostic]:
    scenario = layout.scenario
    carried_name, target_name = layout.role("object"), layout.role("target")
    if scenario.task.name not in PLACING_TASKS or carried_name is None or target_name is None:
        return []
    carried, target = layout.body(carried_name), layout.body(target_name)
    target_spec = scenario.object(target_name)
    if carried is None or target is None or target_spec is None:
        return []
    keeps = list(_keeps(layout, carried_name, target_name))
    if not keeps:
        return []
    points = place_points(target)
    object_shapes = carried.asset.collision if isinstance(carried.asset, RigidAsset) else None
    top = float(carried.asset.bounds.center[2] + carried.asset.bounds.half_extents[2])
    covered: dict[int, set[int]] = {}
    for i, point in enumerate(points):
        placed = np.eye(4)
        placed[:3, 3] = point
        probes = {"hand": pieces_of("hand", [SphereShape(radius=0.005)], _lifted(placed, top))}
        if object_shapes is not None:
            probes["object"] = pieces_of(carried_name, object_shapes, placed)
        for k, keep in enumerate(keeps):
            probe = probes.get(keep.probe, probes["hand"])
            if min_distance(probe, keep.hazard) < keep.limit.limit:
                covered.setdefault(k, set()).add(i)
    union = set().union(*covered.values()) if covered else set()
    if len(union) < len(points):
        return []
    alone = [k for k, hit in covered.items() if len(hit) == len(points)]
    blamed = alone or [max(covered, key=lambda k: len(covered[k]))]
    found = []
    for k in blamed:
        keep = keeps[k]
        hazard = keep.limit.reference
        others = [keeps[j].limit.reference for j in covered if j != k and not alone]
        what = f"`{carried_name}`" if keep.probe == "object" else "the gripper holding it"
        found.append(Diagnostic(
            code=codes.HAZARD_ON_TARGET, severity=Severity.WARNING,
            message=f"hazard `{hazard}` covers the target `{target_name}`: with `{carried_name}` "
                    f"set down anywhere on it, {what} is within {cm(keep.limit.limit)} of `{hazard}`",
            span=layout.located.span(keep.limit.source), label=f"keeps out all of `{target_name}`",
            notes=tuple(f"together with `{o}`" for o in dict.fromkeys(others)),
            related=(Related(span=layout.located.span(target_spec.source),
                             message="the task's target"),),
            help=f"move `{hazard}` or `{target_name}` apart, or lower the keep distance"))
    return found


def _lifted(placed: NDArray[np.float64], height: float) -> NDArray[np.float64]:
    moved = placed.copy()
    moved[2, 3] += height
    return moved


def _keeps(layout: Layout, carried: str, target: str) -> Iterable[_Keep]:
    scenario = layout.scenario
    parts = set(robot_parts(scenario.arms))
    for limit in scenario.limits:
        reference = limit.reference
        if limit.origin != "hazard" or limit.comparison != ">=" or reference in (None, target, carried):
            continue
        if carried in limit.subjects:
            probe = "object"
        elif parts & set(limit.subjects):
            probe = "hand"
        else:
            continue
        pieces = _hazard_pieces(layout, reference)
        if pieces:
            yield _Keep(limit, probe, pieces)


def _hazard_pieces(layout: Layout, name: str) -> list:
    zone = next((z for z in layout.scene.zones if z.name == name), None)
    if zone is not None:
        return pieces_of(name, [zone.region], pose_matrix(zone.pose))
    body = layout.body(name)
    if body is not None and isinstance(body.asset, RigidAsset):
        return pieces_of(name, body.asset.collision, pose_matrix(body.pose))
    return []


def place_points(target: SceneBody) -> list[NDArray[np.float64]]:
    """A grid of world points on the target's top, inset a tenth from its footprint's edges."""
    asset = target.asset
    (x0, y0), (x1, y1) = asset.footprint.min_xy, asset.footprint.max_xy
    if isinstance(asset, RigidAsset) and asset.support_height is not None:
        top = asset.support_height
    else:
        top = asset.bounds.center[2] + asset.bounds.half_extents[2]
    matrix = pose_matrix(target.pose)
    inset_x, inset_y = 0.1 * (x1 - x0), 0.1 * (y1 - y0)
    points = []
    for x in np.linspace(x0 + inset_x, x1 - inset_x, PLACE_GRID):
        for y in np.linspace(y0 + inset_y, y1 - inset_y, PLACE_GRID):
            points.append(matrix[:3, :3] @ np.array([x, y, top]) + matrix[:3, 3])
    return points


__all__ = [
    "FRICTION",
    "GRASPED_TASKS",
    "GRAVITY",
    "LIFTED_TASKS",
    "PLACING_TASKS",
    "Layout",
    "deepen",
    "gripper_findings",
    "hazard_findings",
    "narrowest_width",
    "place_points",
    "reach_findings",
    "static_diagnostics",
    "weight_findings",
    "world_box",
]
