"""Expression grammar (IEC 61131-3 precedence, left-associative binary operators).

:class:`ExpressionParser` reads expressions, call arguments and qualified names from a :class:`TokenCursor`;
the statement and declaration parsers (parser_stmts.py, parser.py) hold one and call it.

Precedence, lowest first: OR; XOR; AND &; = <>; < > <= >=; + -; * / MOD; unary - + NOT; **; postfix.
"""
from __future__ import annotations

import calendar
import math
import re

from . import ast as A
from . import codes
from .lexer import Token, decode_string
from .parser_base import MAX_DEPTH, RESERVED, TokenCursor

BINARY_PREC = {"OR": 1, "XOR": 2, "AND": 3, "&": 3, "=": 4, "<>": 4, "<": 5, ">": 5, "<=": 5, ">=": 5,
               "+": 6, "-": 6, "*": 7, "/": 7, "MOD": 7}

INT_PREFIXES = {"SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD"}
REAL_PREFIXES = {"REAL", "LREAL"}
MAX_INT_DIGITS = 1000          # far beyond any 64-bit value, far below Python's 4,300-digit int() limit
_UNIT_NS = {"D": 86_400_000_000_000, "H": 3_600_000_000_000, "M": 60_000_000_000, "S": 1_000_000_000,
            "MS": 1_000_000, "US": 1_000, "NS": 1}
_DUR_PART = re.compile(r"([0-9][0-9_]*(?:\.[0-9_]+)?)(ms|us|ns|d|h|m|s)_?", re.I)
_CLOCK_RE = re.compile(r"([0-9]+):([0-9]+)(?::([0-9]+)(?:\.([0-9]+))?)?$")


def parse_duration(body: str) -> int | None:
    """``1h2m3s4ms`` / ``-5s`` / ``1.5s`` → nanoseconds (None when malformed)."""
    sign = 1
    if body[:1] in "+-":
        sign = -1 if body[0] == "-" else 1
        body = body[1:]
    pos = 0
    total = 0.0
    exact = 0
    for m in _DUR_PART.finditer(body):
        if m.start() != pos:
            return None
        num = m.group(1).replace("_", "")
        unit = _UNIT_NS[m.group(2).upper()]
        if len(num) > MAX_INT_DIGITS:
            exact += 10 ** MAX_INT_DIGITS * unit          # beyond any TIME: the checker's range rule reports it
        elif "." in num:
            total += float(num) * unit
        else:
            exact += int(num) * unit
        pos = m.end()
    if pos != len(body) or pos == 0:
        return None
    if not math.isfinite(total):
        total, exact = 0.0, exact + 10 ** MAX_INT_DIGITS
    return sign * (exact + round(total))


def parse_clock(text: str) -> int | None:
    m = _CLOCK_RE.match(text)
    if not m or len(text) > MAX_INT_DIGITS:
        return None
    h, mi, s = int(m.group(1)), int(m.group(2)), int(m.group(3) or 0)
    frac = m.group(4) or ""
    if h > 23 or mi > 59 or s > 59:
        return None
    ns = int((frac + "000000000")[:9]) if frac else 0
    return ((h * 60 + mi) * 60 + s) * 1_000_000_000 + ns


def parse_ymd(text: str) -> int | None:
    try:
        y, mo, d = (int(x) for x in text.split("-")[:3])
        if not (1 <= mo <= 12 and 1 <= d <= calendar.monthrange(y, mo)[1]):
            return None
        return calendar.timegm((y, mo, d, 0, 0, 0))
    except (ValueError, OverflowError):
        return None


_POSTFIX = frozenset((".", "[", "(", "^"))


class ExpressionParser:
    """Expressions at the cursor's position: each method consumes one construct and returns its AST node."""

    def __init__(self, cursor: TokenCursor) -> None:
        self.cur = cursor

    # grammar: expression := unary { binop unary }   (precedence climbing, BINARY_PREC)
    def expression(self, min_prec: int = 1) -> A.Expr:
        cur = self.cur
        cur.enter()
        start = cur.tok.start
        left = self.unary()
        chain = 0
        while True:
            t = cur.tok
            if t.kind == "OP":
                op = t.text
            elif t.kind == "IDENT" and t.up in ("OR", "XOR", "AND", "MOD"):
                op = t.up
            else:
                break
            prec = BINARY_PREC.get(op)
            if prec is None or prec < min_prec:
                break
            cur.advance()
            right = self.expression(prec + 1)
            chain += 1
            if chain + cur.depth > 2 * MAX_DEPTH:
                cur.fail("expression has too many operators in a row (over 400); split it using "
                         "intermediate variables", codes.NESTING_TOO_DEEP)
            left = A.Binary("AND" if op == "&" else op, left, right, span=cur.span_from(start))
        cur.leave()
        return left

    # grammar: unary := ('-' | '+' | NOT) unary | power
    def unary(self) -> A.Expr:
        cur = self.cur
        t = cur.tok
        if (t.kind == "OP" and t.text in "-+" and t.text) or (t.kind == "IDENT" and t.up == "NOT"):
            cur.advance()
            cur.enter()
            operand = self.unary()
            cur.leave()
            op = "NOT" if t.kind == "IDENT" else t.text
            return A.Unary(op, operand, span=cur.span_from(t.start))
        return self.power()

    # grammar: power := postfix { '**' unary }
    def power(self) -> A.Expr:
        cur = self.cur
        start = cur.tok.start
        left = self.postfix()
        chain = 0
        while cur.at_op("**"):
            cur.advance()
            cur.enter()
            right = self.unary() if (cur.at_op("-") or cur.at_op("+")) else self.postfix()
            cur.leave()
            chain += 1               # each one nests the tree a level deeper, as the binary operators' chain does
            if chain + cur.depth > 2 * MAX_DEPTH:
                cur.fail("expression has too many operators in a row (over 400); split it using "
                         "intermediate variables", codes.NESTING_TOO_DEEP)
            left = A.Binary("**", left, right, span=cur.span_from(start))
        return left

    # grammar: postfix := primary { '.' ident | '.' digit | '[' expr {',' expr} ']' | '(' args ')' }
    def postfix(self) -> A.Expr:
        cur = self.cur
        start = cur.tok.start
        node = self.primary()
        parts = 0
        while True:
            t = cur.tok
            if t.kind == "OP" and t.text in _POSTFIX:
                parts += 1           # each member, index and call nests the tree a level deeper
                if parts + cur.depth > 2 * MAX_DEPTH:
                    cur.fail(f"too many members, indexes and calls in a row (over {2 * MAX_DEPTH}); split the "
                             "expression using intermediate variables", codes.NESTING_TOO_DEEP)
            if cur.at_op("."):
                cur.advance()
                t = cur.tok
                if t.kind == "INT":
                    cur.advance()
                    node = A.BitAccess(node, self.decimal_value(t), span=cur.span_from(start))
                    continue
                name = cur.ident("a member name after `.`")
                node = A.Member(node, name.text, span=cur.span_from(start))
            elif cur.at_op("["):
                cur.advance()
                idx = [self.expression()]
                while cur.accept_op(","):
                    idx.append(self.expression())
                cur.expect_op("]", "to close the index")
                node = A.Index(node, idx, span=cur.span_from(start))
            elif cur.at_op("("):
                if not isinstance(node, (A.Name, A.Member, A.Index)):
                    break
                args = self.call_args()
                node = A.Call(node, args, span=cur.span_from(start))
            elif cur.at_op("^"):
                cur.fail("pointer dereference `^` is not supported; IEC 61131-3 2nd edition and Sysmac "
                         "libraries do not use pointers")
            else:
                break
        return node

    # grammar: args := '(' [ arg { ',' arg } ] ')' ; arg := [NOT] ident ('=>' [expr]) | ident ':=' expr | expr
    def call_args(self) -> list[A.Arg]:
        cur = self.cur
        cur.expect_op("(")
        args: list[A.Arg] = []
        if cur.accept_op(")"):
            return args
        while True:
            start = cur.tok.start
            t, nxt = cur.tok, cur.peek()
            negated = False
            if t.kind == "IDENT" and t.up == "NOT" and nxt.kind == "IDENT" and cur.peek(2).text == "=>":
                negated = True
                cur.advance()
                t, nxt = cur.tok, cur.peek()
            if t.kind == "IDENT" and nxt.kind == "OP" and nxt.text in (":=", "=>") and t.up not in RESERVED:
                cur.advance()
                cur.advance()
                if nxt.text == "=>":
                    value = None if (cur.at_op(",") or cur.at_op(")")) else self.expression()
                    args.append(A.Arg(t.text, value, True, negated, span=cur.span_from(start)))
                else:
                    args.append(A.Arg(t.text, self.expression(), span=cur.span_from(start)))
            else:
                args.append(A.Arg(None, self.expression(), span=cur.span_from(start)))
            if cur.accept_op(","):
                continue
            cur.expect_op(")", "to close the argument list")
            return args

    # grammar: qualname := ['\'|'\\'] ident { ('\'|'\\') ident }
    def qualname(self, what: str = "a name") -> tuple[A.QualName, str | None]:
        """Parse a possibly namespace-qualified name. Returns (name, enum_value) where enum_value is set
        when the last part was ``Type#Value``."""
        cur = self.cur
        start = cur.tok.start
        cur.accept_op("\\\\") or cur.accept_op("\\")
        parts: list[str] = []
        while True:
            t = cur.tok
            if t.kind == "TYPED":
                cur.advance()
                parts.append(t.text[:-1])
                value = cur.tok
                if value.kind != "IDENT":
                    cur.fail_expected("an enumeration value after `#`")
                cur.advance()
                return A.QualName(parts[-1], tuple(parts[:-1]), span=cur.span_from(start)), value.text
            parts.append(cur.ident(what).text)
            if (cur.at_op("\\") or cur.at_op("\\\\")) and cur.peek().kind in ("IDENT", "TYPED"):
                cur.advance()
                continue
            return A.QualName(parts[-1], tuple(parts[:-1]), span=cur.span_from(start)), None

    # grammar: primary := literal | typed_literal | enum_literal | qualname | '(' expression ')'
    def primary(self) -> A.Expr:
        cur = self.cur
        t = cur.tok
        kind = t.kind
        start = t.start
        if kind == "INT":
            cur.advance()
            return A.Literal("int", self.decimal_value(t), None, t.text, span=cur.tok_span(t))
        if kind == "BASED":
            cur.advance()
            return A.Literal("int", self.based_value(t), None, t.text, span=cur.tok_span(t))
        if kind == "REAL":
            cur.advance()
            return A.Literal("real", float(t.text.replace("_", "")), None, t.text, span=cur.tok_span(t))
        if kind in ("STRING", "WSTRING"):
            cur.advance()
            value, err = decode_string(t.text[1:-1], kind == "WSTRING")
            if err:
                cur.diags.error(codes.BAD_ESCAPE, err, cur.tok_span(t))
            return A.Literal(kind.lower(), value, None, t.text, span=cur.tok_span(t))
        if kind in ("TIME", "DATE", "TOD", "DT"):
            cur.advance()
            return self.temporal_literal(t)
        if kind == "TYPED":
            prefix = t.text[:-1].upper()
            if prefix in INT_PREFIXES or prefix in REAL_PREFIXES or prefix in ("BOOL", "STRING", "WSTRING"):
                return self.typed_literal(t, prefix)
            name, enum_value = self.qualname()
            assert enum_value is not None           # qualname() starting at `Type#` always reads the value
            return A.EnumLiteral(name, enum_value, span=cur.span_from(start))
        if kind == "IDENT":
            if t.up in ("MOD", "AND", "OR", "XOR") and cur.peek().kind == "OP" and cur.peek().text == "(":
                cur.advance()      # functional form of an operator: MOD(a, b), AND(a, b, c)
                return A.Name(A.QualName(t.up, span=cur.tok_span(t)), span=cur.tok_span(t))
            if t.up in ("TRUE", "FALSE"):
                cur.advance()
                return A.Literal("bool", t.up == "TRUE", None, t.text, span=cur.tok_span(t))
        if kind == "IDENT" or (kind == "OP" and t.text in ("\\", "\\\\")):
            name, enum_value = self.qualname()
            if enum_value is not None:
                return A.EnumLiteral(name, enum_value, span=cur.span_from(start))
            return A.Name(name, span=cur.span_from(start))
        if kind == "OP" and t.text == "(":
            cur.advance()
            inner = self.expression()
            cur.expect_op(")", "to close the parenthesis")
            return inner
        if kind == "ADDRESS":
            cur.fail("direct addresses (`%IX0.0`) are only allowed after AT in a declaration")
        cur.fail_expected("an expression")

    def decimal_value(self, t: Token) -> int:
        """A decimal integer literal; one far beyond 64 bits is reported here, before Python's int() refuses
        it (more than 4,300 digits), and the checker's range rule does the rest."""
        cur = self.cur
        digits = t.text.replace("_", "")
        if len(digits) > MAX_INT_DIGITS:
            cur.diags.error(codes.BAD_LITERAL, f"integer literal of {len(digits):,} digits: the largest integer types "
                            f"(LINT, ULINT, LWORD) hold at most 20 digits", cur.tok_span(t))
            return 0
        return int(digits)

    def based_value(self, t: Token) -> int:
        cur = self.cur
        base_text, digits = t.text.split("#", 1)
        base = int(base_text)
        digits = digits.replace("_", "")
        if base not in (2, 8, 16):
            cur.diags.error(codes.BAD_LITERAL, f"base {base} is not allowed in `{t.text}`; use 2#, 8# or 16#",
                            cur.tok_span(t))
            return 0
        try:
            return int(digits, base)
        except ValueError:
            cur.diags.error(codes.BAD_LITERAL, f"`{t.text}` contains digits that are not valid in base {base}",
                            cur.tok_span(t))
            return 0

    def typed_literal(self, prefix_tok: Token, prefix: str) -> A.Expr:
        cur = self.cur
        cur.advance()
        start = prefix_tok.start
        sign = ""
        if cur.at_op("-") or cur.at_op("+"):
            sign = cur.advance().text
        t = cur.tok
        text = cur.src.text[start:t.end]
        if t.kind in ("INT", "BASED", "REAL") and prefix not in ("STRING", "WSTRING"):
            cur.advance()
            if t.kind == "REAL":
                if prefix not in REAL_PREFIXES:
                    cur.fail(f"`{text}`: a {prefix} literal cannot have a fraction", codes.BAD_LITERAL, t)
                value = float(t.text.replace("_", ""))
            else:
                value = self.based_value(t) if t.kind == "BASED" else self.decimal_value(t)
            if sign == "-":
                value = -value
            if prefix in REAL_PREFIXES:
                return A.Literal("real", float(value), prefix, text, span=cur.span_from(start))
            if prefix == "BOOL":
                if value not in (0, 1):
                    cur.fail(f"`{text}`: BOOL literals are 0, 1, TRUE or FALSE", codes.BAD_LITERAL, t)
                return A.Literal("bool", bool(value), prefix, text, span=cur.span_from(start))
            return A.Literal("int", value, prefix, text, span=cur.span_from(start))
        if t.kind == "IDENT" and t.up in ("TRUE", "FALSE") and prefix == "BOOL" and not sign:
            cur.advance()
            return A.Literal("bool", t.up == "TRUE", prefix, text, span=cur.span_from(start))
        if t.kind in ("STRING", "WSTRING") and prefix in ("STRING", "WSTRING") and not sign:
            cur.advance()
            chars, err = decode_string(t.text[1:-1], prefix == "WSTRING")
            if err:
                cur.diags.error(codes.BAD_ESCAPE, err, cur.tok_span(t))
            return A.Literal(prefix.lower(), chars, prefix, text, span=cur.span_from(start))
        cur.fail_expected(f"a {prefix} value after `{prefix_tok.text}`")

    def temporal_literal(self, t: Token) -> A.Literal:
        cur = self.cur
        prefix, body = t.text.split("#", 1)
        up = prefix.upper()
        span = cur.tok_span(t)
        if t.kind == "TIME":
            value = parse_duration(body)
            kind = "ltime" if up in ("LTIME", "LT") else "time"
        elif t.kind == "DATE":
            value = parse_ymd(body)
            kind = "date"
        elif t.kind == "TOD":
            value = parse_clock(body)
            kind = "tod"
        else:
            ymd, _, clock = body.rpartition("-")          # YYYY-MM-DD-hh:mm:ss: the clock follows the last '-'
            day, tod = parse_ymd(ymd), parse_clock(clock)
            value = None if day is None or tod is None else day * 1_000_000_000 + tod
            kind = "dt"
        if value is None:
            cur.diags.error(codes.BAD_LITERAL, f"`{t.text}` is not a valid {kind.upper()} literal", span)
            value = 0
        elif not -(1 << 63) <= value < (1 << 63):
            cur.diags.error(codes.BAD_LITERAL,
                            f"`{t.text}` is outside the range of {kind.upper()} (64-bit nanoseconds, "
                            "about ±106751 days)", span)
        return A.Literal(kind, value, None, t.text, span=span)
