"""One argument binder for every call with named slots: task roles and asset parameters.

``task pick_place(pot, target=shelf)`` and ``mug(4 cm, height=10 cm)`` bind their
arguments the same way: unnamed values fill the slots in order and come before named
ones; a name must be a slot of the call; a slot is given once. What differs is only the
wording (:class:`Slots`) and what a value must be (the ``convert`` function).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from .. import ast
from ..catalog import Param
from ..diagnostics import DiagnosticSink, Related, did_you_mean
from ..spans import Span
from .scope import Scope


class Slots:
    """The slots of one call, and how the binder speaks of them."""

    def __init__(self, names: Sequence[str]):
        self.names = tuple(names)

    after_named_help = "write unnamed values first, or give this one its name"

    def too_many(self) -> tuple[str, str, str | None]:
        """(message, label, help) for a value without a slot."""
        raise NotImplementedError

    def unknown(self, name: str) -> tuple[str, str, str, str | None]:
        """(code, message, label, help) for a name that is not a slot."""
        raise NotImplementedError

    def twice(self, name: str) -> str:
        return f"`{name}` is given twice"


class TaskRoles(Slots):
    def __init__(self, task: str, roles: Sequence[str]):
        super().__init__(roles)
        self.task = task

    after_named_help = "write unnamed roles first, or give this one its role name"

    def too_many(self) -> tuple[str, str, str | None]:
        return f"too many arguments for task `{self.task}`", f"`{self.task}` takes {', '.join(self.names)}", None

    def unknown(self, name: str) -> tuple[str, str, str, str | None]:
        return ("FSV303", f"task `{self.task}` has no role `{name}`", "not a role of this task",
                did_you_mean(name, self.names, "roles"))

    def twice(self, name: str) -> str:
        return f"role `{name}` is given twice"


class Parameters(Slots):
    def __init__(self, owner: str, params: Sequence[Param]):
        super().__init__([p.name for p in params])
        self.owner = owner

    def too_many(self) -> tuple[str, str, str | None]:
        return (f"unexpected value for `{self.owner}`", "parameters are given by name",
                f"write `name=value`; `{self.owner}` takes " + ", ".join(f"`{n}`" for n in self.names))

    def unknown(self, name: str) -> tuple[str, str, str, str | None]:
        return ("FSV103", f"`{self.owner}` has no parameter `{name}`", "unknown parameter",
                did_you_mean(name, self.names, "parameters"))


@dataclass
class Binding:
    values: dict[str, object] = field(default_factory=dict)  # slot -> accepted value
    given: dict[str, Span] = field(default_factory=dict)  # slot -> where it was given
    failed: bool = False  # a value fitted no slot, or its slot rejected it


Convert = Callable[[str, ast.Value], object]  # (slot, value) -> the accepted value, or None


def bind(sink: DiagnosticSink, arguments: Sequence[ast.Argument], slots: Slots, convert: Convert,
         positional_ok: bool = True) -> Binding:
    """Bind ``arguments`` to ``slots``, reporting what does not fit; values go through ``convert``."""
    binding = Binding()
    named_seen = False
    for index, argument in enumerate(arguments):
        if argument.keyword is None and named_seen:
            sink.error("FSV305", "a value without a name after named ones", argument.span,
                       "unnamed value", help=slots.after_named_help)
            continue
        named_seen = named_seen or argument.keyword is not None
        slot = _slot(sink, index, argument, slots, positional_ok)
        if slot is None:
            binding.failed = True
            continue
        if slot in binding.given:
            sink.error("FSV208", slots.twice(slot), argument.span, "given again",
                       related=[Related(span=binding.given[slot], message="first given here")])
            continue
        binding.given[slot] = argument.span
        value = convert(slot, argument.value)
        if value is None:
            binding.failed = True
        else:
            binding.values[slot] = value
    return binding


def _slot(sink: DiagnosticSink, index: int, argument: ast.Argument, slots: Slots,
          positional_ok: bool) -> str | None:
    if argument.keyword is None:
        if positional_ok and index < len(slots.names):
            return slots.names[index]
        message, label, help = slots.too_many()
        sink.error("FSV305", message, argument.span, label, help=help)
        return None
    name = argument.keyword.value
    if name in slots.names:
        return name
    code, message, label, help = slots.unknown(name)
    sink.error(code, message, argument.keyword.span, label, help=help)
    return None


def bind_params(scope: Scope, call: ast.Call, params: Sequence[Param], owner: str,
                positional_ok: bool = True) -> dict:
    """The parameters of an asset, zone, predicate or vision setting, defaults filled in."""
    by_name = {p.name: p for p in params}

    def convert(name: str, value: ast.Value) -> object:
        return scope.values.param(by_name[name], value, owner, scope.resolve_path)

    binding = bind(scope.sink, call.arguments, Parameters(owner, params), convert, positional_ok)
    out = binding.values
    for param in params:
        if param.required and param.name not in binding.given:
            scope.sink.error("FSV206", f"`{owner}` needs `{param.name}`", call.span,
                             f"missing `{param.name}`", help=f"add `{param.name}=...` inside the parentheses")
        elif param.name not in binding.given and param.default is not None:
            out[param.name] = param.default
    return out
