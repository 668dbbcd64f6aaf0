"""The fast path of the parser: text to AST in one pass, for a file without syntax errors.

lark's own parse (:mod:`fsvla.dsl.parser`) passes each token through several layers
of generic callbacks into a parse tree, which :func:`fsvla.dsl.build.build_ast` then
walks again. Here one loop lexes, parses and calls :class:`~fsvla.dsl.build.AstBuilder`
directly, driven by lark's own tables for this grammar: the LALR actions, each parser
state's contextual scanner and each rule's child filter. So it accepts exactly the
files lark accepts and gives every node the span that lark's ``propagate_positions``
gives it. It reports nothing: at the first syntax error it raises :class:`Unparsed`
and the caller parses the file again with lark, which diagnoses and recovers.

The tables come from :mod:`fsvla.dsl.lalr_tables`, which caches them, so checking
well-formed files never imports lark.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
from collections.abc import Iterator
from functools import lru_cache
from importlib.util import find_spec
from operator import itemgetter
from pathlib import Path

from ..resources import grammar_path
from . import ast
from .build import AstBuilder
from .spans import Span

FORMAT = 1  # of the table data
# How a reduction builds its value (lark's ParseTreeBuilder, with maybe_placeholders):
INLINE = 0  # a `_rule`: its children, spliced into the parent's
PASS = 1  # a `?rule` alternative with one child: the child itself, position unchanged
EXPAND_SINGLE = 2  # a `?rule` alternative: the child when there is one, else a node
BUILD = 3  # a node, from AstBuilder
_IGNORE, _NEWLINE, _KEYWORD = 1, 2, 4  # what a lexer does with a terminal it matched


class Unparsed(Exception):
    """The text has a syntax error (or an indentation fault): parse it with lark to say which."""


class Lexeme(str):
    """A token the AST keeps: its text, with the attributes of a lark Token that AstBuilder reads."""

    __slots__ = ("type", "line", "column", "end_line", "end_column")


class _Lexer:
    """One parser state's scanner: lark's terminals for that state, in lark's order.

    Where the spec has a ``blank`` prefix (see :mod:`fsvla.dsl.lalr_tables`), each match
    first skips the run of ignored blanks before a token, which lark matches as a token
    of its own: the same tokens, in half the matches. Where that finds nothing (an error),
    the scanner without the prefix decides.
    """

    __slots__ = ("patterns", "first", "kinds", "keywords", "_spec", "_plain")

    def __init__(self, spec: dict):
        prefix = spec.get("blank") or ""
        self.patterns = tuple(re.compile(f"{prefix}(?:{p})" if prefix else p, spec["flags"])
                              for p in spec["patterns"])
        self.first = self.patterns[0].match  # lark splits a scanner past 100 terminals
        self.keywords = spec["keywords"]  # NAME -> {"suite": "SUITE", ...}: lark's "unless" callbacks
        self.kinds: dict[str, int] = {}
        for kind in spec["ignore"]:
            self.kinds[kind] = self.kinds.get(kind, 0) | _IGNORE
        for kind in spec["newline"]:
            self.kinds[kind] = self.kinds.get(kind, 0) | _NEWLINE
        for kind in self.keywords:
            self.kinds[kind] = self.kinds.get(kind, 0) | _KEYWORD
        self._spec = spec
        self._plain = None if prefix else self.patterns

    def match_plain(self, text: str, pos: int) -> re.Match | None:
        """lark's own match at ``pos``: the first terminal, in order, that matches there."""
        if self._plain is None:
            self._plain = tuple(re.compile(p, self._spec["flags"]) for p in self._spec["patterns"])
        for pattern in self._plain:
            match = pattern.match(text, pos)
            if match:
                return match
        return None


class Tables:
    """lark's tables for the grammar, ready to drive (see :mod:`fsvla.dsl.lalr_tables`)."""

    def __init__(self, data: dict):
        self.start, self.end = data["start"], data["end"]
        self.actions: list[dict[str, int]] = data["actions"]  # >= 0: shift (goto) state, < 0: ~rule
        self.kept = frozenset(data["kept"])
        self.indenter = data["indenter"]
        self.rules = []
        for origin, size, mode, callback, include, trailing in data["rules"]:
            include = tuple(map(tuple, include))
            method = getattr(AstBuilder, callback) if callback is not None else None
            pick = _picker(include, trailing, mode)
            self.rules.append((origin, size, mode, method, include, trailing, pick))
        self._lexer_specs = data["lexers"]
        self._state_lexer: list[int] = data["state_lexer"]
        self._compiled: dict[int, _Lexer] = {}
        self.lexers: list[_Lexer | None] = [None] * len(self.actions)  # by state

    def lexer(self, state: int) -> _Lexer:
        """The scanner of ``state``, compiled on first use (as lark compiles its own)."""
        index = self._state_lexer[state]
        lexer = self._compiled.get(index)
        if lexer is None:
            lexer = self._compiled[index] = _Lexer(self._lexer_specs[index])
        self.lexers[state] = lexer
        return lexer


def _picker(include: tuple, trailing: int, mode: int):
    """For a rule that only drops children (no None to insert, no `_rule` to splice), a
    getter of the children it keeps, faster than :func:`_filter`; else None."""
    if trailing or any(expand or nones for _, expand, nones in include):
        return None
    indices = [i for i, _, _ in include]
    if indices == list(range(indices[0], indices[-1] + 1)) if indices else True:
        first = indices[0] if indices else 0
        return itemgetter(slice(first, first + len(indices)))  # a list
    return None if mode == INLINE else itemgetter(*indices)  # a tuple: the `_rule` lists extend


@lru_cache(maxsize=1)
def load_tables() -> Tables | None:
    """The tables, once per process, from the cache file or else from lark (then cached);
    None when lark's parser holds something this module does not reproduce."""
    path = cache_path()
    data = _read_cache(path)
    if data is not None:
        try:
            return Tables(data)
        except (KeyError, IndexError, TypeError, ValueError, AttributeError, re.error):
            pass  # a cache file that does not load is replaced
    from .lalr_tables import extract_tables, write_cache

    data = extract_tables()
    if data is None:
        return None
    write_cache(path, data)
    return Tables(data)


def cache_path() -> Path:
    """The cache file, named by a hash of the grammar, lark's version and the two modules
    that write and read the data (and by user: a file someone else wrote is not read)."""
    digest = hashlib.sha256()
    digest.update(str(FORMAT).encode())
    digest.update(grammar_path().read_bytes())
    digest.update(Path(__file__).read_bytes())
    digest.update(Path(__file__).with_name("lalr_tables.py").read_bytes())
    lark = find_spec("lark")
    if lark is not None and lark.origin:
        digest.update(Path(lark.origin).read_bytes())  # lark/__init__.py holds its version
    uid = os.getuid() if hasattr(os, "getuid") else 0
    return Path(tempfile.gettempdir()) / f".fsvla_lalr_{uid}_{digest.hexdigest()[:20]}.json"


def _read_cache(path: Path) -> dict | None:
    try:
        if hasattr(os, "getuid") and path.stat().st_uid != os.getuid():
            return None  # not written by us: do not trust it
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("format") == FORMAT else None


def parse(text: str, file: str) -> ast.ScenarioDecl:
    """The AST of ``text`` (which ends with a newline); raises :class:`Unparsed` on a syntax error."""
    tables = load_tables()
    if tables is None:
        raise Unparsed("no tables")
    builder = AstBuilder(file)
    actions, rules = tables.actions, tables.rules
    states, values, places = [tables.start], [], []  # places: each value's position, or None

    def reduce(rule: tuple) -> None:
        """Filter the rule's children and position its node as lark's tree builder does."""
        origin, size, mode, method, include, trailing, pick = rule
        if size:
            raw, raw_places = values[-size:], places[-size:]
            del values[-size:], places[-size:], states[-size:]
            first, last = raw_places[0], raw_places[-1]
            where = _extent(raw_places) if first is None or last is None else \
                (first[0], first[1], last[2], last[3])
        else:
            raw, where = [], None
        children = pick(raw) if pick is not None else _filter(raw, include, trailing)
        if mode == INLINE:
            value = children
        elif mode == EXPAND_SINGLE and len(children) == 1:
            value = children[0]  # `?rule` with one child: the child, now spanning the whole rule
            if value is None:
                where = None
            elif isinstance(value, str):
                where = (value.line, value.column, value.end_line, value.end_column)
        else:
            value = method(builder, Span(file, *where), children)
        states.append(actions[states[-1]][origin])
        values.append(value)
        places.append(where)

    for kind, token, where in _lex(text, tables, states):
        while True:
            action = actions[states[-1]].get(kind)
            if action is None:
                raise Unparsed(kind)
            if action >= 0:
                states.append(action)
                values.append(token)
                places.append(where)
                break
            rule = rules[~action]
            if rule[2] == PASS:  # the one child keeps its value and place: only the state changes
                states[-1] = actions[states[-2]][rule[0]]
            else:
                reduce(rule)
    while states[-1] != tables.end:
        action = actions[states[-1]].get("$END")
        if action is None or action >= 0:
            raise Unparsed("$END")
        reduce(rules[~action])
    return values[-1]


def _lex(text: str, tables: Tables, states: list[int]) -> Iterator[tuple[str, Lexeme | None, tuple]]:
    """The tokens of ``text`` as lark's contextual lexer and FsvIndenter give them: each lexed
    with the scanner of the parser's state at that moment, which ``states`` holds."""
    nl, indent_type, dedent_type = (tables.indenter[k] for k in ("nl", "indent", "dedent"))
    tab_len, kept, lexers = tables.indenter["tab_len"], tables.kept, tables.lexers
    indents = [0]
    pos, line, line_start, size = 0, 1, 0, len(text)
    while pos < size:
        lexer = lexers[states[-1]] or tables.lexer(states[-1])
        match = lexer.first(text, pos)
        if match is None:
            for pattern in lexer.patterns[1:]:
                match = pattern.match(text, pos)
                if match:
                    break
            else:
                match = lexer.match_plain(text, pos)
                if match is None:
                    raise Unparsed("no terminal matches")
        kind = match.lastgroup
        start, pos = match.span(kind)  # skipped blanks hold no newline
        value = text[start:pos]
        start_line, start_column = line, start - line_start + 1
        what = lexer.kinds.get(kind, 0)
        if what:
            if what & _NEWLINE:
                newlines = value.count("\n")
                if newlines:
                    line += newlines
                    line_start = start + value.rindex("\n") + 1
            if what & _IGNORE:
                continue
            if what & _KEYWORD:
                kind = lexer.keywords[kind].get(value, kind)
        end_column = pos - line_start + 1
        if kind in kept:
            token = Lexeme(value)
            token.type, token.line, token.column = kind, start_line, start_column
            token.end_line, token.end_column = line, end_column
            yield kind, token, (start_line, start_column, line, end_column)
            continue
        yield kind, None, (start_line, start_column, line, end_column)
        if kind == nl:  # the indentation post-lexer
            indent_text = value.rsplit("\n", 1)[1]
            indent = indent_text.count(" ") + indent_text.count("\t") * tab_len
            mark = (line, end_column, line, end_column + 1)
            if indent > indents[-1]:
                indents.append(indent)
                yield indent_type, None, mark
                continue
            while indent < indents[-1]:
                indents.pop()
                yield dedent_type, None, mark
            if indent != indents[-1]:
                raise Unparsed("indentation fault")
    if len(indents) > 1:
        raise Unparsed("unclosed block at the end")  # lark dedents here; its tree path handles it


def _filter(raw: list, include: tuple, trailing: int) -> list:
    """The children lark keeps (ChildFilter): inlined `_rule`s spliced, None for absent optionals."""
    children = []
    for i, expand, nones in include:
        if nones:
            children.extend([None] * nones)
        if expand:
            if children:
                children.extend(raw[i])
            else:
                children = raw[i]  # reuse the inlined list, as lark does (left recursion)
        else:
            children.append(raw[i])
    if trailing:
        children.extend([None] * trailing)
    return children


def _extent(places: list) -> tuple[int, int, int, int] | None:
    """From the start of the first positioned child to the end of the last one."""
    for first in places:
        if first is not None:
            break
    else:
        return None
    for last in reversed(places):
        if last is not None:
            return (first[0], first[1], last[2], last[3])
    return None
