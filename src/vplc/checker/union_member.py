"""ST1109 — a UNION member that cannot share the union's memory image, or a member with an initial value.

Sysmac unions (W501 6-3-6) overlay their members in one memory image (W506 A-5-1: the members overlap in the
same memory locations; the size is the largest member's). vplc models members whose memory image is fixed:
BOOL, bit strings, integers, REAL/LREAL, TIME, and one-dimensional arrays of them. A union has no initial values
of its own (all its bits start at 0).

Passing::

    TYPE uWord : UNION
        W : WORD;
        Bits : ARRAY[0..15] OF BOOL;
    END_UNION; END_TYPE

Failing::

    TYPE uText : UNION
        S : STRING[8];             (* ST1109: a STRING has no fixed memory image in vplc *)
        W : WORD := 16#0001;       (* ST1109: a union member has no initial value *)
    END_UNION; END_TYPE
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context


def check(ctx: Context, st: T.StructType, f: A.VarDecl, ftype: T.Type) -> None:
    if f.init is not None:
        ctx.diags.error(codes.UNION_MEMBER,
                        f"member `{f.name}` of UNION {st.name} has an initial value; a union's members "
                        "share one memory image, which starts at 0", f.init.span)
    if not T.is_error(ftype) and T.union_layout(ftype) is None:
        ctx.diags.error(codes.UNION_MEMBER,
                        f"member `{f.name}` of UNION {st.name} is of type {ftype.name}: vplc overlays "
                        "only BOOL, bit strings, integers, REAL/LREAL, TIME and one-dimensional arrays of them "
                        "(W501 6-3-6)", f.name_span)
