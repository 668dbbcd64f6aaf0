"""Visual markers for hazard zones (`ZONES` in the catalog).

A zone has no body: its marker is a thin (``MARKER_THICKNESS``) visual lying on the
support surface, which a camera sees and nothing collides with. The corridor is the
exception: its two walls are static collision boxes. The zone frame has its origin
on the surface at the zone's centre (for an edge zone: at the support surface's
centre), z up, and at yaw 0 its axes are the table frame's: +x away from the robot,
+y to the robot's left. An edge zone's ``front`` is the support's edge nearest the
robot (-x), ``back`` +x, ``left`` +y, ``right`` -y. A corridor runs along x at yaw 0
(from the robot outwards): its walls are at -y and +y, ``length`` along x, ``width``
(the gap) along y.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import trimesh

from .geometry import bounds_of, inline_mesh, shape_aabb, shape_to_trimesh, union_aabb
from .model import (
    Appearance,
    BoxShape,
    CylinderShape,
    ParamValue,
    Pose,
    Shape,
    VisualPart,
    ZoneAsset,
)

MARKER_THICKNESS = 0.002
STRIPE_WIDTH = 0.02  # width of one stripe or ring of a striped marker
CORRIDOR_WALL_THICKNESS = 0.02

# Which edge of the support a side names, as an outward direction in the support frame
# (+x away from the robot, +y to its left): the front edge is the one nearest the robot.
EDGE_DIRECTIONS: Mapping[str, tuple[float, float]] = {
    "front": (-1.0, 0.0),
    "back": (1.0, 0.0),
    "left": (0.0, 1.0),
    "right": (0.0, -1.0),
}

HEAT = Appearance(base_color=(1.0, 0.45, 0.05, 1.0), emission=(1.0, 0.4, 0.05, 3.0), roughness=0.8)
YELLOW = Appearance(base_color=(1.0, 0.85, 0.0, 1.0), roughness=0.7)
BLACK = Appearance(base_color=(0.03, 0.03, 0.03, 1.0), roughness=0.7)
RED = Appearance(base_color=(0.85, 0.05, 0.05, 1.0), roughness=0.7)
WHITE = Appearance(base_color=(0.97, 0.97, 0.97, 1.0), roughness=0.7)
AMBER = Appearance(base_color=(1.0, 0.6, 0.0, 1.0), emission=(1.0, 0.55, 0.0, 0.5), roughness=0.7)
WALL_GREY = Appearance(base_color=(0.55, 0.57, 0.6, 1.0), roughness=0.6)

STRIPE_COLOURS: Mapping[str, tuple[Appearance, Appearance]] = {
    "energized_zone": (YELLOW, BLACK),
    "no_go_zone": (RED, WHITE),
}


def build_zone_marker(
    kind: str, params: Mapping[str, ParamValue], *, support_size: Sequence[float] | None = None
) -> ZoneAsset:
    """The marker of a zone. ``params`` are merged with the catalog defaults, in SI.

    ``support_size`` (x, y extents of the support's top) is needed by ``edge_zone``.
    """
    if kind in ("heat_zone", "energized_zone", "no_go_zone"):
        return _area_marker(kind, params)
    if kind == "edge_zone":
        if support_size is None:
            raise ValueError("edge_zone needs the support's size (support_size=(x, y))")
        return _edge_marker(params, support_size)
    if kind == "corridor":
        return _corridor(params)
    raise ValueError(
        f"unknown zone kind {kind!r}; known: heat_zone, energized_zone, no_go_zone, "
        "edge_zone, corridor"
    )


def _area_marker(kind: str, params: Mapping[str, ParamValue]) -> ZoneAsset:
    size, radius = params.get("size"), params.get("radius")
    if (size is None) == (radius is None):
        raise ValueError(
            f"{kind} needs exactly one of `size` and `radius`, got size={size!r}, radius={radius!r}"
        )
    height = float(params.get("height", 0.0) or 0.0)
    region_height = max(height, MARKER_THICKNESS)
    if size is not None:
        sx, sy = (float(v) for v in size)
        region: Shape = BoxShape(
            name="region",
            pose=Pose(position=(0.0, 0.0, region_height / 2.0)),
            half_size=(sx / 2.0, sy / 2.0, region_height / 2.0),
        )
        if kind == "heat_zone":
            visuals = [_part("glow", _slab(sx, sy), HEAT)]
        else:
            visuals = _striped_rectangle(sx, sy, *STRIPE_COLOURS[kind])
    else:
        r = float(radius)
        region = CylinderShape(
            name="region",
            pose=Pose(position=(0.0, 0.0, region_height / 2.0)),
            radius=r,
            half_length=region_height / 2.0,
        )
        if kind == "heat_zone":
            visuals = [_part("glow", _disc(0.0, r), HEAT)]
        else:
            visuals = _striped_disc(r, *STRIPE_COLOURS[kind])
    return _zone(kind, params, region, visuals)


def _edge_marker(params: Mapping[str, ParamValue], support_size: Sequence[float]) -> ZoneAsset:
    side, width = str(params["side"]), float(params["width"])
    if side not in EDGE_DIRECTIONS:
        raise ValueError(f"edge_zone side must be one of {sorted(EDGE_DIRECTIONS)}, got {side!r}")
    sx, sy = (float(v) for v in support_size)
    dx, dy = EDGE_DIRECTIONS[side]
    across = sx if dx else sy  # extent perpendicular to the edge
    if width > across:
        raise ValueError(f"edge_zone width {width} m exceeds the support's extent {across} m")
    band_x, band_y = (width, sy) if dx else (sx, width)
    centre = (dx * (sx - width) / 2.0, dy * (sy - width) / 2.0)
    line = min(0.004, width / 4.0)  # a black line on the band's inner border
    line_x, line_y = (line, sy) if dx else (sx, line)
    line_centre = (centre[0] - dx * (width - line) / 2.0, centre[1] - dy * (width - line) / 2.0)
    region = BoxShape(
        name="region",
        pose=Pose(position=(*centre, MARKER_THICKNESS / 2.0)),
        half_size=(band_x / 2.0, band_y / 2.0, MARKER_THICKNESS / 2.0),
    )
    visuals = [
        _part("band", _slab(band_x, band_y, centre), AMBER),
        _part("border", _slab(line_x, line_y, line_centre, lift=1e-4), BLACK),
    ]
    return _zone("edge_zone", params, region, visuals)


def _corridor(params: Mapping[str, ParamValue]) -> ZoneAsset:
    """Two walls along x (the passage runs away from the robot), ``width`` apart in y."""
    width, length, wall_h = (
        float(params["width"]),
        float(params["length"]),
        float(params["wall_height"]),
    )
    t = CORRIDOR_WALL_THICKNESS
    walls = [
        BoxShape(
            name=name,
            pose=Pose(position=(0.0, side * (width + t) / 2.0, wall_h / 2.0)),
            half_size=(length / 2.0, t / 2.0, wall_h / 2.0),
        )
        for side, name in ((-1.0, "wall_neg_y"), (1.0, "wall_pos_y"))
    ]
    region = BoxShape(
        name="region",
        pose=Pose(position=(0.0, 0.0, wall_h / 2.0)),
        half_size=(length / 2.0, width / 2.0, wall_h / 2.0),
    )
    visuals = [_part(w.name, shape_to_trimesh(w), WALL_GREY) for w in walls]
    visuals += _striped_rectangle(length, width, YELLOW, BLACK, name="floor")
    return _zone("corridor", params, region, visuals, collision=walls)


def _zone(
    kind: str,
    params: Mapping[str, ParamValue],
    region: Shape,
    visuals: list[VisualPart],
    collision: list[Shape] | None = None,
) -> ZoneAsset:
    boxes = [shape_aabb(region)] + [shape_aabb(s) for s in collision or []]
    for part in visuals:
        vertices = np.asarray(part.mesh.vertices)
        boxes.append((vertices.min(axis=0), vertices.max(axis=0)))
    bounds, footprint = bounds_of(*union_aabb(boxes))
    return ZoneAsset(
        kind=kind,
        params=dict(params),
        region=region,
        visuals=visuals,
        collision=collision or [],
        bounds=bounds,
        footprint=footprint,
    )


# --- marker meshes ------------------------------------------------------------------------


def _part(name: str, mesh: trimesh.Trimesh, appearance: Appearance) -> VisualPart:
    return VisualPart(name=name, mesh=inline_mesh(mesh), appearance=appearance)


def _slab(
    sx: float, sy: float, centre: Sequence[float] = (0.0, 0.0), lift: float = 0.0
) -> trimesh.Trimesh:
    mesh = trimesh.creation.box(extents=(sx, sy, MARKER_THICKNESS))
    mesh.apply_translation((centre[0], centre[1], MARKER_THICKNESS / 2.0 + lift))
    return mesh


def _disc(inner: float, outer: float) -> trimesh.Trimesh:
    """A flat disc (inner=0) or annulus (a closed section loop) of the marker's thickness."""
    t = MARKER_THICKNESS
    if inner <= 0.0:
        section = [(0.0, 0.0), (outer, 0.0), (outer, t), (0.0, t)]
    else:
        section = [(inner, 0.0), (outer, 0.0), (outer, t), (inner, t), (inner, 0.0)]
    return trimesh.creation.revolve(np.asarray(section), sections=48)


def _striped_rectangle(
    sx: float, sy: float, first: Appearance, second: Appearance, name: str = "stripes"
) -> list[VisualPart]:
    """Alternating stripes across x, one visual part per colour."""
    count = max(2, math.ceil(sx / STRIPE_WIDTH))
    width = sx / count
    groups: tuple[list[trimesh.Trimesh], list[trimesh.Trimesh]] = ([], [])
    for i in range(count):
        groups[i % 2].append(_slab(width, sy, (-sx / 2.0 + (i + 0.5) * width, 0.0)))
    return [
        _part(f"{name}_{i}", trimesh.util.concatenate(meshes), look)
        for i, (meshes, look) in enumerate(zip(groups, (first, second)))
    ]


def _striped_disc(radius: float, first: Appearance, second: Appearance) -> list[VisualPart]:
    """Concentric rings, one visual part per colour; the centre disc has the first colour."""
    count = max(2, math.ceil(radius / STRIPE_WIDTH))
    width = radius / count
    groups: tuple[list[trimesh.Trimesh], list[trimesh.Trimesh]] = ([], [])
    for i in range(count):
        groups[i % 2].append(_disc(i * width, (i + 1) * width))
    return [
        _part(f"rings_{i}", trimesh.util.concatenate(meshes), look)
        for i, (meshes, look) in enumerate(zip(groups, (first, second)))
    ]
