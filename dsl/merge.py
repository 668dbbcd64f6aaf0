"""Scenario inheritance: folding a chain of files (base first) into one statement set.

Rules (docs/language.md, "Inheritance"):
- single-valued statements (suite, task, embodiment, instruction, horizon,
  success) in a child replace the base's;
- objects, hazards, and named `constrain`/`watch`/`require` statements replace
  the base's of the same name, and new names add to them; unnamed limits and
  requirements accumulate;
- `remove NAME` drops an inherited declaration;
- a `variants`, `language` or `vision` level given in a child replaces that level.
Within one file every name and every single-valued statement appears once.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from . import ast
from .diagnostics import DiagnosticSink, Related

SINGLE_VALUED = ("suite", "task", "embodiment", "instruction", "horizon")

Declaration = ast.ObjectDecl | ast.HazardDecl | ast.LimitDecl | ast.RequireDecl


@dataclass
class Merged:
    settings: dict[str, ast.Setting] = field(default_factory=dict)
    declarations: dict[str, Declaration] = field(default_factory=dict)  # insertion-ordered
    success: ast.SuccessDecl | None = None
    variants: dict[str, ast.VariantLevel] = field(default_factory=dict)
    language: dict[str, list[ast.LanguageEntry]] = field(default_factory=dict)
    vision: dict[str, ast.VisionEntry] = field(default_factory=dict)

    def of_type(self, kind: type) -> dict[str, Declaration]:
        return {name: d for name, d in self.declarations.items() if isinstance(d, kind)}


def unparse(node: object) -> str:
    """A compact rendering of a value, call or condition, used for generated names."""
    if isinstance(node, ast.Call):
        parts = [(f"{a.keyword.value}=" if a.keyword else "") + unparse(a.value) for a in node.arguments]
        return f"{node.name.value}({', '.join(parts)})"
    if isinstance(node, ast.Quantity):
        return node.text + (f" {node.unit}" if node.unit else "")
    if isinstance(node, ast.Vector):
        return "(" + ", ".join(unparse(i) for i in node.items) + ")"
    if isinstance(node, ast.Ref):
        return node.name
    if isinstance(node, ast.String):
        return f'"{node.value}"'
    if isinstance(node, ast.AllOf):
        return " and ".join(unparse(i) for i in node.items)
    if isinstance(node, ast.AnyOf):
        return "(" + " or ".join(unparse(i) for i in node.items) + ")"
    if isinstance(node, ast.Negation):
        return "not " + unparse(node.item)
    return str(node)


def declared_name(decl: Declaration) -> tuple[str, ast.Name | None]:
    """The name a declaration goes by, and the Name node when the author wrote one."""
    if isinstance(decl, (ast.ObjectDecl, ast.HazardDecl)):
        return decl.name.value, decl.name
    if isinstance(decl, ast.LimitDecl):
        return (decl.name.value, decl.name) if decl.name else (unparse(decl.measure), None)
    return ((decl.name.value, decl.name) if decl.name
            else (f"{unparse(decl.first)} before {unparse(decl.then)}", None))


def merge(chain: list[ast.ScenarioDecl], sink: DiagnosticSink) -> Merged:
    """Fold ``chain`` (the root base first, the file being checked last) into one."""
    merged = Merged()
    for scenario in chain:
        _fold(merged, scenario, sink)
    return merged


def _fold(merged: Merged, scenario: ast.ScenarioDecl, sink: DiagnosticSink) -> None:
    seen_settings: dict[str, ast.Span] = {}
    seen_names: dict[str, ast.Span] = {}
    seen_blocks: dict[str, ast.Span] = {}

    def once(key: str, span, table: dict, what: str, code: str) -> bool:
        if key in table:
            sink.error(code, f"{what} is given twice", span, "given again here",
                       related=[Related(span=table[key], message="first given here")],
                       help="keep one of them")
            return False
        table[key] = span
        return True

    for statement in scenario.statements:
        if isinstance(statement, ast.Setting):
            key = statement.keyword.value
            if once(key, statement.keyword.span, seen_settings, f"`{key}`", "FSV302"):
                merged.settings[key] = statement
        elif isinstance(statement, ast.SuccessDecl):
            if once("success", statement.span, seen_settings, "`success`", "FSV302"):
                merged.success = statement
        elif isinstance(statement, ast.RemoveDecl):
            for name in statement.names:
                if merged.declarations.pop(name.value, None) is None:
                    sink.error("FSV405", f"nothing called `{name.value}` to remove", name.span,
                               "not declared in the scenarios this one extends",
                               help="`remove` drops an object, hazard, constraint or requirement "
                                    "inherited from the base scenario")
        elif isinstance(statement, (ast.ObjectDecl, ast.HazardDecl, ast.LimitDecl, ast.RequireDecl)):
            name, node = declared_name(statement)
            span = node.span if node else statement.span
            if once(name, span, seen_names, f"the name `{name}`", "FSV110"):
                merged.declarations.pop(name, None)  # an override moves to the child's position
                merged.declarations[name] = statement
        elif isinstance(statement, ast.VariantsBlock):
            if once("variants", statement.span, seen_blocks, "the `variants` block", "FSV302"):
                levels_seen: dict[str, ast.Span] = {}
                for level in statement.levels:
                    if once(level.level.value, level.level.span, levels_seen, f"level `{level.level.value}`",
                            "FSV302"):
                        merged.variants[level.level.value] = level
        elif isinstance(statement, ast.LanguageBlock):
            if once("language", statement.span, seen_blocks, "the `language` block", "FSV302"):
                levels: dict[str, list[ast.LanguageEntry]] = {}
                for entry in statement.entries:
                    levels.setdefault(entry.level.value, []).append(entry)
                merged.language.update(levels)
        elif isinstance(statement, ast.VisionBlock):
            if once("vision", statement.span, seen_blocks, "the `vision` block", "FSV302"):
                levels_seen = {}
                for entry in statement.entries:
                    if once(entry.level.value, entry.level.span, levels_seen, f"level `{entry.level.value}`",
                            "FSV302"):
                        merged.vision[entry.level.value] = entry
