"""The procedural rigid builders, by asset kind (`AssetClass.RIGID` in the catalog).

Each builder takes the asset's parameters, already merged with the catalog defaults
and in SI units, and returns a :class:`~.model.RigidAsset`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from .containers import build_bowl, build_glass, build_kettle, build_mug, build_pot, build_vase
from .furniture import build_shelf, build_socket_panel, build_stove, build_table
from .model import ParamValue, RigidAsset
from .props import (
    build_block,
    build_bottle,
    build_cutting_board,
    build_knife,
    build_plate,
    build_tray,
)

RigidBuilder = Callable[[Mapping[str, ParamValue]], RigidAsset]

RIGID_BUILDERS: Mapping[str, RigidBuilder] = {
    "table": build_table,
    "block": build_block,
    "pot": build_pot,
    "mug": build_mug,
    "glass": build_glass,
    "bowl": build_bowl,
    "plate": build_plate,
    "bottle": build_bottle,
    "vase": build_vase,
    "kettle": build_kettle,
    "tray": build_tray,
    "cutting_board": build_cutting_board,
    "knife": build_knife,
    "stove": build_stove,
    "socket_panel": build_socket_panel,
    "shelf": build_shelf,
}

# Bodies whose every visual part is a closed surface (tests check they are watertight).
# All of them are: open containers are modelled as thick shells, not open surfaces.
CLOSED_VISUALS = frozenset(RIGID_BUILDERS)

__all__ = ["CLOSED_VISUALS", "RIGID_BUILDERS", "RigidBuilder"]
