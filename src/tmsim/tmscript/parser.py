"""Lexer and parser for the TM script lines sent in TMSCT packets.

One statement per line. Grammar (informal)::

    line      = "" | decl | assign | incdec | expr
    decl      = TYPE ["[" "]"] NAME ["=" expr]           TYPE = int|float|double|string|bool|byte
    assign    = target ("=" | "+=" | "-=" | "*=" | "/=") expr
    incdec    = target ("++" | "--")
    target    = NAME { "[" expr "]" | "." NAME }
    expr      = or ;  or = and {"||" and} ; and = cmp {"&&" cmp} ; cmp = add [CMPOP add]
    add       = mul {("+"|"-") mul} ; mul = unary {("*"|"/"|"%") unary} ; unary = ("-"|"!"|"+") unary | postfix
    postfix   = primary { "[" expr "]" | "." NAME }
    primary   = NUMBER | STRING | true | false | NAME ["(" [expr {"," expr}] ")"] | "{" [expr {"," expr}] "}"
              | "(" expr ")"

Bounds (tmsim/limits.py), each a syntax error of its line (``ERROR;line``): at most TOKENS_MAX tokens per
script (a line that is a call with constant arguments only - a motion line - counts as one), DEPTH_MAX
levels of nesting per expression, STATEMENTS_MAX statements per script, string constants of at most
STRING_MAX characters, hexadecimal constants of at most 32 bits. A decimal integer constant beyond the
int range is a float constant ([MAN 2.24 §2.2]: constants take the smallest type that holds them).

The tokenizer and the parse methods are generators that yield every PARSE_SLICE tokens, so the simulator
can parse a long line in pieces between its other robots' turns (``iter_lines``); ``split_lines`` and
``parse_line`` run them through at once.
"""
from __future__ import annotations

import re
from collections.abc import Generator, Iterator
from dataclasses import dataclass, field
from typing import Any

from tmsim.limits import DEPTH_MAX, HEX_DIGITS_MAX, INT_MAX, PARSE_SLICE, STATEMENTS_MAX, STRING_MAX, TOKENS_MAX

TYPES = frozenset({"int", "float", "double", "string", "bool", "byte"})


class ScriptSyntaxError(Exception):
    """A line that cannot be parsed; ``str()`` says what was expected."""


# ---- AST ------------------------------------------------------------------------------------------
@dataclass
class Num:
    value: float | int
    is_float: bool


@dataclass
class Str:
    value: str


@dataclass
class Bool:
    value: bool


@dataclass
class Name:
    id: str


@dataclass
class Index:
    obj: object
    index: object


@dataclass
class Member:
    obj: object
    name: str


@dataclass
class Call:
    name: str
    args: list


@dataclass
class Array:
    items: list


@dataclass
class Unary:
    op: str
    operand: object


@dataclass
class Binary:
    op: str
    left: object
    right: object


@dataclass
class Decl:
    type: str
    is_array: bool
    name: str
    init: object = None


@dataclass
class Assign:
    target: object
    op: str
    value: object


@dataclass
class IncDec:
    target: object
    op: str


@dataclass
class ExprStmt:
    expr: object


@dataclass
class Empty:
    pass


@dataclass
class Line:
    number: int          # 1-based line number inside the script
    text: str
    stmt: object = None
    error: str | None = None
    warnings: list = field(default_factory=list)


# ---- lexer ----------------------------------------------------------------------------------------
_TOKEN = re.compile(r"""
    (?P<ws>[ \t]+)
  | (?P<comment>//.*)
  | (?P<hex>0[xX][0-9A-Fa-f]+)
  | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_]\w*)
  | (?P<str>"(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')
  | (?P<op>\+\+|--|\+=|-=|\*=|/=|==|!=|<=|>=|&&|\|\||[()\[\]{},.=+\-*/%<>!])
""", re.VERBOSE)
_ESCAPES = {"n": "\n", "t": "\t", "r": "\r"}


def _unescape(body: str) -> str:
    if "\\" not in body:
        return body
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(1)), body)


def number_value(text: str) -> tuple[int | float, bool]:
    """(value, is_float) of a decimal or 0x constant; ScriptSyntaxError when it cannot be a TM number.

    [MAN 2.24 §2.2] a constant takes the smallest type that holds it: a decimal integer beyond int
    (32 bits; 2147483648 is kept so that -2147483648 works) is a float constant; a float constant
    beyond the double range reads as infinity (a motion with it is a robot error, a variable refuses it).
    A hexadecimal constant is 32 bits at most: 0x80000000..0xFFFFFFFF are the negative ints.
    """
    if text[:2] in ("0x", "0X"):
        digits = text[2:].lstrip("0")
        if len(digits) > HEX_DIGITS_MAX:
            raise ScriptSyntaxError(f"hexadecimal constant {text[:12]}... is wider than 32 bits")
        value = int(digits or "0", 16)
        return (value - (1 << 32) if value > INT_MAX else value), False
    if "." in text or "e" in text or "E" in text:
        return float(text), True
    if len(text) <= 10 and int(text) <= INT_MAX + 1:
        return int(text), False
    return float(text), True


_TOO_LONG = f"script longer than {TOKENS_MAX} elements (names, numbers, operators); split it into packets"


def tokenize(text: str) -> list[tuple[str, object]]:
    """Return (kind, value) tokens: num, str, name, op; raises ScriptSyntaxError."""
    tokens: list[tuple[str, object]] = []
    for _ in _tokenize(text, tokens):
        pass
    return tokens


def _tokenize(text: str, tokens: list):
    """``tokenize`` as a generator that fills ``tokens`` and yields every PARSE_SLICE tokens (a long line is
    tokenized in pieces, see ``iter_lines``)."""
    pos, n, pause_at = 0, len(text), PARSE_SLICE
    match = _TOKEN.match
    while pos < n:
        m = match(text, pos)
        if m is None:
            if text[pos] in "\"'":
                raise ScriptSyntaxError(f"string starting at column {pos + 1} is not closed")
            raise ScriptSyntaxError(f"unexpected character {text[pos]!r} at column {pos + 1}")
        kind, value, end = m.lastgroup, m.group(), m.end()
        if kind in ("num", "hex"):
            if end < n and (text[end].isalnum() or text[end] == "_"):
                raise ScriptSyntaxError(f"malformed number at column {pos + 1}")
            tokens.append(("num", number_value(value)))
        elif kind == "name" or kind == "op":
            tokens.append((kind, value))
        elif kind == "str":
            if end - pos - 2 > STRING_MAX:
                raise ScriptSyntaxError(f"string constant longer than {STRING_MAX} characters")
            tokens.append(("str", _unescape(value[1:-1])))
        pos = end
        if len(tokens) > TOKENS_MAX:
            raise ScriptSyntaxError(_TOO_LONG)
        if len(tokens) >= pause_at:
            pause_at += PARSE_SLICE
            yield len(tokens)
    tokens.append(("end", None))


# ---- parser ---------------------------------------------------------------------------------------
class _Parser:
    def __init__(self, tokens):
        self.toks = tokens
        self.pos = 0
        self.last = len(tokens) - 1
        self.nesting = 0                # expressions open right now (parentheses, arguments, unary chains)
        self.pause_at = PARSE_SLICE     # the parse methods are generators: they yield the token position
                                        # every PARSE_SLICE tokens, so a long line can be parsed in pieces

    def peek(self, offset=0):
        index = self.pos + offset
        return self.toks[index] if index < self.last else self.toks[self.last]

    def next(self):
        tok = self.toks[self.pos]
        self.pos += 1
        return tok

    def accept(self, value):
        if self.toks[self.pos] == ("op", value):
            self.pos += 1
            return True
        return False

    def expect(self, value):
        if not self.accept(value):
            raise ScriptSyntaxError(f"expected '{value}' but found {_describe(self.peek())}")

    def line(self):
        """The statement of the whole line, parsed at once."""
        return _finish(self.steps())

    # grammar: line = "" | decl | assign | incdec | expr
    def steps(self):
        if self.peek()[0] == "end":
            return Empty()
        kind, value = self.peek()
        if kind == "name" and value in TYPES and self.peek(1)[0] in ("name",) or (
                kind == "name" and value in TYPES and self.peek(1) == ("op", "[") and self.peek(2) == ("op", "]")):
            stmt = yield from self.decl()
        else:
            expr = yield from self.expr()
            kind, value = self.peek()
            if kind == "op" and value in ("=", "+=", "-=", "*=", "/="):
                self.next()
                _check_target(expr)
                stmt = Assign(expr, value, (yield from self.expr()))
            elif kind == "op" and value in ("++", "--"):
                self.next()
                _check_target(expr)
                stmt = IncDec(expr, value)
            else:
                stmt = ExprStmt(expr)
        if self.peek()[0] != "end":
            raise ScriptSyntaxError(f"unexpected {_describe(self.peek())} after the statement")
        return stmt

    # grammar: decl = TYPE ["[" "]"] NAME ["=" expr]
    def decl(self):
        type_name = self.next()[1]
        is_array = False
        if self.accept("["):
            self.expect("]")
            is_array = True
        kind, name = self.next()
        if kind != "name" or name in TYPES:
            raise ScriptSyntaxError(f"expected a variable name after '{type_name}'")
        init = (yield from self.expr()) if self.accept("=") else None
        return Decl("float" if type_name == "double" else type_name, is_array, name, init)

    def expr(self):
        self.nesting += 1
        if self.nesting > DEPTH_MAX:
            raise ScriptSyntaxError(f"expression nested deeper than {DEPTH_MAX} levels")
        node = yield from self.binary(1)
        self.nesting -= 1
        return node

    _PRECEDENCE = {"||": 1, "&&": 2, "==": 3, "!=": 3, "<": 3, ">": 3, "<=": 3, ">=": 3,
                   "+": 4, "-": 4, "*": 5, "/": 5, "%": 5}

    # grammar: binary operators by precedence climbing, all left-associative:
    #          || < && < comparisons < + - < * / %
    def binary(self, min_prec):
        left = yield from self.unary()
        while True:
            kind, op = self.toks[self.pos]
            prec = self._PRECEDENCE.get(op, 0) if kind == "op" else 0
            if prec < min_prec:
                return left
            self.pos += 1
            left = Binary(op, left, (yield from self.binary(prec + 1)))

    # grammar: unary = ("-"|"!"|"+") unary | postfix
    def unary(self):
        if self.peek()[0] == "op" and self.peek()[1] in ("-", "!", "+"):
            op = self.next()[1]
            self.nesting += 1
            if self.nesting > DEPTH_MAX:
                raise ScriptSyntaxError(f"expression nested deeper than {DEPTH_MAX} levels")
            operand = yield from self.unary()
            self.nesting -= 1
            if op == "-" and isinstance(operand, Num):
                return Num(-operand.value, operand.is_float)
            return operand if op == "+" else Unary(op, operand)
        return (yield from self.postfix())

    # grammar: postfix = primary { "[" expr "]" | "." NAME }
    def postfix(self):
        node = yield from self.primary()
        while True:
            if self.accept("["):
                node = Index(node, (yield from self.expr()))
                self.expect("]")
            elif self.accept("."):
                kind, name = self.next()
                if kind != "name":
                    raise ScriptSyntaxError("expected a member name after '.'")
                node = Member(node, name)
            else:
                return node

    # grammar: primary = NUMBER | STRING | BOOL | NAME [call] | array | "(" expr ")"
    def primary(self):
        if self.pos >= self.pause_at:            # a long line: let the caller spread it over turns
            self.pause_at = self.pos + PARSE_SLICE
            yield self.pos
        kind, value = self.next()
        if kind == "num":
            return Num(value[0], value[1])
        if kind == "str":
            return Str(value)
        if kind == "name":
            if value in ("true", "false"):
                return Bool(value == "true")
            if self.accept("("):
                return Call(value, (yield from self.items(")")))
            return Name(value)
        if (kind, value) == ("op", "{"):
            return Array((yield from self.items("}")))
        if (kind, value) == ("op", "("):
            node = yield from self.expr()
            self.expect(")")
            return node
        raise ScriptSyntaxError(f"unexpected {_describe((kind, value))}")

    def items(self, closer):
        items: list[object] = []
        if self.accept(closer):
            return items
        while True:
            items.append((yield from self.expr()))
            if self.accept(closer):
                return items
            self.expect(",")


def _check_target(expr):
    if not isinstance(expr, (Name, Index, Member)):
        raise ScriptSyntaxError("the left side of an assignment must be a variable or an IO point")


def _check_depth(stmt):
    """ScriptSyntaxError when an expression of ``stmt`` nests deeper than DEPTH_MAX (e.g. a sum of more
    than DEPTH_MAX terms: each '+' holds the terms before it)."""
    stack = [(stmt, 0)]
    while stack:
        node, depth = stack.pop()
        if depth > DEPTH_MAX:
            raise ScriptSyntaxError(f"expression nested deeper than {DEPTH_MAX} levels")
        kind = type(node)
        if kind is Binary:
            stack += ((node.left, depth + 1), (node.right, depth + 1))
        elif kind is Call or kind is Array:
            stack += ((item, depth + 1) for item in (node.args if kind is Call else node.items))
        elif kind is Unary:
            stack.append((node.operand, depth + 1))
        elif kind is Index:
            stack += ((node.obj, depth + 1), (node.index, depth + 1))
        elif kind is Member:
            stack.append((node.obj, depth + 1))
        elif kind is Decl:
            if node.init is not None:
                stack.append((node.init, depth))
        elif kind is Assign:
            stack += ((node.target, depth), (node.value, depth))
        elif kind is IncDec:
            stack.append((node.target, depth))
        elif kind is ExprStmt:
            stack.append((node.expr, depth))


def _describe(tok):
    kind, value = tok
    if kind == "end":
        return "end of line"
    if kind == "str":
        return f"string \"{value}\""
    if kind == "num":
        return f"number {value[0]}"
    return f"'{value}'"


_CACHE: dict[str, tuple[object, int]] = {}
_CACHE_SIZE = 4096
_CACHE_LINE = 512          # longer lines are not kept: the cache stays below ~4 MB


# A call whose arguments are all plain literals - the shape of nearly every streamed motion line,
# e.g. Line("CAR",380,-100,350,180,0,90,400,100,50,true) - is parsed by two regular expressions
# instead of the tokenizer and the recursive descent (4x faster). Anything else (names, operators,
# arrays, escapes, comments, hex, '+' signs, malformed numbers) returns None and takes the full path,
# which yields the same tree for these lines (tests/sim/test_script.py compares both).
_LITERAL = r"""(?:-?[ \t]*(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|"[^"\\,]*"|(?:true|false)(?!\w))"""
_SIMPLE_CALL = re.compile(rf"[ \t]*([A-Za-z_]\w*)[ \t]*\(((?:[ \t]*{_LITERAL}[ \t]*(?:,[ \t]*{_LITERAL}[ \t]*)*)?"
                          rf"|[ \t]*)\)[ \t]*")


def _simple_call(text: str):
    """ExprStmt(Call(...)) for a call whose arguments are literals (no comma inside a string), else None.
    One regular expression checks the whole line; the arguments are then split at the commas."""
    match = _SIMPLE_CALL.fullmatch(text)
    if match is None or match.group(1) in ("true", "false"):
        return None
    body, args = match.group(2), list[Str | Bool | Num]()
    if body.strip(" \t"):
        for piece in body.split(","):
            piece = piece.strip(" \t")
            first = piece[0]
            if first == '"':
                args.append(Str(piece[1:-1]))
            elif first == "t" or first == "f":
                args.append(Bool(first == "t"))
            else:
                minus = first == "-"
                value, is_float = number_value(piece[1:].lstrip(" \t") if minus else piece)
                args.append(Num(-value if minus else value, is_float))
    return ExprStmt(Call(match.group(1), args))


def _parse(text: str) -> tuple[object, int]:
    """(statement node or ScriptSyntaxError, tokens it counts against TOKENS_MAX).

    Statement trees are never modified after parsing, so the results of recently seen short lines are
    cached (PLC clients send the same lines again and again).
    """
    cached = _CACHE.get(text)
    if cached is None:
        cached = _finish(_parse_steps(text))
        if len(text) <= _CACHE_LINE:
            if len(_CACHE) >= _CACHE_SIZE:
                _CACHE.clear()
            _CACHE[text] = cached
    return cached


def _finish(steps: Generator[Any, Any, tuple[object, int]]) -> tuple[object, int]:
    """Run a generator of the parser to its end; its return value."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


def _parse_steps(text: str):
    """``_parse`` without the cache, as a generator: it yields after every PARSE_SLICE tokens tokenized or
    parsed and returns (statement node or ScriptSyntaxError, tokens)."""
    cost = 1
    try:
        stmt = _simple_call(text)
        if stmt is None:
            tokens: list[tuple[str, object]] = []
            yield from _tokenize(text, tokens)
            cost = len(tokens)
            stmt = yield from _Parser(tokens).steps()
            _check_depth(stmt)
    except ScriptSyntaxError as exc:
        stmt = exc
    except RecursionError:
        stmt = ScriptSyntaxError(f"expression nested deeper than {DEPTH_MAX} levels")
    return stmt, cost


def parse_line(text: str) -> object:
    """Parse one script line into a statement node; raises ScriptSyntaxError."""
    stmt = _parse(text)[0]
    if isinstance(stmt, ScriptSyntaxError):
        raise stmt
    return stmt


def split_lines(script: str) -> list[Line]:
    """Split a script on CR LF (the protocol's line separator) and parse each line. The line that goes
    beyond STATEMENTS_MAX statements or TOKENS_MAX tokens is an error; the lines after it are not parsed."""
    return [line for line in iter_lines(script) if type(line) is Line]


def iter_lines(script: str) -> Iterator[Line | int]:
    """``split_lines`` as a generator, so that a caller can spread the parsing of a long script over
    several turns of the simulator's scheduler: it yields each Line, and while it parses a line longer
    than the cache keeps (_CACHE_LINE), the number PARSE_SLICE after every PARSE_SLICE tokens."""
    statements, tokens, full = 0, 0, False
    for number, text in enumerate(script.split("\r\n"), start=1):
        line = Line(number, text)
        if full:
            line.stmt = Empty()
            yield line
            continue
        if "\r" in text or "\n" in text:
            line.error = "lines must be separated by CR LF"
            yield line
            continue
        if len(text) <= _CACHE_LINE:
            stmt, cost = _parse(text)
        else:
            steps = _parse_steps(text)
            while True:
                try:
                    next(steps)
                except StopIteration as done:
                    stmt, cost = done.value
                    break
                yield PARSE_SLICE
        if isinstance(stmt, Empty):
            line.stmt = stmt
            yield line
            continue
        statements += 1
        tokens += cost
        if statements > STATEMENTS_MAX:
            line.error = f"a script holds at most {STATEMENTS_MAX} statements; send the rest in another packet"
        elif tokens > TOKENS_MAX:
            line.error = _TOO_LONG
        elif isinstance(stmt, ScriptSyntaxError):
            line.error = str(stmt)
        else:
            line.stmt = stmt
        full = statements > STATEMENTS_MAX or tokens > TOKENS_MAX
        yield line
