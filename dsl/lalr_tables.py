"""lark's tables for the grammar as plain data, for :mod:`fsvla.dsl.lalr`; cached as JSON.

What the fast path needs of lark's parser for this grammar: the LALR actions, each
rule's child filter and shape, each parser state's scanner (its patterns in lark's
order, its ignored and keyword terminals) and the indentation post-lexer's settings.
Taken from lark once, then kept in the temporary folder (as lark keeps its own cache)
under the name :func:`fsvla.dsl.lalr.cache_path` gives; checking well-formed files
then neither imports lark nor this module.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from pathlib import Path

try:  # the regex parser of `re`, to read the terminals' first characters
    from re import _constants as _sre
    from re import _parser as _sre_parser
except ImportError:  # Python 3.10
    import sre_constants as _sre
    import sre_parse as _sre_parser

from .build import AstBuilder
from .lalr import BUILD, EXPAND_SINGLE, FORMAT, INLINE, PASS


def write_cache(path: Path, data: dict) -> None:
    """Write the cache file atomically; where that fails the next process extracts again."""
    try:
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            json.dump(data, stream)
        os.replace(temporary, path)
    except OSError:
        Path(temporary).unlink(missing_ok=True)


def extract_tables() -> dict | None:
    """lark's tables for the grammar as JSON-ready data; None where they hold something
    this module does not reproduce (a lexer callback of another kind, byte or `regex`
    scanners, a rule without a builder method)."""
    from lark.lexer import UnlessCallback
    from lark.parsers.lalr_analysis import Shift

    from .parser import FsvIndenter, build_parser

    frontend = build_parser().parser
    indenter = frontend.lexer.postlexer
    contextual = frontend.lexer.lexer
    table = frontend.parser.parser.parse_table
    if type(indenter) is not FsvIndenter or indenter.OPEN_PAREN_types or sorted(table.states) != list(
            range(len(table.states))):
        return None
    rules: dict = {}
    actions = []
    for state in range(len(table.states)):
        row = {}
        for symbol, (action, argument) in table.states[state].items():
            if action is Shift:
                row[symbol] = argument
            else:
                row[symbol] = ~rules.setdefault(argument, len(rules))
        actions.append(row)
    rule_specs, kept = [], set()
    for rule in sorted(rules, key=rules.get):
        spec = _rule_spec(rule, kept)
        if spec is None:
            return None
        rule_specs.append(spec)
    lexer_index: dict[int, int] = {}
    lexers, state_lexer = [], []
    for state in range(len(table.states)):
        lexer = contextual.lexers[state]
        if id(lexer) not in lexer_index:
            spec = _lexer_spec(lexer, UnlessCallback)
            if spec is None:
                return None
            lexer_index[id(lexer)] = len(lexers)
            lexers.append(spec)
        state_lexer.append(lexer_index[id(lexer)])
    return {"format": FORMAT, "start": table.start_states["start"], "end": table.end_states["start"],
            "actions": actions, "rules": rule_specs, "kept": sorted(kept), "lexers": lexers,
            "state_lexer": state_lexer,
            "indenter": {"nl": indenter.NL_type, "indent": indenter.INDENT_type,
                         "dedent": indenter.DEDENT_type, "tab_len": indenter.tab_len}}


def _rule_spec(rule, kept: set[str]) -> list | None:
    """What lark's ParseTreeBuilder does on reducing ``rule`` (with ``maybe_placeholders``):
    which children it keeps (ChildFilter), where it inserts None, whether it inlines."""
    options = rule.options
    origin, size = rule.origin.name, len(rule.expansion)
    if origin.startswith("_") and options.expand1:
        return None
    if origin.startswith("_"):
        mode = INLINE
    elif options.expand1 and not rule.alias:
        mode = EXPAND_SINGLE
    else:
        mode = BUILD
    empty = options.empty_indices
    if empty:
        gaps = [len(ones) for ones in "".join(str(int(b)) for b in empty).split("0")]
    else:
        gaps = [0] * (size + 1)
    include, nones = [], 0
    for i, symbol in enumerate(rule.expansion):
        nones += gaps[i]
        if options.keep_all_tokens or not (symbol.is_term and symbol.filter_out):
            include.append([i, not symbol.is_term and symbol.name.startswith("_"), nones])
            nones = 0
            if symbol.is_term:
                kept.add(symbol.name)
    trailing = nones + gaps[size]
    callback = str(rule.alias or options.template_source or origin)
    always_single = len(include) == 1 and not include[0][1] and not include[0][2] and not trailing
    if mode == BUILD or (mode == EXPAND_SINGLE and not always_single):
        if not callable(getattr(AstBuilder, callback, None)):
            return None
    else:
        callback = None
    if mode == EXPAND_SINGLE and always_single and size == 1:
        mode = PASS  # the one child keeps its value and its position
    return [origin, size, mode, callback, include, trailing]


def _lexer_spec(lexer, unless_type) -> dict | None:
    """One state's BasicLexer: its scanner's patterns, and its keyword callbacks as tables."""
    if lexer.re is not re or lexer.use_bytes or lexer.g_regex_flags:
        return None
    scanner = lexer.scanner  # built on first use: its patterns and callbacks are now set
    keywords = {}
    for kind, callback in lexer.callback.items():
        if type(callback) is not unless_type:
            return None
        terminals = callback.scanner.terminals
        if any(t.pattern.type != "str" or t.pattern.flags for t in terminals):
            return None
        keywords[kind] = {t.pattern.value: t.name for t in terminals}
    return {"patterns": [m.pattern for m in scanner._mres], "flags": 0,
            "ignore": sorted(lexer.ignore_types), "newline": sorted(lexer.newline_types),
            "keywords": keywords, "blank": _blank_prefix(lexer)}


def _blank_prefix(lexer) -> str | None:
    """A regex prefix that skips the run of blanks that an ignored terminal of ``lexer``
    would match (one of the shape ``[...]+``), where no other terminal can start with a
    blank: then at a blank lark's scanner can only match that run, as a whole, and go on
    after it in the same state; the prefix does the same inside the next match. None
    where that cannot be shown."""
    for blank in lexer.terminals:
        chars = _run_chars(blank.pattern.to_regexp()) if blank.name in lexer.ignore_types else None
        if chars and "\n" not in chars:
            break
    else:
        return None
    if any(_may_start_with(t.pattern.to_regexp(), chars) for t in lexer.terminals if t is not blank):
        return None
    # Backtracking into the prefix can only let the blanks' own (ignored) terminal match.
    return f"(?:{blank.pattern.to_regexp()})?"


def _run_chars(regex: str) -> set[str] | None:
    """The characters of a regex of the shape ``[abc]+`` (literals and ranges), else None."""
    items = list(_sre_parse(regex))
    if len(items) != 1 or items[0][0] is not _sre.MAX_REPEAT:
        return None
    low, high, body = items[0][1]
    body = list(body)
    if low != 1 or high != _sre.MAXREPEAT or len(body) != 1 or body[0][0] is not _sre.IN:
        return None
    chars = set()
    for op, value in body[0][1]:
        if op is _sre.LITERAL:
            chars.add(chr(value))
        elif op is _sre.RANGE and value[1] - value[0] < 256:
            chars.update(chr(c) for c in range(value[0], value[1] + 1))
        else:
            return None
    return chars


def _may_start_with(regex: str, chars: set[str]) -> bool:
    """Whether a match of ``regex`` may begin with one of ``chars`` (True when unsure)."""
    try:
        return _first_in(_sre_parse(regex), chars)
    except Exception:  # noqa: BLE001 - any doubt means "maybe"
        return True


def _first_in(pattern, chars: set[str]) -> bool:
    for op, value in pattern:
        if op is _sre.LITERAL:
            return chr(value) in chars
        if op is _sre.IN:
            return _set_may_hold(value, chars)
        if op is _sre.AT:  # an anchor matches no character
            continue
        if op is _sre.SUBPATTERN:
            subs, low = [value[-1]], value[-1].getwidth()[0]
        elif op is _sre.BRANCH:
            subs = value[1]
            low = min(sub.getwidth()[0] for sub in subs)
        elif op in (_sre.MAX_REPEAT, _sre.MIN_REPEAT, getattr(_sre, "POSSESSIVE_REPEAT", None)):
            subs, low = [value[2]], value[0] * value[2].getwidth()[0]
        else:  # any character, a negated literal, a lookaround...: maybe
            return True
        if any(_first_in(sub, chars) for sub in subs):
            return True
        if low > 0:
            return False
    return True  # it may match the empty string: whatever follows may start with a blank


def _set_may_hold(items, chars: set[str]) -> bool:
    for op, value in items:
        if op is _sre.LITERAL and chr(value) in chars:
            return True
        if op is _sre.RANGE and any(value[0] <= ord(c) <= value[1] for c in chars):
            return True
        if op is _sre.CATEGORY and value not in (_sre.CATEGORY_DIGIT, _sre.CATEGORY_WORD):
            return True
        if op not in (_sre.LITERAL, _sre.RANGE, _sre.CATEGORY):  # NEGATE and the like: maybe
            return True
    return False


def _sre_parse(regex: str):
    return _sre_parser.parse(regex)
