"""ST1901 (warning) — a local variable that is declared but never used.

Passing::

    VAR Count : INT; END_VAR
    Count := Count + 1;

Failing::

    VAR Count, Spare : INT; END_VAR     (* ST1901: `Spare` is never used *)
    Count := Count + 1;
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from .context import Context


def check(ctx: Context, pou: A.Pou, in_prelude: bool) -> None:
    if pou.native or in_prelude:
        return
    for section in pou.sections:
        if section.kind not in ("VAR", "VAR_TEMP", "VAR_STAT"):
            continue
        for decl in section.vars:
            sym = decl.sym
            if sym is not None and not sym.used:
                ctx.diags.warning(codes.UNUSED_VARIABLE,
                                  f"`{decl.name}` is declared but never used; remove it", decl.name_span)
