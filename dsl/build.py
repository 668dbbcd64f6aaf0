"""Parse tree to typed AST: one short method per grammar rule."""

from __future__ import annotations

import re

from lark import Token, Transformer, Tree, v_args

from . import ast
from .spans import Span

_ESCAPES = {'"': '"', "\\": "\\", "n": "\n", "t": "\t"}


def unquote(token: str) -> str:
    """The text of a STRING token: `\\"`, `\\\\`, `\\n` and `\\t` are escapes; any other backslash is kept.

    (Not Python's literal_eval, which fails on `\\N` or `\\x4` and warns on `\\q`.)
    """
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(0)), token[1:-1], flags=re.DOTALL)


@v_args(meta=True)
class AstBuilder(Transformer):
    """Builds :mod:`fsvla.dsl.ast` nodes; every node gets the span of its rule."""

    def __init__(self, file: str):
        super().__init__()
        self.file = file

    # ---------------------------------------------------------- helpers
    def _span(self, meta) -> Span:
        return Span(file=self.file, line=meta.line, column=meta.column,
                    end_line=meta.end_line, end_column=meta.end_column)

    def _name(self, token: Token) -> ast.Name:
        return ast.Name(str(token), Span.of(self.file, token))

    # ---------------------------------------------------------- values
    def quantity(self, meta, children):
        number, unit = children
        return ast.Quantity(float(number), str(unit) if unit is not None else None,
                            self._span(meta), str(number))

    def vector(self, meta, children):
        return ast.Vector(tuple(children), self._span(meta))

    def string(self, meta, children):
        return self._string(children[0])

    def _string(self, token: Token) -> ast.String:
        return ast.String(unquote(str(token)), Span.of(self.file, token))

    def ref(self, meta, children):
        return ast.Ref(str(children[0]), self._span(meta))

    def call(self, meta, children):
        name, *arguments = children
        arguments = tuple(a for a in arguments if a is not None)
        return ast.Call(self._name(name), arguments, self._span(meta))

    def keyword_argument(self, meta, children):
        keyword, value = children
        return ast.Argument(self._name(keyword), value, self._span(meta))

    def positional_argument(self, meta, children):
        return ast.Argument(None, children[0], self._span(meta))

    def names(self, meta, children):
        return tuple(self._name(token) for token in children)

    # ---------------------------------------------------------- conditions
    def and_condition(self, meta, children):
        return ast.AllOf(tuple(children), self._span(meta))

    def or_condition(self, meta, children):
        return ast.AnyOf(tuple(children), self._span(meta))

    def negation(self, meta, children):
        return ast.Negation(children[0], self._span(meta))

    # ---------------------------------------------------------- placements
    def at(self, meta, children):
        return ast.At(children[0], self._span(meta))

    def on(self, meta, children):
        return ast.On(self._name(children[0]), self._span(meta))

    def yaw(self, meta, children):
        return ast.Yaw(children[0], self._span(meta))

    def relation(self, meta, children):
        kind, anchor, distance = children
        return ast.Relation(self._name(kind), self._name(anchor), distance, self._span(meta))

    def warn(self, meta, children):
        return ast.Modifier("warn", children[0], self._span(meta))

    def cost(self, meta, children):
        return ast.Modifier("cost", self._name(children[0]), self._span(meta))

    def weight(self, meta, children):
        return ast.Modifier("weight", children[0], self._span(meta))

    # ---------------------------------------------------------- statements
    def _setting(self, keyword: str, meta, value) -> ast.Setting:
        span = self._span(meta)
        keyword_span = Span.point(self.file, span.line, span.column, len(keyword))
        return ast.Setting(ast.Name(keyword, keyword_span), value, span)

    def suite(self, meta, children):
        return self._setting("suite", meta, self._name(children[0]))

    def embodiment(self, meta, children):
        return self._setting("embodiment", meta, self._name(children[0]))

    def task(self, meta, children):
        return self._setting("task", meta, children[0])

    def instruction(self, meta, children):
        return self._setting("instruction", meta, self._string(children[0]))

    def horizon(self, meta, children):
        return self._setting("horizon", meta, children[0])

    def remove(self, meta, children):
        return ast.RemoveDecl(tuple(self._name(t) for t in children), self._span(meta))

    def object(self, meta, children):
        name, asset, *placements = children
        return ast.ObjectDecl(self._name(name), asset, tuple(placements), self._span(meta))

    def hazard(self, meta, children):
        name, definition, *rest = children
        placements = tuple(c for c in rest if not isinstance(c, ast.Keep))
        keeps = tuple(c for c in rest if isinstance(c, ast.Keep))
        return ast.HazardDecl(self._name(name), definition, placements, keeps, self._span(meta))

    def keep(self, meta, children):
        subjects, distance, *modifiers = children
        return ast.Keep(subjects, distance, tuple(modifiers), self._span(meta))

    def limit(self, meta, children):
        keyword, *rest = children
        name = self._name(rest.pop(0)) if isinstance(rest[0], Token) else None
        measure = rest.pop(0)
        comparator = limit = None
        if rest and isinstance(rest[0], Token) and rest[0].type == "COMPARATOR":
            comparator = self._name(rest.pop(0))
            limit = rest.pop(0)
        return ast.LimitDecl(self._name(keyword), name, measure, comparator, limit,
                             tuple(rest), self._span(meta))

    def require(self, meta, children):
        rest = list(children)
        name = self._name(rest.pop(0)) if isinstance(rest[0], Token) else None
        first, then = rest.pop(0), rest.pop(0)
        within = rest.pop(0) if rest and isinstance(rest[0], ast.Quantity) else None
        modifiers = tuple(m for m in rest if m is not None)
        return ast.RequireDecl(name, first, then, within, modifiers, self._span(meta))

    def success(self, meta, children):
        condition, hold = children
        return ast.SuccessDecl(condition, hold, self._span(meta))

    # ---------------------------------------------------------- blocks
    def _rule(self, kind: str, meta, target=None, other=None, amount=None, extra=None) -> ast.Rule:
        span = self._span(meta)
        kind_name = ast.Name(kind, Span.point(self.file, span.line, span.column, len(kind)))
        return ast.Rule(kind_name, self._name(target) if target is not None else None,
                        self._name(other) if other is not None else None, amount, extra, span)

    def jitter(self, meta, children):
        target, amount, extra = children
        return self._rule("jitter", meta, target, None, amount, extra)

    def approach(self, meta, children):
        target, other, amount = children
        return self._rule("approach", meta, target, other, amount)

    def clutter(self, meta, children):
        amount, near = children
        return self._rule("clutter", meta, None, near, amount)

    def tighten(self, meta, children):
        target, amount = children
        return self._rule("tighten", meta, target, None, amount)

    def couple(self, meta, children):
        target, amount = children
        return self._rule("couple", meta, target, None, amount)

    def variant_level(self, meta, children):
        level, *rules = children
        return ast.VariantLevel(self._name(level), tuple(rules), self._span(meta))

    def variants(self, meta, children):
        return ast.VariantsBlock(tuple(children), self._span(meta))

    def language_entry(self, meta, children):
        level, category, *texts = children
        return ast.LanguageEntry(self._name(level), self._name(category) if category is not None else None,
                                 tuple(self._string(t) for t in texts), self._span(meta))

    def language(self, meta, children):
        return ast.LanguageBlock(tuple(children), self._span(meta))

    def vision_entry(self, meta, children):
        level, *settings = children
        return ast.VisionEntry(self._name(level), tuple(settings), self._span(meta))

    def vision(self, meta, children):
        return ast.VisionBlock(tuple(children), self._span(meta))

    # ---------------------------------------------------------- scenario
    def extends(self, meta, children):
        token = children[0]
        if token.type == "STRING":
            return ast.Extends(unquote(str(token)), True, self._span(meta))
        return ast.Extends(str(token), False, self._span(meta))

    def scenario(self, meta, children):
        abstract, name, extends, *statements = children
        return ast.ScenarioDecl(self._name(name), abstract is not None, extends,
                                tuple(statements), self._span(meta), self.file)

    def start(self, meta, children):
        return children[-1]


def build_ast(tree: Tree, file: str) -> ast.ScenarioDecl:
    return AstBuilder(file).transform(tree)
