"""Articulated assets generated from jinja2 URDF templates (``templates/*.urdf.j2``).

Each builder lays its links out as boxes (collision = visual = boxes), renders the
kind's template, then reads the rendered URDF back with :mod:`.urdf`, so the asset's
links, joints and parts are exactly those of the URDF it carries. Every body is
fixed to the world (``fixed_base``).

Frame (the table frame at yaw 0): +x points away from the robot, +y to the robot's
left, z up. ``size`` is the extent along (x, y, z): depth, width, height. Each body
faces the robot: its front (drawer opening, door, lid knob side) is the -x face, and
its parts open towards -x (the drawer slides out along -x, the door swings out of the
-x face on a vertical hinge at its left (+y) edge, the lid lifts on a hinge along its
back (+x) top edge). Left is +y, right is -y.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import jinja2

from .geometry import bounds_of, inertia_tensor, union_aabb
from .materials import PLASTIC, WOOD, Substance, physics_material
from .model import ArticulatedAsset, BoxShape, ParamValue, Part, Pose, Rgba, start_positions
from .urdf import parse_urdf

TEMPLATE_DIR = Path(__file__).parent / "templates"
OPEN_LIMIT = math.radians(110.0)  # how far a door or lid swings open
DOOR_GAP = 0.003  # m between a hinged door's bottom edge and the table
DRAWER_CLEARANCE = 0.002  # gap between a drawer and its carcass

METAL_GREY = PLASTIC.appearance(color=(0.72, 0.73, 0.75, 1.0)).base_color
DARK_GLASS = (0.08, 0.09, 0.1, 1.0)
HANDLE = (0.2, 0.2, 0.22, 1.0)


@dataclass(frozen=True)
class Panel:
    """A box of a link: full ``size``, ``center`` in the link frame, colour."""

    name: str
    size: tuple[float, float, float]
    center: tuple[float, float, float]
    rgba: Rgba

    @property
    def color_name(self) -> str:
        return "rgba_" + "_".join(f"{round(c * 255):d}" for c in self.rgba)


@dataclass(frozen=True)
class BoxLink:
    """A link made of panels with its inertial (mass, centre, ixx ixy ixz iyy iyz izz)."""

    name: str
    boxes: Sequence[Panel]
    mass: float
    com: tuple[float, float, float]
    inertia: tuple[float, float, float, float, float, float]


def box_link(name: str, boxes: Sequence[Panel], substance: Substance = WOOD) -> BoxLink:
    pieces = [
        (
            BoxShape(pose=Pose(position=b.center), half_size=tuple(s / 2.0 for s in b.size)),
            substance.density,
        )
        for b in boxes
    ]
    mass, _, centre, tensor = inertia_tensor(pieces)
    inertia = (tensor[0, 0], tensor[0, 1], tensor[0, 2], tensor[1, 1], tensor[1, 2], tensor[2, 2])
    return BoxLink(
        name=name,
        boxes=list(boxes),
        mass=mass,
        com=tuple(float(c) for c in centre),
        inertia=tuple(float(i) for i in inertia),
    )


def _number(value: float) -> str:
    value = float(value)
    return "0" if abs(value) < 1e-12 else f"{value:.9g}"


def _vector(values: Sequence[float]) -> str:
    return " ".join(_number(v) for v in values)


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(TEMPLATE_DIR),
        undefined=jinja2.StrictUndefined,
        autoescape=jinja2.select_autoescape(["j2"]),
        keep_trailing_newline=True,
    )
    env.filters["num"] = _number
    env.filters["vec"] = _vector
    return env


def render_urdf(kind: str, **context: object) -> str:
    """Render ``templates/<kind>.urdf.j2``; a missing variable is an error."""
    return _environment().get_template(f"{kind}.urdf.j2").render(**context)


def _assemble(
    kind: str, params: Mapping[str, ParamValue], urdf: str, parts: Mapping[str, str]
) -> ArticulatedAsset:
    """Parse the rendered URDF and name its movable parts (part name -> joint name)."""
    structure = parse_urdf(urdf)
    joints = {j.name: j for j in structure.joints}
    named = [
        Part(name=part, link=joints[joint].child, joint=joint) for part, joint in parts.items()
    ]
    # a part that starts open (``open``) stands out of the body: the bounds hold it there too,
    # so that layouts keep clutter and other objects out of an open drawer's way
    shut = structure.rest_aabb()
    lo, hi = shut
    start = start_positions(structure.joints, list(parts.values()), params)
    if start:
        lo, hi = union_aabb([shut, structure.rest_aabb(start)])
    bounds, footprint = bounds_of(lo, hi)
    total_mass = sum(link.mass for link in structure.links)
    volume = sum(
        8.0 * math.prod(s.half_size)
        for link in structure.links
        for s in link.collision
        if isinstance(s, BoxShape)
    )
    return ArticulatedAsset(
        kind=kind,
        params=dict(params),
        urdf=urdf,
        root_link=structure.root_link,
        links=structure.links,
        joints=structure.joints,
        parts=named,
        material=physics_material(WOOD, None, total_mass / volume),
        bounds=bounds,
        footprint=footprint,
    )


MIN_SIDE = 0.05  # the smallest side of an articulated body that leaves room for its parts


def _checked_size(kind: str, params: Mapping[str, ParamValue]) -> tuple[float, float, float]:
    """``size`` as (depth along x, width along y, height along z); the front is at -x."""
    d, w, h = (float(v) for v in params["size"])
    if min(d, w, h) < MIN_SIDE:
        raise ValueError(
            f"{kind}: every side of size must be at least {MIN_SIDE} m, got ({d}, {w}, {h})"
        )
    return d, w, h


def _wall(size: Sequence[float]) -> float:
    return min(0.015, min(size) / 10.0)


def _shell_panels(
    d: float, w: float, h: float, t: float, rgba: Rgba, *, top: bool = True
) -> list[Panel]:
    """A carcass open at the front (-x): bottom, (top), left (+y), right (-y), back (+x)."""
    inner_h = h - (2 * t if top else t)
    z_mid = t + inner_h / 2.0
    panels = [
        Panel("bottom", (d, w, t), (0.0, 0.0, t / 2.0), rgba),
        Panel("left", (d, t, inner_h), (0.0, (w - t) / 2.0, z_mid), rgba),
        Panel("right", (d, t, inner_h), (0.0, -(w - t) / 2.0, z_mid), rgba),
        Panel("back", (t, w - 2 * t, inner_h), ((d - t) / 2.0, 0.0, z_mid), rgba),
    ]
    if top:
        panels.append(Panel("top", (d, w, t), (0.0, 0.0, h - t / 2.0), rgba))
    return panels


def build_drawer_cabinet(params: Mapping[str, ParamValue]) -> ArticulatedAsset:
    d, w, h = _checked_size("drawer_cabinet", params)
    travel = float(params["travel"])
    t, c = _wall((d, w, h)), DRAWER_CLEARANCE
    wood = WOOD.color
    body = box_link("body", _shell_panels(d, w, h, t, wood))
    # drawer frame: the bottom of the carcass opening, on the front (-x) plane; the
    # drawer runs from there towards +x (into the carcass)
    inner_w, inner_h = w - 2 * t - 2 * c, h - 2 * t - 2 * c
    depth = d - 2 * t - c
    if travel > depth:
        raise ValueError(
            f"drawer_cabinet: travel {travel} m exceeds the drawer's depth {depth:.3f} m"
        )
    side_h = 0.7 * inner_h
    drawer = box_link(
        "drawer",
        [
            Panel("front", (t, inner_w, inner_h), (t / 2.0, 0.0, c + inner_h / 2.0), wood),
            Panel("floor", (depth, inner_w, t), (t + depth / 2.0, 0.0, c + t / 2.0), wood),
            Panel(
                "side_left",
                (depth, t, side_h),
                (t + depth / 2.0, (inner_w - t) / 2.0, c + side_h / 2.0),
                wood,
            ),
            Panel(
                "side_right",
                (depth, t, side_h),
                (t + depth / 2.0, -(inner_w - t) / 2.0, c + side_h / 2.0),
                wood,
            ),
            Panel(
                "back",
                (t, inner_w - 2 * t, side_h),
                (t + depth - t / 2.0, 0.0, c + side_h / 2.0),
                wood,
            ),
            Panel("handle", (0.02, 0.4 * inner_w, 0.015), (-0.01, 0.0, c + 0.6 * inner_h), HANDLE),
        ],
    )
    urdf = render_urdf(
        "drawer_cabinet",
        size=(d, w, h),
        travel=travel,
        body=body,
        drawer=drawer,
        drawer_origin=(-d / 2.0, 0.0, t),
    )
    return _assemble("drawer_cabinet", params, urdf, {"drawer": "drawer_joint"})


def build_microwave(params: Mapping[str, ParamValue]) -> ArticulatedAsset:
    d, w, h = _checked_size("microwave", params)
    t = _wall((d, w, h))
    control = 0.25 * w  # the control strip on the right (-y) of the front
    panels = _shell_panels(d, w, h, t, METAL_GREY)
    panels.append(
        Panel(
            "controls",
            (t, control, h - 2 * t),
            (-(d - t) / 2.0, -(w - control) / 2.0, h / 2.0),
            DARK_GLASS,
        )
    )
    body = box_link("body", panels, PLASTIC)
    door_w = w - control
    # door frame: on the hinge, the left (+y) edge of the front (-x) face; the closed
    # door runs from there towards -y, its bottom edge DOOR_GAP above what the body
    # stands on (a door down to the table dragged its weight across it as it swung)
    door = box_link(
        "door",
        [
            Panel("panel", (t, door_w, h - DOOR_GAP),
                  (-t / 2.0, -door_w / 2.0, (h + DOOR_GAP) / 2.0), DARK_GLASS),
            Panel("handle", (0.02, 0.015, 0.5 * h), (-t - 0.01, -(door_w - 0.03), h / 2.0), HANDLE),
        ],
        PLASTIC,
    )
    urdf = render_urdf(
        "microwave",
        size=(d, w, h),
        body=body,
        door=door,
        door_origin=(-d / 2.0, w / 2.0, 0.0),
        door_limit=OPEN_LIMIT,
    )
    return _assemble("microwave", params, urdf, {"door": "door_joint"})


def build_lidded_box(params: Mapping[str, ParamValue]) -> ArticulatedAsset:
    d, w, h = _checked_size("lidded_box", params)
    t = _wall((d, w, h))
    wood = WOOD.color
    walls = _shell_panels(d, w, h - t, t, wood, top=False)
    walls.append(
        Panel(
            "front", (t, w - 2 * t, h - 2 * t), (-(d - t) / 2.0, 0.0, (h - t) / 2.0 + t / 2.0), wood
        )
    )
    body = box_link("body", walls)
    # lid frame: on the hinge, the back (+x) top edge; the closed lid runs towards -x
    lid = box_link(
        "lid",
        [
            Panel("panel", (d, w, t), (-d / 2.0, 0.0, t / 2.0), wood),
            Panel("knob", (0.012, 0.3 * w, t), (-d - 0.006, 0.0, t / 2.0), HANDLE),
        ],
    )
    urdf = render_urdf(
        "lidded_box",
        size=(d, w, h),
        body=body,
        lid=lid,
        lid_origin=(d / 2.0, 0.0, h - t),
        lid_limit=OPEN_LIMIT,
    )
    return _assemble("lidded_box", params, urdf, {"lid": "lid_joint"})


ArticulatedBuilder = Callable[[Mapping[str, ParamValue]], ArticulatedAsset]

ARTICULATED_BUILDERS: Mapping[str, ArticulatedBuilder] = {
    "drawer_cabinet": build_drawer_cabinet,
    "microwave": build_microwave,
    "lidded_box": build_lidded_box,
}
