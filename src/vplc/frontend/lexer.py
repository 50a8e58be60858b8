"""Lexer: one compiled regular expression, matched token by token (nested comments scanned by hand).

Every repetition over a token's parts is possessive (``*+``, ``++``): Python's regular expression engine keeps
backtracking state for each repetition of a group, hundreds of bytes per character, so a 10 MB string literal
or a T# literal of a million units would otherwise need gigabytes. None of these tokens needs to give back a
repetition to match.

Tokens keep their kind, text and offsets; keywords are ordinary ``IDENT`` tokens recognised by the parser
through ``Token.up`` (IEC keywords are case-insensitive). Comments and whitespace are dropped; pragmas
``{...}`` are returned as ``PRAGMA`` tokens (the parser attaches ``{native}`` to the next POU and reports
any other pragma as ignored).
"""
from __future__ import annotations

import re

from . import codes
from .diagnostics import DiagnosticBag
from .source import SourceFile, Span

_DURATION = r"[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]+)?(?i:ms|us|ns|d|h|m|s)_?)++"
_CLOCK = r"[0-9]+:[0-9]+(?::[0-9]+(?:\.[0-9]+)?)?"
_YMD = r"[0-9]{4}-[0-9]{1,2}-[0-9]{1,2}"

# Whitespace is skipped as the lead of the next token's match (one match per token, not two); a name that no
# "#" or "://" follows is tried right after comments and pragmas: such a name can be no other token (a typed or
# time literal and an I/O port address all need one of them just after the name), and names are most tokens. The
# full list below still reads every name that one of them follows.
_TOKEN_RE = re.compile(
    r"""
    [ \t\r\n\f\v]*+
    (?:
    (?P<LINECOMMENT>//[^\n]*)
  | (?P<COMMENT>\(\*|/\*)
  | (?P<PRAGMA>\{)
  | (?P<NAME>[A-Za-z_][A-Za-z0-9_]*+)(?!\#|://)
  | (?P<DT>(?i:DATE_AND_TIME|LDATE_AND_TIME|LDT|DT)\#""" + _YMD + r"-" + _CLOCK + r""")
  | (?P<TOD>(?i:TIME_OF_DAY|LTIME_OF_DAY|LTOD|TOD)\#""" + _CLOCK + r""")
  | (?P<DATE>(?i:LDATE|DATE|D)\#""" + _YMD + r""")
  | (?P<TIME>(?i:LTIME|TIME|LT|T)\#""" + _DURATION + r"""(?![A-Za-z0-9_]))
  | (?P<TYPED>[A-Za-z_][A-Za-z0-9_]*\#)
  | (?P<BASED>[0-9]+\#[0-9A-Za-z_]+)
  | (?P<REAL>[0-9][0-9_]*\.[0-9][0-9_]*(?:[eE][+-]?[0-9]+)?|[0-9][0-9_]*[eE][+-]?[0-9]+)
  | (?P<INT>[0-9][0-9_]*)
  | (?P<IOPORT>(?:ECAT|IOBus|NXBus)://[^:;\r\n]*)
  | (?P<IDENT>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<STRING>'(?:\$.|[^'$\r\n])*+')
  | (?P<WSTRING>"(?:\$.|[^"$\r\n])*+")
  | (?P<BADSTRING>['"][^\r\n]*)
  | (?P<ADDRESS>%[IQM][XBWDL]?[0-9]+(?:\.[0-9]+)*+|%[IQM]\*|%(?i:[WHDA]|E[0-9A-F]{1,2}_)?[0-9]+(?:\.[0-9]+)?)
  | (?P<OP>:=|=>|<=|>=|<>|\*\*|\.\.|\\\\|[-+*/&=<>()\[\],;:.\#\\^])
  | (?P<BAD>.)
    )
    """,
    re.VERBOSE | re.DOTALL | re.ASCII,     # ASCII: a keyword's case is ASCII's (TıME# is no TIME literal, T#1ſ no 1 s)
)


class Token:
    __slots__ = ("kind", "text", "start", "end", "up")

    def __init__(self, kind: str, text: str, start: int, end: int) -> None:
        self.kind = kind
        self.text = text
        self.start = start
        self.end = end
        self.up = text.upper() if kind == "IDENT" else text

    def __repr__(self) -> str:
        return f"{self.kind}({self.text!r}@{self.start})"


def comment_end(text: str, pos: int) -> int:
    """Return the offset after the comment that starts at ``pos`` (``(*`` nests, ``/*`` nests), or -1 when it is
    not closed (an editor or a formatter can skip a comment the way the lexer does).

    Linear in the comment's length: the next opener and the next closer are each searched again only once the
    scan has passed them (100,000 nested openers followed by their closers are read once, not once per level)."""
    opener = text[pos:pos + 2]
    closer = "*)" if opener == "(*" else "*/"
    n = len(text)
    depth = 0
    i = pos
    j = -1                          # the next closer at or after i
    k = pos                         # the next opener at or after i (n: none left)
    while True:
        if j < i:
            j = text.find(closer, i)
            if j < 0:
                return -1
        if k < i:
            k = text.find(opener, i)
            if k < 0:
                k = n
        if k < j:
            depth += 1
            i = k + 2
        else:
            depth -= 1
            i = j + 2
            if depth == 0:
                return i


def tokenize(src: SourceFile, diags: DiagnosticBag, comments: list | None = None) -> list[Token]:
    """Split ``src`` into tokens; problems become diagnostics and the scan continues.

    When ``comments`` is a list, the style and offsets of every comment are appended to it as
    ``(style, start, end)`` with style ``"(*"``, ``"/*"`` or ``"//"``."""
    text = src.text
    tokens: list[Token] = []
    append = tokens.append
    match = _TOKEN_RE.match
    pos = 0
    n = len(text)
    bad_start = -1
    while pos < n:
        m = match(text, pos)
        if m is None:                   # only whitespace left (BAD, the last alternative, matches any character)
            break
        kind = m.lastgroup or "BAD"     # every alternative is a named group
        start, end = m.span(kind)
        if bad_start >= 0 and (kind != "BAD" or start != pos):    # a run of bad characters ends at whitespace too
            chunk = text[bad_start:pos]
            diags.error(codes.BAD_CHARACTER, f"unexpected character {chunk[0]!r} (U+{ord(chunk[0]):04X}); "
                        "remove it or put it inside a comment or string", Span(src, bad_start, pos))
            bad_start = -1
        if kind == "NAME":
            append(Token("IDENT", text[start:end], start, end))
            pos = end
            continue
        if kind == "BAD":
            if bad_start < 0:
                bad_start = start
            pos = end
            continue
        if kind == "LINECOMMENT":
            if comments is not None:
                comments.append(("//", start, end))
            pos = end
            continue
        if kind == "COMMENT":
            stop = comment_end(text, start)
            if stop < 0:
                diags.error(codes.UNCLOSED_COMMENT, "comment is never closed; add `*)` at its end",
                            Span(src, start, start + 2))
                break
            if comments is not None:
                comments.append((text[start:start + 2], start, stop))
            pos = stop
            continue
        if kind == "PRAGMA":
            stop = text.find("}", start)
            if stop < 0:
                diags.error(codes.UNCLOSED_PRAGMA, "pragma is never closed; add `}`", Span(src, start, start + 1))
                break
            append(Token("PRAGMA", text[start:stop + 1], start, stop + 1))
            pos = stop + 1
            continue
        if kind == "BADSTRING":
            diags.error(codes.UNCLOSED_STRING, "string literal is not closed on this line; add the closing quote",
                        Span(src, start, end))
            append(Token("STRING" if text[start] == "'" else "WSTRING", text[start:end] + text[start], start, end))
            pos = end
            continue
        append(Token(kind, text[start:end], start, end))
        pos = end
    if bad_start >= 0:
        ch = text[bad_start]
        diags.error(codes.BAD_CHARACTER, f"unexpected character {ch!r} (U+{ord(ch):04X}); "
                    "remove it or put it inside a comment or string", Span(src, bad_start, pos if pos < n else n))
    tokens.append(Token("EOF", "", n, n))
    return tokens


_ESCAPES = {"$": "$", "'": "'", '"': '"', "L": "\n", "N": "\n", "P": "\f", "R": "\r", "T": "\t"}


def decode_string(body: str, wide: bool) -> tuple[str, str | None]:
    """Decode the ``$`` escapes of a string literal body (without quotes).

    Returns ``(value, error)`` where ``error`` names the first invalid escape, or None."""
    if "$" not in body:
        return body, None
    out: list[str] = []
    i = 0
    n = len(body)
    error = None
    hexlen = 4 if wide else 2
    while i < n:
        c = body[i]
        if c != "$":
            out.append(c)
            i += 1
            continue
        nxt = body[i + 1:i + 2]
        esc = _ESCAPES.get(nxt.upper())
        if esc is not None:
            out.append(esc)
            i += 2
            continue
        digits = body[i + 1:i + 1 + hexlen]
        if len(digits) == hexlen and all(ch in "0123456789abcdefABCDEF" for ch in digits):
            out.append(chr(int(digits, 16)))
            i += 1 + hexlen
            continue
        if error is None:
            error = f"invalid escape `${nxt}`; write `$$` for a dollar sign or `$hh` (two hex digits) for a byte"
        out.append(nxt)
        i += 2
    return "".join(out), error
