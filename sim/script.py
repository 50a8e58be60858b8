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
    primary   = NUMBER | STRING | true | false | NAME ["(" [expr {"," expr}] ")"] | "{" [expr {"," expr}] "}" | "(" expr ")"
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

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


def tokenize(text: str) -> list[tuple[str, object]]:
    """Return (kind, value) tokens: num, str, name, op; raises ScriptSyntaxError."""
    tokens, pos, n = [], 0, len(text)
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
            if kind == "hex":
                tokens.append(("num", (int(value, 16), False)))
            elif "." in value or "e" in value or "E" in value:
                tokens.append(("num", (float(value), True)))
            else:
                tokens.append(("num", (int(value), False)))
        elif kind == "name" or kind == "op":
            tokens.append((kind, value))
        elif kind == "str":
            tokens.append(("str", _unescape(value[1:-1])))
        pos = end
    tokens.append(("end", None))
    return tokens


# ---- parser ---------------------------------------------------------------------------------------
class _Parser:
    def __init__(self, tokens):
        self.toks = tokens
        self.pos = 0
        self.last = len(tokens) - 1

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

    # grammar: line = "" | decl | assign | incdec | expr
    def line(self):
        if self.peek()[0] == "end":
            return Empty()
        kind, value = self.peek()
        if kind == "name" and value in TYPES and self.peek(1)[0] in ("name",) or (
                kind == "name" and value in TYPES and self.peek(1) == ("op", "[") and self.peek(2) == ("op", "]")):
            stmt = self.decl()
        else:
            expr = self.expr()
            kind, value = self.peek()
            if kind == "op" and value in ("=", "+=", "-=", "*=", "/="):
                self.next()
                _check_target(expr)
                stmt = Assign(expr, value, self.expr())
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
        init = self.expr() if self.accept("=") else None
        return Decl("float" if type_name == "double" else type_name, is_array, name, init)

    def expr(self):
        return self.binary(1)

    _PRECEDENCE = {"||": 1, "&&": 2, "==": 3, "!=": 3, "<": 3, ">": 3, "<=": 3, ">=": 3,
                   "+": 4, "-": 4, "*": 5, "/": 5, "%": 5}

    # grammar: binary operators by precedence climbing, all left-associative:
    #          || < && < comparisons < + - < * / %
    def binary(self, min_prec):
        left = self.unary()
        while True:
            kind, op = self.toks[self.pos]
            prec = self._PRECEDENCE.get(op, 0) if kind == "op" else 0
            if prec < min_prec:
                return left
            self.pos += 1
            left = Binary(op, left, self.binary(prec + 1))

    # grammar: unary = ("-"|"!"|"+") unary | postfix
    def unary(self):
        if self.peek()[0] == "op" and self.peek()[1] in ("-", "!", "+"):
            op = self.next()[1]
            operand = self.unary()
            if op == "-" and isinstance(operand, Num):
                return Num(-operand.value, operand.is_float)
            return operand if op == "+" else Unary(op, operand)
        return self.postfix()

    # grammar: postfix = primary { "[" expr "]" | "." NAME }
    def postfix(self):
        node = self.primary()
        while True:
            if self.accept("["):
                node = Index(node, self.expr())
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
        kind, value = self.next()
        if kind == "num":
            return Num(value[0], value[1])
        if kind == "str":
            return Str(value)
        if kind == "name":
            if value in ("true", "false"):
                return Bool(value == "true")
            if self.accept("("):
                return Call(value, self.items(")"))
            return Name(value)
        if (kind, value) == ("op", "{"):
            return Array(self.items("}"))
        if (kind, value) == ("op", "("):
            node = self.expr()
            self.expect(")")
            return node
        raise ScriptSyntaxError(f"unexpected {_describe((kind, value))}")

    def items(self, closer):
        items = []
        if self.accept(closer):
            return items
        while True:
            items.append(self.expr())
            if self.accept(closer):
                return items
            self.expect(",")


def _check_target(expr):
    if not isinstance(expr, (Name, Index, Member)):
        raise ScriptSyntaxError("the left side of an assignment must be a variable or an IO point")


def _describe(tok):
    kind, value = tok
    if kind == "end":
        return "end of line"
    if kind == "str":
        return f"string \"{value}\""
    if kind == "num":
        return f"number {value[0]}"
    return f"'{value}'"


_CACHE: dict[str, object] = {}
_CACHE_SIZE = 4096


# A call whose arguments are all plain literals - the shape of nearly every streamed motion line,
# e.g. Line("CAR",380,-100,350,180,0,90,400,100,50,true) - is parsed by two regular expressions
# instead of the tokenizer and the recursive descent (4x faster). Anything else (names, operators,
# arrays, escapes, comments, hex, '+' signs, malformed numbers) returns None and takes the full path,
# which yields the same tree for these lines (tests/sim/test_script.py compares both).
_LITERAL = r"""(?:-?[ \t]*(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|"[^"\\,]*"|(?:true|false)(?!\w))"""
_SIMPLE_CALL = re.compile(r"[ \t]*([A-Za-z_]\w*)[ \t]*\(((?:[ \t]*%s[ \t]*(?:,[ \t]*%s[ \t]*)*)?|[ \t]*)\)[ \t]*"
                          % (_LITERAL, _LITERAL))


def _simple_call(text: str):
    """ExprStmt(Call(...)) for a call whose arguments are literals (no comma inside a string), else None.
    One regular expression checks the whole line; the arguments are then split at the commas."""
    match = _SIMPLE_CALL.fullmatch(text)
    if match is None or match.group(1) in ("true", "false"):
        return None
    body, args = match.group(2), []
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
                digits = piece[1:].lstrip(" \t") if minus else piece
                if "." in digits or "e" in digits or "E" in digits:
                    args.append(Num(-float(digits) if minus else float(digits), True))
                else:
                    args.append(Num(-int(digits) if minus else int(digits), False))
    return ExprStmt(Call(match.group(1), args))


def parse_line(text: str) -> object:
    """Parse one script line into a statement node; raises ScriptSyntaxError.

    Statement trees are never modified after parsing, so the results of recently seen lines are
    cached (PLC clients send the same lines again and again).
    """
    cached = _CACHE.get(text)
    if cached is None:
        try:
            cached = _simple_call(text) or _Parser(tokenize(text)).line()
        except ScriptSyntaxError as exc:
            cached = exc
        except RecursionError:
            cached = ScriptSyntaxError("expression nested too deeply")
        if len(_CACHE) >= _CACHE_SIZE:
            _CACHE.clear()
        _CACHE[text] = cached
    if isinstance(cached, ScriptSyntaxError):
        raise cached
    return cached


def split_lines(script: str) -> list[Line]:
    """Split a script on CR LF (the protocol's line separator) and parse each line."""
    lines = []
    for number, text in enumerate(script.split("\r\n"), start=1):
        line = Line(number, text)
        try:
            if "\r" in text or "\n" in text:
                raise ScriptSyntaxError("lines must be separated by CR LF")
            line.stmt = parse_line(text)
        except ScriptSyntaxError as exc:
            line.error = str(exc)
        lines.append(line)
    return lines
