"""Source files and spans.

Every token and AST node carries a :class:`Span` (file, start offset, end offset). Line and column
numbers are computed only when a diagnostic is rendered (:meth:`SourceFile.line_col`).
"""
from __future__ import annotations

import bisect
from dataclasses import dataclass, field


class SourceFile:
    """The decoded text of one ST file, with a lazily built line index."""

    __slots__ = ("path", "text", "_line_starts")

    def __init__(self, path: str, text: str) -> None:
        self.path = path
        self.text = text
        self._line_starts: list[int] | None = None

    def __repr__(self) -> str:
        return f"SourceFile({self.path!r})"

    def _starts(self) -> list[int]:
        if self._line_starts is None:
            starts = [0]
            text = self.text
            pos = text.find("\n")
            while pos >= 0:
                starts.append(pos + 1)
                pos = text.find("\n", pos + 1)
            self._line_starts = starts
        return self._line_starts

    def line_col(self, offset: int) -> tuple[int, int]:
        """1-based line and column of a character offset."""
        starts = self._starts()
        offset = max(0, min(offset, len(self.text)))
        line = bisect.bisect_right(starts, offset) - 1
        return line + 1, offset - starts[line] + 1

    def line_text(self, line: int) -> str:
        """Text of a 1-based line without its line break."""
        starts = self._starts()
        if line < 1 or line > len(starts):
            return ""
        start = starts[line - 1]
        end = starts[line] - 1 if line < len(starts) else len(self.text)
        return self.text[start:end].rstrip("\r")


@dataclass(frozen=True, slots=True)
class Span:
    """A half-open character range ``[start, end)`` in one source file."""

    file: SourceFile = field(repr=False, compare=False)
    start: int
    end: int

    def to(self, other: Span) -> Span:
        """The span covering ``self`` up to the end of ``other``."""
        return Span(self.file, self.start, max(self.end, other.end))

    @property
    def line(self) -> int:
        return self.file.line_col(self.start)[0]

    @property
    def column(self) -> int:
        return self.file.line_col(self.start)[1]


BUILTIN_FILE = SourceFile("<builtin>", "")
BUILTIN_SPAN = Span(BUILTIN_FILE, 0, 0)
