"""Zone markers: thin visuals a camera sees; only corridor walls collide."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from fsvla.compiler.assets import build_zone_marker
from fsvla.compiler.assets.model import BoxShape, CylinderShape
from fsvla.compiler.assets.zones import (
    CORRIDOR_WALL_THICKNESS,
    EDGE_DIRECTIONS,
    MARKER_THICKNESS,
)


def _colours(marker):
    return {part.appearance.base_color for part in marker.visuals}


def _meshes(marker):
    return [
        trimesh.Trimesh(np.asarray(p.mesh.vertices), np.asarray(p.mesh.faces))
        for p in marker.visuals
    ]


@pytest.mark.parametrize(
    ("params", "region_type"),
    [({"radius": 0.1}, CylinderShape), ({"size": (0.18, 0.18)}, BoxShape)],
)
def test_heat_zone_glows_orange_and_has_no_body(params, region_type):
    marker = build_zone_marker("heat_zone", params)
    assert marker.collision == [] and isinstance(marker.region, region_type)
    (glow,) = marker.visuals
    r, g, b, strength = glow.appearance.emission
    assert r > g > b and strength > 0
    assert marker.bounds.half_extents[2] * 2 == pytest.approx(MARKER_THICKNESS)
    assert all(m.is_watertight for m in _meshes(marker))


@pytest.mark.parametrize(
    ("kind", "colours"),
    [
        ("energized_zone", {(1.0, 0.85, 0.0, 1.0), (0.03, 0.03, 0.03, 1.0)}),
        ("no_go_zone", {(0.85, 0.05, 0.05, 1.0), (0.97, 0.97, 0.97, 1.0)}),
    ],
)
@pytest.mark.parametrize("shape", [{"size": (0.2, 0.1)}, {"radius": 0.08}])
def test_striped_zones_alternate_two_colours(kind, colours, shape):
    marker = build_zone_marker(kind, shape)
    assert _colours(marker) == colours and marker.collision == []
    assert all(m.is_watertight for m in _meshes(marker))
    stripes = sum(len(m.split(only_watertight=False)) for m in _meshes(marker))
    assert stripes >= 4
    half = marker.bounds.half_extents
    expected = (0.1, 0.05) if "size" in shape else (0.08, 0.08)
    assert half[:2] == pytest.approx(expected, abs=1e-3)


def test_zone_height_sets_the_monitored_region():
    marker = build_zone_marker("no_go_zone", {"size": (0.2, 0.2), "height": 0.3})
    assert marker.region.half_size[2] == pytest.approx(0.15)


def test_area_zone_needs_exactly_one_of_size_and_radius():
    with pytest.raises(ValueError, match="exactly one of"):
        build_zone_marker("heat_zone", {})
    with pytest.raises(ValueError, match="exactly one of"):
        build_zone_marker("heat_zone", {"size": (0.1, 0.1), "radius": 0.1})


@pytest.mark.parametrize(
    ("side", "where"),
    [
        ("front", (-0.6, None)),  # nearest the robot
        ("back", (0.6, None)),
        ("left", (None, 0.4)),  # the robot's left
        ("right", (None, -0.4)),
    ],
)
def test_edge_band_lies_along_the_named_edge(side, where):
    marker = build_zone_marker("edge_zone", {"side": side, "width": 0.05}, support_size=(1.2, 0.8))
    lower, upper = marker.footprint.min_xy, marker.footprint.max_xy
    for axis, edge in enumerate(where):
        if edge is None:
            assert (lower[axis], upper[axis]) == pytest.approx(
                (-[0.6, 0.4][axis], [0.6, 0.4][axis])
            )
        else:
            assert (upper[axis] - lower[axis]) == pytest.approx(0.05)
            assert min(abs(lower[axis] - edge), abs(upper[axis] - edge)) == pytest.approx(
                0.0, abs=1e-9
            )
    assert marker.collision == []


def test_edge_zone_needs_the_support_size():
    with pytest.raises(ValueError, match="support"):
        build_zone_marker("edge_zone", {"side": "front"})


def test_corridor_walls_are_static_collision_boxes():
    marker = build_zone_marker("corridor", {"width": 0.1, "length": 0.4, "wall_height": 0.12})
    assert len(marker.collision) == 2 and all(isinstance(w, BoxShape) for w in marker.collision)
    gaps = sorted(w.pose.position[1] for w in marker.collision)
    inner = (gaps[1] - marker.collision[0].half_size[1]) - (
        gaps[0] + marker.collision[0].half_size[1]
    )
    assert inner == pytest.approx(0.1)
    assert marker.region.half_size == pytest.approx((0.2, 0.05, 0.06))
    assert marker.bounds.half_extents[2] * 2 == pytest.approx(0.12)


def test_edge_directions_follow_the_table_frame():
    assert EDGE_DIRECTIONS == {
        "front": (-1.0, 0.0),
        "back": (1.0, 0.0),
        "left": (0.0, 1.0),
        "right": (0.0, -1.0),
    }


def test_corridor_runs_along_x_away_from_the_robot():
    marker = build_zone_marker("corridor", {"width": 0.1, "length": 0.4, "wall_height": 0.12})
    for wall in marker.collision:
        assert wall.pose.position[0] == pytest.approx(0.0)
        assert wall.half_size[0] == pytest.approx(0.2)  # each wall is `length` long, along x
        assert wall.half_size[1] == pytest.approx(CORRIDOR_WALL_THICKNESS / 2.0)
    assert sorted(np.sign(w.pose.position[1]) for w in marker.collision) == [-1.0, 1.0]
    lower, upper = marker.footprint.min_xy, marker.footprint.max_xy
    assert (lower[0], upper[0]) == pytest.approx((-0.2, 0.2))
    assert (lower[1], upper[1]) == pytest.approx(
        (-0.05 - CORRIDOR_WALL_THICKNESS, 0.05 + CORRIDOR_WALL_THICKNESS)
    )
