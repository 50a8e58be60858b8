"""ST1501 — a constant array index outside the declared bounds.

Passing::

    VAR Buf : ARRAY[0..9] OF BYTE; END_VAR
    Buf[9] := 16#0D;

Failing::

    Buf[10] := 16#0D;      (* ST1501: index 10 is outside Buf's bounds 0..9 *)
    Sum(Data := Buf[8]);   (* ST1501 when Data is ARRAY[0..3]: only 2 elements remain from Buf[8] *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .consteval import const_int
from .context import ExprHost


def check(ck: ExprHost, e: A.Index, array_type: T.ArrayType) -> None:
    for ix, (lo, hi) in zip(e.indices, array_type.dims, strict=False):
        if lo is None or hi is None:        # an open dimension
            continue
        value = const_int(ix, ck.ctx, ck.scope)
        if value is not None and not lo <= value <= hi:
            ck.ctx.diags.error(codes.OUT_OF_BOUNDS, f"index {value} is outside the bounds {lo}..{hi} of "
                               f"`{ck.text(e.base)}`", ix.span)


def check_slice(ck: ExprHost, element: A.Index, param_type: T.ArrayType, param_name: str) -> None:
    """Sysmac "array element passed to an array parameter": enough elements must remain from that element."""
    base = T.unalias(element.base.ty) if element.base.ty is not None else None
    if param_type.open or not isinstance(base, T.ArrayType) or base.open or len(base.dims) != 1:
        return
    index = const_int(element.indices[0], ck.ctx, ck.scope)
    if index is None:
        return
    _, hi = base.dims[0]
    assert hi is not None                   # not open (returned above)
    remaining = hi - index + 1
    if 0 < remaining < param_type.count():
        ck.ctx.diags.error(codes.OUT_OF_BOUNDS, f"only {remaining} element(s) of `{ck.text(element.base)}` remain from "
                           f"index {index}, but parameter `{param_name}` needs {param_type.count()}", element.span)
