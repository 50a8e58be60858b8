"""Signatures of the IEC 61131-3 standard functions that ST cannot declare (generic / overloaded).

Each :class:`Builtin` resolves a call from its argument types: it returns the result type and, for each
argument, the type it is widened to (``None`` when used as is), or raises :class:`SignatureError`.
The runtime implements the same names (vplc.runtime). Sysmac instructions that ST can declare live in
prelude/sysmac_decl.st instead; IEC function blocks (TON, R_TRIG, ...) in prelude/iec_fbs.st.

Sysmac dialect: LEN and FIND return UINT (IEC: INT).
"""
from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from . import types as T


class SignatureError(Exception):
    def __init__(self, message: str, arg_index: int | None = None) -> None:
        super().__init__(message)
        self.arg_index = arg_index


# A standard function's signature check: (argument types, dialect) -> (result type, the conversion of each
# argument or None); raises SignatureError naming the argument that does not fit.
Resolved = tuple[T.Type, list[T.Type | None]]
Resolver = Callable[[list[T.Type], str], Resolved]


@dataclass(frozen=True)
class Builtin:
    name: str
    min_args: int
    max_args: int | None          # None: extensible (CONCAT, MAX, ...)
    resolve: Resolver              # (arg_types, dialect) -> (result, [conv or None])
    formal_names: tuple[str, ...] = ()   # accepted formal parameter names, in order (IN, IN1, ...)
    vendor: bool = False


# ---- helpers ----------------------------------------------------------------------------------

def _need(pred: Callable[[T.Type], bool], t: T.Type, i: int, what: str) -> None:
    if T.is_error(t) or pred(t):
        return
    raise SignatureError(f"argument {i + 1} must be {what}, not {t.name}", i)


def _common(types_: list[T.Type], first: int = 0) -> T.Type:
    result = types_[first]
    for i in range(first + 1, len(types_)):
        t = types_[i]
        if T.is_error(t) or T.is_error(result):
            result = t if T.is_error(result) else result
            continue
        c = T.common_type(result, t)
        if c is None:
            if T.is_string(result) and T.is_string(t):
                continue
            raise SignatureError(f"arguments of type {result.name} and {t.name} cannot be mixed; convert one "
                                 f"of them explicitly (e.g. {t.name}_TO_{result.name})", i)
        result = c
    return result


def _convs(arg_types: list[T.Type], target: T.Type) -> list[T.Type | None]:
    return [None if (T.is_error(a) or T.same_type(a, target)) else target for a in arg_types]


def _real_of(t: T.Type) -> T.Type:
    return T.base_of(t) if T.is_real(t) else T.LREAL


# ---- families -----------------------------------------------------------------------------------

def _numeric_same(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_num, args[0], 0, "a number")
    return T.base_of(args[0]) if not T.is_error(args[0]) else T.ERROR, [None]


def _real_math(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_num, args[0], 0, "a number")
    r = _real_of(args[0]) if not T.is_error(args[0]) else T.ERROR
    return r, _convs(args, r)


def _atan2(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(T.is_num, a, i, "a number")
    r = _common([_real_of(a) if not T.is_error(a) else a for a in args])
    return r, _convs(args, r)


def _expt(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_num, args[0], 0, "a number")
    _need(T.is_num, args[1], 1, "a number")
    r = _real_of(args[0]) if not T.is_error(args[0]) else T.ERROR
    return r, [None if T.same_type(args[0], r) else r, None]


def _arith(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(lambda t: T.is_num(t) or T.is_time(t), a, i, "a number or TIME")
    r = _common(args)
    return r, _convs(args, r)


def _mod(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(T.is_int, a, i, "an integer")
    r = _common(args)
    return r, _convs(args, r)


def _sel(args: list[T.Type], dialect: str) -> Resolved:
    _need(lambda t: T.base_of(t) is T.BOOL, args[0], 0, "BOOL")
    r = _common(args, 1)
    return r, [None, *_convs(args[1:], r)]


def _maxmin(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(T.is_elementary, a, i, "an elementary value")
    r = _common(args)
    return r, _convs(args, r)


def _mux(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_int, args[0], 0, "an integer selector")
    r = _common(args, 1)
    return r, [None, *_convs(args[1:], r)]


def _shift(args: list[T.Type], dialect: str) -> Resolved:
    _need(lambda t: T.is_bits(t) and T.base_of(t) is not T.BOOL or T.is_int(t), args[0], 0,
          "a bit string (BYTE..LWORD)")
    _need(T.is_int, args[1], 1, "an integer")
    return (T.base_of(args[0]) if not T.is_error(args[0]) else T.ERROR), [None, None]


def _bitwise(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(T.is_bits, a, i, "BOOL or a bit string")
    r = _common(args)
    return r, _convs(args, r)


def _not(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_bits, args[0], 0, "BOOL or a bit string")
    return T.base_of(args[0]), [None]


def _compare(args: list[T.Type], dialect: str) -> Resolved:
    """LT, LE, GT, GE, EQ, NE as functions (IEC 61131-3 comparison functions; Sysmac accepts them in ST like ADD):
    operands of one comparable type, the result BOOL. LT/LE/GT/GE/EQ are extensible, `LT(a, b, c)` meaning
    `a < b AND b < c`."""
    if all(T.is_string(a) or T.is_error(a) for a in args):
        return T.BOOL, [None] * len(args)
    for i, a in enumerate(args):
        _need(lambda t: T.is_elementary(t) or isinstance(T.base_of(t), T.EnumType), a, i, "a comparable value")
    if any(isinstance(T.base_of(a), T.EnumType) for a in args):
        first = T.base_of(args[0])
        for i, a in enumerate(args):
            if not T.is_error(a) and T.base_of(a) is not first:
                raise SignatureError(f"argument {i + 1} must be a value of {first.name}, not {a.name}", i)
        return T.BOOL, [None] * len(args)
    c = _common(list(args))
    return T.BOOL, _convs(args, c)


def _move(args: list[T.Type], dialect: str) -> Resolved:
    return args[0], [None]


def _str_default(dialect: str) -> T.StringType:
    return default_string(dialect)


def _string_fn(pattern: str) -> Resolver:
    """pattern letters: s = STRING arg, i = integer arg; result STRING."""
    def resolve(args: list[T.Type], dialect: str) -> Resolved:
        for i, (a, p) in enumerate(zip(args, pattern, strict=False)):
            if p == "s":
                _need(T.is_string, a, i, "a STRING")
            else:
                _need(T.is_int, a, i, "an integer")
        wide = any(isinstance(bt := T.base_of(a), T.StringType) and bt.wide for a in args)
        return (default_string(dialect, wide)), [None] * len(args)
    return resolve


def _concat(args: list[T.Type], dialect: str) -> Resolved:
    for i, a in enumerate(args):
        _need(T.is_string, a, i, "a STRING")
    wide = any(isinstance(bt := T.base_of(a), T.StringType) and bt.wide for a in args)
    return default_string(dialect, wide), [None] * len(args)


def _len(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_string, args[0], 0, "a STRING")
    return (T.UINT if dialect == "sysmac" else T.INT), [None]


def _find(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_string, args[0], 0, "a STRING")
    _need(T.is_string, args[1], 1, "a STRING")
    return (T.UINT if dialect == "sysmac" else T.INT), [None, None]


def _bound(args: list[T.Type], dialect: str) -> Resolved:
    _need(lambda t: isinstance(T.unalias(t), T.ArrayType), args[0], 0, "an array")
    _need(T.is_int, args[1], 1, "an integer dimension")
    return T.DINT, [None, None]


def _fixed(params: tuple[T.Type, ...], result: T.Type) -> Resolver:
    def resolve(args: list[T.Type], dialect: str) -> Resolved:
        convs = []
        for i, (a, p) in enumerate(zip(args, params, strict=False)):
            if not (T.widens_to(a, p) or (dialect == "sysmac" and T.sysmac_assignable(a, p))):
                raise SignatureError(f"argument {i + 1} must be {p.name}, not {a.name}", i)
            convs.append(None if T.same_type(a, p) or T.is_error(a) else p)
        return result, convs
    return resolve


def default_string(dialect: str, wide: bool = False) -> T.StringType:
    if dialect == "sysmac":
        return T.StringType(1986, wide, capacity=1985, explicit=False)
    return T.StringType(254, wide, explicit=False)


# ---- conversions ------------------------------------------------------------------------------

CONVERTIBLE = {**{k: v for k, v in T.ELEMENTARY.items()}, "STRING": None, "WSTRING": None}
_CONV_RE = re.compile(r"^([A-Z_]+?)_TO_([A-Z_]+)$")
# BCD conversions: IEC 2nd edition BCD_TO_<int> / <int>_TO_BCD, and the typed names of the 3rd edition and
# Sysmac, <bits>_BCD_TO_<int> / <int>_TO_BCD_<bits> (e.g. WORD_BCD_TO_UINT, UINT_TO_BCD_WORD).
_BCD_DECODE_RE = re.compile(r"^(?:(BYTE|WORD|DWORD|LWORD)_)?BCD_TO_([A-Z]+)$")
_BCD_ENCODE_RE = re.compile(r"^([A-Z]+)_TO_BCD(?:_(BYTE|WORD|DWORD|LWORD))?$")
_BITS_OF_WIDTH = {8: "BYTE", 16: "WORD", 32: "DWORD", 64: "LWORD"}


def _conversion(src_name: str, dst_name: str) -> Builtin | None:
    if src_name not in CONVERTIBLE or dst_name not in CONVERTIBLE:
        return None
    src, dst = CONVERTIBLE[src_name], CONVERTIBLE[dst_name]

    def resolve(args: list[T.Type], dialect: str) -> Resolved:
        a = args[0]
        if not T.is_error(a):
            ok = (T.is_string(a) if src is None else
                  (T.same_type(T.base_of(a), src) or T.widens_to(a, src) or
                   (isinstance(T.base_of(a), T.EnumType) and T.is_int(src)) or
                   (dialect == "sysmac" and T.sysmac_assignable(a, src))))   # W501 6-107: INT_TO_STRING(LEN(s))
            if not ok:
                raise SignatureError(f"{src_name}_TO_{dst_name} expects a {src_name}, not {a.name}", 0)
        result = default_string(dialect, dst_name == "WSTRING") if dst is None else dst
        conv = None if (src is None or T.is_error(a) or T.same_type(T.base_of(a), src)) else src
        return result, [conv]
    return Builtin(f"{src_name}_TO_{dst_name}", 1, 1, resolve, ("IN",))


def bcd_kind(name: str) -> str | None:
    """"decode" for BCD_TO_x / <bits>_BCD_TO_x, "encode" for x_TO_BCD / x_TO_BCD_<bits>, else None (upper case)."""
    if _BCD_DECODE_RE.match(name):
        return "decode"
    return "encode" if _BCD_ENCODE_RE.match(name) else None


def _bcd(name: str) -> Builtin | None:
    """BCD_TO_x / x_TO_BCD builtins, or None when ``name`` is not one. The integer side must be an integer
    type; the bit-string side is the one named, or (2nd edition) any bit string when decoding and the bit
    string of the integer's width when encoding."""
    m = _BCD_DECODE_RE.match(name)
    if m and T.is_int(T.ELEMENTARY.get(m.group(2), T.BOOL)):
        bits_name, result = m.group(1), T.ELEMENTARY[m.group(2)]

        def decode(args: list[T.Type], dialect: str) -> Resolved:
            a = args[0]
            if bits_name is None:
                _need(lambda t: T.base_of(t).kind == "bit", a, 0, "a bit string (BYTE, WORD, DWORD, LWORD)")
                return result, [None]
            want = T.ELEMENTARY[bits_name]
            _need(lambda t: T.same_type(T.base_of(t), want) or T.widens_to(t, want), a, 0, f"a {bits_name}")
            return result, [None if T.is_error(a) or T.same_type(T.base_of(a), want) else want]
        return Builtin(name, 1, 1, decode, ("IN",))
    m = _BCD_ENCODE_RE.match(name)
    if m and T.is_int(T.ELEMENTARY.get(m.group(1), T.BOOL)):
        source = T.ELEMENTARY[m.group(1)]
        result = T.ELEMENTARY[m.group(2) or _BITS_OF_WIDTH[source.bits]]

        def encode(args: list[T.Type], dialect: str) -> Resolved:
            a = args[0]
            _need(lambda t: T.same_type(T.base_of(t), source) or T.widens_to(t, source), a, 0, f"a {source.name}")
            return result, [None if T.is_error(a) or T.same_type(T.base_of(a), source) else source]
        return Builtin(name, 1, 1, encode, ("IN",))
    return None


def _trunc(args: list[T.Type], dialect: str) -> Resolved:
    _need(T.is_real, args[0], 0, "REAL or LREAL")
    return T.DINT, [None]


# ---- table ----------------------------------------------------------------------------------

def _b(name: str, lo: int, hi: int | None, fn: Resolver, formal: Iterable[str] = ()) -> Builtin:
    return Builtin(name, lo, hi, fn, tuple(formal))


_TIME = T.TIME
BUILTINS: dict[str, Builtin] = {b.name: b for b in [
    _b("ABS", 1, 1, _numeric_same, ("IN",)),
    *[_b(n, 1, 1, _real_math, ("IN",)) for n in ("SQRT", "LN", "LOG", "EXP", "SIN", "COS", "TAN", "ASIN", "ACOS",
                                                 "ATAN")],
    _b("ATAN2", 2, 2, _atan2, ("Y", "X")),
    _b("EXPT", 2, 2, _expt, ("IN1", "IN2")),
    _b("ADD", 2, None, _arith), _b("MUL", 2, None, _arith),
    _b("SUB", 2, 2, _arith, ("IN1", "IN2")), _b("DIV", 2, 2, _arith, ("IN1", "IN2")),
    _b("MOD", 2, 2, _mod, ("IN1", "IN2")),
    _b("SEL", 3, 3, _sel, ("G", "IN0", "IN1")),
    _b("MAX", 2, None, _maxmin), _b("MIN", 2, None, _maxmin),
    _b("LIMIT", 3, 3, _maxmin, ("MN", "IN", "MX")),
    _b("MUX", 3, None, _mux),
    *[_b(n, 2, 2, _shift, ("IN", "N")) for n in ("SHL", "SHR", "ROL", "ROR")],
    _b("AND", 2, None, _bitwise), _b("OR", 2, None, _bitwise), _b("XOR", 2, None, _bitwise),
    _b("NOT", 1, 1, _not, ("IN",)),
    _b("MOVE", 1, 1, _move, ("IN",)),
    *[_b(n, 2, None, _compare) for n in ("LT", "LE", "GT", "GE", "EQ")],
    _b("NE", 2, 2, _compare, ("IN1", "IN2")),
    _b("LEN", 1, 1, _len, ("IN",)),
    _b("LEFT", 2, 2, _string_fn("si"), ("IN", "L")),
    _b("RIGHT", 2, 2, _string_fn("si"), ("IN", "L")),
    _b("MID", 3, 3, _string_fn("sii"), ("IN", "L", "P")),
    _b("CONCAT", 2, None, _concat),
    _b("INSERT", 3, 3, _string_fn("ssi"), ("IN1", "IN2", "P")),
    _b("DELETE", 3, 3, _string_fn("sii"), ("IN", "L", "P")),
    _b("REPLACE", 4, 4, _string_fn("ssii"), ("IN1", "IN2", "L", "P")),
    _b("FIND", 2, 2, _find, ("IN1", "IN2")),
    _b("TRUNC", 1, 1, _trunc, ("IN",)),
    _b("LOWER_BOUND", 2, 2, _bound, ("ARR", "DIM")),
    _b("UPPER_BOUND", 2, 2, _bound, ("ARR", "DIM")),
    _b("ADD_TIME", 2, 2, _fixed((_TIME, _TIME), _TIME), ("IN1", "IN2")),
    _b("SUB_TIME", 2, 2, _fixed((_TIME, _TIME), _TIME), ("IN1", "IN2")),
    _b("MUL_TIME", 2, 2, _fixed((_TIME, T.LREAL), _TIME), ("IN1", "IN2")),
    _b("DIV_TIME", 2, 2, _fixed((_TIME, T.LREAL), _TIME), ("IN1", "IN2")),
    _b("ADD_TOD_TIME", 2, 2, _fixed((T.TOD, _TIME), T.TOD), ("IN1", "IN2")),
    _b("ADD_DT_TIME", 2, 2, _fixed((T.DT, _TIME), T.DT), ("IN1", "IN2")),
    _b("SUB_DATE_DATE", 2, 2, _fixed((T.DATE, T.DATE), _TIME), ("IN1", "IN2")),
    _b("SUB_TOD_TIME", 2, 2, _fixed((T.TOD, _TIME), T.TOD), ("IN1", "IN2")),
    _b("SUB_TOD_TOD", 2, 2, _fixed((T.TOD, T.TOD), _TIME), ("IN1", "IN2")),
    _b("SUB_DT_TIME", 2, 2, _fixed((T.DT, _TIME), T.DT), ("IN1", "IN2")),
    _b("SUB_DT_DT", 2, 2, _fixed((T.DT, T.DT), _TIME), ("IN1", "IN2")),
    _b("CONCAT_DATE_TOD", 2, 2, _fixed((T.DATE, T.TOD), T.DT), ("IN1", "IN2")),
]}


# Omron instructions with a generic signature ST cannot declare (W560 2-209, Math Instructions: Out :=
# DegToRad(In); / RadToDeg(In);, In REAL or LREAL, Out of the type of In). Vendor names: `--portable` flags them
# (ST2001) as it flags the prelude's instructions.
for _vendor in (Builtin("DegToRad", 1, 1, _real_math, ("In",), vendor=True),
                Builtin("RadToDeg", 1, 1, _real_math, ("In",), vendor=True)):
    BUILTINS[_vendor.name.upper()] = _vendor


# Not in IEC 61131-3 2nd edition (3rd edition or common extensions): reported by `--portable`.
EDITION3 = frozenset({"LOWER_BOUND", "UPPER_BOUND", "ATAN2"})


def is_edition3(builtin: Builtin) -> bool:
    """True for builtins of the 3rd edition only: EDITION3, the generic TO_x, the typed BCD names."""
    name = builtin.name
    return (name in EDITION3 or name.startswith("TO_") or "_BCD_TO_" in name
            or (name.rpartition("_TO_")[2].startswith("BCD_")))


def lookup(name: str) -> Builtin | None:
    """The builtin called ``name`` (case-insensitive), including every ``X_TO_Y`` conversion."""
    up = name.upper()
    b = BUILTINS.get(up)
    if b is not None:
        return b
    if "BCD" in up:
        b = _bcd(up)
        if b is not None:
            BUILTINS[up] = b
        return b
    m = _CONV_RE.match(up)
    if m:
        conv = _conversion(m.group(1), m.group(2))
        if conv is not None:
            BUILTINS[up] = conv
            return conv
    if up.startswith("TO_") and up[3:] in CONVERTIBLE:      # IEC 3rd edition generic conversion TO_<type>
        dst = CONVERTIBLE[up[3:]]

        def resolve(args: list[T.Type], dialect: str, _dst: T.Type | None = dst, _name: str = up[3:]) -> Resolved:
            _need(lambda t: T.is_elementary(t), args[0], 0, "an elementary value")
            return (default_string(dialect, _name == "WSTRING") if _dst is None else _dst), [None]
        b = Builtin(up, 1, 1, resolve, ("IN",))
        BUILTINS[up] = b
        return b
    if up.startswith("TRUNC_") and up[6:] in T.ELEMENTARY and T.is_int(T.ELEMENTARY[up[6:]]):
        target = T.ELEMENTARY[up[6:]]

        def truncate(args: list[T.Type], dialect: str, _t: T.Type = target) -> Resolved:
            _need(T.is_real, args[0], 0, "REAL or LREAL")
            return _t, [None]
        b = Builtin(up, 1, 1, truncate, ("IN",))
        BUILTINS[up] = b
        return b
    return None


def names() -> list[str]:
    """Every fixed builtin name (conversions are generated on demand: all ``X_TO_Y`` of elementary types)."""
    return sorted(BUILTINS)
