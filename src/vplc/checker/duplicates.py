"""ST1002 — a name is declared twice in the same scope.

Passing::

    VAR Speed : INT; Accel : INT; END_VAR

Failing::

    VAR Speed : INT; Speed : REAL; END_VAR     (* ST1002: Speed is declared twice *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend.source import Span
from .context import Context
from .symbols import VarSymbol

CODE = codes.DUPLICATE_NAME


def report(ctx: Context, what: str, name: str, span: Span, previous: object) -> None:
    notes = []
    prev_span = getattr(getattr(previous, "decl", None), "span", None) or getattr(
        getattr(previous, "pou", None), "name_span", None)
    if prev_span is not None and prev_span.file.text:
        line, col = prev_span.file.line_col(prev_span.start)
        notes.append(f"first declared at {prev_span.file.path}:{line}:{col}")
    ctx.diags.error(CODE, f"{what} `{name}` is declared more than once; rename or remove one of them", span, notes)


def check_locals(ctx: Context, pou: A.Pou) -> dict[str, VarSymbol | None]:
    """Build the local scope of a POU (NAME → VarSymbol), reporting duplicates; returns the scope."""
    scope: dict[str, VarSymbol | None] = {}
    for section in pou.sections:
        for decl in section.vars:
            up = decl.name.upper()
            if up in scope:
                report(ctx, "variable", decl.name, decl.name_span, scope[up])
                continue
            if up == pou.name.upper() and pou.kind == "FUNCTION":
                report(ctx, "variable", decl.name, decl.name_span, None)
                continue
            scope[up] = decl.sym
    return scope
