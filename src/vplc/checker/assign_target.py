"""ST1301-ST1304 — writes that IEC forbids or that cannot work.

* ST1301 writing to a CONSTANT; ST1304 writing to a function input inside the function is allowed,
  but writing the loop variable inside its FOR loop is not.
* ST1302 writing an FB output from outside the FB (only the FB sets its outputs).
* ST1303 (warning) writing an FB input from outside after the instance was called in the same body:
  the value is used only at the next call.

Passing::

    VAR CONSTANT MaxSpeed : INT := 100; END_VAR
    mover.Execute := TRUE; mover(CBT := Cobot);

Failing::

    MaxSpeed := 50;                        (* ST1301 *)
    FOR i := 0 TO 9 DO i := i + 1; END_FOR; (* ST1304 *)
    mover.Done := FALSE;                   (* ST1302 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import ExprHost
from .symbols import VarSymbol


def root_name(e: A.Expr) -> A.Name | None:
    while isinstance(e, (A.Member, A.Index, A.BitAccess)):
        e = e.base
    return e if isinstance(e, A.Name) else None


def check_write(ck: ExprHost, target: A.Expr, what: str = "assignment") -> None:
    ctx = ck.ctx
    root = root_name(target)
    if root is None:
        ctx.diags.error(codes.NOT_A_VARIABLE,
                        f"cannot assign to `{ck.text(target)}`; the target must be a variable", target.span)
        return
    sym = root.sym
    if not isinstance(sym, VarSymbol):
        if sym is not None:
            ctx.diags.error(codes.NOT_A_VARIABLE,
                            f"cannot assign to `{ck.text(target)}`; it is not a variable", target.span)
        return
    effective = sym.target if sym.section == "VAR_EXTERNAL" and sym.target is not None else sym
    if id(effective) in ctx.vendor_objects:
        ctx.diags.error(codes.WRITE_CONSTANT,
                        f"`{sym.name}` is a Sysmac system-defined variable and is read-only; use a "
                        "variable of your own", target.span)
        return
    if sym.constant or effective.constant:
        ctx.diags.error(codes.WRITE_CONSTANT,
                        f"`{sym.name}` is a CONSTANT and cannot be written; remove CONSTANT from its "
                        "section or use another variable", target.span)
        return
    if target is root and any(v is sym for v in ck.flow.for_vars):
        ctx.diags.error(codes.WRITE_FOR_VARIABLE,
                        f"`{sym.name}` is the variable of an enclosing FOR loop and must not be written "
                        "inside the loop; use a WHILE loop or another variable", target.span)
        return
    if isinstance(target, A.Member):
        base_t = T.unalias(target.base.ty) if target.base.ty is not None else None
        if isinstance(base_t, T.PouType) and base_t.kind == "fb":
            p = base_t.param(target.member)
            if p is not None and p.direction == "out":
                ctx.diags.error(codes.WRITE_FB_OUTPUT,
                                f"`{target.member}` is an output of {base_t.name}; only the function block "
                                "itself writes its outputs", target.span)
                return
            key = ck.text(target.base).upper()
            if p is not None and p.direction == "in" and key in ck.flow.called_instances:
                ctx.diags.warning(codes.WRITE_INPUT_AFTER_CALL,
                                  f"input `{target.member}` of `{ck.text(target.base)}` is written after "
                                  "the instance was called; the value takes effect only at the next call. Pass it "
                                  f"in the call instead (`{ck.text(target.base)}({target.member} := ...)`)",
                                  target.span)
