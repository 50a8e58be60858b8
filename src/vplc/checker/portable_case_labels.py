"""ST2006 (warning, only with ``--portable``) — a CASE label that is not a decimal integer or enumeration value.

IEC 61131-3 2nd edition CASE labels are signed decimal integers, enumeration values or subranges of those.
Based (`16#1001`), typed (`UINT#5`) literals and named constants are vendor extensions.

Passing (portable)::

    CASE Code OF
    4097: (* 16#1001 *) Text := 'Time_Out out of range';
    END_CASE;

Failing (portable)::

    CASE Code OF
    16#1001: Text := 'Time_Out out of range';     (* ST2006 *)
    END_CASE;
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from .context import Context
from .symbols import EnumValueSymbol


def _portable(e: A.Expr) -> bool:
    if isinstance(e, A.Unary) and e.op == "-":
        e = e.operand
    if isinstance(e, A.Literal):
        return e.kind == "int" and e.type_prefix is None and "#" not in e.text
    if isinstance(e, A.EnumLiteral):
        return True
    return isinstance(e, A.Name) and isinstance(getattr(e, "sym", None), EnumValueSymbol)


def _label_text(e: A.Expr) -> str:
    text = e.span.file.text[e.span.start:e.span.end]
    if isinstance(e, A.Literal) and e.kind == "int" and isinstance(e.value, int):
        return f"`{text}`; write `{e.value}: (* {text} *)`"
    return f"`{text}`; write its decimal value (or an enumeration value)"


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.Case):
            for branch in node.branches:
                for label in branch.labels:
                    parts = [label.lo, label.hi] if isinstance(label, A.CaseRange) else [label]
                    for p in parts:
                        if not _portable(p):
                            ctx.diags.warning(codes.PORTABLE_CASE_LABEL,
                                              "IEC 61131-3 CASE labels are signed decimal integers, "
                                              f"enumeration values or subranges, not {_label_text(p)}", p.span)
