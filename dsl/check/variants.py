"""The ``variants`` block: structure levels L1 and L2 and their rules (``jitter``, ``approach``,
``clutter``, ``tighten``, ``couple``), and L0's nuisance jitter (``jitter`` rules, or ``none``)."""

from __future__ import annotations

from .. import ast, models
from ..diagnostics import did_you_mean
from ..units import Dimension
from ..values import format_si
from .scope import Part, source_ref


class VariantChecker(Part):
    def variants(self) -> dict:
        out: dict = {}
        for level_name, level in self.scope.merged.variants.items():
            if level_name not in ("L0", "L1", "L2"):
                self.sink.error("FSV501", f"unknown structure level `{level_name}`", level.level.span,
                                "not L0, L1 or L2", help="write rules for `L1` (placement variation) "
                                "and `L2` (harder layouts); `L0` takes only its nuisance `jitter`, or `none`")
                continue
            if not self._fits_level(level_name, level):
                continue
            rules = [self._rule(rule) for rule in level.rules]
            out[level_name] = tuple(r for r in rules if r is not None)
        return out

    def _fits_level(self, level_name: str, level: ast.VariantLevel) -> bool:
        """``none`` only at L0, and L0 only ``jitter`` (FSV506)."""
        if level.none is not None and level_name != "L0":
            self.sink.error("FSV506", "`none` is only for `L0`", level.none.span, f"not an {level_name} rule",
                            help=f"leave `{level_name}` out to vary nothing there")
            return False
        wrong = next((rule for rule in level.rules if level_name == "L0" and rule.kind.value != "jitter"), None)
        if wrong is not None:
            self.sink.error("FSV506", f"`{wrong.kind.value}` is not an L0 rule", wrong.kind.span,
                            "L0 takes only `jitter`",
                            help="L0 is the canonical layout with a nuisance jitter; move it to `L1` or `L2`")
            return False
        return True

    def _rule(self, rule: ast.Rule):
        check = {"jitter": self._jitter, "approach": self._approach, "clutter": self._clutter,
                 "tighten": self._tighten}.get(rule.kind.value, self._couple)
        return check(rule, source_ref(rule.span))

    def _jitter(self, rule: ast.Rule, source: models.SourceRef):
        target = rule.target.value
        scope = self.scope
        if target == "table" or (target not in scope.objects and target not in scope.zones):
            movable = [n for n in scope.objects if n != "table"] + list(scope.zones)
            self.sink.error("FSV101", f"`{target}` is not an object or hazard that can move", rule.target.span,
                            "cannot be jittered", help=did_you_mean(target, movable, "names"))
            return None
        distance = self.values.amount(rule.amount, Dimension.LENGTH, "the jitter radius")
        yaw = self.values.amount(rule.extra, Dimension.ANGLE, "the yaw jitter") if rule.extra else 0.0
        if distance is None or yaw is None:
            return None
        return models.Jitter(target=target, distance=distance, yaw=yaw, source=source)

    def _approach(self, rule: ast.Rule, source: models.SourceRef):
        hazard, toward = rule.target.value, rule.other.value
        objects, zones = self.scope.objects, self.scope.zones
        if not (hazard in zones or (hazard in objects and objects[hazard].hazard_role)):
            self.sink.error("FSV502", f"`approach` moves a hazard, and `{hazard}` is not one",
                            rule.target.span, "not a hazard",
                            help=did_you_mean(hazard, [n for n, o in objects.items() if o.hazard_role]
                                              + list(zones), "hazards"))
            return None
        if toward not in objects:
            self._unknown_object(rule.other)
            return None
        distance = self.values.amount(rule.amount, Dimension.LENGTH, "the approach distance", strict=True)
        return None if distance is None else models.Approach(hazard=hazard, toward=toward,
                                                              distance=distance, source=source)

    def _clutter(self, rule: ast.Rule, source: models.SourceRef):
        count = self.values.quantity(rule.amount, Dimension.NUMBER, "the clutter count")
        if count is None:
            return None
        if count != int(count) or not 0 <= count <= 12:
            self.sink.error("FSV204", "the clutter count must be a whole number from 0 to 12",
                            rule.amount.span, "out of range")
            return None
        near = rule.other.value if rule.other else None
        if near is not None and near not in self.scope.objects:
            self._unknown_object(rule.other)
            return None
        return models.Clutter(count=int(count), near=near, source=source)

    def _unknown_object(self, name: ast.Name) -> None:
        self.sink.error("FSV101", f"unknown object `{name.value}`", name.span, "not declared",
                        help=did_you_mean(name.value, self.scope.objects, "objects"))

    def _couple(self, rule: ast.Rule, source: models.SourceRef):
        requirements = self.scope.requirements
        requirement = next((r for r in requirements if r.name == rule.target.value), None)
        if requirement is None and rule.target.value in self.scope.merged.declarations:
            return None  # declared, but it has errors of its own that are already reported
        if requirement is None:
            self.sink.error("FSV502", f"`couple` needs a named requirement, and `{rule.target.value}` is not one",
                            rule.target.span, "not a requirement",
                            help=did_you_mean(rule.target.value, [r.name for r in requirements],
                                              "requirements") or "name one: `require NAME: A before B`")
            return None
        within = self.values.quantity(rule.amount, Dimension.TIME, "the coupling window")
        if within is not None and within <= 0:
            self.sink.error("FSV204", "the coupling window must be longer than zero", rule.amount.span, "")
            return None
        return None if within is None else models.Couple(requirement=requirement.name, within=within,
                                                         source=source)

    def _tighten(self, rule: ast.Rule, source: models.SourceRef):
        target = rule.target.value
        limits = self.scope.limits
        limit = next((lim for lim in limits if lim.name == target), None)
        if limit is None and target in self.scope.merged.declarations:
            return None  # declared, but it has errors of its own that are already reported
        if limit is None:
            named = [lim.name for lim in limits if "(" not in lim.name]
            self.sink.error("FSV502", f"`tighten` needs a named limit, and `{target}` is not one",
                            rule.target.span, "not a limit",
                            help=did_you_mean(target, named, "limits") if named else
                            "name the limit: `constrain NAME: clearance(...) >= ...`")
            return None
        dimension = next(d for d in Dimension if d.si_unit == limit.unit)
        value = self.values.quantity(rule.amount, dimension, f"the new limit of `{target}`")
        if value is None:
            return None
        stricter = value > limit.limit if limit.comparison == ">=" else value < limit.limit
        if not stricter:
            self.sink.error("FSV503", f"`tighten` must make `{target}` stricter", rule.amount.span,
                            f"the L0 limit is {format_si(limit.limit, dimension, rule.amount.unit)}",
                            help="for a lower bound (>=) give a larger value; for an upper bound (<=) "
                                 "a smaller one")
            return None
        return models.Tighten(target=target, limit=value, source=source)
