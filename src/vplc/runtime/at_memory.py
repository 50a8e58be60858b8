"""The controller's memory areas that Sysmac AT specifications address (W501: CIO, Work %W, Holding %H, DM %D and
EM %E banks), for global variables placed in them (checker/at_address.py): one byte array per area (and EM bank),
16-bit words little-endian, so variables at the same words read each other's bits.

A variable is read and written through a property of the Globals class; its bits start at word * 16 + bit. The
memory belongs to one PLC (its Globals object), like every other variable.
"""
from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from .unions import ElementView, Scalar, decode_bits, encode_bits


class AreaMemory:
    """The areas of one PLC, created on first use (an EM bank is 64 KiB)."""

    def __init__(self) -> None:
        self.areas: dict[tuple[str, int], bytearray] = {}

    def area(self, name: str, bank: int, words: int) -> bytearray:
        mem = self.areas.get((name, bank))
        if mem is None:
            mem = self.areas[(name, bank)] = bytearray(2 * words)
        return mem


def _read(mem: bytearray, offset: int, size: int, kind: str) -> Scalar:
    first, shift = offset >> 3, offset & 7
    last = (offset + size + 7) >> 3
    raw = int.from_bytes(mem[first:last], "little") >> shift
    return decode_bits(raw & ((1 << size) - 1), kind, size)


def _write(mem: bytearray, offset: int, size: int, kind: str, value: Scalar) -> None:
    first, shift = offset >> 3, offset & 7
    last = (offset + size + 7) >> 3
    raw = int.from_bytes(mem[first:last], "little")
    mask = ((1 << size) - 1) << shift
    raw = (raw & ~mask) | (encode_bits(value, kind, size) << shift)
    mem[first:last] = raw.to_bytes(last - first, "little")


class AreaArray(ElementView):
    """An array variable in a memory area: a live view of its elements."""
    __slots__ = ("mem", "offset", "kind", "size")

    def __init__(self, mem: bytearray, offset: int, kind: str, size: int, n: int) -> None:
        self.mem, self.offset, self.kind, self.size, self.n = mem, offset, kind, size, n

    def _get(self, i: int) -> Scalar:
        return _read(self.mem, self.offset + i * self.size, self.size, self.kind)

    def _set(self, i: int, v: Scalar) -> None:
        _write(self.mem, self.offset + i * self.size, self.size, self.kind, v)


def area_property(area: str, bank: int, words: int, word: int, bit: int, kind: str, size: int,
                  count: int | None) -> property:
    """The property of the Globals class for one variable placed in a memory area."""
    offset = word * 16 + bit
    if kind == "bool" and count:
        size = 1

    def mem(s: Any) -> bytearray:                # s: the PLC's instance of the generated Globals class
        return s.i__mem.area(area, bank, words)
    if count is None:
        return property(lambda s: _read(mem(s), offset, size, kind),
                        lambda s, v: _write(mem(s), offset, size, kind, v))

    def set_all(s: Any, values: Iterable[Scalar]) -> None:
        AreaArray(mem(s), offset, kind, size, count)[:] = list(values)
    return property(lambda s: AreaArray(mem(s), offset, kind, size, count), set_all)
