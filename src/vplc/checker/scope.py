"""Symbol tables and name lookup (namespaces, case-insensitive names).

Lookup rule for a bare name: the namespace of the file that uses it, then the global namespace, then any
library namespace where it is unique (else ST1003 ambiguous). ``Ns\\Name`` looks only in ``Ns``.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Generic, TypeGuard, TypeVar

from ..frontend import types as T
from .symbols import EnumValueSymbol, VarSymbol

GENERIC_TYPES: dict[str, T.SpecialType] = {}


def _generic(name: str, pred: Callable[[T.Type], bool], shown: str | None = None) -> None:
    t = T.SpecialType(shown or name, "generic", pred)
    GENERIC_TYPES[name] = t


def _elementary_or_array(t: T.Type) -> bool:
    u = T.unalias(t)
    return T.is_elementary(u) or (isinstance(u, T.ArrayType) and T.is_elementary(u.element))


_generic("ANY", lambda t: True)
_generic("ANY_ELEMENTARY", T.is_elementary)
# ToAryByte's In and AryByteTo's OutVal: an elementary value or an array of one (W502 2-455, 2-461)
_generic("ANY_ELEMENTARY_OR_ARRAY", _elementary_or_array, "ANY_ELEMENTARY or an array of it")
_generic("ANY_NUM", T.is_num)
_generic("ANY_INT", T.is_int)
_generic("ANY_REAL", T.is_real)
_generic("ANY_BIT", T.is_bits)
_generic("ANY_STRING", T.is_string)
_generic("ANY_DATE", T.is_date_like)
# EnumToNum's In: a value of any enumeration (W502, Data Type Conversion Instructions)
_generic("ANY_ENUM", lambda t: isinstance(T.base_of(t), T.EnumType), "an enumeration")


def is_generic(t: T.Type) -> TypeGuard[T.SpecialType]:
    return isinstance(t, T.SpecialType) and t.kind == "generic"


class Ambiguous(Exception):
    def __init__(self, candidates: list[str]) -> None:
        super().__init__(", ".join(candidates))
        self.candidates = candidates


E = TypeVar("E")


@dataclass
class NamedTable(Generic[E]):
    """Maps (namespace, NAME) → entry; namespace '' is the global namespace."""
    entries: dict[tuple[str, str], E] = field(default_factory=dict)
    by_name: dict[str, list[tuple[str, E]]] = field(default_factory=dict)

    def add(self, ns: str | None, name: str, obj: E) -> E | None:
        """Register; returns the previous object with the same key (a duplicate) or None."""
        key = ((ns or "").upper(), name.upper())
        prev = self.entries.get(key)
        if prev is not None:
            return prev
        self.entries[key] = obj
        self.by_name.setdefault(name.upper(), []).append((ns or "", obj))
        return None

    def lookup(self, name: str, namespace: tuple[str, ...] = (), from_ns: str | None = None) -> E | None:
        up = name.upper()
        if namespace:
            return self.entries.get(("\\".join(namespace).upper(), up))
        if from_ns:                     # the namespace itself, then the namespaces it is nested in
            ns = from_ns.upper()
            while True:
                hit = self.entries.get((ns, up))
                if hit is not None:
                    return hit
                if "\\" not in ns:
                    break
                ns = ns.rsplit("\\", 1)[0]
        hit = self.entries.get(("", up))
        if hit is not None:
            return hit
        cands = self.by_name.get(up, [])
        if len(cands) == 1:
            return cands[0][1]
        if len(cands) > 1:
            raise Ambiguous([f"{ns}\\{name}" if ns else name for ns, _ in cands])
        return None


@dataclass
class Tables:
    pous: NamedTable[T.PouType] = field(default_factory=NamedTable)
    types: NamedTable[T.Type] = field(default_factory=NamedTable)
    globals: dict[str, VarSymbol] = field(default_factory=dict)
    enum_values: dict[str, list[EnumValueSymbol]] = field(default_factory=dict)

    def add_enum(self, enum: T.EnumType) -> None:
        for name, value in enum.values.items():
            self.enum_values.setdefault(name.upper(), []).append(EnumValueSymbol(enum, name, value))
