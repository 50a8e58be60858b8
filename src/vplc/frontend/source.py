"""Source files and spans.

Every token and AST node carries a :class:`Span` (file, start offset, end offset). Line and column
numbers are computed only when a diagnostic is rendered (:meth:`SourceFile.line_col`).
"""
from __future__ import annotations

import bisect
import os
import select
import stat
from dataclasses import dataclass, field

MAX_SOURCE_BYTES = 64 * 1024 * 1024      # an ST file, as an XML project file (ladder/xmlsafe.py)


class FileRefused(Exception):
    """A file that is not read: not a regular file or a pipe, larger than its limit, or a pipe that sends nothing
    (the message says which, without the file's name: the caller names it)."""


PIPE_SILENCE_S = 10.0          # a pipe that sends nothing this long (its writer is stuck) is given up


def read_file_bytes(path: str | os.PathLike[str], limit: int, head: bool = False, pipes: bool = True) -> bytes:
    """The bytes of the regular file or pipe ``path``, at most ``limit`` of them. OSError when it cannot be
    opened; FileRefused for a device, socket or folder, for a file of more than ``limit`` bytes (``head``: its
    first ``limit`` bytes instead) and for a pipe silent for PIPE_SILENCE_S (``pipes`` False: for any pipe, before
    it is read). It is opened without waiting (a named pipe nobody writes to would hold a plain open for ever;
    read, it is an empty file) and read no further than ``limit`` (a link to /dev/zero is refused before it is
    read). A pipe with a writer is read as a file (``vplc check /dev/stdin``, ``<(command)``)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
                 | getattr(os, "O_BINARY", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not (stat.S_ISREG(mode) or stat.S_ISFIFO(mode)):
            raise FileRefused("is not a regular file or a pipe (a device, socket or folder)")
        if not pipes and stat.S_ISFIFO(mode):
            raise FileRefused("is a pipe")
        data = _read_up_to(fd, limit if head else limit + 1)
    finally:
        os.close(fd)
    if len(data) > limit:
        raise FileRefused(f"is larger than {_size(limit)}")
    return data


def _read_up_to(fd: int, want: int) -> bytes:
    """At most ``want`` bytes of ``fd``, to its end; a pipe is waited on up to PIPE_SILENCE_S for each part."""
    chunks: list[bytes] = []
    got = 0
    waiter = None
    while got < want:
        try:
            chunk = os.read(fd, min(1 << 20, want - got))
        except BlockingIOError:                     # the pipe's writer has sent nothing more yet
            if waiter is None:
                waiter = select.poll()              # poll, not select: any descriptor number
                waiter.register(fd, select.POLLIN)
            if not waiter.poll(PIPE_SILENCE_S * 1000):
                raise FileRefused(f"is a pipe that sent nothing for {PIPE_SILENCE_S:g} s") from None
            continue
        if not chunk:                               # the end (a pipe: its writer closed it, or there was none)
            break
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)


def _size(limit: int) -> str:
    return f"{limit // 1048576} MiB" if limit % 1048576 == 0 else f"{limit:,} bytes"


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
