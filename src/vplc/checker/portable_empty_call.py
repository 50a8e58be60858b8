"""ST2009 (warning, only with ``--portable``) — a function called with empty parentheses.

IEC 61131-3 2nd edition function calls have at least one argument (function blocks may be called as `Fb();`).
Give the function an input, or make it a function block whose output is read after the call.

Passing (portable)::

    Clock();
    Stamp := Clock.Now;

Failing (portable)::

    Stamp := ReadClock();                       (* ST2009 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from .context import Context


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.Call) and not node.args:
            b = node.binding
            if b is not None and b.kind in ("function", "builtin"):
                name = b.pou.name if b.pou is not None else b.builtin.name
                ctx.diags.warning(codes.PORTABLE_EMPTY_CALL,
                                  f"`{name}()`: IEC 61131-3 2nd edition has no function call without "
                                  "arguments; pass an input, or make it a function block", node.span)
