"""ST1801 (warning) — a FUNCTION that does not assign its result on every path.

Passing::

    FUNCTION Clamp : INT
    VAR_INPUT x : INT; END_VAR
    IF x > 100 THEN Clamp := 100; ELSE Clamp := x; END_IF;
    END_FUNCTION

Failing::

    FUNCTION Clamp : INT
    VAR_INPUT x : INT; END_VAR
    IF x > 100 THEN Clamp := 100; END_IF;       (* ST1801: not assigned when x <= 100 *)
    END_FUNCTION
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context
from .symbols import VarSymbol


def _assigns(stmts: list[A.Stmt], result: VarSymbol) -> bool | None:
    """True: every path assigns; False: some path may end without assigning; None: a path RETURNs first."""
    for s in stmts:
        if isinstance(s, A.Assign) and isinstance(s.target, A.Name) and s.target.sym is result:
            return True
        if isinstance(s, A.Return):
            return False
        if isinstance(s, A.If) and s.else_body is not None and \
                all(_assigns(b.body, result) for b in s.branches) and _assigns(s.else_body, result):
            return True
        if isinstance(s, A.Case) and s.else_body is not None and \
                all(_assigns(cb.body, result) for cb in s.branches) and _assigns(s.else_body, result):
            return True
        if isinstance(s, A.CallStmt) and s.call.binding is not None:
            for ba in s.call.binding.args:
                if ba.param.direction == "out" and isinstance(ba.expr, A.Name) and ba.expr.sym is result:
                    return True
    return False


def check(ctx: Context, pou: A.Pou, result_sym: VarSymbol | None) -> None:
    if pou.kind != "FUNCTION" or pou.native or result_sym is None or result_sym.type is T.VOID:
        return
    if not _assigns(pou.body, result_sym):
        ctx.diags.warning(codes.RESULT_NOT_ASSIGNED,
                             f"FUNCTION {pou.name} does not assign its result `{pou.name}` on every path; "
                             "the result is then 0 / empty", pou.name_span or pou.span)
