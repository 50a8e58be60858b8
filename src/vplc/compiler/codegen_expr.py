"""Expression half of the code generator: typed ST expressions -> Python expression text.

Integer results are wrapped to their IEC width inline, REAL results are rounded to 32 bits, division and
indexing go through checking helpers of :mod:`vplc.runtime.iec` that raise a runtime fault with values.
"""
from __future__ import annotations

import keyword
import re
from dataclasses import dataclass, field
from typing import Any, Protocol

from ..frontend import ast as A
from ..frontend import types as T
from ..frontend.source import Span
from ..runtime import abi, iec
from .inline import readonly_inputs

_PY_RESERVED = set(keyword.kwlist) | {"None", "True", "False", abi.SELF, abi.GLOBALS}

_G_MEMBERS = f"{abi.GLOBALS}.{abi.MEMBERS}"      # the container of memory-area globals

# the checker's symbols and call bindings (checker/symbols.py: VarSymbol, BoundArg, Binding) reach the compiler on
# the typed tree; the compiler sits beside the checker, not above it, and reads them without importing it
BoundArg = Any


def attr(name: str) -> str:
    """Python attribute name of an ST variable (declared spelling; ST names never contain ``__``)."""
    return name + "_" if name in _PY_RESERVED else name


def is_scalar(t: T.Type) -> bool:
    t = T.base_of(t)
    return not isinstance(t, (T.StructType, T.ArrayType, T.PouType))


def holds_bytes(t: T.Type) -> bool:
    """Are the values of ``t`` the integers 0..255 (BYTE, USINT and their subranges and aliases)? An array of them
    is a ``bytearray``: the same elements as a list of ints, but a buffer the garbage collector never walks (a
    library test PLC holds over a hundred 4096-byte buffers; as lists they were most of the time its collections
    took)."""
    u = T.unalias(t)
    if isinstance(u, T.SubrangeType):
        return holds_bytes(u.base)
    return isinstance(u, T.ElementaryType) and u.bits == 8 and u.kind in ("bit", "uint")


def _width(t: T.Type | None) -> T.ElementaryType | None:
    if t is None:
        return None
    t = T.base_of(t)
    if isinstance(t, T.EnumType):
        t = T.base_of(t.base)
    if isinstance(t, T.ElementaryType):
        return t
    return None


class CheckedProject(Protocol):
    """What the code generator reads of a checked project (a ``vplc.project.Project``: the compiler sits below
    the project layer and does not import it, docs/toolchain/layout.md)."""
    dialect: str
    pous: dict[str, T.PouType]
    types: dict[str, T.Type]
    globals: dict
    configurations: list[A.Configuration]
    programs: list[T.PouType]

    def lookup_pou(self, text: str, from_ns: str | None = None) -> T.PouType | None: ...


class CodeWriter:
    """The generated module as it is written: its lines, the ST location (file, line) each line implements, the
    current indentation and the numbering of temporaries. The statement and expression generators share one."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.linemap: dict[int, tuple[str, int]] = {}
        self.ind = 0
        self.loc = ("", 0)
        self._tmp = 0

    def emit(self, text: str) -> None:
        self.lines.append("    " * self.ind + text)
        self.linemap[len(self.lines)] = self.loc

    def tmp(self, prefix: str = "_t") -> str:
        """A fresh local name (prefixes: ``abi.TEMP_PREFIXES``)."""
        self._tmp += 1
        return f"{prefix}{self._tmp}"

    def at(self, span: Span | None) -> None:
        """Lines emitted from now on implement the ST source at ``span``."""
        if span is not None:
            self.loc = (span.file.path, span.line)


@dataclass
class Scope:
    """Where the expressions being generated are read: the instance whose variables they name (``s``, or the
    instance of an FB call compiled in place), the FOR variables whose range is known, the inputs of an inlined
    call read from the value just stored, and the FB instances already fetched into locals."""
    self_name: str = "s"
    loop_index: dict[int, tuple[str, int, int]] = field(default_factory=dict)   # id(FOR variable) -> (loop var, lo, hi)
    forward: dict[int, str] = field(default_factory=dict)        # id(input variable) -> code of its value
    inst_temps: dict[str, str] = field(default_factory=dict)     # code of an FB instance -> local holding it


class ExprGen:
    """Typed ST expressions -> Python expression text, written for the statement generator (codegen.CodeGen),
    which sets the ``scope`` and says where a sub-expression may be computed beforehand (``spill_ok``). It owns
    the names of generated things (structure and POU classes, constants), which the statement generator uses too.

    ``out`` receives the statements a deep expression is split into; ``optimise`` False hands every structured
    input over as a copy (tests); ``inline_cache`` is the inline analysis' memo of this compilation."""

    def __init__(self, proj: CheckedProject, out: CodeWriter, *, optimise: bool, inline_cache: dict) -> None:
        self.proj = proj
        self.out = out
        self.optimise = optimise
        self.inline_cache = inline_cache
        self.consts: dict[str, object] = {}
        self.struct_names: dict[int, tuple[T.StructType, str]] = {}
        self.pou_names: dict[int, str] = {}
        self.scope = Scope()
        self.spill_ok = False      # set by the statement generator where a value may be computed beforehand

    # ---- names of generated things ----------------------------------------------------------
    def struct_name(self, t: T.StructType) -> str:
        entry = self.struct_names.get(id(t))
        if entry is None:
            entry = (t, f"S{len(self.struct_names)}_{''.join(c for c in t.name if c.isalnum() or c == '_')}")
            self.struct_names[id(t)] = entry
        return entry[1]

    def cls_name(self, pt: T.PouType) -> str:
        name = self.pou_names.get(id(pt))
        if name is None:
            clean = "".join(c for c in pt.name if c.isalnum() or c == "_")
            name = f"P{len(self.pou_names)}_{clean}"
            self.pou_names[id(pt)] = name
        return name

    def const(self, value: object, prefix: str = "_k") -> str:
        name = f"{prefix}{len(self.consts)}"
        self.consts[name] = value
        return name

    # ---- default values ---------------------------------------------------------------------
    def default(self, t: T.Type, init: A.Expr | None, path: str) -> str:
        """Python expression creating a fresh value of type ``t`` (initialised by ``init`` if given)."""
        if init is not None and not isinstance(init, (A.ArrayInit, A.StructInit)):
            return self.store_conv(self.expr(init), init, t)
        u = T.unalias(t)
        decl = getattr(u, "decl", None)         # the declaration of a user type, with its initial value
        if init is None and isinstance(decl, A.TypeDecl) and decl.init is not None and not isinstance(u, T.StructType):
            return self.default(t, decl.init, path)
        if isinstance(u, T.SubrangeType):
            return str(u.lo if u.lo > 0 or u.hi < 0 else 0)
        if isinstance(u, T.EnumType):
            return str(next(iter(u.values.values()), 0))
        if isinstance(u, T.StringType):
            return "''"
        if isinstance(u, T.ElementaryType):
            return {"bool": "False", "real": "0.0"}.get(u.kind, "0")
        if isinstance(u, T.StructType):
            code = f"{self.struct_name(u)}()"
            if isinstance(init, A.StructInit):
                parts = []
                for fi in init.fields:
                    f = u.field(fi.name)
                    if f is not None:
                        parts.append(f"{attr(f.name)}={self.default(f.type, fi.value, path)}")
                code = f"_sinit({code}, {', '.join(parts)})"
            return code
        if isinstance(u, T.ArrayType):
            n = u.count()
            el = T.unalias(u.element)
            if isinstance(init, A.ArrayInit):
                items = []
                for it in init.items:
                    rep = self.expr(it.repeat) if it.repeat is not None else None
                    val = self.default(u.element, it.value, path) if it.value is not None else \
                        self.default(u.element, None, path)
                    items.append(f"*[{val} for _ in range({rep})]" if rep else val)
                rest = self.default(u.element, None, path)
                filled = f"_fill([{', '.join(items)}], {n}, lambda: {rest})"
                return f"bytearray({filled})" if holds_bytes(el) else filled
            if isinstance(el, T.PouType):
                lo = u.dims[0][0]
                sub = f"({path}) + '[' + str(_j + {lo}) + ']'"
                return f"[{self.default(el, None, sub)} for _j in range({n})]"
            if holds_bytes(el):
                first = self.default(el, None, path)
                return f"bytearray({n})" if first == "0" else f"bytearray([{first}]) * {n}"
            if is_scalar(el):
                return f"[{self.default(el, None, path)}] * {n}"
            return f"[{self.default(el, None, path)} for _ in range({n})]"
        if isinstance(u, T.PouType):
            if u.native:
                return f"{abi.NATIVE_FB}{u.name}({path})"
            return f"{self.cls_name(u)}({path})"
        return "None"

    # ---- expressions --------------------------------------------------------------------------
    def expr(self, e: A.Expr) -> str:
        code = getattr(self, "ex_" + type(e).__name__)(e)
        if e.conv is not None:
            code = self.apply_conv(code, e.ty, e.conv)
        if len(code) > 300 and _depth(code) > 60:
            code = self.spill(code)
        return code

    def spill(self, code: str) -> str:
        """Compute a deeply nested sub-expression into a temporary first (CPython nests at most 200 levels)."""
        if not self.spill_ok:
            raise NotImplementedError("an expression nested this deeply in a loop or IF condition; "
                                      "compute part of it into a variable first")
        tmp = self.out.tmp("_x")
        self.out.emit(f"{tmp} = {code}")
        return tmp

    def cond(self, e: A.Expr) -> str:
        return self.expr(e)

    def apply_conv(self, code: str, src: T.Type | None, dst: T.Type) -> str:
        s, d = T.base_of(src) if src is not None else None, T.base_of(dst)
        if isinstance(d, T.StringType):
            if isinstance(s, T.StringType) and s.capacity <= d.capacity:
                return code
            return cut(code, d.capacity)
        if not isinstance(d, T.ElementaryType):
            return code
        if d.kind == "real":
            if isinstance(s, T.ElementaryType) and s.kind == "real" and (s.bits <= d.bits):
                return code
            return f"{abi.F32}({code})" if d.bits == 32 else f"float({code})"
        if isinstance(s, T.ElementaryType) and s.kind == "bool" and d.kind != "bool":
            return f"int({code})"
        if isinstance(s, T.ElementaryType) and s.kind == "real" and d.kind in ("int", "uint"):
            return iec.wrap_expr(f"_round({code})", d.bits, d.kind == "int")   # an LREAL Sysmac types as integer
        return _sign_cast(code, s, d)

    def store_conv(self, code: str, e: A.Expr | None, t: T.Type) -> str:
        """Value ``code`` of expression ``e`` converted for storing into type ``t``."""
        tt = T.base_of(t)
        et = T.base_of(e.conv or e.ty) if e is not None and (e.conv or e.ty) is not None else None
        if isinstance(tt, T.StringType):
            if not (isinstance(et, T.StringType) and et.capacity <= tt.capacity) or \
                    (isinstance(e, A.Literal) and isinstance(e.value, str) and len(e.value) > tt.capacity):
                return cut(code, tt.capacity)
            return code
        if isinstance(tt, T.ElementaryType) and tt.kind == "real":
            if isinstance(et, T.ElementaryType) and et.kind == "real" and et.bits <= tt.bits:
                return code
            return f"{abi.F32}({code})" if tt.bits == 32 else f"float({code})"
        if isinstance(tt, (T.StructType, T.ArrayType)):
            return self.copy_code(code, tt)
        return _sign_cast(code, et, tt)

    def copy_code(self, code: str, t: T.Type) -> str:
        """A fresh copy of the structure or array value ``code`` of type ``t``: a structure through the copier
        generated for its type (CodeGen.gen_struct), anything else through the generic deep copy."""
        entry = self.struct_names.get(id(t)) if isinstance(t, T.StructType) else None
        return f"C{entry[1][1:]}({code})" if entry is not None else f"{abi.COPY}({code})"

    def ex_Literal(self, e: A.Literal) -> str:
        t = T.base_of(e.ty) if e.ty is not None else None
        v = e.value
        if e.kind == "bool":
            if isinstance(t, T.ElementaryType) and t.kind != "bool":
                return str(int(v))
            return "True" if v else "False"
        if e.kind in ("string", "wstring"):
            return repr(v)
        if e.kind == "date":
            return str(v * 1_000_000_000)
        if isinstance(t, T.ElementaryType) and t.kind == "real":
            v = float(v)
            return repr(iec.f32(v) if t.bits == 32 else v)
        if isinstance(v, float):
            return repr(v)
        return str(int(v))

    def ex_EnumLiteral(self, e: A.EnumLiteral) -> str:
        return str(e.sym.value)

    def ex_Name(self, e: A.Name) -> str:
        sym = e.sym
        kind = type(sym).__name__
        if kind == "EnumValueSymbol":
            return str(sym.value)
        if kind == "VarSymbol":
            known = self.scope.forward.get(id(sym))
            if known is not None:
                return known
            container, key = _cell(sym, self.scope.self_name)
            if container.endswith(".__dict__"):            # plain attribute access: the fast path
                return f"{container[:-len('.__dict__')]}.{key[1:-1]}"
            if container == _G_MEMBERS:
                return f"{abi.GLOBALS}.{key[1:-1]}"
            return f"{container}[{key}]"
        if kind == "PouSymbol" and sym.type.kind == "program":
            return f"{abi.PROGRAMS}[{sym.type.name.upper()!r}]"
        raise NotImplementedError(f"name {e.name.text()}")

    def ex_Member(self, e: A.Member) -> str:
        base = self.expr_raw(e.base)
        base = self.scope.inst_temps.get(base, base)
        sym = e.sym
        name = sym.name if sym is not None else e.member
        bt = T.base_of(e.base.ty) if e.base.ty is not None else None
        if isinstance(bt, T.PouType) and not bt.native and sym is not None and sym.section == "VAR_IN_OUT" \
                and is_scalar(sym.type):
            return f"{base}.{attr(name)}__r[{base}.{attr(name)}__k]"
        return f"{base}.{attr(name)}"

    def expr_raw(self, e: A.Expr) -> str:
        return getattr(self, "ex_" + type(e).__name__)(e)

    def ex_BitAccess(self, e: A.BitAccess) -> str:
        return f"((({self.expr_raw(e.base)}) >> {e.bit}) & 1 == 1)"

    def ex_Index(self, e: A.Index) -> str:
        base = self.expr_raw(e.base)
        at = T.unalias(e.base.ty)
        what = self.const(_describe(e.base), "_w")
        idx = [self.expr(i) for i in e.indices]
        if not isinstance(at, T.ArrayType):
            raise NotImplementedError("indexing a non-array")
        if at.open:
            return f"{base}[{abi.IXO}({idx[0]}, {base}, {what})]"
        if len(at.dims) == 1:
            lo, hi = _fixed(at.dims[0])
            first = e.indices[0]
            if isinstance(first, A.Literal) and isinstance(first.value, int) and lo <= first.value <= hi:
                return f"{base}[{first.value - lo}]"
            known = self.scope.loop_index.get(id(first.sym)) \
                if isinstance(first, A.Name) and first.conv is None else None
            if known is not None and lo <= known[1] and known[2] <= hi:    # a FOR variable that stays in range
                return f"{base}[{_offset(known[0], lo)}]"
            if isinstance(first, (A.Name, A.Member)) and _plain(idx[0]):   # cheap to read twice: check inline
                return f"{base}[{_offset(idx[0], lo)} if {lo} <= {idx[0]} <= {hi} " \
                       f"else {abi.IX1}({idx[0]}, {lo}, {hi}, {what})]"
            z = self.out.tmp("_z")         # any other index: computed once, checked inline (a call only to fault)
            return f"{base}[{_offset(z, lo)} if {lo} <= ({z} := {idx[0]}) <= {hi} " \
                   f"else {abi.IX1}({z}, {lo}, {hi}, {what})]"
        dims = self.const(tuple(at.dims), "_d")
        return f"{base}[{abi.IXN}(({', '.join(idx)},), {dims}, {what})]"

    def ex_Unary(self, e: A.Unary) -> str:
        x = self.expr(e.operand)
        t = _width(e.ty)
        if e.op == "+":
            return x
        if e.op == "-":
            if t is not None and t.kind == "real":
                return f"(-{x})"
            if t is not None and t.kind in ("int", "uint", "bit", "time"):
                return iec.wrap_expr(f"-{x}", t.bits, t.kind in ("int", "time"))
            return f"(-{x})"
        # NOT
        if t is None or t.kind == "bool":
            return f"(not {x})"
        if t.kind in ("int", "time"):
            return iec.wrap_expr(f"~{x}", t.bits, True)
        return f"({x} ^ {(1 << t.bits) - 1})"

    def ex_Binary(self, e: A.Binary) -> str:
        op = e.op
        a, b = self.expr(e.left), self.expr(e.right)
        if op in ("=", "<>", "<", ">", "<=", ">="):
            py = {"=": "==", "<>": "!="}.get(op, op)
            return f"({a} {py} {b})"
        t = _width(e.ty)
        if op in ("AND", "OR", "XOR"):
            if t is None or t.kind == "bool":
                return {"AND": f"({a} and {b})", "OR": f"({a} or {b})", "XOR": f"({a} != {b})"}[op]
            return f"({a} {dict(AND='&', OR='|', XOR='^')[op]} {b})"
        if t is None:
            return f"({a} {op} {b})"
        if op == "**":
            r = f"{abi.EXPT}({a}, {b})"
            return f"{abi.F32}({r})" if t.bits == 32 and t.kind == "real" else r
        if t.kind == "real":
            if op == "/":
                r = f"{abi.RDIV}({a}, {b})"
            elif op == "MOD":
                r = f"_fmod({a}, {b})"
            else:
                r = f"({a} {op} {b})"
            return f"{abi.F32}({r})" if t.bits == 32 else r
        signed = t.kind in ("int", "time", "date", "tod", "dt")
        k = e.right.value if isinstance(e.right, A.Literal) and type(e.right.value) is int and e.right.conv is None \
            else 0
        if op in ("/", "MOD") and k > 0 and _plain(a):
            # a positive constant divisor: never zero, and |result| <= |a| fits the type; truncate toward zero
            py = "//" if op == "/" else "%"
            return f"({a} {py} {k})" if not signed else f"({a} {py} {k} if {a} >= 0 else -(-{a} {py} {k}))"
        if op == "/":
            if t.kind == "time" and (rw := _width(e.right.ty)) is not None and rw.kind == "real":
                return f"int({abi.RDIV}({a}, {b}))"
            r = f"{abi.IDIV}({a}, {b})"
        elif op == "MOD":
            r = f"{abi.IMOD}({a}, {b})"
        elif op == "*" and t.kind == "time":
            r = f"int(round({a} * {b}))"
        else:
            r = f"{a} {op} {b}"
        bits = t.bits if t.bits > 1 else 64
        if bits == 64 and signed and op in ("+", "-"):
            # 64-bit values are Python big integers past 2**62: comparing is cheaper than wrapping every time
            z = self.out.tmp("_z")
            half = 1 << 63
            return f"({z} if {-half} <= ({z} := {r}) <= {half - 1} else {iec.wrap_expr(z, 64, True)})"
        return iec.wrap_expr(r, bits, signed)

    def ex_Call(self, e: A.Call) -> str:
        return self.call_expr(e)

    def ex_ArrayInit(self, e: A.ArrayInit) -> str:
        return self.default(e.ty, e, "''")

    def ex_StructInit(self, e: A.StructInit) -> str:
        return self.default(e.ty, e, "''")

    # ---- references (VAR_IN_OUT, outputs of functions) ---------------------------------------
    def lvalue(self, e: A.Expr) -> str:
        return self.expr_raw(e)

    def ref(self, e: A.Expr) -> str:
        """(container, key) tuple addressing the lvalue ``e``."""
        if isinstance(e, A.Name):
            container, key = _cell(e.sym, self.scope.self_name)
            return f"({container}, {key})"
        if isinstance(e, A.Member):
            bt = T.unalias(e.base.ty) if e.base.ty is not None else None
            # a union's members are properties over its memory image: the mapping view (runtime/unions.py)
            members = "i__members" if isinstance(bt, T.StructType) and bt.kind == "union" else "__dict__"
            return f"({self.expr_raw(e.base)}.{members}, {attr(e.sym.name if e.sym else e.member)!r})"
        if isinstance(e, A.Index):
            code = self.expr_raw(e)
            base, _, rest = code.partition("[")
            # split "base[idx]" at the outermost last subscript
            depth = 0
            for i in range(len(code) - 1, -1, -1):
                ch = code[i]
                if ch == "]":
                    depth += 1
                elif ch == "[":
                    depth -= 1
                    if depth == 0:
                        return f"({code[:i]}, {code[i + 1:-1]})"
        return f"([{self.expr(e)}], 0)"

    def aggregate_arg(self, ba: BoundArg) -> str:
        if ba.from_element:
            ref = self.ref(ba.expr)
            if self.optimise and ref.endswith(", 0)"):
                return ref[1:-len(", 0)")]          # from the first element: the array itself, no view
            return f"{abi.VIEW}(*{ref})"
        pt, at = T.unalias(ba.param.type), T.unalias(ba.expr.ty)
        if isinstance(pt, T.ArrayType) and pt.open and isinstance(at, T.ArrayType) and not at.open \
                and len(at.dims) == 1 and at.dims[0][0] != 0:
            return f"{abi.VIEW}({self.expr_raw(ba.expr)}, 0, {at.dims[0][0]})"
        return self.expr_raw(ba.expr)

    def input_value(self, ba: BoundArg, p: T.Param) -> str:
        """Value stored into input ``p``; an array element given to an array input copies the array
        starting at that element (Sysmac rule), as many elements as the parameter holds."""
        pt = T.unalias(p.type)
        if ba.from_element and isinstance(pt, T.ArrayType):
            n = pt.count() if not pt.open else None
            view = f"{abi.VIEW}(*{self.ref(ba.expr)})"
            if n is None:
                return f"{abi.COPY}({view})"
            return f"_fill({abi.COPY}({view}), {n}, lambda: {self.default(pt.element, None, repr(p.name))})"
        return self.store_conv(self.expr(ba.expr), ba.expr, p.type)

    def by_reference(self, pt: T.PouType, p: T.Param, ba: BoundArg) -> bool:
        """A structure or array the function only reads is handed over as it is, not copied."""
        return self.optimise and not pt.native and not is_scalar(p.type) and \
            not ba.from_element and ba.expr.conv is None and p.name.upper() in readonly_inputs(pt, self.inline_cache)

    # ---- calls -------------------------------------------------------------------------------
    def call_expr(self, e: A.Call) -> str:
        b = e.binding
        if b.kind == "builtin":
            from ..runtime.stdlib import gen_builtin
            return gen_builtin(self, b)
        pt = b.pou
        if pt.native and pt.name == "VPLC_ScanTime":
            return f"{abi.SCAN_TIME}[0]"                  # the scan time cell the engine sets once per scan
        by_param = {ba.param.name.upper(): ba for ba in b.args}
        args = []
        for p in pt.params:
            ba = by_param.get(p.name.upper())
            generic = T.base_of(p.type).kind == "generic"
            if ba is None:
                if p.direction == "in" and p.default is not None:
                    args.append(self.store_conv(self.expr(p.default), p.default, p.type))
                else:
                    args.append("None")
                if pt.native and generic:
                    args.append("None")
                continue
            if p.direction == "in":
                if generic:
                    args.append(self.expr(ba.expr))
                elif self.by_reference(pt, p, ba):
                    args.append(self.expr_raw(ba.expr))
                else:
                    args.append(self.input_value(ba, p))
            elif p.direction == "inout":
                args.append(self.ref(ba.expr) if is_scalar(p.type) and not generic or
                            (generic and is_scalar(ba.expr.ty)) else self.aggregate_arg(ba))
            else:
                args.append(self.ref(ba.expr))
            if pt.native and generic:
                args.append(self.const(ba.expr.ty, "_ty"))
        fn = f"{abi.NATIVE_FUNCTION}{pt.name}" if pt.native else f"F{self.cls_name(pt)[1:]}"
        return f"{fn}({', '.join(args)})"


def _sign_cast(code: str, src: T.Type | None, dst: T.Type) -> str:
    """Sysmac implicit cast between integers of other signedness (W501 6-107: INT -1 -> UINT 16#FFFF): the
    bits are kept, so the value is wrapped to the destination; widenings need no code."""
    if isinstance(src, T.ElementaryType) and isinstance(dst, T.ElementaryType) and src.kind in ("int", "uint") \
            and dst.kind in ("int", "uint") and not T.widens_to(src, dst):
        return iec.wrap_expr(code, dst.bits, dst.kind == "int")
    return code


def _cell(sym: Any, s: str = "s") -> tuple[str, str]:
    """(container, key) code of a variable: globals live in ``G``, POU variables in the instance ``s``; a scalar
    VAR_IN_OUT holds a reference cell (``s.X__r``, ``s.X__k``)."""
    if sym.section == "VAR_EXTERNAL" and sym.target is not None:
        sym = sym.target
    a = attr(sym.name)
    if sym.section in ("VAR_GLOBAL", "VAR_EXTERNAL"):
        if getattr(sym, "at_address", None) is not None:
            return _G_MEMBERS, repr(a)        # a memory-area variable: a property (runtime/at_memory.py)
        return f"{abi.GLOBALS}.__dict__", repr(a)
    if sym.section == "VAR_IN_OUT" and is_scalar(sym.type):
        return f"{s}.{a}__r", f"{s}.{a}__k"
    return f"{s}.__dict__", repr(a)


_CUT = re.compile(r"(''\.join\(\(.*\)\)|\(.*\))\[:(\d+)\]", re.S)


def cut(code: str, capacity: int) -> str:
    """``code`` (a string) cut to ``capacity`` characters; a value already cut to a longer length (CONCAT,
    LEFT) is cut once, to the shorter length."""
    inner = _CUT.fullmatch(code)
    if inner and int(inner.group(2)) >= capacity and _one_group(inner.group(1).removeprefix("''.join")):
        return f"{inner.group(1)}[:{capacity}]"
    return f"({code})[:{capacity}]"


def _one_group(code: str) -> bool:
    """``code`` is one parenthesised group: its first ``(`` closes only at its last character."""
    depth, quote, escaped = 0, None, False
    for i, ch in enumerate(code):
        if quote:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
            if depth == 0 and i < len(code) - 1:
                return False
    return depth == 0


def _fixed(dim: tuple[int | None, int | None]) -> tuple[int, int]:
    """The bounds of a dimension of an array that is not open (T.ArrayType.open is False)."""
    lo, hi = dim
    if lo is None or hi is None:
        raise NotImplementedError("an open array dimension where the bounds must be known")
    return lo, hi


def _offset(code: str, lo: int) -> str:
    return f"{code} - {lo}" if lo > 0 else f"{code} + {-lo}" if lo < 0 else code


def _plain(code: str) -> bool:
    """``code`` is a dotted name (``s.i``, ``G.k``, ``_i3.Index``): reading it has no effect and costs little."""
    return all(part.isidentifier() for part in code.split("."))


def _depth(code: str) -> int:
    depth = best = 0
    quote = None
    for ch in code:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
            best = max(best, depth)
        elif ch in ")]}":
            depth -= 1
    return best


def _describe(e: A.Expr) -> str:
    if isinstance(e, A.Name):
        return e.name.text()
    if isinstance(e, A.Member):
        return f"{_describe(e.base)}.{e.member}"
    if isinstance(e, A.Index):
        return f"{_describe(e.base)}[...]"
    return "array"
