"""Sysmac conversion, string and time instructions (W502) as Python functions ``fn(rt, *params)``.

Choices where the documentation available to us is silent are listed in docs/toolchain/runtime_sysmac.md.
"""
from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING, Any

from ..frontend import types as T
from . import iec
from .faults import RuntimeFaultError

if TYPE_CHECKING:
    from .engine import Engine

LOW_HIGH, HIGH_LOW = 0, 1
# how generated code hands an instruction its parameters: an ARRAY as a list (or, given ``a[i]``, a view of the
# array from that element), a VAR_IN_OUT scalar as a (container, key) reference (compiler/codegen_expr.py ref:
# an instance's __dict__ and a name, a list and an index, a union's member view and a name)
Array = list[Any] | iec.ArrView
Ref = tuple[Any, Any]
_NS = 1_000_000_000


def _value_bytes(v: Any, t: T.Type) -> bytes:
    """Little-endian memory image of a value of elementary type ``t``."""
    b = T.base_of(t)
    if isinstance(b, T.EnumType):
        b = T.base_of(b.base)
    if isinstance(b, T.StringType):
        return v.encode("latin-1", "replace")
    if not isinstance(b, T.ElementaryType):
        raise RuntimeFaultError(f"the memory image of a {b} is not modelled by vplc")
    if b.kind == "real":
        return struct.pack("<f" if b.bits == 32 else "<d", v)
    if b.kind == "bool":
        return bytes([1 if v else 0])
    nbytes = max(1, b.bits // 8)
    return (v & ((1 << (nbytes * 8)) - 1)).to_bytes(nbytes, "little")


def _order(data: bytes, order: int) -> bytes:
    """The bytes in the order Order asks for. _LOW_HIGH: as they are in memory (least significant first).
    _HIGH_LOW: taken two by two, high byte first; an odd count is completed with 16#00 first (W502 2-455: a
    one-byte In lands in AryOut[1] with 16#00 in AryOut[0]; In[i] of a byte array with i even goes to
    AryOut[i+1], with i odd to AryOut[i-1]; an odd element count ends with 16#00 swapped in)."""
    if order != HIGH_LOW:
        return data
    if len(data) % 2:
        data += b"\0"
    out = bytearray(len(data))
    out[0::2] = data[1::2]
    out[1::2] = data[0::2]
    return bytes(out)


def _elementary(t: T.Type) -> T.ElementaryType | T.StringType:
    """The base type of ``t`` (an enumeration's storage type for an enumeration). The checker lets these
    instructions take only elementary values (checker/scope.py); anything else is a fault naming it."""
    b = T.base_of(t)
    b = T.base_of(b.base) if isinstance(b, T.EnumType) else b
    if not isinstance(b, (T.ElementaryType, T.StringType)):
        raise RuntimeFaultError(f"the memory image of a {b} is not modelled by vplc")
    return b


def ToAryByte(rt: Engine, In: Any, In_t: T.Type, Order: int, AryOut: Array) -> int:
    """W502 2-453 .. 2-455: In (a value, or an array of values: their bytes one after the other) into AryOut."""
    u = T.unalias(In_t)
    if isinstance(u, T.ArrayType):
        element = u.element
        data = b"".join(_value_bytes(x, element) for x in In)
    else:
        element = In_t
        data = _value_bytes(In, In_t)
    if not isinstance(_elementary(element), T.StringType):
        data = _order(data, Order)
    if len(data) > len(AryOut):
        raise RuntimeFaultError(f"ToAryByte: {len(data)} bytes do not fit in the {len(AryOut)}-byte array")
    iec.store_bytes(AryOut, data)
    return len(data)


def _decode(data: bytes, b: T.ElementaryType) -> bool | int | float:
    """A value of elementary type ``b`` from its little-endian memory image ``data`` (exactly its size)."""
    if b.kind == "real":
        return struct.unpack("<f" if len(data) == 4 else "<d", data)[0]
    if b.kind == "bool":
        return bool(data[0] & 1)                 # W502 2-461: bit 0 of the byte
    return int.from_bytes(data, "little", signed=b.kind == "int")


def _size(b: T.ElementaryType) -> int:
    return 4 if b.kind == "real" and b.bits == 32 else max(1, b.bits // 8)


def AryByteTo(rt: Engine, In: Array, Size: int, Order: int, OutVal: Any, OutVal_t: T.Type) -> bool:
    """W502 2-459 .. 2-461: Size bytes of In, in Order, into OutVal (a value, or an array of values)."""
    if Size > len(In):
        raise RuntimeFaultError(f"AryByteTo: Size {Size} exceeds the {len(In)} bytes of the array")
    data = bytes(In[i] & 0xFF for i in range(Size))
    u = T.unalias(OutVal_t)
    if isinstance(u, T.ArrayType):
        _bytes_to_array(data, Order, OutVal, _elementary(u.element))
        return True
    container, key = OutVal
    b = _elementary(OutVal_t)
    if isinstance(b, T.StringType):
        text = data.split(b"\0", 1)[0].decode("latin-1")
        container[key] = text[:b.capacity]
        return True
    n = _size(b)
    container[key] = _decode(_order(data, Order)[:n].ljust(n, b"\0"), b)
    return True


def _bytes_to_array(data: bytes, order: int, out: Array,
                    b: T.ElementaryType | T.StringType) -> None:
    """An array OutVal: a BOOL array takes the bits, bit 0 of the first byte into OutVal[0] (W502 2-461: In[0] into
    OutVal[0] .. OutVal[7], In[1] into OutVal[8] .. OutVal[15], ...; _HIGH_LOW swaps the bytes two by two first);
    other arrays take one element per element size. Elements the bytes do not reach keep their values; bytes
    beyond the last element are discarded."""
    if isinstance(b, T.StringType):
        raise RuntimeFaultError("AryByteTo: an array of STRING as OutVal is not modelled by vplc")
    data = _order(data, order)
    if b.kind == "bool":
        for i in range(min(len(out), 8 * len(data))):
            out[i] = bool(data[i >> 3] >> (i & 7) & 1)
        return
    n = _size(b)
    for i in range(min(len(out), len(data) // n)):
        out[i] = _decode(data[i * n:(i + 1) * n], b)


def StringToAry(rt: Engine, In: str, AryOut: Array) -> int:
    data = In.encode("latin-1", "replace")
    if len(data) > len(AryOut):
        raise RuntimeFaultError(f"StringToAry: {len(data)} characters do not fit in the {len(AryOut)}-byte array")
    iec.store_bytes(AryOut, data)
    return len(data)


def AryToString(rt: Engine, In: Array, Size: int) -> str:
    if Size > len(In):
        raise RuntimeFaultError(f"AryToString: Size {Size} exceeds the {len(In)} bytes of the array")
    data = iec.bytes_of(In, Size)
    return data.split(b"\0", 1)[0].decode("latin-1")[:1985]


class _Unchanged(str):
    """The result of an instruction that ended in error where W502 says Out does not change (ENO FALSE)."""


UNCHANGED = _Unchanged("")       # an assignment of the call keeps its destination; inside an expression it is ''
KEEPS_OUT_ON_ERROR = frozenset({"RealToFormatString", "LrealToFormatString"})


def _format(rt: Engine, name: str, x: float, Exponent: bool, Sign: bool, MinLen: int, DecPlace: int) -> str:
    """W502 2-269: the fraction is rounded half to even (1.5 -> 2, 2.5 -> 2), which Python's formatting of the
    binary value does. DecPlace greater than MinLen is an error: ENO FALSE and Out does not change, so the
    instruction error is recorded and the assignment keeps its destination (UNCHANGED)."""
    if DecPlace > MinLen:
        rt.instruction_error(f"{name}: DecPlace {DecPlace} is greater than MinLen {MinLen} (W502 2-269); "
                             "Out is not changed")
        return UNCHANGED
    text = f"{x:{'+' if Sign else ''}.{int(DecPlace)}{'e' if Exponent else 'f'}}"
    return text.rjust(int(MinLen))


def RealToFormatString(rt: Engine, In: float, Exponent: bool, Sign: bool, MinLen: int, DecPlace: int) -> str:
    return _format(rt, "RealToFormatString", In, Exponent, Sign, MinLen, DecPlace)


def LrealToFormatString(rt: Engine, In: float, Exponent: bool, Sign: bool, MinLen: int, DecPlace: int) -> str:
    return _format(rt, "LrealToFormatString", In, Exponent, Sign, MinLen, DecPlace)


def stores_out(rt: Engine, value: str, capacity: int, name: str) -> bool:
    """May the result of instruction ``name`` go into the STRING variable connected to Out? Not after an error,
    nor when the text is longer than the variable (W502 2-269: that too is an error and Out does not change)."""
    if value is UNCHANGED:
        return False
    if len(value) > capacity:
        rt.instruction_error(f"{name}: the result has {len(value)} characters, more than the {capacity} the "
                             f"variable connected to Out holds (W502 2-269); Out is not changed")
        return False
    return True


def GetTime(rt: Engine) -> int:
    return rt.clock_dt_ns()


def SecToDt(rt: Engine, In: int) -> int:
    return In * _NS


def DtToSec(rt: Engine, In: int) -> int:
    return In // _NS


def NanoSecToTime(rt: Engine, In: int) -> int:
    return In


def TimeToNanoSec(rt: Engine, In: int) -> int:
    return In


def VPLC_ScanTime(rt: Engine) -> int:
    return rt.now_ns


def SecToTime(rt: Engine, In: int) -> int:
    return In * _NS


def TimeToSec(rt: Engine, In: int) -> int:
    return int(In / _NS)                         # toward zero: the fraction of a second is cut off


def CopyDwordToReal(rt: Engine, In: int) -> float:
    return struct.unpack("<f", struct.pack("<I", In & 0xFFFF_FFFF))[0]


def CopyRealToDword(rt: Engine, In: float) -> int:
    return struct.unpack("<I", struct.pack("<f", In))[0]


def CopyLwordToLreal(rt: Engine, In: int) -> float:
    return struct.unpack("<d", struct.pack("<Q", In & 0xFFFF_FFFF_FFFF_FFFF))[0]


def CopyLrealToLword(rt: Engine, In: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", In))[0]


def EnumToNum(rt: Engine, In: int, In_t: T.Type) -> int:
    return int(In)                               # an enumeration value is held as its number


def ModReal(rt: Engine, In1: float, In2: float) -> float:
    if In2 == 0:
        rt.instruction_error("ModReal: In2 is 0; Out is 0")
        return 0.0
    return math.fmod(In1, In2)                   # the sign of In1, as the division's remainder


def _step(ref: Ref, t: T.Type, delta: int) -> bool:
    container, key = ref
    b = _elementary(t)
    value = container[key] + delta              # (a STRING, which the checker refuses here, fails at the +)
    if isinstance(b, T.ElementaryType) and b.kind != "real":
        bits = b.bits
        value &= (1 << bits) - 1
        if b.kind == "int" and value >= 1 << (bits - 1):
            value -= 1 << bits
    container[key] = value
    return True


def Inc(rt: Engine, InOut: Ref, InOut_t: T.Type) -> bool:
    return _step(InOut, InOut_t, 1)


def Dec(rt: Engine, InOut: Ref, InOut_t: T.Type) -> bool:
    return _step(InOut, InOut_t, -1)


def AryMove(rt: Engine, In: Array, AryOut: Array, Size: int) -> bool:
    """Size elements from In to AryOut; a structure element is copied into the existing one (other references to
    it see the new value)."""
    if Size > len(In) or Size > len(AryOut):
        rt.instruction_error(f"AryMove: Size {Size} exceeds the {min(len(In), len(AryOut))} elements the arrays "
                             "hold from the elements given; nothing is copied")
        return False
    values = [In[i] for i in range(Size)]
    for i, v in enumerate(values):
        if type(v) in (int, float, bool, str):
            AryOut[i] = v
        else:
            iec.assign_into(AryOut[i], iec.copy_value(v))
    return True


def SizeOfAry(rt: Engine, In: Array) -> int:
    return len(In)


def ClearString(rt: Engine, InOut: Ref) -> bool:
    container, key = InOut
    container[key] = ""
    return True


def GetMyTaskInterval(rt: Engine) -> int:
    task = getattr(rt, "current_task", None)
    return task.period_ns if task is not None else rt.period_ns


def Get1sClk(rt: Engine) -> bool:
    return rt.now_ns % 1_000_000_000 < 500_000_000


def Get100msClk(rt: Engine) -> bool:
    return rt.now_ns % 100_000_000 < 50_000_000


def Get1msClk(rt: Engine) -> bool:
    return rt.now_ns % 1_000_000 < 500_000


def Get10msClk(rt: Engine) -> bool:
    return rt.now_ns % 10_000_000 < 5_000_000


def Get1minClk(rt: Engine) -> bool:
    return rt.now_ns % 60_000_000_000 < 30_000_000_000


def Get1usCnt(rt: Engine) -> int:
    return rt.now_ns // 1_000                    # W560 2-1465; counted from the start of the run


def Get1msCnt(rt: Engine) -> int:
    return rt.now_ns // 1_000_000


FUNCTIONS = {f.__name__: f for f in (ToAryByte, AryByteTo, StringToAry, AryToString, RealToFormatString,
                                     LrealToFormatString, GetTime, SecToDt, DtToSec, NanoSecToTime,
                                     TimeToNanoSec, VPLC_ScanTime, SecToTime, TimeToSec, CopyDwordToReal,
                                     CopyRealToDword, CopyLwordToLreal, CopyLrealToLword, EnumToNum, ModReal,
                                     Inc, Dec, AryMove, SizeOfAry, ClearString, GetMyTaskInterval, Get1sClk,
                                     Get100msClk, Get1msClk, Get10msClk, Get1minClk, Get1usCnt,
                                     Get1msCnt)}
