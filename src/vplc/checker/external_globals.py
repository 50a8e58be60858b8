"""ST1009 — a POU uses global variables without declaring them in VAR_EXTERNAL (`--dialect sysmac`).

Sysmac Studio refuses it: a program or function block reads or writes a global variable only through an
external variable of the same name and type (W501, external variables; the IEC 61131-10 export writes them as
`ExternalVars`). In the sysmac dialect it is an error, once per POU, naming the globals (the IEC dialect lets a
POU read a global directly); the system-defined variables (P_On, _CurrentTime, ... in prelude/sysmac_sysvars.st)
need no declaration.

Passing::

    PROGRAM Main
    VAR_EXTERNAL Count : INT; END_VAR
    Count := Count + 1;

Failing::

    PROGRAM Main
    Count := Count + 1;        (* ST1009: Main uses the global variable `Count` without VAR_EXTERNAL *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from .context import Context
from .symbols import VarSymbol

SHOWN = 8           # names listed in the message; the rest are counted


def _system_globals(ctx: Context) -> frozenset:
    names = ctx.system_global_names
    if names is None:
        names = frozenset(d.name.upper() for gl, unit in ctx.global_lists if getattr(unit, "in_prelude", False)
                          for section in gl.sections for d in section.vars)
        ctx.system_global_names = names
    return names


def check(ctx: Context, pou: A.Pou, implicit_globals: dict[str, VarSymbol], in_prelude: bool) -> None:
    if ctx.dialect != "sysmac" or in_prelude or not implicit_globals:
        return
    system = _system_globals(ctx)
    names = [g.name for up, g in implicit_globals.items() if up not in system]
    if not names:
        return
    shown = ", ".join(f"`{n}`" for n in names[:SHOWN]) + (f" and {len(names) - SHOWN} more" if len(names) > SHOWN
                                                          else "")
    ctx.diags.error(codes.SYSMAC_MISSING_EXTERNAL,
                    f"{pou.name} uses the global variable{'s' if len(names) > 1 else ''} {shown} "
                    "without VAR_EXTERNAL; Sysmac Studio refuses a global that the POU does not declare as an "
                    "external variable", pou.name_span or pou.span,
                    ["declare each in `VAR_EXTERNAL ... END_VAR` with the global's type, or check with "
                     "`--dialect iec`, which lets a POU read a global directly"])
