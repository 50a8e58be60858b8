"""IEC 61131-3 value semantics used by generated code.

Values: BOOL -> bool, integers and bit strings -> int (wrapped to their width), REAL -> float rounded to
32 bits on every store, LREAL -> float, TIME/LTIME -> int nanoseconds, DATE/TOD/DT -> int nanoseconds
(since 1970-01-01 / since midnight), STRING -> str, enums -> int, structs and FB instances -> objects,
arrays -> flat Python lists (row-major).
"""
from __future__ import annotations

import math
import struct
from collections.abc import Callable, Iterator
from typing import Any

from .faults import RuntimeFaultError

_F32 = struct.Struct("<f")
F32_MAX = 3.4028234663852886e38


def f32(x: float, _pack: Callable[..., bytes] = _F32.pack,
        _unpack: Callable[[bytes], tuple[Any, ...]] = _F32.unpack) -> float:
    """Round a Python float to IEEE single precision (overflow gives +/-inf like the FPU)."""
    try:
        return _unpack(_pack(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
    except TypeError:
        return _unpack(_pack(float(x)))[0]


def wrapper(bits: int, signed: bool) -> Callable[[int], int]:
    """Return a function wrapping an int to ``bits`` (two's complement when ``signed``)."""
    mask = (1 << bits) - 1
    if signed:
        half = 1 << (bits - 1)
        return lambda v: ((v + half) & mask) - half
    return lambda v: v & mask


def wrap_expr(code: str, bits: int, signed: bool) -> str:
    """Python expression text wrapping ``code`` to the width (inlined by the code generator)."""
    mask = (1 << bits) - 1
    if signed:
        half = 1 << (bits - 1)
        return f"(((({code}) + {half}) & {mask}) - {half})"
    return f"(({code}) & {mask})"


def idiv(a: int, b: int) -> int:
    """Integer division truncating toward zero; division by zero is a major fault."""
    if b == 0:
        raise RuntimeFaultError(f"integer division by zero ({a} / 0)")
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b >= 0) else -q


def imod(a: int, b: int) -> int:
    """IEC MOD: the result has the sign of the dividend (a - TRUNC(a/b)*b)."""
    if b == 0:
        raise RuntimeFaultError(f"integer division by zero ({a} MOD 0)")
    return a - idiv(a, b) * b


def rdiv(a: float, b: float) -> float:
    """Real division: IEEE 754 result (division by zero gives +/-inf or NaN, no fault, like the FPU)."""
    try:
        return a / b
    except ZeroDivisionError:
        if a == 0 or a != a:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)


def expt(a: float, b: float) -> float:
    try:
        r = float(a) ** b
    except ZeroDivisionError:
        raise RuntimeFaultError(f"EXPT: 0 raised to the negative power {b}") from None
    except OverflowError:
        return math.inf
    if isinstance(r, complex):
        return math.nan
    return r


def shl(v: int, n: int, bits: int) -> int:
    return (v << n) & ((1 << bits) - 1) if 0 <= n < bits else 0


def shr(v: int, n: int, bits: int) -> int:
    return (v & ((1 << bits) - 1)) >> n if 0 <= n < bits else 0


def rol(v: int, n: int, bits: int) -> int:
    n %= bits
    mask = (1 << bits) - 1
    v &= mask
    return ((v << n) | (v >> (bits - n))) & mask


def ror(v: int, n: int, bits: int) -> int:
    return rol(v, bits - (n % bits), bits)


def ix1(i: int, lo: int, hi: int, what: str = "array") -> int:
    """Offset of index ``i`` in a one-dimensional array ``lo..hi``; out of range is a major fault."""
    if lo <= i <= hi:
        return i - lo
    raise RuntimeFaultError(f"index {i} out of range {lo}..{hi} of {what}")


def ixn(idx: tuple, dims: tuple, what: str = "array") -> int:
    off = 0
    for i, (lo, hi) in zip(idx, dims, strict=False):
        if not lo <= i <= hi:
            raise RuntimeFaultError(f"index {i} out of range {lo}..{hi} of {what}")
        off = off * (hi - lo + 1) + (i - lo)
    return off


def ixo(i: int, arr: list | ArrView, what: str = "array") -> int:
    """Index into an open array (``ARRAY[*]``): bounds are those of the actual array (``lo`` of a view),
    or 0..n-1 when an element was passed as the array start."""
    lo = getattr(arr, "lo", 0)
    if lo <= i < lo + len(arr):
        return i - lo
    raise RuntimeFaultError(f"index {i} out of range {lo}..{lo + len(arr) - 1} of {what}")


def lower_bound(arr: list | ArrView) -> int:
    return getattr(arr, "lo", 0)


def upper_bound(arr: list | ArrView) -> int:
    return getattr(arr, "lo", 0) + len(arr) - 1


class ArrView:
    """The array starting at an element (Sysmac rule for array parameters given ``a[i]``)."""
    __slots__ = ("base", "off", "n", "lo")
    base: Any           # the list (never a view: a view of a view is a view of the list)
    off: int
    n: int
    lo: int

    def __init__(self, base: list | ArrView, off: int, lo: int = 0) -> None:
        if isinstance(base, ArrView):
            off += base.off
            base = base.base
        self.base, self.off, self.n, self.lo = base, off, len(base) - off, lo

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, i: int | slice) -> Any:
        if isinstance(i, slice):
            return [self.base[self.off + k] for k in range(*i.indices(self.n))]
        return self.base[self.off + i]

    def __setitem__(self, i: int | slice, v: Any) -> None:
        if isinstance(i, slice):
            for k, x in zip(range(*i.indices(self.n)), v, strict=False):
                self.base[self.off + k] = x
            return
        self.base[self.off + i] = v

    def __iter__(self) -> Iterator[Any]:
        b, o = self.base, self.off
        return (b[o + k] for k in range(self.n))


def bytes_of(arr: list[int] | ArrView, n: int) -> bytes:
    """The first ``n`` elements of a byte array (a list, or a view starting at an element) as bytes."""
    items = arr.base[arr.off:arr.off + n] if isinstance(arr, ArrView) else arr[:n]
    try:
        return bytes(items)
    except ValueError:                      # elements of a wider integer type: their low bytes, as Sysmac sends
        return bytes(x & 0xFF for x in items)


def store_bytes(arr: bytearray | list[int] | ArrView, data: bytes) -> None:
    """Write ``data`` into the first elements of a byte array (a bytearray or list, or a view starting at an
    element)."""
    if isinstance(arr, ArrView):
        arr.base[arr.off:arr.off + len(data)] = data
    else:
        arr[:len(data)] = data


def copy_value(v: Any) -> Any:
    """Deep copy of a value (structs and arrays are copied; scalars are immutable)."""
    t: Any = type(v)
    if t is bytearray:                          # an array of BYTE / USINT (compiler: holds_bytes)
        return v[:]
    if t is list:
        if v and type(v[0]) in (int, float, bool, str):
            return v[:]
        return [copy_value(x) for x in v]
    if t in (int, float, bool, str):
        return v
    if isinstance(v, ArrView):
        return [copy_value(x) for x in v]
    o = t.__new__(t)
    o.__dict__.update({k: copy_value(x) for k, x in v.__dict__.items()})
    return o


def assign_into(dst: Any, src: Any) -> None:
    """Structure / array assignment: copy ``src`` into the existing ``dst`` object (keeps references)."""
    if isinstance(dst, (list, bytearray, ArrView)):
        n = min(len(dst), len(src))
        if n and type(src[0]) in (int, float, bool, str):      # elements of one elementary type: in one piece
            dst[:n] = src[:n] if len(src) != n or type(src) not in (list, bytearray) else src
            return
        for i in range(n):
            x = src[i]
            if type(x) in (int, float, bool, str):
                dst[i] = x
            elif isinstance(x, (list, bytearray, ArrView)) or hasattr(x, "__dict__"):
                assign_into(dst[i], x)
        return
    for k, x in src.__dict__.items():
        if type(x) in (int, float, bool, str):
            dst.__dict__[k] = x
        else:
            assign_into(dst.__dict__[k], x)


# ---- conversions ---------------------------------------------------------------------------------

def round_half_even(x: float) -> int:
    """REAL -> integer conversion rounding: to nearest, ties to even (IEEE default rounding)."""
    if x != x or x in (math.inf, -math.inf):
        raise RuntimeFaultError(f"cannot convert {x} to an integer")
    return round(x)


def trunc(x: float) -> int:
    if x != x or x in (math.inf, -math.inf):
        raise RuntimeFaultError(f"cannot convert {x} to an integer")
    return int(x)


def fmt_time(ns: int, prefix: str = "T#") -> str:
    """TIME value as IEC text, e.g. T#1h2m3s4ms (Sysmac prints nanosecond fractions when present)."""
    neg = ns < 0
    ns = abs(ns)
    parts = []
    for unit, size in (("d", 86_400_000_000_000), ("h", 3_600_000_000_000), ("m", 60_000_000_000),
                       ("s", 1_000_000_000), ("ms", 1_000_000), ("us", 1_000), ("ns", 1)):
        q, ns = divmod(ns, size)
        if q:
            parts.append(f"{q}{unit}")
    return prefix + ("-" if neg else "") + ("".join(parts) or "0ms")


def fmt_real(x: float, single: bool) -> str:
    if x != x:
        return "nan"
    if x in (math.inf, -math.inf):
        return "inf" if x > 0 else "-inf"
    text = repr(float(f"{x:.7g}")) if single else repr(x)
    return text[:-2] if text.endswith(".0") else text


def fmt_real32(x: float) -> str:
    return fmt_real(x, True)


def fmt_real64(x: float) -> str:
    return fmt_real(x, False)
