"""``constrain`` and ``watch`` statements: a measure, its limit, and the modifiers of a channel
(``warn``, ``cost``, ``weight``) that ``keep`` clauses share."""

from __future__ import annotations

from collections.abc import Iterable

from .. import ast, models
from ..catalog import METRICS, SHAPINGS, ArgKind, Signature
from ..diagnostics import Related, did_you_mean
from ..merge import unparse
from ..spans import Span
from ..units import Dimension
from .scope import Part, Scope, source_ref

SIDE_EFFECT_WATCHES = ("untouched", "do_not_disturb")


def band(scope: Scope, modifiers: Iterable[ast.Modifier], dimension: Dimension, span: Span,
         what: str, example: str) -> tuple[float | None, str, float]:
    """(soft threshold, shaping, weight) of a channel from its modifiers; ``warn`` is required."""
    soft, shaping, weight = None, "linear", 1.0
    seen: dict[str, Span] = {}
    for modifier in modifiers:
        if modifier.kind in seen:
            scope.sink.error("FSV211", f"`{modifier.kind}` is given twice", modifier.span, "given again",
                             related=[Related(span=seen[modifier.kind], message="first given here")])
            continue
        seen[modifier.kind] = modifier.span
        if modifier.kind == "warn":
            soft = _soft_threshold(scope, modifier, dimension)
        elif modifier.kind == "cost":
            if modifier.value.value in SHAPINGS:
                shaping = modifier.value.value
            else:
                scope.sink.error("FSV109", f"unknown cost shaping `{modifier.value.value}`",
                                 modifier.value.span, "not a shaping",
                                 help=did_you_mean(modifier.value.value, SHAPINGS, "shapings"))
        else:
            value = scope.values.quantity(modifier.value, Dimension.NUMBER, "the weight")
            if value is not None and value < 0:
                scope.sink.error("FSV204", "the weight must not be negative", modifier.value.span, "negative")
            elif value is not None:
                weight = value
    if "warn" not in seen:
        scope.sink.error("FSV210", f"{what} has no warning band", span, "missing `warn`",
                         help=f"add a soft threshold, e.g. `{example}`: cost accrues inside the band "
                              "before the hard limit is crossed")
    return soft, shaping, weight


def _soft_threshold(scope: Scope, modifier: ast.Modifier, dimension: Dimension) -> float | None:
    soft = scope.values.quantity(modifier.value, dimension, "the warning band")
    if soft is not None and soft <= 0:
        scope.sink.error("FSV210", "the warning band must be larger than zero", modifier.value.span,
                         "not positive", help="the soft threshold epsilon is the width of the "
                         "warning band before the hard limit (paper eq. 1)")
        return None
    return soft


class ConstraintChecker(Part):
    def limit(self, name: str, decl: ast.LimitDecl) -> None:
        metric = decl.measure.name.value
        keyword = decl.keyword.value
        if keyword == "watch" and metric in SIDE_EFFECT_WATCHES:
            self._presence_watch(name, decl)
            return
        signature = METRICS.get(metric)
        if signature is None:
            choices = list(METRICS) + (list(SIDE_EFFECT_WATCHES) if keyword == "watch" else [])
            self.sink.error("FSV104", f"unknown measure `{metric}`", decl.measure.name.span,
                            f"not something `{keyword}` can measure", help=did_you_mean(metric, choices, "measures"))
            return
        subjects, reference = self._metric_args(signature, decl.measure)
        if not self._comparison(signature, decl):
            return
        limit = self.values.quantity(decl.limit, signature.dimension, f"the limit of `{metric}`")
        soft, shaping, weight = band(self.scope, decl.modifiers, signature.dimension, decl.span,
                                     f"`{keyword} {unparse(decl.measure)}`",
                                     f"warn {_example(signature.dimension, small=True)}")
        if limit is not None and limit < 0:
            self.sink.error("FSV204", "a limit must not be negative", decl.limit.span, "negative")
            return
        if signature.name == "separation" and len(self.scope.arms) < 2 and self.scope.embodiment:
            self.sink.error("FSV304", f"`separation` needs two arms, but `{self.scope.embodiment}` has one",
                            decl.measure.name.span, "a dual-arm measure")
            return
        if None in (limit, soft) or subjects is None:
            return
        family = "side_effect" if keyword == "watch" else signature.channel
        self.scope.limits.append(models.LimitSpec(
            name=name, origin=keyword, family=family, metric=metric, subjects=subjects,
            reference=reference, comparison=signature.comparison, limit=limit,
            unit=signature.dimension.si_unit, soft_threshold=soft, shaping=shaping, weight=weight,
            source=source_ref(decl.span)))

    def _comparison(self, signature: Signature, decl: ast.LimitDecl) -> bool:
        """Whether ``decl`` bounds its measure on the side the measure is bounded."""
        metric = signature.name
        if decl.comparator is None or decl.limit is None:
            self.sink.error("FSV209", f"`{metric}` needs a limit", decl.measure.span, "no limit given",
                            help=f"write `{unparse(decl.measure)} {signature.comparison} "
                                 f"{_example(signature.dimension)}`")
            return False
        if decl.comparator.value != signature.comparison:
            self.sink.error("FSV209", f"`{metric}` takes a limit with `{signature.comparison}`",
                            decl.comparator.span, f"`{metric}` is bounded "
                            + ("above" if signature.comparison == "<=" else "below"),
                            help=f"write `{signature.comparison}`")
            return False
        return True

    def _presence_watch(self, name: str, decl: ast.LimitDecl) -> None:
        metric = decl.measure.name.value
        if decl.comparator is not None:
            self.sink.error("FSV209", f"`{metric}` takes no limit", decl.comparator.span,
                            "remove the comparison", help=f"write `watch {metric}(...) warn 2 cm`")
            return
        args = decl.measure.positional
        if len(args) != 1 or decl.measure.keywords:
            self.sink.error("FSV305", f"`{metric}` takes one name", decl.measure.span, "expected one name",
                            help=f"write `watch {metric}(vase) warn 2 cm`")
            return
        value = args[0].value
        if not isinstance(value, ast.Ref):
            self.sink.error("FSV207", f"`{metric}` takes a name", value.span, "expected a name")
            return
        reference = self.scope.entity(value.name, value.span, f"the argument of `{metric}`")
        soft, shaping, weight = band(self.scope, decl.modifiers, Dimension.LENGTH, decl.span,
                                     f"`watch {unparse(decl.measure)}`", "warn 2 cm")
        if reference is None or soft is None:
            return
        self.scope.limits.append(models.LimitSpec(
            name=name, origin="watch", family="side_effect", metric=metric, subjects=("robot",),
            reference=reference, comparison=">=", limit=0.0, unit="m", soft_threshold=soft,
            shaping=shaping, weight=weight, source=source_ref(decl.span)))

    def _metric_args(self, signature: Signature, call: ast.Call):
        """(subjects, reference) of a measure, or (None, None) when its names do not resolve."""
        if call.keywords:
            self.sink.error("FSV103", f"`{signature.name}` takes no named parameters",
                            call.keywords[0].span, "unexpected")
            return None, None
        args = call.positional
        kinds = signature.positional
        if kinds == (ArgKind.ENTITIES,):
            if not args:
                self.sink.error("FSV305", f"`{signature.name}` needs at least one name", call.span, "no names")
                return None, None
            names = [self.scope.arg_entity(a, signature, allow_zone=False) for a in args]
            return (tuple(names), None) if None not in names else (None, None)
        if len(args) != len(kinds):
            self.sink.error("FSV305", f"`{signature.name}` takes {len(kinds)} name"
                            f"{'s' if len(kinds) > 1 else ''}, not {len(args)}", call.span,
                            f"{len(args)} given")
            return None, None
        names = [self.scope.arg_entity(a, signature, object_only=k is ArgKind.OBJECT)
                 for a, k in zip(args, kinds)]
        if None in names or not self._between_arms(signature, args, names):
            return None, None
        return tuple(names[:1]), (names[1] if len(names) > 1 else None)

    def _between_arms(self, signature: Signature, args: list[ast.Argument], names: list[str]) -> bool:
        if signature.name != "separation":
            return True
        for arg, name in zip(args, names):
            if name not in self.scope.robot_parts():
                self.sink.error("FSV111", f"`separation` measures between arms, and `{name}` is not "
                                "part of the robot", arg.span, "not an arm",
                                help="use `left_arm`, `right_arm`, `left_gripper` or `right_gripper`")
                return False
        return True


def _example(dimension: Dimension | None, small: bool = False) -> str:
    examples = {Dimension.FORCE: ("40 N", "8 N"), Dimension.TORQUE: ("5 Nm", "1 Nm"),
                Dimension.LENGTH: ("4 cm", "2 cm"), Dimension.ANGLE: ("20 deg", "10 deg")}
    big, little = examples.get(dimension, ("1", "0.5"))
    return little if small else big
