"""Source positions: where in which file a piece of a scenario was written."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class Span(BaseModel):
    """A region of one source file; lines and columns are 1-based, ends exclusive."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    file: str
    line: int
    column: int
    end_line: int
    end_column: int

    @classmethod
    def point(cls, file: str, line: int, column: int, width: int = 1) -> "Span":
        return cls(file=file, line=line, column=column, end_line=line, end_column=column + width)

    @classmethod
    def of(cls, file: str, node: object) -> "Span":
        """The span of a lark Tree or Token (anything with line/column/end_* attributes)."""
        line = getattr(node, "line", None) or 1
        column = getattr(node, "column", None) or 1
        end_line = getattr(node, "end_line", None) or line
        end_column = getattr(node, "end_column", None) or column + 1
        return cls(file=file, line=line, column=column, end_line=end_line, end_column=end_column)

    def to(self, other: "Span") -> "Span":
        """The span from the start of this one to the end of ``other`` (same file)."""
        return Span(file=self.file, line=self.line, column=self.column,
                    end_line=other.end_line, end_column=other.end_column)

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"
