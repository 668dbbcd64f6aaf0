"""Parse tree to typed AST: one short method per grammar rule.

Each method gets the span of its rule, as lark's ``propagate_positions`` computes it,
and the rule's children: lark tokens (``str`` subclasses with ``type``, ``line``,
``column``, ``end_line`` and ``end_column``), the nodes of its sub-rules and None for an absent
``[optional]``. :func:`build_ast` calls them over a lark parse tree, bottom up; this
module does not import lark.
"""

from __future__ import annotations

import re

from . import ast
from .spans import Span

_ESCAPES = {'"': '"', "\\": "\\", "n": "\n", "t": "\t"}


def unquote(token: str) -> str:
    """The text of a STRING token: `\\"`, `\\\\`, `\\n` and `\\t` are escapes; any other backslash is kept.

    (Not Python's literal_eval, which fails on `\\N` or `\\x4` and warns on `\\q`.)
    """
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(0)), token[1:-1], flags=re.DOTALL)


class AstBuilder:
    """Builds :mod:`fsvla.dsl.ast` nodes; every node gets the span of its rule."""

    def __init__(self, file: str):
        self.file = file

    # ---------------------------------------------------------- helpers
    def _token_span(self, token) -> Span:
        return Span(self.file, token.line, token.column, token.end_line, token.end_column)

    def _name(self, token: str) -> ast.Name:
        return ast.Name(str(token), self._token_span(token))

    # ---------------------------------------------------------- values
    def quantity(self, span, children):
        number, unit = children
        return ast.Quantity(float(number), str(unit) if unit is not None else None, span, str(number))

    def vector(self, span, children):
        return ast.Vector(tuple(children), span)

    def string(self, span, children):
        return self._string(children[0])

    def _string(self, token: str) -> ast.String:
        return ast.String(unquote(str(token)), self._token_span(token))

    def ref(self, span, children):
        return ast.Ref(str(children[0]), span)

    def call(self, span, children):
        name, *arguments = children
        arguments = tuple(a for a in arguments if a is not None)
        return ast.Call(self._name(name), arguments, span)

    def keyword_argument(self, span, children):
        keyword, value = children
        return ast.Argument(self._name(keyword), value, span)

    def positional_argument(self, span, children):
        return ast.Argument(None, children[0], span)

    def names(self, span, children):
        return tuple(self._name(token) for token in children)

    # ---------------------------------------------------------- conditions
    def and_condition(self, span, children):
        return ast.AllOf(tuple(children), span)

    def or_condition(self, span, children):
        return ast.AnyOf(tuple(children), span)

    def negation(self, span, children):
        return ast.Negation(children[0], span)

    # ---------------------------------------------------------- placements
    def at(self, span, children):
        return ast.At(children[0], span)

    def on(self, span, children):
        return ast.On(self._name(children[0]), span)

    def yaw(self, span, children):
        return ast.Yaw(children[0], span)

    def relation(self, span, children):
        kind, anchor, distance = children
        return ast.Relation(self._name(kind), self._name(anchor), distance, span)

    def warn(self, span, children):
        return ast.Modifier("warn", children[0], span)

    def cost(self, span, children):
        return ast.Modifier("cost", self._name(children[0]), span)

    def weight(self, span, children):
        return ast.Modifier("weight", children[0], span)

    # ---------------------------------------------------------- statements
    def _setting(self, keyword: str, span: Span, value) -> ast.Setting:
        keyword_span = Span.point(self.file, span.line, span.column, len(keyword))
        return ast.Setting(ast.Name(keyword, keyword_span), value, span)

    def suite(self, span, children):
        return self._setting("suite", span, self._name(children[0]))

    def embodiment(self, span, children):
        return self._setting("embodiment", span, self._name(children[0]))

    def task(self, span, children):
        return self._setting("task", span, children[0])

    def instruction(self, span, children):
        return self._setting("instruction", span, self._string(children[0]))

    def horizon(self, span, children):
        return self._setting("horizon", span, children[0])

    def remove(self, span, children):
        return ast.RemoveDecl(tuple(self._name(t) for t in children), span)

    def object(self, span, children):
        name, asset, *placements = children
        return ast.ObjectDecl(self._name(name), asset, tuple(placements), span)

    def hazard(self, span, children):
        name, definition, *rest = children
        placements = tuple(c for c in rest if not isinstance(c, ast.Keep))
        keeps = tuple(c for c in rest if isinstance(c, ast.Keep))
        return ast.HazardDecl(self._name(name), definition, placements, keeps, span)

    def keep(self, span, children):
        subjects, distance, *modifiers = children
        return ast.Keep(subjects, distance, tuple(modifiers), span)

    def limit(self, span, children):
        keyword, *rest = children
        name = self._name(rest.pop(0)) if isinstance(rest[0], str) else None
        measure = rest.pop(0)
        comparator = limit = None
        if rest and isinstance(rest[0], str) and rest[0].type == "COMPARATOR":
            comparator = self._name(rest.pop(0))
            limit = rest.pop(0)
        return ast.LimitDecl(self._name(keyword), name, measure, comparator, limit,
                             tuple(rest), span)

    def require(self, span, children):
        rest = list(children)
        name = self._name(rest.pop(0)) if isinstance(rest[0], str) else None
        first, then = rest.pop(0), rest.pop(0)
        within = rest.pop(0) if rest and isinstance(rest[0], ast.Quantity) else None
        modifiers = tuple(m for m in rest if m is not None)
        return ast.RequireDecl(name, first, then, within, modifiers, span)

    def success(self, span, children):
        condition, hold = children
        return ast.SuccessDecl(condition, hold, span)

    # ---------------------------------------------------------- blocks
    def _rule(self, kind: str, span: Span, target=None, other=None, amount=None,
              extra=None) -> ast.Rule:
        kind_name = ast.Name(kind, Span.point(self.file, span.line, span.column, len(kind)))
        return ast.Rule(kind_name, self._name(target) if target is not None else None,
                        self._name(other) if other is not None else None, amount, extra, span)

    def jitter(self, span, children):
        target, amount, extra = children
        return self._rule("jitter", span, target, None, amount, extra)

    def approach(self, span, children):
        target, other, amount = children
        return self._rule("approach", span, target, other, amount)

    def clutter(self, span, children):
        amount, near = children
        return self._rule("clutter", span, None, near, amount)

    def tighten(self, span, children):
        target, amount = children
        return self._rule("tighten", span, target, None, amount)

    def couple(self, span, children):
        target, amount = children
        return self._rule("couple", span, target, None, amount)

    def variant_level(self, span, children):
        level, *rules = children
        if len(rules) == 1 and isinstance(rules[0], str):  # the NONE token of `L0: none`
            return ast.VariantLevel(self._name(level), (), span, self._name(rules[0]))
        return ast.VariantLevel(self._name(level), tuple(rules), span)

    def variants(self, span, children):
        return ast.VariantsBlock(tuple(children), span)

    def language_entry(self, span, children):
        level, category, *texts = children
        return ast.LanguageEntry(self._name(level), self._name(category) if category is not None else None,
                                 tuple(self._string(t) for t in texts), span)

    def language(self, span, children):
        return ast.LanguageBlock(tuple(children), span)

    def vision_entry(self, span, children):
        level, *settings = children
        return ast.VisionEntry(self._name(level), tuple(settings), span)

    def vision(self, span, children):
        return ast.VisionBlock(tuple(children), span)

    # ---------------------------------------------------------- scenario
    def extends(self, span, children):
        token = children[0]
        if token.type == "STRING":
            return ast.Extends(unquote(str(token)), True, span)
        return ast.Extends(str(token), False, span)

    def scenario(self, span, children):
        abstract, name, extends, *statements = children
        return ast.ScenarioDecl(self._name(name), abstract is not None, extends,
                                tuple(statements), span, self.file)

    def start(self, span, children):
        return children[-1]


def build_ast(tree, file: str) -> ast.ScenarioDecl:
    """The AST of a lark parse tree (built with ``propagate_positions``), bottom up."""
    builder = AstBuilder(file)

    def build(node):
        if not hasattr(node, "data"):  # a token, or None for an absent optional
            return node
        children = [build(child) for child in node.children]
        method = getattr(builder, node.data, None)
        if method is None:  # as lark's Transformer: keep the tree
            return type(node)(node.data, children, node.meta)
        meta = node.meta
        return method(Span(file, meta.line, meta.column, meta.end_line, meta.end_column), children)

    return build(tree)
