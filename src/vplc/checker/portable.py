"""ST2001-ST2003 (warnings, only with ``--portable``) — constructs outside plain IEC 61131-3 2nd edition.

* ST2001 a vendor (Omron Sysmac) instruction or data type is used;
* ST2002 a namespace qualifier (`Ns\\Name`) is used;
* ST2003 a construct outside the 2nd edition is used (CONTINUE, LTIME/LDATE/..., `ARRAY[*]`, VAR_STAT,
  `//` and `/* */` comments, TO_xxx / LOWER_BOUND / UPPER_BOUND / ATAN2).

The other ``--portable`` rules have one module each, run from here: ST2004 portable_enum_values, ST2005
portable_keywords, ST2006 portable_case_labels, ST2007 portable_discarded_result, ST2008 portable_enum_order,
ST2009 portable_empty_call, ST2010 portable_len_type, ST2011 portable_array_types.

Files below a folder named ``platform`` are exempt: that is where a portable library keeps its vendor calls.

Passing (portable)::

    Cmd := CONCAT('$$TMSCT,', Body);

Failing (portable)::

    ToAryByte(In := Cmd, Order := _eBYTE_ORDER#_LOW_HIGH, AryOut := Buf[0]);   (* ST2001 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend.source import Span
from . import (
    portable_array_types,
    portable_case_labels,
    portable_discarded_result,
    portable_empty_call,
    portable_enum_order,
    portable_enum_values,
    portable_keywords,
    portable_len_type,
)
from .context import Context

RULES = (portable_enum_values, portable_keywords, portable_case_labels, portable_discarded_result,
         portable_enum_order, portable_empty_call, portable_len_type, portable_array_types)


def exempt(path: str) -> bool:
    parts = path.replace("\\", "/").split("/")
    return "platform" in parts[:-1]


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    path = unit.span.file.path
    if getattr(unit, "in_prelude", False) or exempt(path):
        return
    for rule in RULES:
        rule.check_unit(ctx, unit)
    for node in A.walk(unit):
        if isinstance(node, A.QualName) and node.namespace:
            ctx.diags.warning(codes.PORTABLE_NAMESPACE,
                              f"namespace qualifier in `{node.text()}` is a vendor extension; use the bare "
                              f"name `{node.name}` for portable code", node.span)
        elif isinstance(node, A.Continue):
            ctx.diags.warning(codes.PORTABLE_NOT_EDITION_2,
                              "CONTINUE is IEC 61131-3 3rd edition only; restructure the loop with IF",
                              node.span)
        elif isinstance(node, A.Literal) and node.kind == "ltime":
            ctx.diags.warning(codes.PORTABLE_NOT_EDITION_2,
                              "LTIME is IEC 61131-3 3rd edition only; use TIME", node.span)
        elif isinstance(node, A.VarSection) and node.kind == "VAR_STAT":
            ctx.diags.warning(codes.PORTABLE_NOT_EDITION_2,
                              "VAR_STAT is not IEC 61131-3 2nd edition; use VAR", node.span)
    for style, start, _end in unit.comments or ():
        if style != "(*":
            ctx.diags.warning(codes.PORTABLE_NOT_EDITION_2,
                              f"`{style}` comments are not IEC 61131-3 2nd edition; write (* ... *)",
                              Span(unit.span.file, start, start + 2))
    for span, what in ctx.edition3_uses:
        if span.file is unit.span.file:
            ctx.diags.warning(codes.PORTABLE_NOT_EDITION_2, f"{what} is not IEC 61131-3 2nd edition", span)
    for span, name, what in ctx.vendor_uses:
        if span.file is unit.span.file:
            ctx.diags.warning(codes.PORTABLE_VENDOR_NAME, f"`{name}` is an Omron Sysmac {what}, not IEC 61131-3; keep "
                              "vendor calls in the library's platform/ folder", span)
