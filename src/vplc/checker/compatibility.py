"""ST1101 / ST1103 — may a value of one type be stored in another (assignment, initial value, input argument)?

IEC 61131-3 implicit conversions only widen (INT into DINT, REAL into LREAL); a subrange takes its base type; an
array takes an array of as many elements per dimension whose elements are compatible (an open ``ARRAY[*]`` takes
any length); a generic parameter (ANY_NUM …) takes what it accepts. The expression checker (exprs.py) and the call
checker (calls.py) both ask this module, which depends on neither.

Passing::

    VAR i : INT; d : DINT; END_VAR
    d := i;            (* INT widens to DINT *)

Failing::

    VAR i : INT; r : REAL; END_VAR
    i := r;            (* ST1101: REAL does not convert implicitly to INT *)
"""
from __future__ import annotations

from ..frontend import types as T
from .scope import is_generic


def compatible(src: T.Type, dst: T.Type) -> bool:
    """May a value of ``src`` be stored in ``dst`` (assignment / input argument)?"""
    if T.is_error(src) or T.is_error(dst):
        return True
    if is_generic(dst):
        return dst.accepts(src)
    if T.widens_to(src, dst) or T.same_type(src, dst):
        return True
    s, d = T.unalias(src), T.unalias(dst)
    if isinstance(d, T.SubrangeType):
        return T.widens_to(s, d.base) or T.same_type(s, d.base)
    if isinstance(s, T.ArrayType) and isinstance(d, T.ArrayType):
        if len(s.dims) != len(d.dims) or not compatible(s.element, d.element):
            return False
        if d.open:
            return True
        if s.open:          # the length of an ARRAY[*] in-out is the caller's: it fits no fixed-size array
            return False
        return all(_length(sd) == _length(dd) for sd, dd in zip(s.dims, d.dims, strict=False))
    return False


def _length(dim: tuple[int | None, int | None]) -> int | None:
    """Elements in one array dimension (None for an open one)."""
    lo, hi = dim
    return None if lo is None or hi is None else hi - lo + 1
