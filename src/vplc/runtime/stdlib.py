"""IEC standard functions (vplc.frontend.builtins) for generated code: code templates and Python helpers.

``gen_builtin(gen, binding)`` returns the Python expression for a builtin call; the helpers below are put
in the namespace of the generated module (``NAMESPACE``).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from ..frontend import builtins as B
from ..frontend import types as T
from . import iec
from .faults import RuntimeFaultError

_Obj = TypeVar("_Obj")


def _nan_on_domain(fn: Callable[[Any], float]) -> Callable[[Any], float]:
    def f(x: Any) -> float:
        try:
            return fn(x)
        except (ValueError, OverflowError):
            return math.nan
    return f


def _fmod(a: float, b: float) -> float:
    if b == 0:
        raise RuntimeFaultError(f"division by zero ({a} MOD 0)")
    return math.fmod(a, b)


def _mux(k: int, values: Sequence[Any]) -> Any:
    if not 0 <= k < len(values):
        raise RuntimeFaultError(f"MUX selector {k} out of range 0..{len(values) - 1}")
    return values[k]


def _bcd_decode(value: int, name: str, hi: int) -> int:
    """Packed BCD bit string -> integer; a nibble above 9 (not BCD) or a result above ``hi`` is a fault."""
    result, scale, rest = 0, 1, value
    while rest:
        digit = rest & 0xF
        if digit > 9:
            raise RuntimeFaultError(f"{name}: 16#{value:X} is not a BCD value (digit 16#{digit:X})")
        result += digit * scale
        scale *= 10
        rest >>= 4
    if result > hi:
        raise RuntimeFaultError(f"{name}: BCD 16#{value:X} = {result} is out of the result's range (max {hi})")
    return result


def _bcd_encode(value: int, bits: int, name: str) -> int:
    """Integer -> packed BCD of ``bits`` bits; a negative value or one with too many digits is a fault."""
    if value < 0 or value >= 10 ** (bits // 4):
        raise RuntimeFaultError(f"{name}: {value} cannot be written as BCD in {bits} bits "
                                f"(0..{10 ** (bits // 4) - 1})")
    return int(str(value), 16)


def _left(s: str, n: int) -> str:
    return s[:max(n, 0)]


def _right(s: str, n: int) -> str:
    return s[len(s) - n:] if n > 0 else ""


def _mid(s: str, n: int, p: int) -> str:
    if p < 1:
        return ""
    return s[p - 1:p - 1 + max(n, 0)]


def _insert(a: str, b: str, p: int) -> str:
    p = max(0, min(p, len(a)))
    return a[:p] + b + a[p:]


def _delete(s: str, n: int, p: int) -> str:
    if p < 1 or n <= 0:
        return s
    return s[:p - 1] + s[p - 1 + n:]


def _replace(a: str, b: str, n: int, p: int) -> str:
    if p < 1:
        p = 1
    return a[:p - 1] + b + a[p - 1 + max(n, 0):]


def _find(a: str, b: str) -> int:
    return a.find(b) + 1 if b else 0


def _sinit(obj: _Obj, **values: Any) -> _Obj:
    obj.__dict__.update(values)
    return obj


def _fill(items: list[Any], n: int, make: Callable[[], Any]) -> list[Any]:
    items = items[:n]
    while len(items) < n:
        items.append(make())
    return items


_MATH_FUNCTIONS: dict[str, Callable[[float], float]] = {
    "SQRT": math.sqrt, "LN": math.log, "LOG": math.log10, "EXP": math.exp, "SIN": math.sin, "COS": math.cos,
    "TAN": math.tan, "ASIN": math.asin, "ACOS": math.acos, "ATAN": math.atan,
    "DEGTORAD": math.radians, "RADTODEG": math.degrees}               # W560 2-209 (Omron, builtins.py)
MATH = {name: _nan_on_domain(fn) for name, fn in _MATH_FUNCTIONS.items()}

NAMESPACE: dict[str, Any] = {
    "_fmod": _fmod, "_mux": _mux, "_bcd_decode": _bcd_decode, "_bcd_encode": _bcd_encode,
    "_left": _left, "_right": _right, "_mid": _mid, "_insert": _insert,
    "_delete": _delete, "_replace": _replace, "_find": _find, "_sinit": _sinit, "_fill": _fill,
    "_round": iec.round_half_even, "_trunc": iec.trunc, "_shl": iec.shl, "_shr": iec.shr, "_rol": iec.rol,
    "_ror": iec.ror, "_lbound": iec.lower_bound, "_ubound": iec.upper_bound,
    "_atan2": _nan_on_domain(lambda yx: math.atan2(*yx)),
    **{"_m" + k: v for k, v in MATH.items()},
}


# ---- conversions -----------------------------------------------------------------------------------

def _kind(t: T.Type) -> tuple[str, Any]:
    """(kind, base type): the base type is an ElementaryType for the elementary kinds and a StringType for
    "string" (Any: its callers use it by the kind, a pairing mypy cannot follow)."""
    t = T.base_of(t)
    if isinstance(t, T.EnumType):
        return "int", T.base_of(t.base)
    if isinstance(t, T.StringType):
        return "string", t
    if isinstance(t, T.ElementaryType):
        k = t.kind
        return ("int" if k in ("int", "uint", "bit") else k), t
    return "other", t


def to_string(v: Any, t: T.Type, dialect: str = "sysmac") -> str:
    """Text of a value as the *_TO_STRING conversions produce it (Sysmac formats, docs/toolchain/runtime.md)."""
    k, bt = _kind(t)
    if k == "bool":
        return "TRUE" if v else "FALSE"
    if k == "int":
        if dialect == "sysmac" and isinstance(bt, T.ElementaryType) and bt.kind == "bit":
            return f"{v:x}"              # Sysmac: bit strings convert to hexadecimal digits
        return str(v)
    if k == "real":
        return iec.fmt_real(v, bt.bits == 32)
    if k == "time":
        return iec.fmt_time(v)
    if k in ("date", "dt", "tod"):
        import datetime as _dt
        if k == "tod":
            s, ns = divmod(v, 1_000_000_000)
            h, rem = divmod(s, 3600)
            text = f"TOD#{h:02d}:{rem // 60:02d}:{rem % 60:02d}"
            return text + (f".{ns:09d}".rstrip("0") if ns else "")
        secs, ns = divmod(v, 1_000_000_000)
        d = _dt.datetime(1970, 1, 1) + _dt.timedelta(seconds=secs)
        if k == "date":
            return f"D#{d:%Y-%m-%d}"
        return f"DT#{d:%Y-%m-%d-%H:%M:%S}" + (f".{ns:09d}".rstrip("0") if ns else "")
    return str(v)


def string_converter(t: T.Type, dialect: str = "sysmac") -> Callable[[Any], str]:
    """``to_string`` specialised to the source type ``t`` once, at compile time (no type dispatch per call)."""
    k, bt = _kind(t)
    if k == "bool":
        return lambda v: "TRUE" if v else "FALSE"
    if k == "int" and not (dialect == "sysmac" and isinstance(bt, T.ElementaryType) and bt.kind == "bit"):
        return str
    if k == "real":
        return iec.fmt_real32 if bt.bits == 32 else iec.fmt_real64
    return lambda v: to_string(v, t, dialect)


def _parse_number(s: str, real: bool) -> int | float:
    text = s.strip().replace("_", "")
    try:
        if real:
            return float(text)
        if "#" in text:
            base, _, digits = text.partition("#")
            return int(digits, int(base))
        return int(float(text)) if "." in text or "e" in text.lower() else int(text)
    except ValueError:
        return 0.0 if real else 0


def conversion(src: T.Type, dst: T.Type, dialect: str = "sysmac") -> Callable[[Any], Any]:
    """Python function converting a value of type ``src`` to ``dst`` (IEC *_TO_* semantics)."""
    sk, st = _kind(src)
    dk, dt = _kind(dst)
    if dk == "string":
        cap = dt.capacity
        text = string_converter(src, dialect)
        if sk in ("bool", "int") and cap >= 66:       # no bool or integer text is longer (LWORD in binary: 64)
            return text
        return lambda v: text(v)[:cap]
    if dk == "bool":
        if sk == "string":
            return lambda v: v.strip().upper() in ("TRUE", "1")
        return lambda v: v != 0
    if dk == "real":
        exact = sk == "int" and st.bits <= 24        # every value of a 24-bit integer is a REAL exactly
        f = iec.f32 if dt.bits == 32 and not exact else float
        if sk == "string":
            return lambda v: f(_parse_number(v, True))
        return f
    if dk in ("int", "time", "date", "tod", "dt"):
        bits = dt.bits
        signed = dt.kind in ("int", "time")
        w = iec.wrapper(bits, signed)
        if sk == "real":
            return lambda v: w(iec.round_half_even(v))
        if sk == "string":
            return lambda v: w(int(_parse_number(v, False)))
        if sk == "bool":
            return lambda v: int(v)
        if dk == "date" and sk == "dt":
            return lambda v: v - v % 86_400_000_000_000
        if dk == "tod" and sk == "dt":
            return lambda v: v % 86_400_000_000_000
        return w
    return lambda v: v


# ---- builtin call generation -----------------------------------------------------------------------

COMPARE_FUNCTIONS = {"LT": " < ", "LE": " <= ", "GT": " > ", "GE": " >= ", "EQ": " == ", "NE": " != "}


def gen_builtin(gen: Any, b: Any) -> str:      # the compiler's ExprGen, the checker's call binding
    name = b.builtin.name.upper()
    args = [gen.expr(ba.expr) for ba in b.args]
    tys = [ba.expr.conv or ba.expr.ty for ba in b.args]
    rt = T.base_of(b.ty) if b.ty is not None else None
    bits = rt.bits if isinstance(rt, T.ElementaryType) else 64
    signed = isinstance(rt, T.ElementaryType) and rt.kind in ("int", "time")
    real = isinstance(rt, T.ElementaryType) and rt.kind == "real"

    def fix(code: str) -> str:
        if real:
            return f"_f32({code})" if bits == 32 else code
        if isinstance(rt, T.ElementaryType) and rt.kind in ("int", "uint", "bit", "time"):
            return iec.wrap_expr(code, bits, signed)
        return code

    bcd = B.bcd_kind(name)
    if bcd == "decode":
        if not isinstance(rt, T.ElementaryType):
            raise NotImplementedError(f"{name} without an integer result")
        return f"_bcd_decode({args[0]}, {name!r}, {rt.hi})"
    if bcd == "encode":
        return f"_bcd_encode({args[0]}, {bits}, {name!r})"
    if "_TO_" in name or name.startswith("TO_"):
        if name.startswith("TRUNC_"):
            return fix(f"_trunc({args[0]})")
        fn = gen.const(conversion(tys[0], b.ty, getattr(gen.proj, "dialect", "sysmac")), "_cv")
        return f"{fn}({args[0]})"
    if name.startswith("TRUNC"):
        return fix(f"_trunc({args[0]})")
    if name == "ABS":
        return fix(f"abs({args[0]})")
    if name in MATH:
        return fix(f"_m{name}({args[0]})")
    if name == "ATAN2":
        return fix(f"_atan2(({args[0]}, {args[1]}))")
    if name == "EXPT":
        return fix(f"_expt({args[0]}, {args[1]})")
    if name in ("ADD", "MUL"):
        return fix((" + " if name == "ADD" else " * ").join(f"({a})" for a in args))
    if name == "SUB":
        return fix(f"({args[0]}) - ({args[1]})")
    if name == "DIV":
        return fix(f"_rdiv({args[0]}, {args[1]})" if real else f"_idiv({args[0]}, {args[1]})")
    if name == "MOD":
        return fix(f"_fmod({args[0]}, {args[1]})" if real else f"_imod({args[0]}, {args[1]})")
    if name == "SEL":
        return f"({args[2]} if {args[0]} else {args[1]})"
    if name in ("MAX", "MIN"):
        return f"{name.lower()}({', '.join(args)})"
    if name == "LIMIT":
        return f"min(max({args[1]}, {args[0]}), {args[2]})"
    if name == "MUX":
        return f"_mux({args[0]}, ({', '.join(args[1:])},))"
    if name in ("SHL", "SHR", "ROL", "ROR"):
        code = f"_{name.lower()}({args[0]}, {args[1]}, {bits})"
        return iec.wrap_expr(code, bits, True) if signed else code
    if name in ("AND", "OR", "XOR"):
        if isinstance(rt, T.ElementaryType) and rt.kind == "bool":
            op = {"AND": " and ", "OR": " or ", "XOR": " != "}[name]
        else:
            op = {"AND": " & ", "OR": " | ", "XOR": " ^ "}[name]
        return "(" + op.join(f"({a})" for a in args) + ")"
    if name == "NOT":
        if isinstance(rt, T.ElementaryType) and rt.kind == "bool":
            return f"(not {args[0]})"
        return fix(f"~({args[0]})")
    if name == "MOVE":
        return args[0]
    if name in COMPARE_FUNCTIONS:            # Python's chained comparison: LT(a, b, c) = a < b AND b < c
        return "(" + COMPARE_FUNCTIONS[name].join(f"({a})" for a in args) + ")"
    if name == "LEN":
        return f"len({args[0]})"
    cap = rt.capacity if isinstance(rt, T.StringType) else 1985
    if name == "LEFT":
        if args[1].isdigit():                       # a constant length: a plain slice
            return f"({args[0]})[:{args[1]}]"
        return f"_left({args[0]}, {args[1]})"
    if name == "RIGHT":
        return f"_right({args[0]}, {args[1]})"
    if name == "MID":
        return f"_mid({args[0]}, {args[1]}, {args[2]})"
    if name == "CONCAT":
        return f"''.join(({', '.join(args)},))[:{cap}]"
    if name == "INSERT":
        return f"_insert({args[0]}, {args[1]}, {args[2]})[:{cap}]"
    if name == "DELETE":
        return f"_delete({args[0]}, {args[1]}, {args[2]})"
    if name == "REPLACE":
        return f"_replace({args[0]}, {args[1]}, {args[2]}, {args[3]})[:{cap}]"
    if name == "FIND":
        return f"_find({args[0]}, {args[1]})"
    if name in ("LOWER_BOUND", "UPPER_BOUND"):
        at = T.unalias(b.args[0].expr.ty)
        dim = b.args[1].expr.value if hasattr(b.args[1].expr, "value") else 1
        if isinstance(at, T.ArrayType) and not at.open:
            lo, hi = at.dims[dim - 1]
            return str(lo if name == "LOWER_BOUND" else hi)
        return f"_lbound({args[0]})" if name == "LOWER_BOUND" else f"_ubound({args[0]})"
    if name in ("ADD_TIME", "ADD_TOD_TIME", "ADD_DT_TIME", "CONCAT_DATE_TOD"):
        return f"({args[0]} + {args[1]})"
    if name in ("SUB_TIME", "SUB_DATE_DATE", "SUB_TOD_TIME", "SUB_TOD_TOD", "SUB_DT_TIME", "SUB_DT_DT"):
        return f"({args[0]} - {args[1]})"
    if name == "MUL_TIME":
        return f"int(round({args[0]} * {args[1]}))"
    if name == "DIV_TIME":
        return f"int(_rdiv({args[0]}, {args[1]}))"
    raise NotImplementedError(f"standard function {name}")
