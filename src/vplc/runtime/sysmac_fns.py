"""Sysmac conversion, string and time instructions (W502) as Python functions ``fn(rt, *params)``.

Choices where the documentation available to us is silent are listed in docs/toolchain/runtime_sysmac.md.
"""
from __future__ import annotations

import struct

from ..frontend import types as T
from . import iec
from .faults import RuntimeFaultError

LOW_HIGH, HIGH_LOW = 0, 1
_NS = 1_000_000_000


def _value_bytes(v, t) -> bytes:
    """Little-endian memory image of a value of elementary type ``t``."""
    b = T.base_of(t)
    if isinstance(b, T.EnumType):
        b = T.base_of(b.base)
    if isinstance(b, T.StringType):
        return v.encode("latin-1", "replace")
    if b.kind == "real":
        return struct.pack("<f" if b.bits == 32 else "<d", v)
    if b.kind == "bool":
        return bytes([1 if v else 0])
    nbytes = max(1, b.bits // 8)
    return (v & ((1 << (nbytes * 8)) - 1)).to_bytes(nbytes, "little")


def _order(data: bytes, order: int) -> bytes:
    """Apply the byte order word by word: words are taken low word first, Order acts inside each word."""
    if order != HIGH_LOW or len(data) < 2:
        return data
    out = bytearray()
    for i in range(0, len(data), 2):
        out += data[i:i + 2][::-1]
    return bytes(out)


def ToAryByte(rt, In, In_t, Order, AryOut) -> int:
    data = _value_bytes(In, In_t)
    if not isinstance(T.base_of(In_t), T.StringType):
        data = _order(data, Order)
    if len(data) > len(AryOut):
        raise RuntimeFaultError(f"ToAryByte: {len(data)} bytes do not fit in the {len(AryOut)}-byte array")
    iec.store_bytes(AryOut, data)
    return len(data)


def AryByteTo(rt, In, Size, Order, OutVal, OutVal_t) -> bool:
    if Size > len(In):
        raise RuntimeFaultError(f"AryByteTo: Size {Size} exceeds the {len(In)} bytes of the array")
    data = bytes(In[i] & 0xFF for i in range(Size))
    container, key = OutVal
    b = T.base_of(OutVal_t)
    if isinstance(b, T.EnumType):
        b = T.base_of(b.base)
    if isinstance(b, T.StringType):
        text = data.split(b"\0", 1)[0].decode("latin-1")
        container[key] = text[:b.capacity]
        return True
    n = 4 if b.kind == "real" and b.bits == 32 else max(1, b.bits // 8)
    data = _order(data[:n].ljust(n, b"\0"), Order)
    if b.kind == "real":
        container[key] = struct.unpack("<f" if n == 4 else "<d", data)[0]
    elif b.kind == "bool":
        container[key] = data[0] != 0
    else:
        container[key] = int.from_bytes(data, "little", signed=b.kind == "int")
    return True


def StringToAry(rt, In, AryOut) -> int:
    data = In.encode("latin-1", "replace")
    if len(data) > len(AryOut):
        raise RuntimeFaultError(f"StringToAry: {len(data)} characters do not fit in the {len(AryOut)}-byte array")
    iec.store_bytes(AryOut, data)
    return len(data)


def AryToString(rt, In, Size) -> str:
    if Size > len(In):
        raise RuntimeFaultError(f"AryToString: Size {Size} exceeds the {len(In)} bytes of the array")
    data = iec.bytes_of(In, Size)
    return data.split(b"\0", 1)[0].decode("latin-1")[:1985]


class _Unchanged(str):
    """The result of an instruction that ended in error where W502 says Out does not change (ENO FALSE)."""


UNCHANGED = _Unchanged("")       # an assignment of the call keeps its destination; inside an expression it is ''
KEEPS_OUT_ON_ERROR = frozenset({"RealToFormatString", "LrealToFormatString"})


def _format(rt, name: str, x: float, Exponent: bool, Sign: bool, MinLen: int, DecPlace: int) -> str:
    """W502 2-269: the fraction is rounded half to even (1.5 -> 2, 2.5 -> 2), which Python's formatting of the
    binary value does. DecPlace greater than MinLen is an error: ENO FALSE and Out does not change, so the
    instruction error is recorded and the assignment keeps its destination (UNCHANGED)."""
    if DecPlace > MinLen:
        rt.instruction_error(f"{name}: DecPlace {DecPlace} is greater than MinLen {MinLen} (W502 2-269); "
                             "Out is not changed")
        return UNCHANGED
    text = f"{x:{'+' if Sign else ''}.{int(DecPlace)}{'e' if Exponent else 'f'}}"
    return text.rjust(int(MinLen))


def RealToFormatString(rt, In, Exponent, Sign, MinLen, DecPlace) -> str:
    return _format(rt, "RealToFormatString", In, Exponent, Sign, MinLen, DecPlace)


def LrealToFormatString(rt, In, Exponent, Sign, MinLen, DecPlace) -> str:
    return _format(rt, "LrealToFormatString", In, Exponent, Sign, MinLen, DecPlace)


def stores_out(rt, value: str, capacity: int, name: str) -> bool:
    """May the result of instruction ``name`` go into the STRING variable connected to Out? Not after an error,
    nor when the text is longer than the variable (W502 2-269: that too is an error and Out does not change)."""
    if value is UNCHANGED:
        return False
    if len(value) > capacity:
        rt.instruction_error(f"{name}: the result has {len(value)} characters, more than the {capacity} the "
                             f"variable connected to Out holds (W502 2-269); Out is not changed")
        return False
    return True


def GetTime(rt) -> int:
    return rt.clock_dt_ns()


def SecToDt(rt, In) -> int:
    return In * _NS


def DtToSec(rt, In) -> int:
    return In // _NS


def NanoSecToTime(rt, In) -> int:
    return In


def TimeToNanoSec(rt, In) -> int:
    return In


def VPLC_ScanTime(rt) -> int:
    return rt.now_ns


FUNCTIONS = {f.__name__: f for f in (ToAryByte, AryByteTo, StringToAry, AryToString, RealToFormatString,
                                     LrealToFormatString, GetTime, SecToDt, DtToSec, NanoSecToTime,
                                     TimeToNanoSec, VPLC_ScanTime)}
