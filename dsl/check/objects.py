"""``object`` statements: names, assets and their parameters; and the IR entries of objects
and hazards once they are placed."""

from __future__ import annotations

from typing import NamedTuple

from .. import ast, models
from ..catalog import ASSETS, ZONES, AssetClass, AssetKind, HazardRole, default_params
from ..diagnostics import did_you_mean
from ..merge import unparse
from .binding import bind_params
from .scope import Part, source_ref


class Declared(NamedTuple):
    """An object or hazard whose kind and parameters are checked, waiting for its placement."""

    name: str
    decl: ast.ObjectDecl | ast.HazardDecl
    kind: AssetKind
    params: dict
    role: HazardRole | None


class ObjectChecker(Part):
    def default_table(self) -> None:
        """A scenario that declares no table stands on the default one."""
        if "table" not in self.scope.merged.declarations:
            self.scope.objects["table"] = models.ObjectSpec(
                name="table", asset="table", params=default_params(ASSETS["table"].params),
                placement=models.Placement(support="world"), source=source_ref(self.scope.scenario.name.span))
            self.scope.object_kinds["table"] = ASSETS["table"]

    def robot_names(self, decls: list[ast.ObjectDecl | ast.HazardDecl]) -> None:
        """Names that the robot's own parts already go by."""
        for decl in decls:
            if decl.name.value in self.scope.robot_parts() or decl.name.value in ("left", "right"):
                self.sink.error("FSV110", f"`{decl.name.value}` is the name of a part of the robot",
                                decl.name.span, "already taken by the robot",
                                help="choose another name; `robot`, `gripper`, `arm`, `left_arm`, ... "
                                     "always mean the robot's own links")

    def declare(self, decl: ast.ObjectDecl) -> Declared | None:
        kind, params = self.asset(decl.asset, decl.name.value)
        if kind is not None and decl.name.value == "table" and kind.name != "table":
            self.sink.error("FSV111", "the object called `table` must be a `table(...)`", decl.asset.name.span,
                            f"a {kind.name}", help="declare the work surface as `object table: table(size=(1.2 m, "
                            "80 cm), height=75 cm)`, and give this object another name")
            return None
        return Declared(decl.name.value, decl, kind, params, None) if kind is not None else None

    def asset(self, call: ast.Call, owner: str) -> tuple[AssetKind | None, dict]:
        """The asset kind of ``call`` and its checked parameters; ``owner`` names the object."""
        name = call.name.value
        if name in ZONES:
            self.sink.error("FSV111", f"`{name}` is a hazard zone, not an object", call.name.span,
                            "a zone kind", help=f"declare it with `hazard {owner}: {unparse(call)}`")
            return None, {}
        kind = ASSETS.get(name)
        if kind is None:
            self.sink.error("FSV102", f"unknown asset `{name}`", call.name.span, "not an asset kind",
                            help=did_you_mean(name, ASSETS, "assets"))
            return None, {}
        return kind, bind_params(self.scope, call, kind.params, name)

    def register(self, declared: list[Declared], placements: dict[str, models.Placement]) -> None:
        """The IR entry of every declaration that could be placed: a zone or an object."""
        scope = self.scope
        for name, decl, kind, params, role in declared:
            if name not in placements:
                continue
            if kind.asset_class is AssetClass.ZONE:
                scope.zones[name] = models.ZoneSpec(name=name, kind=kind.name, params=params,
                                                    placement=placements[name], source=source_ref(decl.name.span))
            else:
                scope.objects[name] = models.ObjectSpec(
                    name=name, asset=kind.name, params=params, placement=placements[name],
                    hazard_role=role.value if role else None, source=source_ref(decl.name.span))
                scope.object_kinds[name] = kind
