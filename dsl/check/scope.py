"""What every part checker shares: the sink, the value checks, and the names declared so far.

A :class:`Scope` is filled in file order (settings, then objects and hazards, then
limits and requirements) and read by the later parts to resolve references, with a
suggestion for a misspelt name and no second error for a name whose declaration already
failed on its own.
"""

from __future__ import annotations

from collections.abc import Callable

from .. import ast, models
from ..catalog import AssetKind, Signature, robot_parts
from ..diagnostics import DiagnosticSink, did_you_mean
from ..merge import Merged
from ..spans import Span
from ..values import ValueChecker

PathResolver = Callable[[ast.String], "str | None"]
ROBOT_PART_WORDS = ("left_arm", "right_arm", "left_gripper", "right_gripper", "arm")


def source_ref(span: Span) -> models.SourceRef:
    return models.SourceRef(file=span.file, line=span.line, column=span.column)


class Scope:
    """The scenario being checked, where its problems go, and what it has declared."""

    def __init__(self, scenario: ast.ScenarioDecl, merged: Merged, sink: DiagnosticSink,
                 resolve_path: PathResolver):
        self.scenario = scenario
        self.merged = merged
        self.sink = sink
        self.values = ValueChecker(sink)
        self.resolve_path = resolve_path
        self.arms: tuple[str, ...] = ("arm",)
        self.embodiment = ""
        self.objects: dict[str, models.ObjectSpec] = {}
        self.object_kinds: dict[str, AssetKind] = {}
        self.zones: dict[str, models.ZoneSpec] = {}
        self.limits: list[models.LimitSpec] = []
        self.requirements: list[models.Requirement] = []

    def missing(self, what: str, example: str) -> None:
        """A statement the (concrete) scenario must have and does not."""
        if not self.scenario.abstract:
            self.sink.error("FSV301", f"missing `{what}`", self.scenario.name.span,
                            f"this scenario has no `{what}` statement",
                            help=f"add a line such as `{example}` (or inherit one with `extends`)")

    # ------------------------------------------------------------ names
    def robot_parts(self) -> dict[str, str]:
        return robot_parts(self.arms)

    def entity_names(self) -> list[str]:
        return list(self.objects) + list(self.zones) + list(self.robot_parts())

    def failed_declaration(self, name: str) -> bool:
        """An object or hazard that is declared but was dropped for errors of its own."""
        decl = self.merged.declarations.get(name)
        return (isinstance(decl, (ast.ObjectDecl, ast.HazardDecl))
                and name not in self.objects and name not in self.zones)

    def entity(self, name: str, span: Span, what: str, allow_zone: bool = True) -> str | None:
        """``name`` as an object, a part of the robot or (``allow_zone``) a zone."""
        if name in self.objects or name in self.robot_parts() or (allow_zone and name in self.zones):
            return name
        if self.failed_declaration(name):
            return None  # declared, but it has errors of its own that are already reported
        if name in self.zones:
            self.sink.error("FSV111", f"`{name}` is a zone, not a body, so {what} cannot be it", span,
                            "a zone", help="name an object or a part of the robot")
            return None
        if name in ROBOT_PART_WORDS and self.embodiment:
            self.sink.error("FSV112", f"`{self.embodiment}` has no `{name}`", span,
                            "not a part of this robot",
                            help=did_you_mean(name, self.robot_parts(), "robot parts"))
            return None
        self.sink.error("FSV101", f"unknown name `{name}`", span, f"not declared ({what})",
                        help=did_you_mean(name, self.entity_names(), "names"))
        return None

    def object_ref(self, value: ast.Value, what: str) -> str | None:
        """``value`` as the name of a declared object."""
        if not isinstance(value, ast.Ref):
            self.sink.error("FSV207", f"{what} must name an object", value.span, "expected a name")
            return None
        if value.name in self.objects:
            return value.name
        if self.failed_declaration(value.name):
            return None  # declared, but it has errors of its own that are already reported
        if value.name in self.zones or value.name in self.robot_parts():
            self.sink.error("FSV111", f"{what} must be an object, and `{value.name}` is "
                            f"{'a zone' if value.name in self.zones else 'part of the robot'}",
                            value.span, "not an object")
            return None
        self.sink.error("FSV101", f"unknown object `{value.name}`", value.span, f"not declared ({what})",
                        help=did_you_mean(value.name, self.objects, "objects"))
        return None

    def arg_entity(self, argument: ast.Argument, signature: Signature, object_only: bool = False,
                   allow_zone: bool = True) -> str | None:
        """A name given to a measure, predicate or vision setting."""
        value = argument.value
        if not isinstance(value, ast.Ref):
            self.sink.error("FSV207", f"`{signature.name}` takes names", value.span, "expected a name")
            return None
        if object_only:
            return self.object_ref(value, f"the argument of `{signature.name}`")
        return self.entity(value.name, value.span, f"an argument of `{signature.name}`", allow_zone)


class Part:
    """One checker of one part of a file; every part reads and fills the same :class:`Scope`."""

    def __init__(self, scope: Scope):
        self.scope = scope
        self.sink = scope.sink
        self.values = scope.values
