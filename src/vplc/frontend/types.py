"""Semantic types of the checked program.

Elementary types carry their IEC width and range; derived types (STRING[n], arrays, structs, enums,
subranges, aliases) and POU types (function, function block, program) are built by the checker from
declarations. Type identity: elementary types are singletons (compare with ``is``); user types are one
object per declaration. ``unalias(t)`` strips alias types.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


class Type:
    """Base class. ``name`` is the IEC text of the type (``INT``, ``STRING[50]``, ``Ns\\stX``)."""
    name: str = "?"
    kind: str = "?"

    def __str__(self) -> str:
        return self.name

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name}>"


class ElementaryType(Type):
    """kind: bool, bit (BYTE..LWORD), int (signed), uint (unsigned), real, time, ltime, date, tod, dt, ldt."""

    def __init__(self, name: str, kind: str, bits: int, lo: int | float | None = None,
                 hi: int | float | None = None) -> None:
        self.name = name
        self.kind = kind
        self.bits = bits
        self.lo = lo
        self.hi = hi

    @property
    def signed(self) -> bool:
        return self.kind == "int"


def _int(name: str, bits: int, signed: bool) -> ElementaryType:
    if signed:
        return ElementaryType(name, "int", bits, -(1 << (bits - 1)), (1 << (bits - 1)) - 1)
    return ElementaryType(name, "uint", bits, 0, (1 << bits) - 1)


def _bits(name: str, bits: int) -> ElementaryType:
    return ElementaryType(name, "bit", bits, 0, (1 << bits) - 1)


BOOL = ElementaryType("BOOL", "bool", 1, 0, 1)
BYTE, WORD, DWORD, LWORD = _bits("BYTE", 8), _bits("WORD", 16), _bits("DWORD", 32), _bits("LWORD", 64)
SINT, INT, DINT, LINT = _int("SINT", 8, True), _int("INT", 16, True), _int("DINT", 32, True), _int("LINT", 64, True)
USINT, UINT, UDINT, ULINT = (_int("USINT", 8, False), _int("UINT", 16, False), _int("UDINT", 32, False),
                             _int("ULINT", 64, False))
REAL = ElementaryType("REAL", "real", 32, -3.4028234663852886e38, 3.4028234663852886e38)
LREAL = ElementaryType("LREAL", "real", 64, -1.7976931348623157e308, 1.7976931348623157e308)
# Durations in nanoseconds (Sysmac TIME is 64-bit ns; LTIME identical).
TIME = ElementaryType("TIME", "time", 64, -(1 << 63), (1 << 63) - 1)
LTIME = ElementaryType("LTIME", "time", 64, -(1 << 63), (1 << 63) - 1)
DATE = ElementaryType("DATE", "date", 64)
TOD = ElementaryType("TIME_OF_DAY", "tod", 64)
DT = ElementaryType("DATE_AND_TIME", "dt", 64)

ELEMENTARY: dict[str, ElementaryType] = {
    t.name: t for t in (BOOL, BYTE, WORD, DWORD, LWORD, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT,
                        REAL, LREAL, TIME, LTIME, DATE, TOD, DT)
}
ELEMENTARY.update({"TOD": TOD, "DT": DT, "LTOD": TOD, "LDT": DT, "LDATE": DATE,
                   "LTIME_OF_DAY": TOD, "LDATE_AND_TIME": DT})


class StringType(Type):
    """STRING[n] / WSTRING[n]. ``length`` is the declared size. In the Sysmac dialect the size counts the
    terminating NUL, so ``capacity`` (max characters) is ``length - 1``; in the IEC dialect it is ``length``."""

    kind = "string"

    def __init__(self, length: int, wide: bool = False, capacity: int | None = None, explicit: bool = True):
        self.length = length
        self.wide = wide
        self.capacity = length if capacity is None else capacity
        self.explicit = explicit
        base = "WSTRING" if wide else "STRING"
        self.name = f"{base}[{length}]" if explicit else base

    def __eq__(self, other: object) -> bool:
        return isinstance(other, StringType) and other.wide == self.wide and other.length == self.length

    def __hash__(self) -> int:
        return hash(("string", self.wide, self.length))


@dataclass(eq=False)
class ArrayType(Type):
    """``dims`` is a list of (lo, hi) inclusive bounds; (None, None) for an open dimension ``*``."""
    dims: list[tuple[int | None, int | None]]
    element: Type
    kind: str = "array"

    @property
    def name(self) -> str:  # type: ignore[override]
        dims = ", ".join("*" if lo is None else f"{lo}..{hi}" for lo, hi in self.dims)
        return f"ARRAY[{dims}] OF {self.element.name}"

    @property
    def open(self) -> bool:
        return any(lo is None for lo, _ in self.dims)

    def count(self) -> int:
        n = 1
        for lo, hi in self.dims:
            n *= 0 if lo is None or hi is None else (hi - lo + 1)
        return n

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ArrayType) and other.dims == self.dims and same_type(other.element, self.element)

    def __hash__(self) -> int:
        return hash(("array", tuple(self.dims)))


@dataclass(eq=False)
class StructField:
    name: str
    type: Type
    init: Any = None       # ast.Expr or None
    decl: Any = None       # ast.VarDecl


@dataclass(eq=False)
class StructType(Type):
    name: str
    fields: dict[str, StructField] = field(default_factory=dict)   # upper-cased key -> field, in order
    decl: Any = None
    kind: str = "struct"
    namespace: str | None = None

    def field(self, name: str) -> StructField | None:
        return self.fields.get(name.upper())


@dataclass(eq=False)
class EnumType(Type):
    """``values`` maps the value name (as declared) to its integer; ``base`` is the storage type (INT)."""
    name: str
    values: dict[str, int] = field(default_factory=dict)
    base: Type = INT
    decl: Any = None
    kind: str = "enum"
    namespace: str | None = None

    def lookup(self, value: str) -> str | None:
        for v in self.values:
            if v.upper() == value.upper():
                return v
        return None


@dataclass(eq=False)
class SubrangeType(Type):
    base: ElementaryType
    lo: int
    hi: int
    alias: str | None = None
    kind: str = "subrange"

    @property
    def name(self) -> str:  # type: ignore[override]
        return self.alias or f"{self.base.name}({self.lo}..{self.hi})"


@dataclass(eq=False)
class AliasType(Type):
    """``TYPE MyInt : INT; END_TYPE`` — behaves like ``target``."""
    name: str
    target: Type = None  # type: ignore[assignment]
    decl: Any = None
    kind: str = "alias"
    namespace: str | None = None


@dataclass(eq=False)
class Param:
    """A formal parameter of a POU type. direction: 'in' | 'out' | 'inout'."""
    name: str
    direction: str
    type: Type
    index: int                     # position among all parameters, declaration order
    default: Any = None            # ast.Expr initial value or None
    decl: Any = None               # ast.VarDecl (None for builtins)


@dataclass(eq=False)
class PouType(Type):
    """Type of a FUNCTION (kind 'function'), FUNCTION_BLOCK ('fb') or PROGRAM ('program').

    ``params`` are the VAR_INPUT/VAR_OUTPUT/VAR_IN_OUT in declaration order; ``ret`` the function result
    type (VOID for FBs/programs). ``pou`` is the ast.Pou (None for builtins)."""
    name: str
    kind: str
    params: list[Param] = field(default_factory=list)
    ret: Type | None = None
    pou: Any = None
    native: bool = False
    namespace: str | None = None

    def param(self, name: str) -> Param | None:
        up = name.upper()
        for p in self.params:
            if p.name.upper() == up:
                return p
        return None

    @property
    def qualified_name(self) -> str:
        return f"{self.namespace}\\{self.name}" if self.namespace else self.name


class SpecialType(Type):
    """VOID (no value), ERROR (after a reported error: compatible with everything, silences cascades),
    and the generic ANY_* families used only in builtin signatures (kind "generic", with the test of their
    members in ``member``)."""

    def __init__(self, name: str, kind: str, member: Callable[[Type], bool] | None = None) -> None:
        self.name = name
        self.kind = kind
        self.member = member

    def accepts(self, t: Type) -> bool:
        """A generic family: is ``t`` one of its members? (VOID and ERROR have none.)"""
        return self.member is not None and self.member(t)


VOID = SpecialType("VOID", "void")
ERROR = SpecialType("<error>", "error")
NULL_STRING = StringType(0, explicit=False)


def unalias(t: Type) -> Type:
    seen = 0
    while isinstance(t, AliasType) and t.target is not None and seen < 64:
        t = t.target
        seen += 1
    return t


def base_of(t: Type) -> Type:
    """Strip aliases and subranges (a subrange behaves as its base type in expressions)."""
    t = unalias(t)
    if isinstance(t, SubrangeType):
        return t.base
    return t


def bits_literal(value: int, bits: int) -> str:
    """A bit string (BYTE, WORD, DWORD, LWORD) in the notation an engineer reads on the controller: hexadecimal,
    all its digits (16#4006, 16#0A, 16#0001_0000 is written 16#00010000)."""
    return f"16#{int(value) & ((1 << bits) - 1):0{max(1, bits // 4)}X}"


INSTANCE_SECTIONS = ("VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_STAT", "VAR_TEMP")   # in-outs and externals refer


def value_cells(t: Type, cap: int, memo: dict | None = None, _active: set | None = None) -> int:
    """The memory a value of ``t`` takes, in cells: one per elementary value or string, plus one per array,
    structure and function-block instance holding them. Counts stop just above ``cap`` (``cap + 1`` means "more");
    a function block that contains itself counts once (the checker reports it as recursion)."""
    t = unalias(t)
    if not isinstance(t, (ArrayType, StructType, PouType)):
        return 1
    memo = {} if memo is None else memo
    key = (id(t), cap)
    known = memo.get(key)
    if known is not None:
        return known
    active = set() if _active is None else _active
    n = 1
    if isinstance(t, ArrayType):
        count = t.count()
        if count:
            n += count * value_cells(t.element, cap, memo, active)
    elif isinstance(t, StructType):
        for f in t.fields.values():
            n += value_cells(f.type, cap, memo, active)
            if n > cap:
                break
    elif t.kind == "fb" and t.pou is not None:
        if id(t) in active:
            return 1
        active.add(id(t))
        for section in t.pou.sections:
            if section.kind in INSTANCE_SECTIONS:
                for decl in section.vars:
                    sym = getattr(decl, "sym", None)
                    n += value_cells(sym.type, cap, memo, active) if sym is not None else 1
            if n > cap:
                break
        active.discard(id(t))
    n = min(n, cap + 1)
    memo[key] = n
    return n


def same_type(a: Type, b: Type) -> bool:
    a, b = unalias(a), unalias(b)
    return a is b or a == b


# ---- type families ----------------------------------------------------------------------------

def is_error(t: Type | None) -> bool:
    return t is None or t is ERROR


def is_int(t: Type) -> bool:
    return base_of(t).kind in ("int", "uint")


def is_bits(t: Type) -> bool:
    return base_of(t).kind in ("bit", "bool")


def is_real(t: Type) -> bool:
    return base_of(t).kind == "real"


def is_num(t: Type) -> bool:
    return base_of(t).kind in ("int", "uint", "real")


def is_string(t: Type) -> bool:
    return isinstance(base_of(t), StringType)


def is_time(t: Type) -> bool:
    return base_of(t).kind == "time"


def is_date_like(t: Type) -> bool:
    return base_of(t).kind in ("date", "tod", "dt")


def is_elementary(t: Type) -> bool:
    return isinstance(base_of(t), (ElementaryType, StringType, EnumType))


# IEC 61131-3 implicit conversions (2nd/3rd edition table): widening only, no sign loss.
_WIDEN: dict[str, tuple[str, ...]] = {
    "SINT": ("INT", "DINT", "LINT", "REAL", "LREAL"),
    "INT": ("DINT", "LINT", "REAL", "LREAL"),
    "DINT": ("LINT", "LREAL"),
    "USINT": ("UINT", "UDINT", "ULINT", "INT", "DINT", "LINT", "REAL", "LREAL"),
    "UINT": ("UDINT", "ULINT", "DINT", "LINT", "REAL", "LREAL"),
    "UDINT": ("ULINT", "LINT", "LREAL"),
    "REAL": ("LREAL",),
    "BOOL": ("BYTE", "WORD", "DWORD", "LWORD"),
    "BYTE": ("WORD", "DWORD", "LWORD"),
    "WORD": ("DWORD", "LWORD"),
    "DWORD": ("LWORD",),
    "TIME": ("LTIME",),
}


def widens_to(src: Type, dst: Type) -> bool:
    """True when a value of ``src`` may be used where ``dst`` is expected without an explicit conversion."""
    s, d = base_of(src), base_of(dst)
    if s is ERROR or d is ERROR:
        return True
    if s is d or s == d:
        return True
    if isinstance(s, StringType) and isinstance(d, StringType):
        return s.wide == d.wide          # length is checked separately for literals
    if isinstance(s, ElementaryType) and isinstance(d, ElementaryType):
        return d.name in _WIDEN.get(s.name, ())
    return False


_RANK = ["SINT", "USINT", "INT", "UINT", "DINT", "UDINT", "LINT", "ULINT", "REAL", "LREAL"]


def common_type(a: Type, b: Type) -> Type | None:
    """The type both operands widen to (result type of a binary numeric/bit operation), or None."""
    a0, b0 = base_of(a), base_of(b)
    if widens_to(a0, b0):
        return b0
    if widens_to(b0, a0):
        return a0
    # Mixed signed/unsigned without a direct widening (e.g. INT and UINT): the smallest type both reach.
    if isinstance(a0, ElementaryType) and isinstance(b0, ElementaryType):
        for name in _RANK:
            cand = ELEMENTARY[name]
            if widens_to(a0, cand) and widens_to(b0, cand):
                return cand
        for name in ("WORD", "DWORD", "LWORD"):
            cand = ELEMENTARY[name]
            if widens_to(a0, cand) and widens_to(b0, cand):
                return cand
    return None


# Omron Sysmac implicit casts (W501 6-5-3 "Implicit Casts", page 6-106/6-107), dialect sysmac only.
# Expressions: the operand of highest rank gives the type; at equal rank an unsigned integer wins.
SYSMAC_RANK = {"USINT": 1, "SINT": 1, "BYTE": 1, "UINT": 2, "INT": 2, "WORD": 2, "REAL": 3,
               "DINT": 4, "UDINT": 4, "DWORD": 4, "LREAL": 5, "LINT": 6, "ULINT": 6, "LWORD": 6}
# Assignments and input arguments: the arrows of the W501 6-107 chart. Besides the widenings above, an integer
# goes to the other-signed integer of the same size (the value may change: INT -1 -> UINT 16#FFFF), so chains
# such as SINT -> USINT -> UINT -> UDINT -> ULINT are allowed (W501: "ULINT := SINT").
_SIGN_SWAP = {"SINT": "USINT", "USINT": "SINT", "INT": "UINT", "UINT": "INT", "DINT": "UDINT", "UDINT": "DINT",
              "LINT": "ULINT", "ULINT": "LINT"}


def _sysmac_reach(name: str) -> frozenset:
    seen, todo = {name}, [name]
    while todo:
        n = todo.pop()
        for m in _WIDEN.get(n, ()) + ((_SIGN_SWAP[n],) if n in _SIGN_SWAP else ()):
            if m not in seen:
                seen.add(m)
                todo.append(m)
    return frozenset(seen)


_SYSMAC_REACH = {n: _sysmac_reach(n) for n in list(_WIDEN) + list(_SIGN_SWAP)}


def sysmac_assignable(src: Type, dst: Type) -> bool:
    """W501 6-107: may a value of ``src`` be assigned (or passed as an input) to ``dst`` on Sysmac?"""
    s, d = base_of(src), base_of(dst)
    if isinstance(s, ElementaryType) and isinstance(d, ElementaryType):
        return d.name in _SYSMAC_REACH.get(s.name, ())
    return False


def sysmac_common(a: Type, b: Type) -> Type | None:
    """W501 6-106: type of an arithmetic expression of two numeric operands on Sysmac, or None."""
    a0, b0 = base_of(a), base_of(b)
    if not (isinstance(a0, ElementaryType) and isinstance(b0, ElementaryType)):
        return None
    ra, rb = SYSMAC_RANK.get(a0.name), SYSMAC_RANK.get(b0.name)
    if ra is None or rb is None or (a0.kind == "bit") != (b0.kind == "bit"):
        return None
    if ra != rb:
        return a0 if ra > rb else b0
    return b0 if b0.kind == "uint" else a0


def literal_fits(value: int, t: Type) -> bool:
    t = unalias(t)
    if isinstance(t, SubrangeType):
        return t.lo <= value <= t.hi
    if isinstance(t, ElementaryType) and t.kind in ("int", "uint", "bit") and t.lo is not None and t.hi is not None:
        return t.lo <= value <= t.hi
    return True


UNION_KINDS = ("bool", "bit", "int", "uint", "real", "time")


def union_layout(t: Type) -> tuple[str, int, int | None] | None:
    """How a member of a Sysmac UNION lies in the union's memory image (W501 6-3-6): (kind read back — bool,
    int, uint or real —, bits per element, element count of a one-dimensional array member or None), or None
    for a type vplc cannot overlay (STRING, structures, enumerations, dates, multi-dimensional arrays)."""
    u = unalias(t)
    count = None
    if isinstance(u, ArrayType):
        if u.open or len(u.dims) != 1:
            return None
        count = u.count()
        u = unalias(u.element)
    b = base_of(u)
    if not isinstance(b, ElementaryType) or b.kind not in UNION_KINDS:
        return None
    kind = {"time": "int", "bit": "uint"}.get(b.kind, b.kind)
    return kind, b.bits, count
