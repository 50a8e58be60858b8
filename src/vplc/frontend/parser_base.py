"""The token cursor the parsers share: position, look-ahead, spans, error reporting and recovery.

One :class:`TokenCursor` exists per parsed file; the expression, statement and declaration parsers each
hold it (see parser.py) and advance it together.
"""
from __future__ import annotations

from collections.abc import Container
from typing import NoReturn

from . import codes
from .diagnostics import DiagnosticBag
from .lexer import Token
from .source import SourceFile, Span

# Words that can never be identifiers (IEC 61131-3 keywords the parser relies on).
RESERVED = frozenset([
    "IF", "THEN", "ELSIF", "ELSE", "END_IF", "CASE", "OF", "END_CASE", "FOR", "TO", "BY", "DO", "END_FOR",
    "WHILE", "END_WHILE", "REPEAT", "UNTIL", "END_REPEAT", "EXIT", "CONTINUE", "RETURN", "VAR", "VAR_INPUT",
    "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL", "VAR_EXTERNAL", "VAR_STAT", "VAR_ACCESS", "VAR_CONFIG",
    "END_VAR", "CONSTANT", "RETAIN", "NON_RETAIN", "TYPE", "END_TYPE", "STRUCT", "END_STRUCT", "ARRAY",
    "FUNCTION", "END_FUNCTION", "FUNCTION_BLOCK", "END_FUNCTION_BLOCK", "PROGRAM", "END_PROGRAM", "CONFIGURATION",
    "END_CONFIGURATION", "RESOURCE", "END_RESOURCE", "AND", "OR", "XOR", "NOT", "MOD", "TRUE", "FALSE", "STRING",
    "WSTRING"
])

# Keywords that end a statement list; recovery stops in front of them.
BLOCK_END = frozenset([
    "END_IF", "ELSIF", "ELSE", "END_CASE", "END_FOR", "END_WHILE", "UNTIL", "END_REPEAT", "END_FUNCTION",
    "END_FUNCTION_BLOCK", "END_PROGRAM", "END_VAR", "END_TYPE", "END_STRUCT", "END_CONFIGURATION", "END_RESOURCE"
])

ITEM_START = frozenset([
    "FUNCTION", "FUNCTION_BLOCK", "PROGRAM", "TYPE", "CONFIGURATION", "VAR_GLOBAL", "NAMESPACE", "END_NAMESPACE"
])

STMT_START = frozenset(["IF", "CASE", "FOR", "WHILE", "REPEAT", "EXIT", "CONTINUE", "RETURN"])

MAX_DEPTH = 200          # nesting of expressions / statements before ST0203


class ParseError(Exception):
    """Internal: an error was reported at the current token; unwind to the nearest recovery point."""


class TokenCursor:
    """The tokens of one file (pragmas set aside), the current position, the nesting depth and the END_*
    words the enclosing constructs expect; reports syntax errors into ``diags``."""

    def __init__(self, src: SourceFile, tokens: list[Token], diags: DiagnosticBag) -> None:
        self.src = src
        self.diags = diags
        self.pragmas: list[Token] = [t for t in tokens if t.kind == "PRAGMA"]
        self.toks = [t for t in tokens if t.kind != "PRAGMA"]
        self.i = 0
        self.depth = 0
        self.end_stack: list[str] = []   # END_* words the enclosing constructs expect

    # ---- cursor ---------------------------------------------------------------------------------
    @property
    def tok(self) -> Token:
        return self.toks[self.i]

    def peek(self, k: int = 1) -> Token:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else self.toks[-1]

    def advance(self) -> Token:
        t = self.toks[self.i]
        if t.kind != "EOF":
            self.i += 1
        return t

    def at_kw(self, word: str) -> bool:
        t = self.toks[self.i]
        return t.kind == "IDENT" and t.up == word

    def at_any_kw(self, words: Container[str]) -> bool:
        t = self.toks[self.i]
        return t.kind == "IDENT" and t.up in words

    def at_op(self, op: str) -> bool:
        t = self.toks[self.i]
        return t.kind == "OP" and t.text == op

    def accept_kw(self, word: str) -> bool:
        if self.at_kw(word):
            self.i += 1
            return True
        return False

    def accept_op(self, op: str) -> bool:
        if self.at_op(op):
            self.i += 1
            return True
        return False

    def expect_kw(self, word: str, context: str = "") -> Token:
        if self.at_kw(word):
            return self.advance()
        self.fail_expected(f"`{word}`", context)

    def expect_op(self, op: str, context: str = "") -> Token:
        if self.at_op(op):
            return self.advance()
        self.fail_expected(f"`{op}`", context)

    def ident(self, what: str = "a name") -> Token:
        t = self.tok
        if t.kind == "IDENT" and t.up not in RESERVED:
            return self.advance()
        if t.kind == "IDENT":
            self.fail(f"`{t.text}` is a reserved keyword and cannot be used as {what}; choose another name")
        self.fail_expected(what)

    # ---- spans and errors ---------------------------------------------------------------------
    def span_from(self, start: int) -> Span:
        prev = self.toks[self.i - 1] if self.i > 0 else self.toks[0]
        return Span(self.src, start, max(start, prev.end))

    def tok_span(self, t: Token | None = None) -> Span:
        t = t or self.tok
        if t.kind == "EOF":
            return Span(self.src, max(0, t.start - 1) if t.start else 0, t.start)
        return Span(self.src, t.start, t.end)

    def describe(self, t: Token) -> str:
        if t.kind == "EOF":
            return "end of file"
        text = t.text if len(t.text) <= 40 else t.text[:37] + "..."
        return f"`{text}`"

    def fail(self, message: str, code: str = codes.UNEXPECTED_TOKEN, t: Token | None = None) -> NoReturn:
        self.diags.error(code, message, self.tok_span(t))
        raise ParseError()

    def fail_expected(self, what: str, context: str = "") -> NoReturn:
        found = self.describe(self.tok)
        ctx = f" {context}" if context else ""
        code = codes.MISSING_END if self.tok.kind == "EOF" or self.at_any_kw(BLOCK_END) else codes.UNEXPECTED_TOKEN
        self.fail(f"expected {what}{ctx}, found {found}", code)

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            self.depth = 0
            self.diags.error(codes.NESTING_TOO_DEEP,
                             f"nesting is deeper than {MAX_DEPTH} levels; split the expression or "
                             "statement using intermediate variables", self.tok_span())
            raise DepthExceeded()

    def leave(self) -> None:
        self.depth -= 1

    # ---- recovery -------------------------------------------------------------------------------
    def sync_statement(self) -> None:
        """Skip to just after the next `;`, or stop in front of a block keyword."""
        start = self.i
        while True:
            t = self.tok
            if t.kind == "EOF":
                return
            if t.kind == "OP" and t.text == ";":
                self.advance()
                return
            if t.kind == "IDENT" and (t.up in BLOCK_END or t.up in ITEM_START or
                                      (t.up in STMT_START and self.i > start)):
                if self.i == start and t.up in BLOCK_END:
                    return
                return
            self.advance()

    def skip_declaration(self, end_word: str, before: int) -> None:
        """Recover inside a declaration list: skip past the next `;`, stopping in front of ``end_word``."""
        while self.tok.kind != "EOF" and not self.at_op(";") and not self.at_kw(end_word):
            self.advance()
        self.accept_op(";")
        if self.i == before:
            self.advance()

    def sync_item(self) -> None:
        """Skip to the next top-level item (FUNCTION, TYPE, ...), after its END_* if we are inside one."""
        while self.tok.kind != "EOF":
            if self.at_any_kw(ITEM_START) and not self.at_kw("VAR_GLOBAL"):
                return
            self.advance()


class DepthExceeded(Exception):
    """Internal: nesting limit hit; unwinds to the enclosing top-level item."""
