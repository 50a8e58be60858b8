"""ST2008 (warning, only with ``--portable``) — `<`, `>`, `<=` or `>=` on enumeration values.

IEC 61131-3 enumerations are unordered names; only `=` and `<>` compare them (Sysmac and vplc order them by
number). Test the states explicitly.

Passing (portable)::

    IF State = SlotQueued OR State = SlotSent THEN ...

Failing (portable)::

    IF State <= SlotSent THEN ...              (* ST2008 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context

ORDERING = ("<", ">", "<=", ">=")


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.Binary) and node.op in ORDERING:
            enum = next((T.base_of(o.ty) for o in (node.left, node.right)
                         if o.ty is not None and isinstance(T.base_of(o.ty), T.EnumType)), None)
            if enum is not None:
                ctx.diags.warning(codes.PORTABLE_ENUM_ORDER,
                                  f"`{node.op}` on values of the enumeration {enum.name}: IEC 61131-3 "
                                  "enumerations have no order; compare with `=` / `<>` for each state", node.span)
