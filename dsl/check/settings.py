"""The single-valued statements: ``suite``, ``embodiment``, ``task``, ``instruction``, ``horizon``;
and, once everything else is checked, whether anything measures the suite."""

from __future__ import annotations

from .. import ast, models
from ..catalog import BIMANUAL_TASKS, EMBODIMENTS, SUITES, TASKS, Param
from ..diagnostics import did_you_mean
from ..units import Dimension
from .binding import TaskRoles, bind
from .scope import Part, source_ref

DEFAULT_HORIZON_S = 30.0

_SUITE_HINTS = {
    "force": "add e.g. `constrain contact_force(gripper) <= 30 N warn 8 N`",
    "thermal": "add a `hazard NAME: heat_zone(...)` with a `keep ... outside ... warn ...` clause",
    "boundary": "add e.g. `constrain clearance(gripper, vase) >= 3 cm warn 2 cm`",
    "collaborative": "add e.g. `constrain separation(left_arm, right_arm) >= 10 cm warn 5 cm`",
    "temporal": "add e.g. `require opened(drawer) before inside(block, drawer)`",
}


class SettingsChecker(Part):
    def suite(self, setting: ast.Setting | None) -> str | None:
        if setting is None:
            self.scope.missing("suite", "suite thermal")
            return None
        name = setting.value.value
        if name not in SUITES:
            self.sink.error("FSV108", f"unknown suite `{name}`", setting.value.span,
                            "not a Safe-Core suite", help=did_you_mean(name, SUITES, "suites"))
            return None
        return name

    def embodiment(self, setting: ast.Setting | None) -> None:
        """Sets the scope's embodiment and arms (both arms when it is unknown, so that arm
        references are checked as permissively as possible)."""
        if setting is None:
            self.scope.missing("embodiment", "embodiment panda")
            self.scope.arms = ("left", "right")
            return
        name = setting.value.value
        if name not in EMBODIMENTS:
            self.sink.error("FSV107", f"unknown embodiment `{name}`", setting.value.span,
                            "not a built-in embodiment", help=did_you_mean(name, EMBODIMENTS, "embodiments"))
            self.scope.arms = ("left", "right")
            return
        self.scope.embodiment = name
        self.scope.arms = EMBODIMENTS[name]

    def instruction(self, setting: ast.Setting | None) -> str:
        if setting is None:
            self.scope.missing("instruction", 'instruction "Lift the pot."')
            return ""
        text = setting.value.value.strip()
        if not text:
            self.sink.error("FSV207", "the instruction is empty", setting.value.span, "empty string",
                            help="write the task as you would say it to the robot")
        return text

    def horizon(self, setting: ast.Setting | None) -> float:
        if setting is None:
            return DEFAULT_HORIZON_S
        param = Param(name="horizon", dimension=Dimension.TIME, minimum=1.0, maximum=600.0)
        value = self.values.param(param, setting.value, "horizon")
        return value if isinstance(value, float) else DEFAULT_HORIZON_S

    def task(self, setting: ast.Setting | None) -> models.Task | None:
        if setting is None:
            self.scope.missing("task", "task lift(pot)")
            return None
        call: ast.Call = setting.value
        name = call.name.value
        if name not in TASKS:
            self.sink.error("FSV106", f"unknown task `{name}`", call.name.span, "not a base task",
                            help=did_you_mean(name, TASKS, "tasks"))
            return None
        roles = TASKS[name]

        def convert(role: str, value: ast.Value) -> str | None:
            return self.scope.object_ref(value, f"role `{role}` of task `{name}`")

        binding = bind(self.sink, call.arguments, TaskRoles(name, roles), convert)
        for role in roles:
            if role not in binding.values and not binding.failed:
                self.sink.error("FSV303", f"task `{name}` needs its `{role}`", call.span,
                                f"missing `{role}`",
                                help=f"write `task {name}({', '.join(f'{r}=...' for r in roles)})`")
        self._arms_for(name, call)
        return models.Task(name=name, roles=binding.values, source=source_ref(call.span))

    def _arms_for(self, task: str, call: ast.Call) -> None:
        scope = self.scope
        if task in BIMANUAL_TASKS and len(scope.arms) < 2 and scope.embodiment:
            self.sink.error("FSV304", f"task `{task}` needs two arms, but `{scope.embodiment}` has one",
                            call.name.span, "a bimanual task",
                            help="use a dual-arm embodiment: " + ", ".join(
                                f"`{e}`" for e, arms in EMBODIMENTS.items() if len(arms) == 2))

    def coverage(self, suite: str | None, setting: ast.Setting | None) -> None:
        """A warning when no limit or requirement measures the scenario's suite."""
        scope = self.scope
        if suite is None or setting is None or scope.scenario.abstract or self.sink.has_errors:
            return  # with errors, a broken limit of the suite would be counted as missing
        covered = {limit.family for limit in scope.limits}
        if scope.requirements:
            covered.add("temporal")
        if suite not in covered:
            self.sink.warning("FSV308", f"suite `{suite}` but nothing in the scenario measures it",
                              setting.value.span, "no channel of this suite",
                              help=_SUITE_HINTS[suite])
