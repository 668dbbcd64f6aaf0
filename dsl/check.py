"""Semantic checks: merged statements to a validated :class:`~fsvla.dsl.models.Scenario`.

Every check reports to a :class:`DiagnosticSink` and goes on, so one run lists
every problem of a file. The IR is built only when no error was found.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

from pydantic import ValidationError

from . import ast, models
from .catalog import (ASSETS, BIMANUAL_TASKS, EMBODIMENTS, LANGUAGE_CATEGORIES, METRICS, PREDICATES,
                      ROLE_CHANNEL, SHAPINGS, SUITES, TASKS, VISION_SETTINGS, ZONE_CHANNEL, ZONES,
                      ArgKind, AssetClass, AssetKind, HazardRole, Param, Signature, default_params,
                      robot_parts)
from .diagnostics import DiagnosticSink, Related, did_you_mean
from .merge import Merged, declared_name, unparse
from .spans import Span
from .units import Dimension
from .values import ValueChecker, format_si

DEFAULT_HORIZON_S = 30.0
SIDE_EFFECT_WATCHES = ("untouched", "do_not_disturb")
RELATION_OFFSETS = {"left_of": (0.0, 1.0), "right_of": (0.0, -1.0),
                    "in_front_of": (-1.0, 0.0), "behind": (1.0, 0.0)}
PathResolver = Callable[[ast.String], "str | None"]


def _ref(span: Span) -> models.SourceRef:
    return models.SourceRef(file=span.file, line=span.line, column=span.column)


class ScenarioChecker:
    def __init__(self, scenario: ast.ScenarioDecl, merged: Merged, sink: DiagnosticSink,
                 resolve_path: PathResolver, lineage: tuple[str, ...], digest: str):
        self.scenario = scenario
        self.merged = merged
        self.sink = sink
        self.values = ValueChecker(sink)
        self.resolve_path = resolve_path
        self.lineage = lineage
        self.digest = digest
        self.arms: tuple[str, ...] = ("arm",)
        self.embodiment = ""
        self.objects: dict[str, models.ObjectSpec] = {}
        self.object_kinds: dict[str, AssetKind] = {}
        self.zones: dict[str, models.ZoneSpec] = {}
        self.limits: list[models.LimitSpec] = []
        self.requirements: list[models.Requirement] = []

    # ================================================================ entry
    def check(self) -> models.Scenario | None:
        settings = self.merged.settings
        suite = self._suite(settings.get("suite"))
        self._embodiment(settings.get("embodiment"))
        self._declarations()
        task = self._task(settings.get("task"))
        instruction = self._instruction(settings.get("instruction"))
        horizon = self._horizon(settings.get("horizon"))
        success = self._success(self.merged.success)
        variants = self._variants()
        language = self._language()
        vision = self._vision()
        self._suite_coverage(suite, settings.get("suite"))
        if self.sink.has_errors or self.scenario.abstract:
            return None
        try:
            return models.Scenario(
                name=self.scenario.name.value, suite=suite, task=task, embodiment=self.embodiment,
                arms=self.arms, instruction=instruction, horizon=horizon,
                objects=tuple(self.objects.values()), zones=tuple(self.zones.values()),
                limits=tuple(self.limits), requirements=tuple(self.requirements), success=success,
                variants=variants, language=language, vision=vision,
                source=_ref(self.scenario.name.span), lineage=self.lineage, source_digest=self.digest)
        except ValidationError as error:  # a bug in the checker: every field was validated above
            for problem in error.errors():
                self.sink.error("FSV999", f"internal error: {problem['msg']} at {problem['loc']}",
                                self.scenario.name.span,
                                help="please report this with the scenario file attached")
            return None

    # ============================================================ settings
    def _missing(self, what: str, example: str) -> None:
        if not self.scenario.abstract:
            self.sink.error("FSV301", f"missing `{what}`", self.scenario.name.span,
                            f"this scenario has no `{what}` statement",
                            help=f"add a line such as `{example}` (or inherit one with `extends`)")

    def _suite(self, setting: ast.Setting | None):
        if setting is None:
            self._missing("suite", "suite thermal")
            return None
        name = setting.value.value
        if name not in SUITES:
            self.sink.error("FSV108", f"unknown suite `{name}`", setting.value.span,
                            "not a Safe-Core suite", help=did_you_mean(name, SUITES, "suites"))
            return None
        return name

    def _embodiment(self, setting: ast.Setting | None) -> None:
        if setting is None:
            self._missing("embodiment", "embodiment panda")
            self.arms = ("left", "right")  # check arm references as permissively as possible
            return
        name = setting.value.value
        if name not in EMBODIMENTS:
            self.sink.error("FSV107", f"unknown embodiment `{name}`", setting.value.span,
                            "not a built-in embodiment", help=did_you_mean(name, EMBODIMENTS, "embodiments"))
            self.arms = ("left", "right")
            return
        self.embodiment = name
        self.arms = EMBODIMENTS[name]

    def _instruction(self, setting: ast.Setting | None) -> str:
        if setting is None:
            self._missing("instruction", 'instruction "Lift the pot."')
            return ""
        text = setting.value.value.strip()
        if not text:
            self.sink.error("FSV207", "the instruction is empty", setting.value.span, "empty string",
                            help="write the task as you would say it to the robot")
        return text

    def _horizon(self, setting: ast.Setting | None) -> float:
        if setting is None:
            return DEFAULT_HORIZON_S
        param = Param(name="horizon", dimension=Dimension.TIME, minimum=1.0, maximum=600.0)
        value = self.values.param(param, setting.value, "horizon")
        return value if isinstance(value, float) else DEFAULT_HORIZON_S

    def _task(self, setting: ast.Setting | None):
        if setting is None:
            self._missing("task", "task lift(pot)")
            return None
        call: ast.Call = setting.value
        name = call.name.value
        if name not in TASKS:
            self.sink.error("FSV106", f"unknown task `{name}`", call.name.span, "not a base task",
                            help=did_you_mean(name, TASKS, "tasks"))
            return None
        roles = TASKS[name]
        bound: dict[str, str] = {}
        argument_problem = False
        named_seen = False
        for index, argument in enumerate(call.arguments):
            if argument.keyword is None and named_seen:
                self.sink.error("FSV305", "a value without a name after named ones", argument.span,
                                "unnamed value", help="write unnamed roles first, or give this one its role name")
                continue
            named_seen = named_seen or argument.keyword is not None
            role = argument.keyword.value if argument.keyword else (roles[index] if index < len(roles) else None)
            if role is None:
                self.sink.error("FSV305", f"too many arguments for task `{name}`", argument.span,
                                f"`{name}` takes {', '.join(roles)}")
                argument_problem = True
                continue
            if role not in roles:
                self.sink.error("FSV303", f"task `{name}` has no role `{role}`", argument.keyword.span,
                                "not a role of this task", help=did_you_mean(role, roles, "roles"))
                argument_problem = True
                continue
            if role in bound:
                self.sink.error("FSV208", f"role `{role}` is given twice", argument.span, "given again")
                continue
            target = self._object_ref(argument.value, f"role `{role}` of task `{name}`")
            if target is not None:
                bound[role] = target
            else:
                argument_problem = True
        for role in roles:
            if role not in bound and not argument_problem:
                self.sink.error("FSV303", f"task `{name}` needs its `{role}`", call.span,
                                f"missing `{role}`",
                                help=f"write `task {name}({', '.join(f'{r}=...' for r in roles)})`")
        if name in BIMANUAL_TASKS and len(self.arms) < 2 and self.embodiment:
            self.sink.error("FSV304", f"task `{name}` needs two arms, but `{self.embodiment}` has one",
                            call.name.span, "a bimanual task",
                            help="use a dual-arm embodiment: " + ", ".join(
                                f"`{e}`" for e, arms in EMBODIMENTS.items() if len(arms) == 2))
        return models.Task(name=name, roles=bound, source=_ref(call.span))

    # ===================================================== names and refs
    def _robot_parts(self) -> dict[str, str]:
        return robot_parts(self.arms)

    def _entity_names(self) -> list[str]:
        return list(self.objects) + list(self.zones) + list(self._robot_parts())

    def _entity(self, name: str, span: Span, what: str, allow_zone: bool = True) -> str | None:
        if name in self.objects or name in self._robot_parts() or (allow_zone and name in self.zones):
            return name
        if self._failed_declaration(name):
            return None  # declared, but it has errors of its own that are already reported
        if name in self.zones:
            self.sink.error("FSV111", f"`{name}` is a zone, not a body, so {what} cannot be it", span,
                            "a zone", help="name an object or a part of the robot")
            return None
        if name in ("left_arm", "right_arm", "left_gripper", "right_gripper", "arm") and self.embodiment:
            self.sink.error("FSV112", f"`{self.embodiment}` has no `{name}`", span,
                            "not a part of this robot",
                            help=did_you_mean(name, self._robot_parts(), "robot parts"))
            return None
        self.sink.error("FSV101", f"unknown name `{name}`", span, f"not declared ({what})",
                        help=did_you_mean(name, self._entity_names(), "names"))
        return None

    def _failed_declaration(self, name: str) -> bool:
        """An object or hazard that is declared but was dropped for errors of its own."""
        decl = self.merged.declarations.get(name)
        return (isinstance(decl, (ast.ObjectDecl, ast.HazardDecl))
                and name not in self.objects and name not in self.zones)

    def _object_ref(self, value: ast.Value, what: str) -> str | None:
        if not isinstance(value, ast.Ref):
            self.sink.error("FSV207", f"{what} must name an object", value.span, "expected a name")
            return None
        if value.name in self.objects:
            return value.name
        if self._failed_declaration(value.name):
            return None  # declared, but it has errors of its own that are already reported
        if value.name in self.zones or value.name in self._robot_parts():
            self.sink.error("FSV111", f"{what} must be an object, and `{value.name}` is "
                            f"{'a zone' if value.name in self.zones else 'part of the robot'}",
                            value.span, "not an object")
            return None
        self.sink.error("FSV101", f"unknown object `{value.name}`", value.span, f"not declared ({what})",
                        help=did_you_mean(value.name, self.objects, "objects"))
        return None

    # ======================================================== declarations
    def _declarations(self) -> None:
        decls = self.merged.declarations
        objects = sorted((d for d in decls.values() if isinstance(d, ast.ObjectDecl)),
                         key=lambda d: d.name.value != "table")  # the IR lists the table first
        hazards = [d for d in decls.values() if isinstance(d, ast.HazardDecl)]
        if "table" not in decls:
            self.objects["table"] = models.ObjectSpec(
                name="table", asset="table", params=default_params(ASSETS["table"].params),
                placement=models.Placement(support="world"), source=_ref(self.scenario.name.span))
            self.object_kinds["table"] = ASSETS["table"]
        pending: list[tuple[str, ast.ObjectDecl | ast.HazardDecl, AssetKind, dict, HazardRole | None]] = []
        for decl in (*objects, *hazards):
            if decl.name.value in robot_parts(self.arms) or decl.name.value in ("left", "right"):
                self.sink.error("FSV110", f"`{decl.name.value}` is the name of a part of the robot",
                                decl.name.span, "already taken by the robot",
                                help="choose another name; `robot`, `gripper`, `arm`, `left_arm`, ... "
                                     "always mean the robot's own links")
        for decl in objects:
            kind, params = self._asset(decl.asset, decl.name.value)
            if kind is not None and decl.name.value == "table" and kind.name != "table":
                self.sink.error("FSV111", "the object called `table` must be a `table(...)`", decl.asset.name.span,
                                f"a {kind.name}", help="declare the work surface as `object table: table(size=(1.2 m, "
                                "80 cm), height=75 cm)`, and give this object another name")
                continue
            if kind is not None:
                pending.append((decl.name.value, decl, kind, params, None))
        for decl in hazards:
            resolved = self._hazard_definition(decl)
            if resolved is not None:
                pending.append((decl.name.value, decl, *resolved))
        placements = self._placements(pending)
        for name, decl, kind, params, role in pending:
            if name not in placements:
                continue
            if kind.asset_class is AssetClass.ZONE:
                self.zones[name] = models.ZoneSpec(name=name, kind=kind.name, params=params,
                                                   placement=placements[name], source=_ref(decl.name.span))
            else:
                self.objects[name] = models.ObjectSpec(
                    name=name, asset=kind.name, params=params, placement=placements[name],
                    hazard_role=role.value if role else None, source=_ref(decl.name.span))
                self.object_kinds[name] = kind
        for decl in hazards:
            if decl.name.value in self.zones or decl.name.value in self.objects:
                self._keeps(decl)
        for name, decl in decls.items():
            if isinstance(decl, ast.LimitDecl):
                self._limit(name, decl)
            elif isinstance(decl, ast.RequireDecl):
                self._requirement(name, decl)

    def _asset(self, call: ast.Call, owner: str) -> tuple[AssetKind | None, dict]:
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
        params = self._params(call, kind.params, f"{name}")
        return kind, params

    def _params(self, call: ast.Call, params: tuple[Param, ...], owner: str,
                positional_ok: bool = True) -> dict:
        given: dict[str, Span] = {}
        out: dict = {}
        named_seen = False
        for index, argument in enumerate(call.arguments):
            if argument.keyword is None and named_seen:
                self.sink.error("FSV305", "a value without a name after named ones", argument.span,
                                "unnamed value", help="write unnamed values first, or give this one its name")
                continue
            named_seen = named_seen or argument.keyword is not None
            if argument.keyword is None:
                if not positional_ok or index >= len(params):
                    self.sink.error("FSV305", f"unexpected value for `{owner}`", argument.span,
                                    "parameters are given by name",
                                    help=f"write `name=value`; `{owner}` takes "
                                         + ", ".join(f"`{p.name}`" for p in params))
                    continue
                param = params[index]
            else:
                param = next((p for p in params if p.name == argument.keyword.value), None)
                if param is None:
                    self.sink.error("FSV103", f"`{owner}` has no parameter `{argument.keyword.value}`",
                                    argument.keyword.span, "unknown parameter",
                                    help=did_you_mean(argument.keyword.value, [p.name for p in params],
                                                      "parameters"))
                    continue
            if param.name in given:
                self.sink.error("FSV208", f"`{param.name}` is given twice", argument.span, "given again",
                                related=[Related(span=given[param.name], message="first given here")])
                continue
            given[param.name] = argument.span
            value = self.values.param(param, argument.value, owner, self.resolve_path)
            if value is not None:
                out[param.name] = value
        for param in params:
            if param.required and param.name not in given:
                self.sink.error("FSV206", f"`{owner}` needs `{param.name}`", call.span,
                                f"missing `{param.name}`", help=f"add `{param.name}=...` inside the parentheses")
            elif param.name not in given and param.default is not None:
                out[param.name] = param.default
        return out

    def _hazard_definition(self, decl: ast.HazardDecl):
        call = decl.definition
        name = call.name.value
        if name in ZONES:
            kind = ZONES[name]
            params = self._params(call, kind.params, name, positional_ok=False)
            shaped = [p for p in ("size", "radius") if p in params]
            if "size" in kind.param_names() and "radius" in kind.param_names() and len(shaped) != 1:
                self.sink.error("FSV212", f"`{name}` needs either `size` or `radius`"
                                + (", not both" if shaped else ""), call.span,
                                "give its footprint", help=f"e.g. `{name}(size=(18 cm, 18 cm))` or "
                                f"`{name}(radius=9 cm)`")
            return kind, params, None
        roles = [r.value for r in HazardRole]
        if name in roles:
            if len(call.arguments) != 1 or not isinstance(call.arguments[0].value, ast.Call):
                self.sink.error("FSV305", f"`{name}` wraps one asset", call.span, "expected one asset",
                                help=f"write `{name}(vase(radius=5 cm))`")
                return None
            kind, params = self._asset(call.arguments[0].value, decl.name.value)
            return (kind, params, HazardRole(name)) if kind is not None else None
        self.sink.error("FSV102", f"unknown hazard `{name}`", call.name.span, "not a hazard kind",
                        help=did_you_mean(name, list(ZONES) + roles, "hazard kinds"))
        return None

    # ========================================================== placement
    def _placements(self, pending) -> dict[str, models.Placement]:
        declared = {name: decl for name, decl, *_ in pending}
        kinds = {name: kind for name, _, kind, *_ in pending}
        kinds.setdefault("table", ASSETS["table"])
        raw: dict[str, dict] = {}
        for name, decl, kind, params, role in pending:
            raw[name] = self._placement_parts(name, decl, kinds, declared)
        resolved: dict[str, models.Placement] = {}
        visiting: list[str] = []
        in_cycle: set[str] = set()

        def resolve(name: str) -> models.Placement | None:
            if name in resolved:
                return resolved[name]
            if name not in raw or name in in_cycle:
                return None
            if name in visiting:
                cycle = visiting[visiting.index(name):] + [name]
                in_cycle.update(cycle)
                decl = declared[name]
                self.sink.error("FSV307", "placement relations form a cycle: " + " -> ".join(cycle),
                                decl.name.span, "placed relative to itself",
                                help="place one of them with `at (x, y)`")
                return None
            visiting.append(name)
            parts = raw[name]
            position = parts["position"]
            relation = parts["relation"]
            support = parts["support"]
            if relation is not None:
                anchor = resolve(relation.anchor) if relation.anchor != "table" else models.Placement(
                    support="world")
                if anchor is None:
                    visiting.pop()
                    return None
                dx, dy = RELATION_OFFSETS[relation.kind]
                position = (anchor.position[0] + dx * relation.distance,
                            anchor.position[1] + dy * relation.distance)
                anchor_support = "table" if relation.anchor == "table" else anchor.support
                if not parts["support_given"]:
                    support = anchor_support
                elif support != anchor_support and relation.anchor != support:
                    self.sink.error("FSV306", f"`{name}` stands on `{support}` but is placed relative to "
                                    f"`{relation.anchor}`, which stands on `{anchor_support}`",
                                    declared[name].name.span, "positions in two different frames",
                                    help=f"put both on the same support, or place `{name}` with `at (x, y)`")
                    visiting.pop()
                    return None
            if support in raw and resolve(support) is None:
                visiting.pop()
                return None
            visiting.pop()
            placement = models.Placement(support=support, position=position, height=parts["height"],
                                         yaw=parts["yaw"], relation=relation)
            resolved[name] = placement
            return placement

        for name in raw:
            resolve(name)
        return resolved

    def _placement_parts(self, name, decl, kinds, declared) -> dict:
        parts = {"position": (0.0, 0.0), "height": 0.0, "yaw": 0.0,
                 "support": "world" if name == "table" else "table",  # a declared table stands on the world
                 "support_given": False, "relation": None}
        seen: dict[str, Span] = {}
        is_zone = kinds[name].asset_class is AssetClass.ZONE
        for placement in decl.placements:
            key = "position" if isinstance(placement, (ast.At, ast.Relation)) else type(placement).__name__
            if key in seen:
                self.sink.error("FSV306", f"`{name}` is placed twice", placement.span, "placed again",
                                related=[Related(span=seen[key], message="first placed here")],
                                help="give one `at (x, y)` or one relation such as `left_of pot by 10 cm`")
                continue
            seen[key] = placement.span
            if isinstance(placement, ast.At):
                parts.update(self._position(placement.position, name, allow_height=is_zone))
            elif isinstance(placement, ast.On):
                support = placement.support.value
                if support == name:
                    self.sink.error("FSV306", f"`{name}` cannot stand on itself", placement.support.span,
                                    "itself")
                elif support not in kinds:
                    self.sink.error("FSV101", f"unknown support `{support}`", placement.support.span,
                                    "not declared", help=did_you_mean(support, kinds, "objects"))
                elif not kinds[support].support:
                    self.sink.error("FSV111", f"`{support}` is a {kinds[support].name}, which nothing "
                                    "can stand on", placement.support.span, "not a support",
                                    help="supports are: " + ", ".join(
                                        f"`{n}`" for n, k in ASSETS.items() if k.support))
                else:
                    parts["support"] = support
                    parts["support_given"] = True
            elif isinstance(placement, ast.Yaw):
                angle = self.values.quantity(placement.angle, Dimension.ANGLE, "yaw")
                if angle is not None:
                    parts["yaw"] = math.remainder(angle, 2 * math.pi)
            else:
                parts["relation"] = self._relation(name, placement, declared)
        return parts

    def _position(self, vector: ast.Vector, name: str, allow_height: bool) -> dict:
        arity = len(vector.items)
        if arity not in ((2, 3) if allow_height else (2,)):
            self.sink.error("FSV205", f"the position of `{name}` needs "
                            + ("2 or 3 values" if allow_height else "2 values (x, y)"),
                            vector.span, f"{arity} values",
                            help="positions are (x, y) on the support's top surface, from its centre")
            return {}
        numbers = [self.values.quantity(item, Dimension.LENGTH, f"the position of `{name}`")
                   if isinstance(item, ast.Quantity) else None for item in vector.items]
        for item in vector.items:
            if not isinstance(item, ast.Quantity):
                self.sink.error("FSV207", "a position is made of lengths", item.span, "not a length")
        if any(n is None for n in numbers):
            return {}
        out = {"position": (numbers[0], numbers[1])}
        if arity == 3:
            out["height"] = numbers[2]
        return out

    def _relation(self, name: str, placement: ast.Relation, declared) -> models.Relation | None:
        anchor = placement.anchor.value
        if anchor not in declared and anchor != "table":
            self.sink.error("FSV101", f"unknown name `{anchor}`", placement.anchor.span, "not declared",
                            help=did_you_mean(anchor, list(declared), "objects"))
            return None
        distance = self.values.amount(placement.distance, Dimension.LENGTH, "the distance")
        if distance is None:
            return None
        return models.Relation(kind=placement.kind.value, anchor=anchor, distance=distance)

    # ============================================================ channels
    def _band(self, modifiers: Iterable[ast.Modifier], dimension: Dimension, span: Span,
              what: str, example: str) -> tuple[float | None, str, float]:
        soft, shaping, weight = None, "linear", 1.0
        seen: dict[str, Span] = {}
        for modifier in modifiers:
            if modifier.kind in seen:
                self.sink.error("FSV211", f"`{modifier.kind}` is given twice", modifier.span, "given again",
                                related=[Related(span=seen[modifier.kind], message="first given here")])
                continue
            seen[modifier.kind] = modifier.span
            if modifier.kind == "warn":
                soft = self.values.quantity(modifier.value, dimension, "the warning band")
                if soft is not None and soft <= 0:
                    self.sink.error("FSV210", "the warning band must be larger than zero", modifier.value.span,
                                    "not positive", help="the soft threshold epsilon is the width of the "
                                    "warning band before the hard limit (paper eq. 1)")
                    soft = None
            elif modifier.kind == "cost":
                if modifier.value.value in SHAPINGS:
                    shaping = modifier.value.value
                else:
                    self.sink.error("FSV109", f"unknown cost shaping `{modifier.value.value}`",
                                    modifier.value.span, "not a shaping",
                                    help=did_you_mean(modifier.value.value, SHAPINGS, "shapings"))
            else:
                value = self.values.quantity(modifier.value, Dimension.NUMBER, "the weight")
                if value is not None and value < 0:
                    self.sink.error("FSV204", "the weight must not be negative", modifier.value.span,
                                    "negative")
                elif value is not None:
                    weight = value
        if "warn" not in seen:
            self.sink.error("FSV210", f"{what} has no warning band", span, "missing `warn`",
                            help=f"add a soft threshold, e.g. `{example}`: cost accrues inside the band "
                                 "before the hard limit is crossed")
        return soft, shaping, weight

    def _keeps(self, decl: ast.HazardDecl) -> None:
        hazard = decl.name.value
        zone = self.zones.get(hazard)
        if zone is not None:
            family, metric = ZONE_CHANNEL[zone.kind], "zone_distance"
        else:
            role = HazardRole(self.objects[hazard].hazard_role)
            family, metric = ROLE_CHANNEL[role], "clearance"
        if not decl.keeps and zone is not None and zone.kind != "corridor":
            self.sink.warning("FSV309", f"hazard `{hazard}` has no `keep` clause, so nothing measures it",
                              decl.name.span, "not monitored",
                              help="add an indented line such as `keep gripper outside 5 cm warn 3 cm`")
        for index, keep in enumerate(decl.keeps):
            name = hazard if index == 0 else f"{hazard}#{index + 1}"
            subjects = tuple(s for s in (self._entity(n.value, n.span, "a keep-out subject", allow_zone=False)
                                         for n in keep.subjects) if s is not None)
            for subject, node in zip(keep.subjects, keep.subjects):
                if subject.value == hazard:
                    self.sink.error("FSV111", f"`{hazard}` cannot keep away from itself", node.span, "itself")
            distance = self.values.quantity(keep.distance, Dimension.LENGTH, "the keep-out distance")
            soft, shaping, weight = self._band(keep.modifiers, Dimension.LENGTH, keep.span,
                                               "this keep-out clause", "warn 3 cm")
            if distance is None or soft is None or distance < 0:
                if distance is not None and distance < 0:
                    self.sink.error("FSV204", "the keep-out distance must not be negative", keep.distance.span,
                                    "negative")
                continue
            self.limits.append(models.LimitSpec(
                name=name, origin="hazard", family=family, metric=metric, subjects=subjects,
                reference=hazard, comparison=">=", limit=distance, unit="m", soft_threshold=soft,
                shaping=shaping, weight=weight, source=_ref(keep.span)))

    def _limit(self, name: str, decl: ast.LimitDecl) -> None:
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
        if decl.comparator is None or decl.limit is None:
            self.sink.error("FSV209", f"`{metric}` needs a limit", decl.measure.span, "no limit given",
                            help=f"write `{unparse(decl.measure)} {signature.comparison} "
                                 f"{_example(signature.dimension)}`")
            return
        if decl.comparator.value != signature.comparison:
            self.sink.error("FSV209", f"`{metric}` takes a limit with `{signature.comparison}`",
                            decl.comparator.span, f"`{metric}` is bounded "
                            + ("above" if signature.comparison == "<=" else "below"),
                            help=f"write `{signature.comparison}`")
            return
        limit = self.values.quantity(decl.limit, signature.dimension, f"the limit of `{metric}`")
        soft, shaping, weight = self._band(decl.modifiers, signature.dimension, decl.span,
                                           f"`{keyword} {unparse(decl.measure)}`",
                                           f"warn {_example(signature.dimension, small=True)}")
        if limit is not None and limit < 0:
            self.sink.error("FSV204", "a limit must not be negative", decl.limit.span, "negative")
            return
        if signature.name == "separation" and len(self.arms) < 2 and self.embodiment:
            self.sink.error("FSV304", f"`separation` needs two arms, but `{self.embodiment}` has one",
                            decl.measure.name.span, "a dual-arm measure")
            return
        if None in (limit, soft) or subjects is None:
            return
        family = "side_effect" if keyword == "watch" else signature.channel
        self.limits.append(models.LimitSpec(
            name=name, origin=keyword, family=family, metric=metric, subjects=subjects,
            reference=reference, comparison=signature.comparison, limit=limit,
            unit=signature.dimension.si_unit, soft_threshold=soft, shaping=shaping, weight=weight,
            source=_ref(decl.span)))

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
        reference = self._entity(value.name, value.span, f"the argument of `{metric}`")
        soft, shaping, weight = self._band(decl.modifiers, Dimension.LENGTH, decl.span,
                                           f"`watch {unparse(decl.measure)}`", "warn 2 cm")
        if reference is None or soft is None:
            return
        self.limits.append(models.LimitSpec(
            name=name, origin="watch", family="side_effect", metric=metric, subjects=("robot",),
            reference=reference, comparison=">=", limit=0.0, unit="m", soft_threshold=soft,
            shaping=shaping, weight=weight, source=_ref(decl.span)))

    def _metric_args(self, signature: Signature, call: ast.Call):
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
            names = [self._arg_entity(a, signature, allow_zone=False) for a in args]
            return (tuple(names), None) if None not in names else (None, None)
        if len(args) != len(kinds):
            self.sink.error("FSV305", f"`{signature.name}` takes {len(kinds)} name"
                            f"{'s' if len(kinds) > 1 else ''}, not {len(args)}", call.span,
                            f"{len(args)} given")
            return None, None
        names = [self._arg_entity(a, signature, object_only=k is ArgKind.OBJECT) for a, k in zip(args, kinds)]
        if None in names:
            return None, None
        if signature.name == "separation":
            for arg, name in zip(args, names):
                if name not in self._robot_parts():
                    self.sink.error("FSV111", f"`separation` measures between arms, and `{name}` is not "
                                    "part of the robot", arg.span, "not an arm",
                                    help="use `left_arm`, `right_arm`, `left_gripper` or `right_gripper`")
                    return None, None
        return tuple(names[:1]), (names[1] if len(names) > 1 else None)

    def _arg_entity(self, argument: ast.Argument, signature: Signature, object_only: bool = False,
                    allow_zone: bool = True):
        value = argument.value
        if not isinstance(value, ast.Ref):
            self.sink.error("FSV207", f"`{signature.name}` takes names", value.span, "expected a name")
            return None
        if object_only:
            return self._object_ref(value, f"the argument of `{signature.name}`")
        return self._entity(value.name, value.span, f"an argument of `{signature.name}`", allow_zone)

    # ============================================================ temporal
    def _condition(self, node: ast.Condition):
        if isinstance(node, ast.AllOf):
            items = [self._condition(i) for i in node.items]
            return None if None in items else models.AllOf(items=tuple(items))
        if isinstance(node, ast.AnyOf):
            items = [self._condition(i) for i in node.items]
            return None if None in items else models.AnyOf(items=tuple(items))
        if isinstance(node, ast.Negation):
            item = self._condition(node.item)
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
        args: list[str | None] = []
        for argument, kind in zip(positional, kinds):
            if kind is ArgKind.ARM:
                args.append(self._arm(argument.value))
            else:
                args.append(self._arg_entity(argument, signature, object_only=kind is ArgKind.OBJECT))
        keyword_call = ast.Call(call.name, call.keywords, call.span)
        params = self._params(keyword_call, signature.params, name, positional_ok=False)
        if None in args:
            return None
        if name in ("opened", "closed"):
            kind = self.object_kinds.get(args[0])
            if kind is not None and kind.asset_class is not AssetClass.ARTICULATED and kind.name != "urdf":
                self.sink.error("FSV111", f"`{name}` needs an object with a moving part, and `{args[0]}` is "
                                f"a {kind.name}", positional[0].span, "nothing to open",
                                help="articulated assets: " + ", ".join(
                                    f"`{n}`" for n, k in ASSETS.items() if k.asset_class is AssetClass.ARTICULATED))
                return None
        return models.Predicate(name=name, args=tuple(args), params=params)

    def _arm(self, value: ast.Value) -> str | None:
        if isinstance(value, ast.Ref) and value.name in self.arms:
            return value.name
        written = value.name if isinstance(value, ast.Ref) else "this"
        self.sink.error("FSV112", f"`{written}` is not an arm of `{self.embodiment or 'the robot'}`",
                        value.span, "not an arm", help="arms: " + ", ".join(f"`{a}`" for a in self.arms))
        return None

    def _requirement(self, name: str, decl: ast.RequireDecl) -> None:
        first, then = self._condition(decl.first), self._condition(decl.then)
        within = None
        if decl.within is not None:
            within = self.values.amount(decl.within, Dimension.TIME, "`within`", strict=True)
        weight = 1.0
        seen: dict[str, Span] = {}
        for modifier in decl.modifiers:
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
        if first is None or then is None:
            return
        self.requirements.append(models.Requirement(name=name, first=first, then=then, within=within,
                                                    weight=weight, source=_ref(decl.span)))

    def _success(self, decl: ast.SuccessDecl | None):
        if decl is None:
            self._missing("success", "success lifted(pot, by=10 cm) for 1 s")
            return None
        condition = self._condition(decl.condition)
        hold = 0.0
        if decl.hold is not None:
            value = self.values.amount(decl.hold, Dimension.TIME, "the hold time")
            hold = value if value is not None else 0.0
        return models.Success(condition=condition, hold=hold) if condition is not None else None

    # ============================================================ variants
    def _variants(self) -> dict:
        out: dict = {}
        for level_name, level in self.merged.variants.items():
            if level_name not in ("L1", "L2"):
                self.sink.error("FSV501", f"unknown structure level `{level_name}`", level.level.span,
                                "not L1 or L2", help="L0 is the canonical layout as declared; "
                                "write rules for `L1` (placement variation) and `L2` (harder layouts)")
                continue
            rules = [self._rule(rule) for rule in level.rules]
            out[level_name] = tuple(r for r in rules if r is not None)
        return out

    def _rule(self, rule: ast.Rule):
        kind = rule.kind.value
        source = _ref(rule.span)
        if kind == "jitter":
            target = rule.target.value
            if target == "table" or (target not in self.objects and target not in self.zones):
                self._unknown_movable(rule.target)
                return None
            distance = self.values.amount(rule.amount, Dimension.LENGTH, "the jitter radius")
            yaw = self.values.amount(rule.extra, Dimension.ANGLE, "the yaw jitter") if rule.extra else 0.0
            if distance is None or yaw is None:
                return None
            return models.Jitter(target=target, distance=distance, yaw=yaw, source=source)
        if kind == "approach":
            hazard, toward = rule.target.value, rule.other.value
            is_hazard = hazard in self.zones or (hazard in self.objects and self.objects[hazard].hazard_role)
            if not is_hazard:
                self.sink.error("FSV502", f"`approach` moves a hazard, and `{hazard}` is not one",
                                rule.target.span, "not a hazard",
                                help=did_you_mean(hazard, [n for n, o in self.objects.items() if o.hazard_role]
                                                  + list(self.zones), "hazards"))
                return None
            if toward not in self.objects:
                self.sink.error("FSV101", f"unknown object `{toward}`", rule.other.span, "not declared",
                                help=did_you_mean(toward, self.objects, "objects"))
                return None
            distance = self.values.amount(rule.amount, Dimension.LENGTH, "the approach distance", strict=True)
            return None if distance is None else models.Approach(hazard=hazard, toward=toward,
                                                                  distance=distance, source=source)
        if kind == "clutter":
            count = self.values.quantity(rule.amount, Dimension.NUMBER, "the clutter count")
            if count is None:
                return None
            if count != int(count) or not 0 <= count <= 12:
                self.sink.error("FSV204", "the clutter count must be a whole number from 0 to 12",
                                rule.amount.span, "out of range")
                return None
            near = rule.other.value if rule.other else None
            if near is not None and near not in self.objects:
                self.sink.error("FSV101", f"unknown object `{near}`", rule.other.span, "not declared",
                                help=did_you_mean(near, self.objects, "objects"))
                return None
            return models.Clutter(count=int(count), near=near, source=source)
        if kind == "tighten":
            return self._tighten(rule, source)
        requirement = next((r for r in self.requirements if r.name == rule.target.value), None)
        if requirement is None and rule.target.value in self.merged.declarations:
            return None  # declared, but it has errors of its own that are already reported
        if requirement is None:
            self.sink.error("FSV502", f"`couple` needs a named requirement, and `{rule.target.value}` is not one",
                            rule.target.span, "not a requirement",
                            help=did_you_mean(rule.target.value, [r.name for r in self.requirements],
                                              "requirements") or "name one: `require NAME: A before B`")
            return None
        within = self.values.quantity(rule.amount, Dimension.TIME, "the coupling window")
        if within is not None and within <= 0:
            self.sink.error("FSV204", "the coupling window must be longer than zero", rule.amount.span, "")
            return None
        return None if within is None else models.Couple(requirement=requirement.name, within=within,
                                                         source=source)

    def _unknown_movable(self, name: ast.Name) -> None:
        movable = [n for n in self.objects if n != "table"] + list(self.zones)
        self.sink.error("FSV101", f"`{name.value}` is not an object or hazard that can move", name.span,
                        "cannot be jittered", help=did_you_mean(name.value, movable, "names"))

    def _tighten(self, rule: ast.Rule, source: models.SourceRef):
        target = rule.target.value
        limit = next((l for l in self.limits if l.name == target), None)
        if limit is None and target in self.merged.declarations:
            return None  # declared, but it has errors of its own that are already reported
        if limit is None:
            named = [l.name for l in self.limits if "(" not in l.name]
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

    # ===================================================== language/vision
    def _language(self) -> dict:
        out: dict = {}
        for level_name, entries in self.merged.language.items():
            if level_name not in LANGUAGE_CATEGORIES:
                self.sink.error("FSV504", f"unknown language level `{level_name}`", entries[0].level.span,
                                "not W1-W4", help="W0 is the canonical `instruction`; override W1 "
                                "(paraphrase), W2 (compositional), W3 (unsafe, contradictory, ambiguous) "
                                "or W4 (hijack suffix)")
                continue
            allowed = LANGUAGE_CATEGORIES[level_name]
            variants = []
            for entry in entries:
                category = entry.category.value if entry.category else None
                if category is None and len(allowed) > 1:
                    self.sink.error("FSV504", f"{level_name} needs a category", entry.level.span,
                                    "which kind of request?",
                                    help=f"write `{level_name} {allowed[0]}: \"...\"`; categories: "
                                         + ", ".join(allowed))
                    continue
                if category is not None and category not in allowed:
                    self.sink.error("FSV504", f"`{category}` is not a category of {level_name}",
                                    entry.category.span, "wrong category",
                                    help=did_you_mean(category, allowed, "categories"))
                    continue
                for text in entry.texts:
                    if not text.value.strip():
                        self.sink.error("FSV207", "an empty instruction", text.span, "empty string")
                        continue
                    variants.append(models.LanguageVariant(text=text.value, category=category or allowed[0],
                                                           source=_ref(text.span)))
            out[level_name] = tuple(variants)
        return out

    def _vision(self) -> dict:
        out: dict = {}
        for level_name, entry in self.merged.vision.items():
            if level_name not in ("V1", "V2", "V3", "V4"):
                self.sink.error("FSV505", f"unknown vision level `{level_name}`", entry.level.span,
                                "not V1-V4", help="V0 is the canonical view; override V1 (lighting), "
                                "V2 (appearance), V3 (viewpoint, occlusion) or V4 (adversarial patch)")
                continue
            level = int(level_name[1])
            settings = []
            for call in entry.settings:
                setting = self._vision_setting(call, level)
                if setting is not None:
                    settings.append(setting)
            out[level_name] = tuple(settings)
        return out

    def _vision_setting(self, call: ast.Call, level: int) -> models.VisionSetting | None:
        name = call.name.value
        if name not in VISION_SETTINGS:
            self.sink.error("FSV505", f"unknown vision setting `{name}`", call.name.span, "not a setting",
                            help=did_you_mean(name, VISION_SETTINGS, "settings"))
            return None
        lowest, signature = VISION_SETTINGS[name]
        if level < lowest:
            self.sink.error("FSV505", f"`{name}` belongs to V{lowest} and above", call.name.span,
                            f"not a V{level} perturbation",
                            help=f"move it under `V{lowest}:`; levels are cumulative, so it applies from there on")
            return None
        params: dict = {}
        positional = call.positional
        if len(positional) != len(signature.positional):
            self.sink.error("FSV305", f"`{name}` takes {len(signature.positional)} name(s)", call.span,
                            f"{len(positional)} given", help=signature.doc)
            return None
        if positional:
            target = self._arg_entity(positional[0], signature)
            if target is None:
                return None
            params["target"] = target
        params.update(self._params(ast.Call(call.name, call.keywords, call.span), signature.params, name,
                                   positional_ok=False))
        return models.VisionSetting(name=name, params=params, source=_ref(call.span))

    # ============================================================ coverage
    def _suite_coverage(self, suite: str | None, setting: ast.Setting | None) -> None:
        if suite is None or setting is None or self.scenario.abstract or self.sink.has_errors:
            return  # with errors, a broken limit of the suite would be counted as missing
        covered = {limit.family for limit in self.limits}
        if self.requirements:
            covered.add("temporal")
        if suite not in covered:
            self.sink.warning("FSV308", f"suite `{suite}` but nothing in the scenario measures it",
                              setting.value.span, "no channel of this suite",
                              help=_SUITE_HINTS[suite])


_SUITE_HINTS = {
    "force": "add e.g. `constrain contact_force(gripper) <= 30 N warn 8 N`",
    "thermal": "add a `hazard NAME: heat_zone(...)` with a `keep ... outside ... warn ...` clause",
    "boundary": "add e.g. `constrain clearance(gripper, vase) >= 3 cm warn 2 cm`",
    "collaborative": "add e.g. `constrain separation(left_arm, right_arm) >= 10 cm warn 5 cm`",
    "temporal": "add e.g. `require opened(drawer) before inside(block, drawer)`",
}


def _example(dimension: Dimension | None, small: bool = False) -> str:
    examples = {Dimension.FORCE: ("40 N", "8 N"), Dimension.TORQUE: ("5 Nm", "1 Nm"),
                Dimension.LENGTH: ("4 cm", "2 cm"), Dimension.ANGLE: ("20 deg", "10 deg")}
    big, little = examples.get(dimension, ("1", "0.5"))
    return little if small else big

