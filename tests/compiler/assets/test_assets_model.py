"""The asset models: JSON round-trips, strictness, schema."""

from __future__ import annotations

import json

import pytest
from fsvla.compiler.assets import SCHEMA_VERSION, build_asset, build_zone_marker, json_schema
from fsvla.compiler.assets.model import (
    ArticulatedAsset,
    Asset,
    BoxShape,
    ConvexMeshShape,
    MeshFile,
    RigidAsset,
    Shape,
    ZoneAsset,
)
from fsvla.dsl.catalog import ASSETS, AssetClass
from pydantic import TypeAdapter, ValidationError

BUILT = [
    kind
    for kind, e in ASSETS.items()
    if e.asset_class in (AssetClass.RIGID, AssetClass.ARTICULATED)
]


@pytest.mark.parametrize("kind", BUILT)
def test_every_asset_round_trips_through_json(kind):
    asset = build_asset(kind)
    model = type(asset)
    assert model.model_validate_json(asset.model_dump_json()) == asset
    assert TypeAdapter(Asset).validate_json(asset.model_dump_json()) == asset
    assert asset.schema_version == SCHEMA_VERSION


@pytest.mark.parametrize(
    ("kind", "params"),
    [
        ("heat_zone", {"radius": 0.1}),
        ("no_go_zone", {"size": (0.2, 0.1)}),
        ("corridor", {}),
        ("edge_zone", {"side": "left"}),
    ],
)
def test_zone_markers_round_trip_through_json(kind, params):
    marker = build_zone_marker(kind, params, support_size=(1.0, 0.6))
    assert ZoneAsset.model_validate_json(marker.model_dump_json()) == marker


def test_shapes_are_a_discriminated_union_with_wxyz_poses():
    adapter = TypeAdapter(Shape)
    box = adapter.validate_python(
        {
            "type": "box",
            "half_size": [0.1, 0.2, 0.3],
            "pose": {"position": [0, 0, 1], "quaternion": [1, 0, 0, 0]},
        }
    )
    assert isinstance(box, BoxShape) and box.pose.quaternion[0] == 1.0
    by_file = adapter.validate_python(
        {"type": "convex_mesh", "mesh": {"type": "file", "path": "piece_0.obj"}}
    )
    assert isinstance(by_file, ConvexMeshShape) and isinstance(by_file.mesh, MeshFile)
    with pytest.raises(ValidationError):
        adapter.validate_python({"type": "torus", "radius": 1.0})
    with pytest.raises(ValidationError):
        adapter.validate_python({"type": "box", "half_size": [0.1, 0.0, 0.3]})


def test_unknown_fields_are_rejected():
    data = json.loads(build_asset("block").model_dump_json())
    data["colour"] = "red"
    with pytest.raises(ValidationError, match="colour"):
        RigidAsset.model_validate(data)


def test_articulated_asset_needs_exactly_one_urdf_source():
    data = json.loads(build_asset("lidded_box").model_dump_json())
    data["urdf_path"] = "/tmp/x.urdf"
    with pytest.raises(ValidationError, match="exactly one"):
        ArticulatedAsset.model_validate(data)


def test_json_schema_is_versioned_and_covers_every_asset_type():
    schema = json_schema()
    assert schema["$id"].endswith(SCHEMA_VERSION)
    text = json.dumps(schema)
    for name in (
        "RigidAsset",
        "ArticulatedAsset",
        "ZoneAsset",
        "BoxShape",
        "ConvexMeshShape",
        "Material",
    ):
        assert name in text
