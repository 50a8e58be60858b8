"""Expression typing: sets ``expr.ty`` / ``expr.conv`` / ``sym`` and binds calls (see frontend_api.md)."""
from __future__ import annotations

import math

from ..frontend import ast as A
from ..frontend import builtins as B
from ..frontend import codes
from ..frontend import types as T
from ..frontend.source import Span
from . import array_bounds, calls, undeclared
from .compatibility import compatible
from .context import Context, Flow, Unit
from .scope import Ambiguous, is_generic
from .symbols import EnumValueSymbol, PouSymbol, VarSymbol

_REAL_ROUNDS_TO_MAX = 3.4028235677973366e38     # from here on a value rounds to infinity in 32 bits

COMPARE = {"=", "<>", "<", ">", "<=", ">="}
LOGIC = {"AND", "OR", "XOR"}
LIT_TYPES = {"bool": T.BOOL, "time": T.TIME, "ltime": T.LTIME, "date": T.DATE, "tod": T.TOD, "dt": T.DT}


def is_untyped_literal(e: A.Expr) -> bool:
    if isinstance(e, A.Unary) and e.op in "-+":
        e = e.operand
    return isinstance(e, A.Literal) and e.type_prefix is None and e.kind in ("int", "real")


def lit_string_type(value: str, wide: bool) -> T.StringType:
    return T.StringType(max(1, len(value)), wide, capacity=len(value), explicit=False)


class ExprChecker:
    """Types the expressions of one POU body, or of a unit's initial values and task properties.

    ``ctx`` is the project being checked (symbol tables, diagnostics, dialect); ``ns`` the namespace of the
    file, for name lookup; ``scope`` the POU's variables by upper-case name (empty outside a POU);
    ``result_sym`` a FUNCTION's result variable; ``in_pou`` makes lookups record globals used without
    VAR_EXTERNAL (``implicit_globals``, read by external_globals.py); ``flow`` is shared with the statement
    checker. Calls bound here are collected in ``calls_made`` (recursion.py).
    """

    def __init__(self, ctx: Context, ns: str | None, scope: dict[str, VarSymbol | None] | None = None,
                 result_sym: VarSymbol | None = None, in_pou: bool = False, flow: Flow | None = None) -> None:
        self.ctx = ctx
        self.ns = ns
        self.scope: dict[str, VarSymbol | None] = scope if scope is not None else {}
        self.result_sym = result_sym
        self.in_pou = in_pou
        self.flow = flow if flow is not None else Flow()
        self.implicit_globals: dict[str, VarSymbol] = {}
        self.calls_made: list[tuple[T.PouType, Span]] = []

    @classmethod
    def for_unit(cls, ctx: Context, unit: Unit | None) -> ExprChecker:
        """The checker of the expressions outside any POU in ``unit`` (initial values, task properties)."""
        return cls(ctx, unit.namespace if unit is not None else None)

    # ---- names --------------------------------------------------------------------------------
    def lookup_var(self, name: str) -> VarSymbol | None:
        up = name.upper()
        sym = self.scope.get(up)
        if sym is not None:
            if sym.section == "VAR_EXTERNAL" and sym.target is not None:
                sym.used = True
            return sym
        if self.result_sym is not None and up == self.result_sym.name.upper():
            return self.result_sym
        g = self.ctx.tables.globals.get(up)
        if g is not None and self.in_pou:
            self.implicit_globals.setdefault(up, g)      # used without VAR_EXTERNAL (external_globals.py)
        return g

    def mark_used(self, sym: object) -> None:
        if isinstance(sym, VarSymbol):
            sym.used = True

    def name(self, e: A.Name, expected: T.Type | None) -> T.Type:
        qn = e.name
        if not qn.namespace:
            sym = self.lookup_var(qn.name)
            if sym is not None:
                e.sym = sym
                self.mark_used(sym)
                if sym.section == "VAR_GLOBAL":
                    self.ctx.note_vendor(sym, e.span)
                return sym.type
            vals = self.ctx.tables.enum_values.get(qn.name.upper())
            if vals:
                exp = T.unalias(expected) if expected is not None else None
                pick = [v for v in vals if v.enum is exp] if isinstance(exp, T.EnumType) else []
                if not pick and len(vals) == 1:
                    pick = vals
                if len(pick) == 1:
                    e.sym = pick[0]
                    self.ctx.note_vendor(pick[0].enum, e.span)
                    return pick[0].enum
                names = ", ".join(f"{v.enum.name}#{v.name}" for v in vals)
                self.ctx.diags.error(codes.AMBIGUOUS_NAME,
                                     f"enumeration value `{qn.name}` is ambiguous here ({names}); "
                                     f"write it with its type, e.g. `{vals[0].enum.name}#{vals[0].name}`", e.span)
                return T.ERROR
        try:
            pou = self.ctx.tables.pous.lookup(qn.name, qn.namespace, self.ns)
        except Ambiguous as amb:
            undeclared.report_ambiguous(self.ctx, qn.text(), amb.candidates, e.span)
            return T.ERROR
        if pou is not None:
            e.sym = PouSymbol(pou)
            self.ctx.diags.error(codes.NOT_CALLABLE, f"{pou.name} is a {calls.KIND_TEXT[pou.kind]}; call it with "
                                 f"`{pou.name}(...)`" if pou.kind == "function" else
                                 f"{pou.name} is a {calls.KIND_TEXT[pou.kind]} type, not a variable; declare an "
                                 f"instance (`my{pou.name} : {pou.name};`) and use that", e.span)
            return T.ERROR
        undeclared.report(self.ctx, qn.text(), e.span, self.visible_names())
        return T.ERROR

    def visible_names(self) -> list[str]:
        names = [s.name for s in self.scope.values() if s is not None]
        names += [s.name for s in self.ctx.tables.globals.values()]
        if self.result_sym is not None:
            names.append(self.result_sym.name)
        return names

    # ---- dispatcher -----------------------------------------------------------------------------
    def expr(self, e: A.Expr, expected: T.Type | None = None) -> T.Type:
        method = getattr(self, "x_" + type(e).__name__)
        ty = method(e, expected)
        e.ty = ty
        return ty

    def x_Literal(self, e: A.Literal, expected: T.Type | None) -> T.Type:
        if e.kind in LIT_TYPES:
            return LIT_TYPES[e.kind]
        if e.kind in ("string", "wstring"):
            if e.type_prefix:
                return B.default_string(self.ctx.dialect, e.kind == "wstring")
            return lit_string_type(e.value, e.kind == "wstring")
        if e.type_prefix:
            t = T.ELEMENTARY[e.type_prefix]
            if e.kind == "int" and not T.literal_fits(e.value, t):
                self.ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                     f"{e.value} does not fit in {t.name} ({t.lo}..{t.hi})", e.span)
            elif e.kind == "real":
                self.real_fits(e, t)
            return t
        return self.untyped_number(e, e.value, expected)

    def real_fits(self, e: A.Literal, t: T.Type) -> None:
        """ST1107 for a real literal that overflows its type (REAL ±3.4028235E38, LREAL ±1.7976931E308)."""
        value = e.value
        base = T.base_of(t)
        real = base if isinstance(base, T.ElementaryType) and base.kind == "real" else None
        limit = _REAL_ROUNDS_TO_MAX if real is not None and real.bits == 32 else math.inf
        if isinstance(value, float) and (math.isinf(value) or abs(value) >= limit):
            rt = real if real is not None else T.LREAL
            self.ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                 f"{e.text or value} does not fit in {rt.name} (±{rt.hi:.8g})", e.span)

    def untyped_number(self, e: A.Expr, value: int | float, expected: T.Type | None) -> T.Type:
        exp = T.unalias(expected) if expected is not None else None
        if isinstance(e, A.Literal) and e.kind == "real" or isinstance(value, float):
            t = T.base_of(exp) if exp is not None and T.is_real(exp) else T.LREAL
            if isinstance(e, A.Literal):
                self.real_fits(e, t)
            return t
        if exp is not None and isinstance(T.base_of(exp), T.ElementaryType) and \
                T.base_of(exp).kind in ("int", "uint", "bit", "real"):
            # literal_fits() is True for every type without bounds
            if isinstance(exp, (T.SubrangeType, T.ElementaryType)) and not T.literal_fits(value, exp):
                self.ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE, f"{value} does not fit in {exp.name} "
                                     f"({exp.lo}..{exp.hi})", e.span)
            return T.base_of(exp)
        for t in (T.DINT, T.LINT, T.ULINT):
            if T.literal_fits(value, t):
                return t
        self.ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE, f"{value} is too large for any integer type", e.span)
        return T.ERROR

    def x_Name(self, e: A.Name, expected: T.Type | None) -> T.Type:
        return self.name(e, expected)

    def x_EnumLiteral(self, e: A.EnumLiteral, expected: T.Type | None) -> T.Type:
        qn = e.type_name
        try:
            t = self.ctx.tables.types.lookup(qn.name, qn.namespace, self.ns)
        except Ambiguous as amb:
            undeclared.report_ambiguous(self.ctx, qn.text(), amb.candidates, e.span)
            return T.ERROR
        enum = T.unalias(t) if t is not None else None
        if t is None or not isinstance(enum, T.EnumType):
            if t is None:
                undeclared.report_type(self.ctx, qn.text(), qn.span or e.span)
            else:
                self.ctx.diags.error(codes.UNKNOWN_TYPE, f"{t.name} is not an enumeration type", e.span)
            return T.ERROR
        key = enum.lookup(e.value)
        if key is None:
            self.ctx.diags.error(codes.UNDECLARED, f"enumeration {enum.name} has no value `{e.value}`; its values are "
                                 + ", ".join(enum.values), e.span)
            return T.ERROR
        e.sym = EnumValueSymbol(enum, key, enum.values[key])
        self.ctx.note_vendor(enum, e.span)
        return t

    def x_Member(self, e: A.Member, expected: T.Type | None) -> T.Type:
        bt = T.unalias(self.expr(e.base))
        if T.is_error(bt):
            return T.ERROR
        if isinstance(bt, T.StructType):
            f = bt.field(e.member)
            if f is None:
                self.ctx.diags.error(codes.NO_SUCH_MEMBER,
                                     f"structure {bt.name} has no member `{e.member}`; its members are "
                                     + ", ".join(x.name for x in bt.fields.values()), e.span)
                return T.ERROR
            e.sym = f.decl.sym if f.decl is not None and f.decl.sym is not None else VarSymbol(f.name, f.type, "MEMBER")
            if e.sym.type is None or e.sym.type is not f.type:
                e.sym = VarSymbol(f.name, f.type, "MEMBER", decl=f.decl)
            return f.type
        if isinstance(bt, T.PouType) and bt.kind == "fb":
            p = bt.param(e.member)
            if p is not None and p.direction in ("in", "out"):
                e.sym = p.decl.sym if p.decl is not None else VarSymbol(p.name, p.type, "VAR_INPUT", bt)
                if p.direction == "out" and isinstance(T.unalias(p.type), T.ArrayType):
                    e.fb_array_output = f"{bt.name}.{p.name}"      # see x_Index (ST1008)
                return p.type
            what = "an in-out parameter" if p is not None else "not an input or output"
            inner = bt.pou is not None and any(d.name.upper() == e.member.upper()
                                               for s in bt.pou.sections for d in s.vars)
            if p is None and not inner:
                self.ctx.diags.error(codes.NO_SUCH_MEMBER,
                                     f"function block {bt.name} has no parameter `{e.member}`", e.span)
            else:
                self.ctx.diags.error(codes.NO_SUCH_MEMBER,
                                     f"`{e.member}` is {what} of {bt.name}; only inputs and outputs can "
                                     "be accessed from outside the function block", e.span)
            return T.ERROR
        self.ctx.diags.error(codes.NO_SUCH_MEMBER,
                             f"`{self.text(e.base)}` is of type {bt.name}, which has no members", e.span)
        return T.ERROR

    def x_BitAccess(self, e: A.BitAccess, expected: T.Type | None) -> T.Type:
        bt = T.base_of(self.expr(e.base))
        if T.is_error(bt):
            return T.BOOL
        if not isinstance(bt, T.ElementaryType) or bt.kind not in ("int", "uint", "bit") or bt is T.BOOL:
            self.ctx.diags.error(codes.OPERATOR_TYPE, f"bit access `.{e.bit}` needs an integer or bit-string variable, "
                                 f"not {bt.name}", e.span)
        elif e.bit >= bt.bits:
            self.ctx.diags.error(codes.OUT_OF_BOUNDS,
                                 f"bit {e.bit} does not exist in {bt.name} (bits 0..{bt.bits - 1})",
                                 e.span)
        return T.BOOL

    def x_Index(self, e: A.Index, expected: T.Type | None) -> T.Type:
        bt = T.unalias(self.expr(e.base))
        for ix in e.indices:
            it = self.expr(ix, T.DINT)
            if not T.is_error(it) and not T.is_int(it) and not isinstance(T.unalias(it), T.EnumType):
                self.ctx.diags.error(codes.BAD_INDEXING, f"array index must be an integer, not {it.name}", ix.span)
        if T.is_error(bt):
            return T.ERROR
        if not isinstance(bt, T.ArrayType):
            self.ctx.diags.error(codes.BAD_INDEXING,
                                 f"`{self.text(e.base)}` is of type {bt.name}, not an array; it cannot "
                                 "be indexed", e.span)
            return T.ERROR
        if len(e.indices) != len(bt.dims):
            self.ctx.diags.error(codes.BAD_INDEXING, f"`{self.text(e.base)}` has {len(bt.dims)} dimension(s) but "
                                 f"{len(e.indices)} index(es) were given", e.span)
            return bt.element
        array_bounds.check(self, e, bt)
        output = getattr(e.base, "fb_array_output", None)
        if output is not None and self.ctx.dialect == "sysmac":
            # Sysmac Studio: "Cannot use an element of array" output of a function block instance
            self.ctx.diags.error(codes.SYSMAC_ARRAY_OUTPUT_ELEMENT,
                                 f"`{self.text(e)}`: Sysmac Studio does not allow an element of the array "
                                 f"output {output} of a function block instance; copy the whole output into an "
                                 f"array variable (`Buf := {self.text(e.base)};`) and index that", e.span)
        return bt.element

    def x_Unary(self, e: A.Unary, expected: T.Type | None) -> T.Type:
        if e.op == "NOT":
            t = self.expr(e.operand, expected)
            if not T.is_error(t) and not T.is_bits(t):
                self.ctx.diags.error(codes.OPERATOR_TYPE, f"NOT needs BOOL or a bit string, not {t.name}", e.span)
                return T.ERROR
            return T.base_of(t)
        if isinstance(e.operand, A.Literal) and e.operand.kind == "int" and e.operand.type_prefix is None:
            value = -e.operand.value if e.op == "-" else e.operand.value
            t = self.untyped_number(e, value, expected)
            e.operand.ty = t
            return t
        t = self.expr(e.operand, expected)
        if T.is_error(t):
            return t
        if not (T.is_num(t) or T.is_time(t)) or (e.op == "-" and T.base_of(t).kind == "uint"):
            self.ctx.diags.error(codes.OPERATOR_TYPE,
                                 f"unary `{e.op}` needs a signed number or TIME, not {t.name}", e.span)
            return T.ERROR
        e.sysmac_ty = e.operand.sysmac_ty
        return T.base_of(t)

    @staticmethod
    def context_type(e: A.Expr, other: T.Type, hint: T.Type | None) -> T.Type | None:
        """Type an untyped literal takes from the other operand (a real literal next to an integer takes
        the enclosing context, e.g. REAL in ``r := i / 2.0``)."""
        inner = e.operand if isinstance(e, A.Unary) else e
        if isinstance(inner, A.Literal) and inner.kind == "real" and not T.is_real(other):
            return hint if hint is not None and T.is_real(hint) else None
        return other

    def literal_context(self, e: A.Expr, other: T.Type, hint: T.Type | None) -> T.Type | None:
        """context_type, except that on Sysmac an integer literal too large for the other operand keeps a type of
        its own (W501 6-106: `UintVar * 100000000` is a DINT expression, not an out-of-range UINT)."""
        ctx = self.context_type(e, other, hint)
        inner = e.operand if isinstance(e, A.Unary) else e
        if self.ctx.dialect == "sysmac" and ctx is not None and isinstance(inner, A.Literal) and inner.kind == "int" \
                and T.is_int(ctx):
            value = -inner.value if isinstance(e, A.Unary) and e.op == "-" else inner.value
            if not T.literal_fits(value, ctx):
                return None
        return ctx

    def needs_context(self, e: A.Expr) -> bool:
        if is_untyped_literal(e):
            return True
        return isinstance(e, A.Name) and not e.name.namespace and self.lookup_var(e.name.name) is None

    def x_Binary(self, e: A.Binary, expected: T.Type | None) -> T.Type:
        op = e.op
        hint = None if op in COMPARE else expected
        if self.needs_context(e.left) and not self.needs_context(e.right):
            rt = self.expr(e.right, hint)
            lt = self.expr(e.left, self.literal_context(e.left, rt, hint) if op != "**" else None)
        else:
            lt = self.expr(e.left, hint)
            rt = self.expr(e.right, self.literal_context(e.right, lt, hint)
                           if (self.needs_context(e.right) and op != "**") else hint)
        if T.is_error(lt) or T.is_error(rt):
            return T.BOOL if op in COMPARE else T.ERROR
        if op in COMPARE:
            return self.comparison(e, lt, rt)
        if op in LOGIC:
            if T.is_bits(lt) and T.is_bits(rt):
                c = T.common_type(lt, rt)
                if c is not None:
                    self.widen_both(e, lt, rt, c)
                    return c
            return self.op_error(e, lt, rt, "BOOL or bit-string operands of the same kind")
        return self.arithmetic(e, lt, rt)

    def comparison(self, e: A.Binary, lt: T.Type, rt: T.Type) -> T.Type:
        a, b = T.base_of(lt), T.base_of(rt)
        if e.op in ("=", "<>") and (self.bool_digit(e.right, a, b) or self.bool_digit(e.left, b, a)):
            return T.BOOL
        if isinstance(a, T.StringType) and isinstance(b, T.StringType) and a.wide == b.wide:
            return T.BOOL
        if isinstance(a, T.EnumType) or isinstance(b, T.EnumType):
            if a is b:
                return T.BOOL
            return self.op_error(e, lt, rt, "values of the same enumeration")
        if isinstance(a, T.ElementaryType) and isinstance(b, T.ElementaryType):
            c = self.numeric_common(e, a, b)
            if c is not None:
                self.widen_both(e, lt, rt, c)
                return T.BOOL
        return self.op_error(e, lt, rt, "comparable values of the same type")

    @staticmethod
    def bool_digit(lit: A.Expr, other: T.Type, this: T.Type) -> bool:
        """`Flag = 1`, `Flag <> 0`: a plain 0 or 1 compared with a BOOL is a BOOL literal (IEC 61131-3
        boolean_literal; Sysmac accepts it). The literal becomes FALSE / TRUE."""
        if not (isinstance(lit, A.Literal) and lit.kind == "int" and lit.type_prefix is None and lit.value in (0, 1)
                and isinstance(other, T.ElementaryType) and other.kind == "bool" and T.is_int(this)):
            return False
        lit.ty = T.BOOL
        lit.kind, lit.value = "bool", bool(lit.value)
        return True

    def numeric_common(self, e: A.Binary, a: T.Type, b: T.Type) -> T.Type | None:
        """Common type of two operands. Sysmac (W501 6-106): the operand of highest rank, unsigned at equal
        rank. Where Sysmac's rank table puts an integer above a floating-point operand (DINT above REAL, LINT
        above LREAL), Sysmac computes the expression in that integer; vplc computes it in LREAL, keeps Sysmac's
        type in ``e.sysmac_ty`` (so `d := r * d` is accepted as on the controller, see coerce) and warns
        (ST1108) where the floating-point operand meets the integer."""
        c = T.common_type(a, b)
        if self.ctx.dialect != "sysmac" or not (T.is_num(a) and T.is_num(b)):
            return c
        sa = T.base_of(getattr(e.left, "sysmac_ty", None) or a)
        sb = T.base_of(getattr(e.right, "sysmac_ty", None) or b)
        s = T.sysmac_common(sa, sb)
        if s is None:
            return c
        if T.is_int(s) and (T.is_real(a) or T.is_real(b)):
            e.sysmac_ty = s
            real = next((t for t in (sa, sb) if T.is_real(t)), None)
            if real is not None:                     # an inner expression already warned otherwise
                self.ctx.diags.warning(
                    codes.SYSMAC_INTEGER_RANK,
                    f"Sysmac types this {sa.name} {e.op} {sb.name} expression as {s.name} (W501 6-106: "
                    f"{s.name} ranks above {real.name}) and computes it in {s.name}; vplc computes it in LREAL "
                    f"(stored into an integer, the result is rounded to nearest): convert explicitly so both agree",
                    e.span)
            return T.LREAL
        return s

    def arithmetic(self, e: A.Binary, lt: T.Type, rt: T.Type) -> T.Type:
        op = e.op
        a, b = T.base_of(lt), T.base_of(rt)
        ka, kb = getattr(a, "kind", ""), getattr(b, "kind", "")
        if ka in ("int", "uint", "real") and kb in ("int", "uint", "real"):
            if op == "**":
                r = a if ka == "real" else (T.LREAL if kb == "real" and b is T.LREAL else T.REAL)
                self.widen(e.left, lt, r)
                return r
            if op == "MOD" and (ka == "real" or kb == "real"):
                return self.op_error(e, lt, rt, "integer operands")
            c = self.numeric_common(e, a, b)
            if c is not None:
                self.widen_both(e, lt, rt, c)
                return c
            return self.op_error(e, lt, rt, "numbers of compatible types")
        # time / date arithmetic (IEC ADD_TIME, SUB_DT_DT, MUL_TIME ... written with operators)
        if op in ("+", "-") and ka == "time" and kb == "time":
            return T.LTIME if T.LTIME in (a, b) else T.TIME
        if op in ("+", "-") and ka in ("tod", "dt") and kb == "time":
            return a
        if op == "-" and ka == kb and ka in ("date", "tod", "dt"):
            return T.TIME
        if op in ("*", "/") and ka == "time" and kb in ("int", "uint", "real"):
            return a
        if op == "*" and kb == "time" and ka in ("int", "uint", "real"):
            return b
        if ka == "bit" or kb == "bit":
            return self.op_error(e, lt, rt, "numbers (bit strings such as WORD have no arithmetic; convert with "
                                 "WORD_TO_UINT etc.)")
        return self.op_error(e, lt, rt, "numbers of compatible types")

    def op_error(self, e: A.Binary, lt: T.Type, rt: T.Type, needs: str) -> T.Type:
        self.ctx.diags.error(codes.OPERATOR_TYPE,
                             f"operator {e.op} cannot combine {lt.name} and {rt.name}; it needs {needs}",
                             e.span)
        return T.BOOL if e.op in COMPARE else T.ERROR

    def widen_both(self, e: A.Binary, lt: T.Type, rt: T.Type, common: T.Type) -> None:
        self.widen(e.left, lt, common)
        self.widen(e.right, rt, common)

    def widen(self, e: A.Expr, have: T.Type, want: T.Type) -> None:
        if not T.is_error(have) and not T.same_type(T.base_of(have), want) and e.conv is None:
            e.conv = want

    def x_Call(self, e: A.Call, expected: T.Type | None) -> T.Type:
        return calls.check_call(self, e, expected, statement=False)

    def x_ArrayInit(self, e: A.Expr, expected: T.Type | None) -> T.Type:
        self.ctx.diags.error(codes.UNEXPECTED_TOKEN,
                             "an array initializer `[...]` is only allowed as an initial value", e.span)
        return T.ERROR

    def x_StructInit(self, e: A.Expr, expected: T.Type | None) -> T.Type:
        self.ctx.diags.error(codes.UNEXPECTED_TOKEN,
                             "a structure initializer `(...)` is only allowed as an initial value", e.span)
        return T.ERROR

    def text(self, e: A.Expr | A.CaseRange) -> str:
        return e.span.file.text[e.span.start:e.span.end] if e.span is not None else "?"

    # ---- assignment compatibility ---------------------------------------------------------------
    def coerce(self, value: A.Expr, have: T.Type, want: T.Type, what: str) -> None:
        """Check that ``value`` (of type ``have``) may be stored where ``want`` is expected; record conv."""
        if T.is_error(have) or T.is_error(want):
            return
        if isinstance(T.unalias(want), T.PouType) or isinstance(T.unalias(have), T.PouType):
            self.ctx.diags.error(codes.TYPE_MISMATCH, f"{what}: function block instances cannot be assigned or copied",
                                 value.span)
            return
        sysmac = getattr(value, "sysmac_ty", None)
        if sysmac is not None and isinstance(T.base_of(want), T.ElementaryType) and T.is_int(want) \
                and T.sysmac_assignable(sysmac, want):
            value.conv = T.base_of(want)            # W501 6-106/6-107: Sysmac's integer expression fits here
            return
        if not compatible(have, want) and not (self.ctx.dialect == "sysmac" and T.sysmac_assignable(have, want)):
            hint = ""
            a, b = T.base_of(have), T.base_of(want)
            if isinstance(a, T.ElementaryType) and isinstance(b, T.ElementaryType):
                hint = f"; convert explicitly with {a.name}_TO_{b.name}"
            elif isinstance(a, T.StringType) != isinstance(b, T.StringType):
                hint = ""
            self.ctx.diags.error(codes.TYPE_MISMATCH,
                                 f"{what}: cannot use a value of type {have.name} where {want.name} is "
                                 f"expected{hint}", value.span)
            return
        if not is_generic(want):
            self.widen(value, have, T.base_of(want))
        from . import string_length
        string_length.check(self, value, want)

    def initial_value(self, init: A.Expr, want: T.Type, what: str) -> None:
        """Check an initializer (array / struct initializers allowed) against the declared type."""
        t = T.unalias(want)
        if isinstance(init, A.ArrayInit):
            init.ty = want
            if not isinstance(t, T.ArrayType):
                if not T.is_error(t):
                    self.ctx.diags.error(codes.TYPE_MISMATCH,
                                         f"{what}: an array initializer needs an array, not {want.name}",
                                         init.span)
                return
            count = 0
            for item in init.items:
                n = 1
                if item.repeat is not None:
                    self.expr(item.repeat, T.DINT)
                    n = item.repeat.value if isinstance(item.repeat, A.Literal) else 1
                if item.value is not None:
                    self.initial_value(item.value, t.element, what)
                count += n
            if not t.open and count > t.count():
                self.ctx.diags.error(codes.OUT_OF_BOUNDS, f"{what}: {count} initial values for an array of {t.count()} "
                                     "elements", init.span)
            return
        if isinstance(init, A.StructInit):
            init.ty = want
            if isinstance(t, T.StructType):
                for fi in init.fields:
                    f = t.field(fi.name)
                    if f is None:
                        self.ctx.diags.error(codes.NO_SUCH_MEMBER,
                                             f"structure {t.name} has no member `{fi.name}`", fi.span)
                        continue
                    self.initial_value(fi.value, f.type, f"initial value of {fi.name}")
                return
            if isinstance(t, T.PouType) and t.kind == "fb":
                for fi in init.fields:
                    p = t.param(fi.name)
                    if p is None or p.direction != "in":
                        self.ctx.diags.error(codes.UNKNOWN_PARAMETER,
                                             f"`{fi.name}` is not an input of {t.name}", fi.span)
                        continue
                    self.initial_value(fi.value, p.type, f"initial value of {fi.name}")
                return
            if not T.is_error(t):
                self.ctx.diags.error(codes.TYPE_MISMATCH,
                                     f"{what}: a structure initializer needs a structure, not {want.name}",
                                     init.span)
            return
        have = self.expr(init, want)
        self.coerce(init, have, want, what)
