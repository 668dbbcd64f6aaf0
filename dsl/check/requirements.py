"""Conditions over predicates, and the statements made of them: ``require A before B`` and
``success``."""

from __future__ import annotations

from .. import ast, models
from ..catalog import ASSETS, PREDICATES, ArgKind, AssetClass
from ..diagnostics import Related, did_you_mean
from ..spans import Span
from ..units import Dimension
from .binding import bind_params
from .scope import Part, source_ref


class RequirementChecker(Part):
    def requirement(self, name: str, decl: ast.RequireDecl) -> None:
        first, then = self.condition(decl.first), self.condition(decl.then)
        within = None
        if decl.within is not None:
            within = self.values.amount(decl.within, Dimension.TIME, "`within`", strict=True)
        weight = self._weight(decl.modifiers)
        if first is None or then is None:
            return
        self.scope.requirements.append(models.Requirement(
            name=name, first=first, then=then, within=within, weight=weight, source=source_ref(decl.span)))

    def _weight(self, modifiers: tuple[ast.Modifier, ...]) -> float:
        weight = 1.0
        seen: dict[str, Span] = {}
        for modifier in modifiers:
            if modifier.kind != "weight":
                self.sink.error("FSV211", f"a requirement takes no `{modifier.kind}`", modifier.span,
                                "not for `require`",
                                help="a requirement is met or broken; only its `weight` can be set")
            elif "weight" in seen:
                self.sink.error("FSV211", "`weight` is given twice", modifier.span, "given again",
                                related=[Related(span=seen["weight"], message="first given here")])
            else:
                seen["weight"] = modifier.span
                value = self.values.amount(modifier.value, Dimension.NUMBER, "the weight")
                weight = value if value is not None else weight
        return weight

    def success(self, decl: ast.SuccessDecl | None) -> models.Success | None:
        if decl is None:
            self.scope.missing("success", "success lifted(pot, by=10 cm) for 1 s")
            return None
        condition = self.condition(decl.condition)
        hold = 0.0
        if decl.hold is not None:
            value = self.values.amount(decl.hold, Dimension.TIME, "the hold time")
            hold = value if value is not None else 0.0
        return models.Success(condition=condition, hold=hold) if condition is not None else None

    # ---------------------------------------------------------- conditions
    def condition(self, node: ast.Condition):
        if isinstance(node, ast.AllOf):
            items = [self.condition(i) for i in node.items]
            return None if None in items else models.AllOf(items=tuple(items))
        if isinstance(node, ast.AnyOf):
            items = [self.condition(i) for i in node.items]
            return None if None in items else models.AnyOf(items=tuple(items))
        if isinstance(node, ast.Negation):
            item = self.condition(node.item)
            return None if item is None else models.Not(item=item)
        return self._predicate(node)

    def _predicate(self, call: ast.Call) -> models.Predicate | None:
        name = call.name.value
        signature = PREDICATES.get(name)
        if signature is None:
            self.sink.error("FSV105", f"unknown predicate `{name}`", call.name.span, "not a predicate",
                            help=did_you_mean(name, PREDICATES, "predicates"))
            return None
        positional = call.positional
        kinds = signature.positional + signature.optional_positional
        if not len(signature.positional) <= len(positional) <= len(kinds):
            count = (f"{len(signature.positional)}" if not signature.optional_positional
                     else f"{len(signature.positional)} or {len(kinds)}")
            noun = "name" if count == "1" else "names"
            self.sink.error("FSV305", f"`{name}` takes {count} {noun}, not {len(positional)}", call.span,
                            f"{len(positional)} given", help=signature.doc)
            return None
        args = [self._arm(argument.value) if kind is ArgKind.ARM
                else self.scope.arg_entity(argument, signature, object_only=kind is ArgKind.OBJECT)
                for argument, kind in zip(positional, kinds)]
        keyword_call = ast.Call(call.name, call.keywords, call.span)
        params = bind_params(self.scope, keyword_call, signature.params, name, positional_ok=False)
        if None in args:
            return None
        if name in ("opened", "closed") and not self._articulated(name, args[0], positional[0]):
            return None
        return models.Predicate(name=name, args=tuple(args), params=params)

    def _articulated(self, predicate: str, name: str, argument: ast.Argument) -> bool:
        """``opened``/``closed`` need an object with a moving part."""
        kind = self.scope.object_kinds.get(name)
        if kind is None or kind.asset_class is AssetClass.ARTICULATED or kind.name == "urdf":
            return True
        self.sink.error("FSV111", f"`{predicate}` needs an object with a moving part, and `{name}` is "
                        f"a {kind.name}", argument.span, "nothing to open",
                        help="articulated assets: " + ", ".join(
                            f"`{n}`" for n, k in ASSETS.items() if k.asset_class is AssetClass.ARTICULATED))
        return False

    def _arm(self, value: ast.Value) -> str | None:
        scope = self.scope
        if isinstance(value, ast.Ref) and value.name in scope.arms:
            return value.name
        written = value.name if isinstance(value, ast.Ref) else "this"
        self.sink.error("FSV112", f"`{written}` is not an arm of `{scope.embodiment or 'the robot'}`",
                        value.span, "not an arm", help="arms: " + ", ".join(f"`{a}`" for a in scope.arms))
        return None
