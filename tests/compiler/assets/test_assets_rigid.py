"""Procedural rigid assets: closed visuals, convex collision, matching bounds, sane masses."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from fsvla.compiler.assets import build_asset
from fsvla.compiler.assets.geometry import shape_aabb, shape_to_trimesh, union_aabb
from fsvla.compiler.assets.model import BoxShape, ConvexMeshShape, CylinderShape, InlineMesh
from fsvla.compiler.assets.rigid import CLOSED_VISUALS, RIGID_BUILDERS

KINDS = sorted(RIGID_BUILDERS)
BOUNDS_TOLERANCE = 0.003  # m: collision and visual bounding boxes agree to a few mm
CONTAINERS = ("pot", "mug", "glass", "bowl", "vase", "kettle")
STATIC = {"table", "shelf", "stove", "socket_panel"}
MASS_RANGE = {  # kg, with the catalog defaults
    "table": (10.0, 60.0),
    "block": (0.01, 0.2),
    "pot": (0.5, 2.0),
    "mug": (0.15, 0.6),
    "glass": (0.1, 0.5),
    "bowl": (0.15, 0.8),
    "plate": (0.2, 1.0),
    "bottle": (0.2, 1.5),
    "vase": (0.2, 1.5),
    "kettle": (0.5, 2.0),
    "tray": (0.2, 1.5),
    "cutting_board": (0.3, 1.5),
    "knife": (0.03, 0.3),
    "stove": (1.0, 15.0),
    "socket_panel": (0.1, 2.0),
    "shelf": (0.5, 10.0),
}


@pytest.fixture(scope="module")
def assets():
    return {kind: build_asset(kind) for kind in KINDS}


def _visual_meshes(asset):
    return [
        trimesh.Trimesh(np.asarray(p.mesh.vertices), np.asarray(p.mesh.faces), process=False)
        for p in asset.visuals
    ]


def test_mass_table_covers_every_rigid_kind():
    assert set(MASS_RANGE) == set(KINDS)


@pytest.mark.parametrize("kind", KINDS)
def test_visuals_are_inline_and_watertight_where_closed(assets, kind):
    asset = assets[kind]
    assert asset.visuals and all(isinstance(p.mesh, InlineMesh) for p in asset.visuals)
    if kind in CLOSED_VISUALS:
        for part, mesh in zip(asset.visuals, _visual_meshes(asset)):
            assert mesh.is_watertight, f"{kind}: visual part {part.name!r} is not closed"


@pytest.mark.parametrize("kind", KINDS)
def test_collision_is_only_primitives_and_convex_pieces(assets, kind):
    for shape in assets[kind].collision:
        if isinstance(shape, ConvexMeshShape):
            mesh = trimesh.Trimesh(np.asarray(shape.mesh.vertices), np.asarray(shape.mesh.faces))
            assert trimesh.convex.is_convex(mesh), f"{kind}: piece {shape.name!r} is not convex"
        else:
            assert shape.type in ("box", "cylinder", "capsule", "sphere")


@pytest.mark.parametrize("kind", KINDS)
def test_collision_bounds_match_visual_bounds(assets, kind):
    asset = assets[kind]
    lower, upper = union_aabb([shape_aabb(s) for s in asset.collision])
    meshes = _visual_meshes(asset)
    v_lower = np.min([m.bounds[0] for m in meshes], axis=0)
    v_upper = np.max([m.bounds[1] for m in meshes], axis=0)
    np.testing.assert_allclose(lower, v_lower, atol=BOUNDS_TOLERANCE)
    np.testing.assert_allclose(upper, v_upper, atol=BOUNDS_TOLERANCE)


@pytest.mark.parametrize("kind", KINDS)
def test_body_frame_origin_is_the_bottom_centre(assets, kind):
    bounds = assets[kind].bounds
    assert bounds.center[2] - bounds.half_extents[2] == pytest.approx(0.0, abs=1e-9)
    footprint = assets[kind].footprint
    assert footprint.max_xy[0] - footprint.min_xy[0] == pytest.approx(2 * bounds.half_extents[0])
    assert footprint.max_xy[1] - footprint.min_xy[1] == pytest.approx(2 * bounds.half_extents[1])


@pytest.mark.parametrize("kind", KINDS)
def test_mass_and_inertia_are_physical(assets, kind):
    asset = assets[kind]
    low, high = MASS_RANGE[kind]
    assert low <= asset.mass <= high, f"{kind}: {asset.mass:.3f} kg"
    a, b, c = sorted(asset.inertia)
    assert a > 0 and a + b >= c * (1 - 1e-6), (
        f"{kind}: inertia {asset.inertia} breaks the triangle rule"
    )
    assert asset.material.density * sum(
        shape_to_trimesh(s).volume for s in asset.collision
    ) == pytest.approx(asset.mass, rel=0.05)
    assert asset.material.static_friction >= asset.material.dynamic_friction > 0


@pytest.mark.parametrize("kind", KINDS)
def test_static_fixtures(assets, kind):
    assert assets[kind].is_static == (kind in STATIC)


@pytest.mark.parametrize("kind", CONTAINERS)
def test_containers_are_rings_of_wall_pieces_around_an_open_cavity(assets, kind):
    asset = assets[kind]
    walls = [s for s in asset.collision if s.name.startswith("wall")]
    assert len(walls) >= 8 and all(isinstance(s, BoxShape) for s in walls)
    assert isinstance(asset.cavity, CylinderShape)
    cavity_centre = np.asarray(asset.cavity.pose.position)
    base = next(s for s in asset.collision if s.name == "base")
    assert shape_aabb(base)[1][2] <= cavity_centre[2] - asset.cavity.half_length + 1e-9
    # the cavity's centre is free: no wall piece's bounding box contains it
    assert all(
        not np.all((shape_aabb(w)[0] <= cavity_centre) & (cavity_centre <= shape_aabb(w)[1]))
        for w in walls
    )


def test_mass_parameter_overrides_density():
    mug = build_asset("mug", {"mass": 0.5})
    assert mug.mass == pytest.approx(0.5)
    default = build_asset("mug")
    assert mug.inertia[0] / default.inertia[0] == pytest.approx(0.5 / default.mass)


def test_friction_parameter_sets_the_material():
    assert build_asset("block", {"friction": 1.1}).material.static_friction == pytest.approx(1.1)


def test_stove_has_a_glowing_heating_plate():
    stove = build_asset("stove")
    glowing = [p for p in stove.visuals if p.appearance and p.appearance.emission]
    assert [p.name for p in glowing] == ["heating_plate"]
    r, g, b, strength = glowing[0].appearance.emission
    assert r > g > b and strength > 0
    assert stove.support_height == pytest.approx(0.03)


def test_handles_and_spout_stick_out():
    pot, kettle, mug = build_asset("pot"), build_asset("kettle"), build_asset("mug")
    assert pot.bounds.half_extents[1] > 0.09 + 0.02 and pot.bounds.half_extents[0] == pytest.approx(
        0.09
    )
    assert {"handle_left", "handle_right"} <= {s.name for s in pot.collision}
    handles = {s.name: s.pose.position for s in pot.collision if s.name.startswith("handle_")}
    assert handles["handle_left"][1] > 0.09 and handles["handle_right"][1] < -0.09  # left is +y
    assert {"spout", "handle_grip"} <= {s.name for s in kettle.collision}
    assert mug.footprint.max_xy[0] > 0.04 + 0.015


def test_knife_blade_is_thin():
    knife = build_asset("knife")
    blade = next(s for s in knife.collision if s.name == "blade")
    assert 2 * blade.half_size[2] <= 0.003
    assert knife.bounds.half_extents[0] == pytest.approx(0.11)


def test_table_top_is_the_support_height():
    table = build_asset("table", {"size": (1.0, 0.6), "height": 0.7})
    assert table.support_height == pytest.approx(0.7)
    assert table.bounds.half_extents == pytest.approx((0.5, 0.3, 0.35))


def test_socket_outlet_faces_the_robot_at_minus_x():
    panel = build_asset("socket_panel", {"size": (0.08, 0.12), "height": 0.12})
    shapes = {s.name: s for s in panel.collision}
    upright, faceplate = shapes["panel"], shapes["faceplate"]
    assert upright.pose.position[0] > 0.0  # the upright panel stands at the back (+x)
    assert upright.half_size[1] == pytest.approx(0.06)  # and spans the width (y)
    assert faceplate.pose.position[0] < upright.pose.position[0] - upright.half_size[0]
    slots = {p.name: p for p in panel.visuals if p.name.startswith("slot_")}
    assert set(slots) == {"slot_left", "slot_right"}
    left = np.asarray(slots["slot_left"].mesh.vertices).mean(axis=0)
    right = np.asarray(slots["slot_right"].mesh.vertices).mean(axis=0)
    assert left[1] > 0.0 > right[1]  # the robot's left is +y


def test_tray_rims_are_named_from_the_robot():
    tray = build_asset("tray", {"size": (0.35, 0.25)})
    rims = {s.name: s.pose.position for s in tray.collision if s.name.startswith("rim_")}
    assert rims["rim_front"][0] < 0.0 < rims["rim_back"][0]
    assert rims["rim_right"][1] < 0.0 < rims["rim_left"][1]


def test_named_colour_paints_material_and_visuals_and_keeps_transparency():
    from fsvla.compiler.assets.materials import NAMED_COLORS
    from fsvla.dsl.catalog import COLOR_NAMES

    assert set(NAMED_COLORS) == set(COLOR_NAMES)
    blue = build_asset("block", {"color": "blue"})
    assert blue.material.base_color == (*NAMED_COLORS["blue"], 1.0)
    assert build_asset("block").material.base_color != blue.material.base_color
    glass = build_asset("glass", {"color": "green"})
    assert glass.material.base_color[:3] == NAMED_COLORS["green"]
    assert glass.material.base_color[3] == build_asset("glass").material.base_color[3] < 1.0
    for part in build_asset("mug", {"color": "yellow"}).visuals:
        assert part.appearance is None or part.appearance.base_color[:3] == NAMED_COLORS["yellow"]
    # physics is untouched by a colour
    assert blue.mass == build_asset("block").mass
    with pytest.raises(ValueError, match="must be one of"):
        build_asset("block", {"color": "navy"})


def test_every_movable_rigid_kind_takes_a_colour():
    from fsvla.dsl.catalog import ASSETS

    for kind in set(KINDS) - STATIC:
        assert ASSETS[kind].param("color") is not None, kind
