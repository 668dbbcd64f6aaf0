"""The compiler's asset library: procedural, templated and file assets as plain data.

``build_asset(kind, params)`` turns a catalog asset kind (``fsvla.dsl.catalog.ASSETS``)
and its parameters into a simulator-neutral :class:`RigidAsset` or
:class:`ArticulatedAsset`; ``build_zone_marker`` does the same for hazard zones
(``ZONES``). Nothing here imports a simulator.
"""

from .model import (
    SCHEMA_VERSION,
    ArticulatedAsset,
    Asset,
    Material,
    Pose,
    RigidAsset,
    Shape,
    ZoneAsset,
    json_schema,
)
from .registry import build_asset, build_zone_marker, merge_params

__all__ = [
    "SCHEMA_VERSION",
    "ArticulatedAsset",
    "Asset",
    "Material",
    "Pose",
    "RigidAsset",
    "Shape",
    "ZoneAsset",
    "build_asset",
    "build_zone_marker",
    "json_schema",
    "merge_params",
]
