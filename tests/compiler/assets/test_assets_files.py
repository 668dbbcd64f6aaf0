"""File assets: convex pieces from a mesh file, URDF files, and the path guard."""

from __future__ import annotations

import os

import numpy as np
import pytest
import trimesh
from fsvla.compiler.assets import ArticulatedAsset, build_asset
from fsvla.compiler.assets.decomposition import convex_pieces, split_decomposition
from fsvla.compiler.assets.files import AssetPathError
from fsvla.compiler.assets.model import ConvexMeshShape, MeshFile
from fsvla.compiler.assets.urdf import UrdfError

try:
    import coacd  # noqa: F401

    HAVE_COACD = True
except ImportError:
    HAVE_COACD = False


def _pieces_as_meshes(asset):
    return [
        trimesh.Trimesh(np.asarray(s.mesh.vertices), np.asarray(s.mesh.faces))
        for s in asset.collision
        if isinstance(s, ConvexMeshShape)
    ]


@pytest.fixture
def scenario_dir(tmp_path, l_mesh):
    folder = tmp_path / "scenarios" / "boundary"
    folder.mkdir(parents=True)
    l_mesh.export(folder / "bracket.obj")
    trimesh.creation.box(extents=(0.1, 0.06, 0.04)).export(folder / "brick.stl")
    return folder


def test_non_convex_mesh_file_yields_several_convex_pieces(scenario_dir, l_mesh):
    asset = build_asset("mesh", {"path": "bracket.obj"}, base_dir=scenario_dir)
    pieces = _pieces_as_meshes(asset)
    assert len(pieces) >= 2 and len(pieces) == len(asset.collision)
    assert all(trimesh.convex.is_convex(p) for p in pieces)
    lower = np.min([p.bounds[0] for p in pieces], axis=0)
    upper = np.max([p.bounds[1] for p in pieces], axis=0)
    np.testing.assert_allclose(upper - lower, l_mesh.extents, atol=1e-3)
    # the pieces hug the L: far less volume than its hull
    assert sum(p.volume for p in pieces) < 0.8 * l_mesh.convex_hull.volume
    assert lower[2] == pytest.approx(0.0, abs=1e-6)  # re-centred: origin at the bottom centre
    visual = asset.visuals[0]
    assert isinstance(visual.mesh, MeshFile) and visual.mesh.path.endswith("bracket.obj")


def test_convex_mesh_file_is_its_hull_with_scale_and_mass(scenario_dir):
    asset = build_asset(
        "mesh", {"path": "brick.stl", "scale": 2.0, "mass": 0.3}, base_dir=scenario_dir
    )
    assert [s.name for s in asset.collision] == ["hull_0"]
    assert asset.bounds.half_extents == pytest.approx((0.1, 0.06, 0.04), abs=1e-6)
    assert asset.mass == pytest.approx(0.3)


@pytest.mark.skipif(not HAVE_COACD, reason="coacd not installed")
def test_coacd_is_used_when_installed(l_mesh):
    pieces, method = convex_pieces(l_mesh)
    assert method == "coacd" and len(pieces) >= 2


def test_split_fallback_decomposes_without_coacd(l_mesh):
    pieces, method = convex_pieces(l_mesh, method="split")
    assert method == "split" and 2 <= len(pieces) <= 8
    assert all(trimesh.convex.is_convex(p) for p in pieces)
    assert sum(p.volume for p in pieces) >= l_mesh.volume * (1 - 1e-6)  # the pieces cover it
    assert sum(p.volume for p in pieces) < 0.8 * l_mesh.convex_hull.volume
    assert len(split_decomposition(trimesh.creation.box())) == 1  # convex: no needless cuts


def test_path_traversal_outside_the_root_is_rejected(scenario_dir, l_mesh):
    outside = scenario_dir.parent.parent / "secret.obj"
    l_mesh.export(outside)
    with pytest.raises(AssetPathError, match="outside the allowed roots"):
        build_asset("mesh", {"path": "../../secret.obj"}, base_dir=scenario_dir)
    with pytest.raises(AssetPathError, match="outside the allowed roots"):
        build_asset("mesh", {"path": str(outside)}, base_dir=scenario_dir)
    asset = build_asset(
        "mesh",
        {"path": "../../secret.obj"},
        base_dir=scenario_dir,
        allowed_roots=[scenario_dir.parent.parent],
    )
    assert asset.collision


def test_symbolic_link_out_of_the_root_is_rejected(scenario_dir, l_mesh):
    outside = scenario_dir.parent / "elsewhere.obj"
    l_mesh.export(outside)
    os.symlink(outside, scenario_dir / "link.obj")
    with pytest.raises(AssetPathError, match="outside the allowed roots"):
        build_asset("mesh", {"path": "link.obj"}, base_dir=scenario_dir)


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("missing.obj", "not found"),
        ("notes.txt", "must end in one of"),
    ],
)
def test_bad_mesh_paths_are_explained(scenario_dir, path, message):
    (scenario_dir / "notes.txt").write_text("hello")
    with pytest.raises(AssetPathError, match=message):
        build_asset("mesh", {"path": path}, base_dir=scenario_dir)


def test_relative_path_without_a_base_dir_is_rejected():
    with pytest.raises(AssetPathError, match="base_dir"):
        build_asset("mesh", {"path": "bracket.obj"})


URDF = """<?xml version="1.0"?>
<robot name="hinged">
  <link name="base">
    <inertial><mass value="1.0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry><origin xyz="0 0 0.05"/></collision>
    <visual><geometry><mesh filename="{visual}"/></geometry></visual>
  </link>
  <link name="flap">
    <collision><geometry><mesh filename="{collision}" scale="1 1 1"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="flap"/><origin xyz="0 0.1 0.1" rpy="0 0 1.5707963"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="1.5" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def test_urdf_file_loads_with_its_movable_parts(scenario_dir):
    (scenario_dir / "hinged.urdf").write_text(
        URDF.format(visual="bracket.obj", collision="meshes/../brick.stl")
    )
    asset = build_asset("urdf", {"path": "hinged.urdf", "scale": 2.0}, base_dir=scenario_dir)
    assert isinstance(asset, ArticulatedAsset) and asset.urdf is None
    assert asset.urdf_path == str((scenario_dir / "hinged.urdf").resolve())
    assert [(p.name, p.joint) for p in asset.parts] == [("flap", "hinge")]
    assert asset.root_link == "base"
    flap = next(link for link in asset.links if link.name == "flap")
    assert isinstance(flap.collision[0], ConvexMeshShape)  # the mesh's convex hull, scaled
    assert np.ptp(np.asarray(flap.collision[0].mesh.vertices)[:, 0]) == pytest.approx(0.2, abs=1e-6)
    assert next(j for j in asset.joints if j.name == "hinge").origin.position == pytest.approx(
        (0, 0.2, 0.2)
    )



@pytest.mark.parametrize(("dynamics", "friction"), [("", 0.0), ('<dynamics damping="0.1" friction="0.3"/>', 0.3)])
def test_a_joint_keeps_its_urdf_friction(scenario_dir, dynamics, friction):
    """What holds a lid standing where it is let go (an expert reads it)."""
    text = URDF.format(visual="bracket.obj", collision="brick.stl").replace("</joint>", f"{dynamics}</joint>")
    (scenario_dir / "hinged.urdf").write_text(text)
    asset = build_asset("urdf", {"path": "hinged.urdf"}, base_dir=scenario_dir)
    assert next(j for j in asset.joints if j.name == "hinge").friction == friction


def test_a_negative_joint_friction_is_rejected(scenario_dir):
    text = URDF.format(visual="bracket.obj", collision="brick.stl").replace(
        "</joint>", '<dynamics friction="-1"/></joint>')
    (scenario_dir / "hinged.urdf").write_text(text)
    with pytest.raises(UrdfError, match="must not be negative"):
        build_asset("urdf", {"path": "hinged.urdf"}, base_dir=scenario_dir)

@pytest.mark.parametrize(
    ("reference", "error", "message"),
    [
        ("../../secret.obj", AssetPathError, "outside the allowed roots"),
        ("package://robots/flap.stl", AssetPathError, "package://"),
        ("file:///etc/passwd", AssetPathError, "outside the allowed roots"),
    ],
)
def test_urdf_references_outside_the_root_are_rejected(
    scenario_dir, l_mesh, reference, error, message
):
    l_mesh.export(scenario_dir.parent.parent / "secret.obj")
    (scenario_dir / "bad.urdf").write_text(URDF.format(visual=reference, collision="brick.stl"))
    with pytest.raises(error, match=message):
        build_asset("urdf", {"path": "bad.urdf"}, base_dir=scenario_dir)


def test_urdf_file_with_entities_is_rejected(scenario_dir):
    (scenario_dir / "bomb.urdf").write_text(
        "<!DOCTYPE r [<!ENTITY a 'aaaa'>]><robot name='r'>&a;</robot>"
    )
    with pytest.raises(UrdfError, match="DOCTYPE"):
        build_asset("urdf", {"path": "bomb.urdf"}, base_dir=scenario_dir)
