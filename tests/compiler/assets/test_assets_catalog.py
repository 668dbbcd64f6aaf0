"""Every catalog entry has a builder, and the registry checks what it is given."""

from __future__ import annotations

import pytest
from fsvla.compiler.assets import (
    ArticulatedAsset,
    RigidAsset,
    ZoneAsset,
    build_asset,
    build_zone_marker,
)
from fsvla.compiler.assets.articulated import ARTICULATED_BUILDERS
from fsvla.compiler.assets.rigid import RIGID_BUILDERS
from fsvla.dsl.catalog import ASSETS, ZONES, AssetClass

RIGID = [name for name, entry in ASSETS.items() if entry.asset_class is AssetClass.RIGID]
ARTICULATED = [
    name for name, entry in ASSETS.items() if entry.asset_class is AssetClass.ARTICULATED
]


def test_builders_match_the_catalog_exactly():
    assert set(RIGID_BUILDERS) == set(RIGID)
    assert set(ARTICULATED_BUILDERS) == set(ARTICULATED)


@pytest.mark.parametrize("kind", RIGID + ARTICULATED)
def test_every_catalog_asset_builds_with_its_defaults(kind):
    asset = build_asset(kind, {})
    expected = RigidAsset if kind in RIGID else ArticulatedAsset
    assert isinstance(asset, expected)
    assert asset.kind == kind
    assert asset.bounds.half_extents[2] > 0


@pytest.mark.parametrize("kind", RIGID + ARTICULATED)
@pytest.mark.parametrize("end", ["minimum", "maximum"])
def test_assets_build_at_the_ends_of_their_parameter_ranges(kind, end):
    entry = ASSETS[kind]
    params = {}
    for param in entry.params:
        value = getattr(param, end)
        if value is not None:
            params[param.name] = (value,) * param.arity if param.arity > 1 else value
    if kind in ARTICULATED and end == "minimum":
        with pytest.raises(ValueError, match="at least"):
            build_asset(kind, params)
        return
    asset = build_asset(kind, params)
    assert asset.bounds.half_extents[0] > 0


def test_articulated_parts_match_the_catalog():
    for kind in ARTICULATED:
        asset = build_asset(kind)
        assert tuple(p.name for p in asset.parts) == ASSETS[kind].parts


@pytest.mark.parametrize("kind", list(ZONES))
def test_every_catalog_zone_has_a_marker(kind):
    params = {
        "heat_zone": {"radius": 0.1},
        "energized_zone": {"size": (0.1, 0.06)},
        "no_go_zone": {"size": (0.2, 0.1)},
        "edge_zone": {"side": "front"},
        "corridor": {},
    }[kind]
    marker = build_zone_marker(kind, params, support_size=(1.2, 0.8))
    assert isinstance(marker, ZoneAsset)
    assert marker.visuals


def test_unknown_kind_names_the_kind_and_the_known_ones():
    with pytest.raises(ValueError) as error:
        build_asset("vas", {})
    message = str(error.value)
    assert "'vas'" in message and "did you mean 'vase'" in message and "drawer_cabinet" in message


def test_zone_kind_given_to_build_asset_is_redirected():
    with pytest.raises(ValueError, match="build_zone_marker"):
        build_asset("heat_zone", {"radius": 0.1})
    with pytest.raises(ValueError, match="build_asset"):
        build_zone_marker("pot", {})


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"radus": 0.1}, "no parameter 'radus'.*did you mean 'radius'"),
        ({"radius": 5.0}, "at most 0.3"),
        ({"radius": (0.1, 0.1)}, "takes 1 value"),
        ({"radius": "big"}, "must be a number"),
    ],
)
def test_bad_parameters_are_rejected_with_the_value(params, message):
    with pytest.raises(ValueError, match=message):
        build_asset("pot", params)


def test_parameters_override_defaults_and_lists_become_tuples():
    asset = build_asset("tray", {"size": [0.4, 0.3]})
    assert asset.params["size"] == (0.4, 0.3)
    assert asset.params["height"] == ASSETS["tray"].param("height").default
    assert asset.footprint.max_xy == pytest.approx((0.2, 0.15))


def test_required_file_parameter_is_enforced():
    with pytest.raises(ValueError, match="needs the parameter 'path'"):
        build_asset("mesh", {})
