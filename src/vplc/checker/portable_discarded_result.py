"""ST2007 (warning, only with ``--portable``) — a function called as a statement, its result thrown away.

IEC 61131-3 2nd edition calls a function only inside an expression; a call statement is for function blocks
(and Sysmac's instructions). Assign the result, even if only to a variable that says it is not needed.

Passing (portable)::

    Ended := CBTi_EndSlot(CBT := CBT, S := I, State := SlotFailed, ErrorID := Err);

Failing (portable)::

    CBTi_EndSlot(CBT := CBT, S := I, State := SlotFailed, ErrorID := Err);     (* ST2007 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.CallStmt):
            b = node.call.binding
            if b is None or b.kind not in ("function", "builtin") or b.ty is T.VOID or T.is_error(b.ty):
                continue
            name = b.pou.name if b.pou is not None else b.builtin.name
            ctx.diags.warning(codes.PORTABLE_DISCARDED_RESULT,
                              f"the result of function {name} is thrown away; IEC 61131-3 calls a "
                              f"function only inside an expression: assign it (`x := {name}(...);`)",
                              node.call.span)
