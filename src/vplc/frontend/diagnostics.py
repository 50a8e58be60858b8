"""Diagnostics: one record per finding, rendered as ``path:line:col: error[ST1234]: message``.

The full table of codes (with a failing and a fixed example each) is docs/toolchain/diagnostics.md.
"""
from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass, field

from .source import Span

ERROR = "error"
WARNING = "warning"
NOTE = "note"


@dataclass(slots=True)
class Diagnostic:
    code: str
    severity: str
    message: str
    span: Span
    notes: list[str] = field(default_factory=list)

    @property
    def is_error(self) -> bool:
        return self.severity == ERROR

    def location(self) -> str:
        where = getattr(self.span.file, "where", None)      # ST generated from a ladder: file:POU:rung N:element
        if where is not None:
            return f"{self.span.file.path}:{where(self.span.start)}"
        line, col = self.span.file.line_col(self.span.start)
        return f"{self.span.file.path}:{line}:{col}"

    def render(self, context: bool = True) -> str:
        """``path:line:col: severity[CODE]: message``, then the source line and a caret under the span."""
        head = f"{self.location()}: {self.severity}[{self.code}]: {self.message}"
        lines = [head]
        if context and self.span.file.text:
            line, col = self.span.file.line_col(self.span.start)
            text = self.span.file.line_text(line)
            if len(text) > 200:  # keep huge lines readable: show a window around the column
                lo = max(0, col - 100)
                text = text[lo:lo + 200]
                col -= lo
            text = text.replace("\t", " ")
            end_line, end_col = self.span.file.line_col(max(self.span.start, self.span.end - 1))
            width = end_col - col + 1 if end_line == line else len(text) - col + 1
            width = max(1, min(width, len(text) - col + 2, 200))
            gutter = "   ST | " if hasattr(self.span.file, "where") else f"{line:>5} | "
            lines.append(gutter + text)
            lines.append(" " * (len(gutter) + col - 1) + "^" * width)
        for note in self.notes:
            lines.append(f"      = note: {note}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        line, col = self.span.file.line_col(self.span.start)
        end_line, end_col = self.span.file.line_col(self.span.end)
        where = getattr(self.span.file, "where", None)
        if where is not None:                                # no line in the XML file: the element instead
            line = col = end_line = end_col = 0
        return {
            "path": self.span.file.path, "line": line, "column": col,
            **({"element": where(self.span.start)} if where is not None else {}),
            "end_line": end_line, "end_column": end_col,
            "severity": self.severity, "code": self.code, "message": self.message, "notes": list(self.notes),
        }


def _elide_quotes(message: str) -> str:
    """A quoted piece of source longer than 60 characters is shown by its ends (a 5,000-digit literal).

    Backticks pair left to right: the 1st opens, the 2nd closes, the 3rd opens again ... Only the text inside a
    pair is a quote; the prose between two quotes stays whole, and an unpaired last backtick is left alone.
    """
    parts = message.split("`")
    for i in range(1, len(parts) - 1, 2):
        if len(parts[i]) > 60:
            parts[i] = f"{parts[i][:28]}…{parts[i][-28:]}"
    return "`".join(parts)


class DiagnosticBag:
    """Collects diagnostics of one stage; deduplicates identical reports at the same place."""

    def __init__(self) -> None:
        self.items: list[Diagnostic] = []
        self._seen: set[tuple] = set()

    def add(self, code: str, severity: str, message: str, span: Span, notes: list[str] | None = None) -> Diagnostic:
        message = _elide_quotes(message)
        if len(message) > 400:  # e.g. a 1,000,000-character identifier: keep the message readable
            message = message[:397] + "..."
        key = (code, span.file.path, span.start, message)
        diag = Diagnostic(code, severity, message, span, list(notes or []))
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(diag)
        return diag

    def error(self, code: str, message: str, span: Span, notes: list[str] | None = None) -> Diagnostic:
        return self.add(code, ERROR, message, span, notes)

    def warning(self, code: str, message: str, span: Span, notes: list[str] | None = None) -> Diagnostic:
        return self.add(code, WARNING, message, span, notes)

    def note(self, code: str, message: str, span: Span, notes: list[str] | None = None) -> Diagnostic:
        return self.add(code, NOTE, message, span, notes)

    def extend(self, diags: Iterable[Diagnostic]) -> None:
        for d in diags:
            self.add(d.code, d.severity, d.message, d.span, d.notes)


def sort_key(d: Diagnostic) -> tuple[str, int, str]:
    return (d.span.file.path, d.span.start, d.code)


def render_all(diags: list[Diagnostic], context: bool = True) -> str:
    return "\n".join(d.render(context) for d in sorted(diags, key=sort_key))


def to_json(diags: list[Diagnostic]) -> str:
    return json.dumps({"diagnostics": [d.to_dict() for d in sorted(diags, key=sort_key)]}, indent=2)
