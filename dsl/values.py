"""Checking written values against what a parameter expects, and converting them to SI."""

from __future__ import annotations

from collections.abc import Callable

from . import ast
from .catalog import Param, Value
from .diagnostics import DiagnosticSink, did_you_mean
from .units import UNITS, Dimension, describe_units


def format_si(value: float, dimension: Dimension, like_unit: str | None = None) -> str:
    """An SI value written back in the author's unit (or a readable one)."""
    if dimension is Dimension.NUMBER:
        return f"{value:g}"
    unit = like_unit if like_unit in UNITS and UNITS[like_unit][0] is dimension else dimension.si_unit
    if like_unit is None and dimension is Dimension.LENGTH and abs(value) < 1.0:
        unit = "cm"
    if like_unit is None and dimension is Dimension.ANGLE:
        unit = "deg"
    return f"{value / UNITS[unit][1]:g} {unit}"


class ValueChecker:
    """Converts quantities, vectors and symbols, reporting every problem to the sink."""

    def __init__(self, sink: DiagnosticSink):
        self.sink = sink

    def quantity(self, q: ast.Quantity, dimension: Dimension, what: str) -> float | None:
        if q.unit is None:
            if dimension is Dimension.NUMBER or q.number == 0:
                return q.number
            example = f"{q.text} {dimension.example_unit}"
            self.sink.error("FSV201", f"missing unit: {what} is {_article(dimension.value)}", q.span,
                            f"expected {_article(dimension.value)} in {describe_units(dimension)}",
                            help=f"write the unit after the number, e.g. `{example}`")
            return None
        unit_dimension, value = UNITS[q.unit][0], q.number * UNITS[q.unit][1]
        if dimension is Dimension.NUMBER:
            self.sink.error("FSV203", f"{what} is a plain number, not {_article(unit_dimension.value)}", q.span,
                            f"`{q.unit}` is a unit of {unit_dimension.value}",
                            help=f"remove the unit: `{q.text}`")
            return None
        if unit_dimension is not dimension:
            self.sink.error("FSV203", f"wrong unit: {what} is {_article(dimension.value)}, but `{q.unit}` "
                            f"measures {unit_dimension.value}", q.span,
                            f"expected {describe_units(dimension)}",
                            help=f"give {what} in {describe_units(dimension)}")
            return None
        return value

    def amount(self, q: ast.Quantity, dimension: Dimension, what: str, *,
               strict: bool = False) -> float | None:
        """A quantity that must not be negative (nor zero, when ``strict``)."""
        value = self.quantity(q, dimension, what)
        if value is None:
            return None
        if value < 0 or (strict and value == 0):
            bound = "larger than zero" if strict else "zero or more"
            self.sink.error("FSV204", f"{what} must be {bound}", q.span,
                            "negative" if value < 0 else "zero", help=f"give {what} as a value {bound}")
            return None
        return value

    def in_range(self, value: float, param: Param, q: ast.Quantity, what: str) -> bool:
        too_low = param.minimum is not None and value < param.minimum - 1e-12
        too_high = param.maximum is not None and value > param.maximum + 1e-12
        if not (too_low or too_high):
            return True
        unit = q.unit
        bounds = []
        if param.minimum is not None:
            bounds.append(f"at least {format_si(param.minimum, param.dimension, unit)}")
        if param.maximum is not None:
            bounds.append(f"at most {format_si(param.maximum, param.dimension, unit)}")
        self.sink.error("FSV204", f"{what} is out of range", q.span,
                        f"must be {' and '.join(bounds)}",
                        help=f"choose a value {' and '.join(bounds)}")
        return False

    def param(self, param: Param, value: ast.Value, owner: str,
              resolve_path: Callable[[ast.String], str | None] | None = None) -> Value | None:
        """Check one parameter value; returns it in SI, or None after reporting a problem."""
        what = f"`{param.name}` of `{owner}`"
        if param.choices is not None:
            if isinstance(value, ast.Ref) and value.name in param.choices:
                return value.name
            written = value.name if isinstance(value, ast.Ref) else None
            self.sink.error("FSV207", f"{what} must be one of {', '.join(param.choices)}", value.span,
                            "not one of the choices",
                            help=did_you_mean(written, param.choices, "choices") if written else
                            f"write one of: {', '.join(param.choices)}")
            return None
        if param.path:
            if not isinstance(value, ast.String):
                self.sink.error("FSV207", f"{what} is a file path in quotes", value.span,
                                "expected a quoted path", help='write it as `path="models/cup.obj"`')
                return None
            return resolve_path(value) if resolve_path else value.value
        if param.arity > 1:
            return self._vector(param, value, what)
        if not isinstance(value, ast.Quantity):
            self.sink.error("FSV207", f"{what} must be {_article(_kind_word(param))}", value.span,
                            f"found {_describe_value(value)}")
            return None
        number = self.quantity(value, param.dimension, what)
        if number is None or not self.in_range(number, param, value, what):
            return None
        if param.integer:
            if number != int(number):
                self.sink.error("FSV207", f"{what} must be a whole number", value.span, "not a whole number")
                return None
            return int(number)
        return number

    def _vector(self, param: Param, value: ast.Value, what: str) -> tuple[float, ...] | None:
        if not isinstance(value, ast.Vector):
            self.sink.error("FSV205", f"{what} needs {param.arity} values", value.span,
                            f"found {_describe_value(value)}",
                            help=f"write {param.arity} values in parentheses, e.g. "
                                 f"`{param.name}=({', '.join(['…'] * param.arity)})`")
            return None
        if len(value.items) != param.arity:
            self.sink.error("FSV205", f"{what} needs {param.arity} values, not {len(value.items)}",
                            value.span, f"{len(value.items)} values")
            return None
        out: list[float] = []
        for item in value.items:
            if not isinstance(item, ast.Quantity):
                self.sink.error("FSV207", f"each value of {what} must be {_article(_kind_word(param))}",
                                item.span, f"found {_describe_value(item)}")
                return None
            number = self.quantity(item, param.dimension, what)
            if number is None or not self.in_range(number, param, item, what):
                return None
            out.append(number)
        return tuple(out)


def _article(word: str) -> str:
    return ("an " if word[:1] in "aeiou" else "a ") + word


def _kind_word(param: Param) -> str:
    if param.dimension is Dimension.NUMBER:
        return "number"
    return f"{param.dimension.value} ({describe_units(param.dimension)})"


def _describe_value(value: ast.Value) -> str:
    if isinstance(value, ast.Quantity):
        return "a quantity"
    if isinstance(value, ast.Vector):
        return f"{len(value.items)} values in parentheses"
    if isinstance(value, ast.String):
        return "a string"
    if isinstance(value, ast.Ref):
        return f"the name `{value.name}`"
    return f"a call to `{value.name.value}`"
