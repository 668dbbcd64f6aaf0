"""One entry point per catalog family: `build_asset` for bodies, `build_zone_marker` for zones.

Parameter names, defaults and ranges come from ``fsvla.dsl.catalog``: the given
parameters (SI units) are checked against the kind's declared ones, merged over the
defaults, and handed to the kind's builder.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence
from pathlib import Path

from fsvla.dsl.catalog import ASSETS, ZONES, AssetClass, AssetKind, Param, default_params

from .articulated import ARTICULATED_BUILDERS
from .files import load_mesh_asset, load_urdf_asset
from .materials import NAMED_COLORS
from .model import ArticulatedAsset, ParamValue, RigidAsset, ZoneAsset
from .rigid import RIGID_BUILDERS
from .zones import build_zone_marker as _build_zone_marker


def build_asset(
    kind: str,
    params: Mapping[str, ParamValue] | None = None,
    *,
    base_dir: Path | None = None,
    allowed_roots: Sequence[Path] = (),
) -> RigidAsset | ArticulatedAsset:
    """The asset of catalog kind ``kind`` with ``params`` (SI) over the catalog defaults.

    File assets (``mesh``, ``urdf``) resolve ``path`` against ``base_dir`` (the .fsv
    file's folder) and must stay inside ``allowed_roots`` (default: ``base_dir``)."""
    entry = _lookup(kind, ASSETS, other=ZONES, other_hint="a zone kind; use build_zone_marker")
    merged = merge_params(entry, params or {})
    if entry.asset_class is AssetClass.RIGID:
        return recolored(RIGID_BUILDERS[kind](merged), merged.get("color"))
    if entry.asset_class is AssetClass.ARTICULATED:
        return ARTICULATED_BUILDERS[kind](merged)
    if kind == "mesh":
        mesh = load_mesh_asset(merged, base_dir=base_dir, allowed_roots=allowed_roots)
        return recolored(mesh, merged.get("color"))
    if kind == "urdf":
        return load_urdf_asset(merged, base_dir=base_dir, allowed_roots=allowed_roots)
    raise ValueError(f"asset kind {kind!r} (class {entry.asset_class.value}) has no builder")


def recolored(asset: RigidAsset, color: ParamValue | None) -> RigidAsset:
    """``asset`` painted the named colour (its material and every visual part; each
    keeps its own transparency, roughness and glow), or unchanged for None."""
    if color is None:
        return asset
    r, g, b = NAMED_COLORS[str(color)]
    material = asset.material.model_copy(
        update={"base_color": (r, g, b, asset.material.base_color[3])})
    visuals = [part if part.appearance is None else part.model_copy(update={
        "appearance": part.appearance.model_copy(
            update={"base_color": (r, g, b, part.appearance.base_color[3])})})
        for part in asset.visuals]
    return asset.model_copy(update={"material": material, "visuals": visuals})


def build_zone_marker(
    kind: str,
    params: Mapping[str, ParamValue] | None = None,
    *,
    support_size: Sequence[float] | None = None,
) -> ZoneAsset:
    """The visual marker (and, for a corridor, the walls) of catalog zone ``kind``."""
    entry = _lookup(kind, ZONES, other=ASSETS, other_hint="an asset kind; use build_asset")
    return _build_zone_marker(kind, merge_params(entry, params or {}), support_size=support_size)


def merge_params(entry: AssetKind, params: Mapping[str, ParamValue]) -> dict[str, ParamValue]:
    """``params`` over the entry's defaults, each checked for name, arity, range and choice."""
    declared = {p.name: p for p in entry.params}
    for name in params:
        if name not in declared:
            raise ValueError(
                f"{entry.name} has no parameter {name!r}{_suggest(name, declared)}; "
                f"parameters: {', '.join(declared) or 'none'}"
            )
    merged: dict[str, ParamValue] = dict(default_params(entry.params))
    merged.update({name: _normalise(value) for name, value in params.items()})
    for param in entry.params:
        value = merged.get(param.name)
        if value is None:
            if param.required:
                raise ValueError(f"{entry.name} needs the parameter {param.name!r}")
            continue
        _check_value(entry.name, param, value)
    return merged


def _check_value(kind: str, param: Param, value: ParamValue) -> None:
    components = value if isinstance(value, tuple) else (value,)
    if len(components) != param.arity:
        raise ValueError(f"{kind}.{param.name} takes {param.arity} value(s), got {value!r}")
    if param.choices is not None:
        if value not in param.choices:
            raise ValueError(
                f"{kind}.{param.name} must be one of {', '.join(param.choices)}, got {value!r}"
            )
        return
    if param.path:
        return
    for component in components:
        if isinstance(component, bool) or not isinstance(component, (int, float)):
            raise ValueError(f"{kind}.{param.name} must be a number, got {component!r}")
        if param.minimum is not None and component < param.minimum:
            raise ValueError(
                f"{kind}.{param.name} must be at least {param.minimum}, got {component}"
            )
        if param.maximum is not None and component > param.maximum:
            raise ValueError(
                f"{kind}.{param.name} must be at most {param.maximum}, got {component}"
            )


def _normalise(value: ParamValue) -> ParamValue:
    if isinstance(value, list):
        return tuple(float(v) for v in value)
    if isinstance(value, tuple):
        return tuple(float(v) for v in value)
    return value


def _lookup(
    kind: str, table: Mapping[str, AssetKind], *, other: Mapping[str, AssetKind], other_hint: str
) -> AssetKind:
    if kind in table:
        return table[kind]
    if kind in other:
        raise ValueError(f"{kind!r} is {other_hint}")
    known = ", ".join(sorted(table))
    raise ValueError(f"unknown asset kind {kind!r}{_suggest(kind, table)}; known kinds: {known}")


def _suggest(name: str, known: Mapping[str, object]) -> str:
    close = difflib.get_close_matches(name, list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""
