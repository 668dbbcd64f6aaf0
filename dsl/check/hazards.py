"""``hazard`` statements: a zone kind or a hazard role wrapping an asset, and its ``keep`` clauses."""

from __future__ import annotations

from .. import ast, models
from ..catalog import ROLE_CHANNEL, ZONE_CHANNEL, ZONES, HazardRole
from ..diagnostics import did_you_mean
from ..units import Dimension
from .binding import bind_params
from .constraints import band
from .objects import Declared, ObjectChecker
from .scope import Part, source_ref


class HazardChecker(Part):
    def declare(self, decl: ast.HazardDecl, objects: ObjectChecker) -> Declared | None:
        """The zone or wrapped asset that ``decl`` defines (an asset is checked by ``objects``)."""
        call = decl.definition
        name = call.name.value
        if name in ZONES:
            return Declared(decl.name.value, decl, ZONES[name], self._zone_params(call), None)
        roles = [r.value for r in HazardRole]
        if name in roles:
            if len(call.arguments) != 1 or not isinstance(call.arguments[0].value, ast.Call):
                self.sink.error("FSV305", f"`{name}` wraps one asset", call.span, "expected one asset",
                                help=f"write `{name}(vase(radius=5 cm))`")
                return None
            kind, params = objects.asset(call.arguments[0].value, decl.name.value)
            return Declared(decl.name.value, decl, kind, params, HazardRole(name)) if kind is not None else None
        self.sink.error("FSV102", f"unknown hazard `{name}`", call.name.span, "not a hazard kind",
                        help=did_you_mean(name, list(ZONES) + roles, "hazard kinds"))
        return None

    def _zone_params(self, call: ast.Call) -> dict:
        name = call.name.value
        kind = ZONES[name]
        params = bind_params(self.scope, call, kind.params, name, positional_ok=False)
        shaped = [p for p in ("size", "radius") if p in params]
        if "size" in kind.param_names() and "radius" in kind.param_names() and len(shaped) != 1:
            self.sink.error("FSV212", f"`{name}` needs either `size` or `radius`"
                            + (", not both" if shaped else ""), call.span,
                            "give its footprint", help=f"e.g. `{name}(size=(18 cm, 18 cm))` or "
                            f"`{name}(radius=9 cm)`")
        return params

    def keeps(self, decl: ast.HazardDecl) -> None:
        """One limit per ``keep`` clause of a placed hazard (the first is named after it)."""
        hazard = decl.name.value
        zone = self.scope.zones.get(hazard)
        if zone is not None:
            family, metric = ZONE_CHANNEL[zone.kind], "zone_distance"
        else:
            role = HazardRole(self.scope.objects[hazard].hazard_role)
            family, metric = ROLE_CHANNEL[role], "clearance"
        if not decl.keeps and zone is not None and zone.kind != "corridor":
            self.sink.warning("FSV309", f"hazard `{hazard}` has no `keep` clause, so nothing measures it",
                              decl.name.span, "not monitored",
                              help="add an indented line such as `keep gripper outside 5 cm warn 3 cm`")
        for index, keep in enumerate(decl.keeps):
            name = hazard if index == 0 else f"{hazard}#{index + 1}"
            self._keep(name, hazard, keep, family, metric)

    def _keep(self, name: str, hazard: str, keep: ast.Keep, family: str, metric: str) -> None:
        subjects = tuple(s for s in (self.scope.entity(n.value, n.span, "a keep-out subject", allow_zone=False)
                                     for n in keep.subjects) if s is not None)
        for subject in keep.subjects:
            if subject.value == hazard:
                self.sink.error("FSV111", f"`{hazard}` cannot keep away from itself", subject.span, "itself")
        distance = self.values.quantity(keep.distance, Dimension.LENGTH, "the keep-out distance")
        soft, shaping, weight = band(self.scope, keep.modifiers, Dimension.LENGTH, keep.span,
                                     "this keep-out clause", "warn 3 cm")
        if distance is None or soft is None or distance < 0:
            if distance is not None and distance < 0:
                self.sink.error("FSV204", "the keep-out distance must not be negative", keep.distance.span,
                                "negative")
            return
        self.scope.limits.append(models.LimitSpec(
            name=name, origin="hazard", family=family, metric=metric, subjects=subjects,
            reference=hazard, comparison=">=", limit=distance, unit="m", soft_threshold=soft,
            shaping=shaping, weight=weight, source=source_ref(keep.span)))
