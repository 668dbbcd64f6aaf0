"""Semantic checks: merged statements to a validated :class:`~fsvla.dsl.models.Scenario`.

One checker per part of a file, in the order a file is read (``settings``, ``objects``,
``hazards`` and ``placement``, ``constraints``, ``requirements``, ``variants``,
``overrides`` for the language and vision blocks), sharing one :class:`Scope`; task roles
and asset parameters are bound by one binder (``binding``). Every check reports to a
:class:`DiagnosticSink` and goes on, so one run lists every problem of a file. The IR is
built only when no error was found.
"""

from __future__ import annotations

from pydantic import ValidationError

from .. import ast, models
from ..diagnostics import DiagnosticSink
from ..merge import Merged
from .constraints import ConstraintChecker
from .hazards import HazardChecker
from .objects import ObjectChecker
from .overrides import LanguageChecker, VisionChecker
from .placement import PlacementChecker
from .requirements import RequirementChecker
from .scope import PathResolver, Scope, source_ref
from .settings import SettingsChecker
from .variants import VariantChecker


class ScenarioChecker:
    def __init__(self, scenario: ast.ScenarioDecl, merged: Merged, sink: DiagnosticSink,
                 resolve_path: PathResolver, lineage: tuple[str, ...], digest: str):
        self.scope = Scope(scenario, merged, sink, resolve_path)
        self.lineage = lineage
        self.digest = digest

    def check(self) -> models.Scenario | None:
        scope = self.scope
        settings = scope.merged.settings
        header = SettingsChecker(scope)
        suite = header.suite(settings.get("suite"))
        header.embodiment(settings.get("embodiment"))
        requirements = RequirementChecker(scope)
        self._declarations(requirements)
        task = header.task(settings.get("task"))
        instruction = header.instruction(settings.get("instruction"))
        horizon = header.horizon(settings.get("horizon"))
        success = requirements.success(scope.merged.success)
        variants = VariantChecker(scope).variants()
        language = LanguageChecker(scope).language()
        vision = VisionChecker(scope).vision()
        header.coverage(suite, settings.get("suite"))
        if scope.sink.has_errors or scope.scenario.abstract:
            return None
        try:
            return models.Scenario(
                name=scope.scenario.name.value, suite=suite, task=task, embodiment=scope.embodiment,
                arms=scope.arms, instruction=instruction, horizon=horizon,
                objects=tuple(scope.objects.values()), zones=tuple(scope.zones.values()),
                limits=tuple(scope.limits), requirements=tuple(scope.requirements), success=success,
                variants=variants, language=language, vision=vision,
                source=source_ref(scope.scenario.name.span), lineage=self.lineage, source_digest=self.digest)
        except ValidationError as error:  # a bug in the checker: every field was validated above
            for problem in error.errors():
                scope.sink.error("FSV999", f"internal error: {problem['msg']} at {problem['loc']}",
                                 scope.scenario.name.span,
                                 help="please report this with the scenario file attached")
            return None

    def _declarations(self, requirements: RequirementChecker) -> None:
        """Objects and hazards (placed together, the table first), then their keep-out limits,
        then ``constrain``/``watch``/``require`` in the order they were declared."""
        scope = self.scope
        decls = scope.merged.declarations
        objects = sorted((d for d in decls.values() if isinstance(d, ast.ObjectDecl)),
                         key=lambda d: d.name.value != "table")  # the IR lists the table first
        hazards = [d for d in decls.values() if isinstance(d, ast.HazardDecl)]
        object_checker, hazard_checker = ObjectChecker(scope), HazardChecker(scope)
        object_checker.default_table()
        object_checker.robot_names([*objects, *hazards])
        declared = [object_checker.declare(d) for d in objects]
        declared += [hazard_checker.declare(d, object_checker) for d in hazards]
        declared = [d for d in declared if d is not None]
        object_checker.register(declared, PlacementChecker(scope).placements(declared))
        for decl in hazards:
            if decl.name.value in scope.zones or decl.name.value in scope.objects:
                hazard_checker.keeps(decl)
        constraints = ConstraintChecker(scope)
        for name, decl in decls.items():
            if isinstance(decl, ast.LimitDecl):
                constraints.limit(name, decl)
            elif isinstance(decl, ast.RequireDecl):
                requirements.requirement(name, decl)


__all__ = ["ScenarioChecker", "Scope"]
