"""Sysmac unions (W501 6-3-6 derivative data types; memory allocation of unions: "the members overlap in the same
memory locations", the size is the largest member's, A-5-1 of W506): a union holds one memory image, kept as a
little-endian integer in a one-element list (the cell), and each member reads and writes its bits of it.

Layout of a member: a BOOL is bit 0; an array of BOOL takes one bit per element (element i is bit i — W501's
BOOL arrays are bit-packed); any other elementary member takes its bytes from the first byte, an array of them
one element after the other. Integers read signed or unsigned as their type, REAL/LREAL as IEEE 754.
"""
from __future__ import annotations

import struct
from collections.abc import Iterable, Iterator
from typing import Any, overload

# what a member of a union or a variable in a memory area holds: BOOL, an integer or bit string, REAL/LREAL
Scalar = bool | int | float


def decode_bits(bits: int, kind: str, size: int) -> Scalar:
    """The value of ``size`` bits of an image as a member of ``kind`` (bool, int, uint/bit, real) reads it; a
    union and a memory area (at_memory.py) share this layout."""
    if kind == "bool":
        return bool(bits & 1)
    if kind == "real":
        return struct.unpack("<f" if size == 32 else "<d", bits.to_bytes(size // 8, "little"))[0]
    if kind == "int" and bits >> (size - 1):
        return bits - (1 << size)
    return bits


def encode_bits(value: Scalar, kind: str, size: int) -> int:
    """The ``size`` bits that hold ``value`` as a member of ``kind``: the inverse of ``decode_bits``."""
    if kind == "bool":
        return 1 if value else 0
    if kind == "real":
        return int.from_bytes(struct.pack("<f" if size == 32 else "<d", value), "little")
    return int(value) & ((1 << size) - 1)


def read(cell: list[int], kind: str, size: int, offset: int = 0) -> Scalar:
    """The member of ``size`` bits at bit ``offset`` of the union's image."""
    return decode_bits(cell[0] >> offset & ((1 << size) - 1), kind, size)


def write(cell: list[int], kind: str, size: int, value: Scalar, offset: int = 0) -> None:
    mask = ((1 << size) - 1) << offset
    cell[0] = (cell[0] & ~mask) | (encode_bits(value, kind, size) << offset)


class ElementView:
    """A live view of the elements of an array stored in a memory image (a union's image, a memory area): the
    list behaviour both share; a subclass reads and writes one element at a checked index."""
    __slots__ = ("n",)
    n: int                                  # the number of elements, set by the subclass

    def _get(self, i: int) -> Scalar:
        raise NotImplementedError

    def _set(self, i: int, v: Scalar) -> None:
        raise NotImplementedError

    def _checked(self, i: int) -> int:
        if not 0 <= i < self.n:
            raise IndexError(i)
        return i

    def __len__(self) -> int:
        return self.n

    @overload
    def __getitem__(self, i: int) -> Scalar: ...

    @overload
    def __getitem__(self, i: slice) -> list[Scalar]: ...

    def __getitem__(self, i: int | slice) -> Scalar | list[Scalar]:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(self.n))]
        return self._get(self._checked(i))

    def __setitem__(self, i: int | slice, v: Any) -> None:
        if isinstance(i, slice):
            for k, x in zip(range(*i.indices(self.n)), v, strict=False):
                self[k] = x
            return
        self._set(self._checked(i), v)

    def __iter__(self) -> Iterator[Scalar]:
        return (self[i] for i in range(self.n))

    def __eq__(self, other: Any) -> bool:          # compared with a list (or another view) by its elements
        return list(self) == list(other)

    def __repr__(self) -> str:
        return repr(list(self))


class MemberArray(ElementView):
    """An array member of a union: a live view of its elements in the union's image (writing an element writes
    the image, so the other members see it)."""
    __slots__ = ("cell", "kind", "size")

    def __init__(self, cell: list[int], kind: str, size: int, n: int) -> None:
        self.cell, self.kind, self.size, self.n = cell, kind, size, n

    def _get(self, i: int) -> Scalar:
        return read(self.cell, self.kind, self.size, i * self.size)

    def _set(self, i: int, v: Scalar) -> None:
        write(self.cell, self.kind, self.size, v, i * self.size)


def member_property(kind: str, size: int, count: int | None) -> property:
    """The property of a union class for one member (``count``: elements of an array member, else None)."""
    if count is None:
        return property(lambda s: read(s.i__m, kind, size), lambda s, v: write(s.i__m, kind, size, v))

    def set_all(s: Any, values: Iterable[Scalar]) -> None:      # s: an instance of the generated union class
        view = MemberArray(s.i__m, kind, size, count)
        view[:] = list(values)
    return property(lambda s: MemberArray(s.i__m, kind, size, count), set_all)


class Members:
    """The members of one union as a mapping (attribute name -> value), for code that reads and writes variables
    by name (vplc.api's read/write, the HMI, traces)."""
    __slots__ = ("union",)

    def __init__(self, union: Any) -> None:         # an instance of a generated union class
        self.union = union

    def __getitem__(self, key: str) -> Any:
        return getattr(self.union, key)

    def __setitem__(self, key: str, value: Any) -> None:
        setattr(self.union, key, value)

    def __contains__(self, key: str) -> bool:
        return hasattr(type(self.union), key)


members = property(Members)
