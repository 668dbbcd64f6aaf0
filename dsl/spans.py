"""Source positions: where in which file a piece of a scenario was written."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar


@dataclass(frozen=True, slots=True)
class Span:
    """A region of one source file; lines and columns are 1-based, ends exclusive.

    A plain frozen dataclass rather than a pydantic model: the parser makes thousands
    of them per file. Pydantic models that hold one (diagnostics) still validate and
    serialise it field by field, and reject unknown fields, as before.
    """

    __pydantic_config__: ClassVar[dict] = {"extra": "forbid"}

    file: str
    line: int
    column: int
    end_line: int
    end_column: int

    @classmethod
    def point(cls, file: str, line: int, column: int, width: int = 1) -> "Span":
        return cls(file, line, column, line, column + width)

    @classmethod
    def of(cls, file: str, node: object) -> "Span":
        """The span of a lark Tree or Token (anything with line/column/end_* attributes)."""
        line = getattr(node, "line", None) or 1
        column = getattr(node, "column", None) or 1
        end_line = getattr(node, "end_line", None) or line
        end_column = getattr(node, "end_column", None) or column + 1
        return cls(file, line, column, end_line, end_column)

    def to(self, other: "Span") -> "Span":
        """The span from the start of this one to the end of ``other`` (same file)."""
        return Span(self.file, self.line, self.column, other.end_line, other.end_column)

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


def _init(self: Span, file: str, line: int, column: int, end_line: int, end_column: int) -> None:
    _set_file(self, file)
    _set_line(self, line)
    _set_column(self, column)
    _set_end_line(self, end_line)
    _set_end_column(self, end_column)


# The dataclass's own __init__ assigns each field through object.__setattr__ (it is frozen);
# writing the slots directly is 40% faster, for the thousands of spans a file makes.
_set_file, _set_line, _set_column, _set_end_line, _set_end_column = (
    getattr(Span, name).__set__ for name in ("file", "line", "column", "end_line", "end_column"))
_init.__qualname__ = "Span.__init__"
Span.__init__ = _init
