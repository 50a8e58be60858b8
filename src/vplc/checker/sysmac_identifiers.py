"""ST1011 (``--dialect sysmac``) — a name Sysmac Studio does not accept.

W501 6-3-12 (Restrictions on Variable Names and Other Program-related Names, page 6-65) lists the character
combinations a variable name (POU instances included), a POU definition name, a data type name, a structure or
union member name and an enumerator cannot have: a string that starts with ``P_`` (the prefix of the
system-defined variables P_On, P_First_Run, ...), that starts with an underline, that ends with an underline or
that contains underlines one after the other. Engineers importing generated code report the ``P_`` case: Studio
renamed a PROGRAM P_SIM_ROBOT to PR_SIM_ROBOT without a message, and the task assignment then named a program that
did not exist. Names starting with a digit are not identifiers at all (the lexer refuses them). The prelude's
names (Omron's own ``_sSOCKET``, ``P_On``, ...) are not checked.

Passing::

    VAR PartCount : INT; END_VAR

Failing::

    VAR P_Count : INT; _Count : INT; Count_ : INT; Part__Count : INT; END_VAR
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend.source import Span
from .context import Context, Unit

CODE = codes.SYSMAC_NAME


def problem(name: str) -> str | None:
    """What makes ``name`` unacceptable to Sysmac Studio (W501 6-3-12), or None."""
    if name[:2].upper() == "P_":
        return "starts with `P_` (reserved for system-defined variables such as P_On)"
    if name.startswith("_"):
        return "starts with an underline"
    if name.endswith("_"):
        return "ends with an underline"
    if "__" in name:
        return "contains two underlines in a row"
    return None


def _report(ctx: Context, what: str, name: str, span: Span | None) -> None:
    why = problem(name)
    if why is not None and span is not None:
        ctx.diags.error(CODE, f"{what} `{name}` {why}: Sysmac Studio does not accept it (W501 6-3-12); rename it",
                        span)


def check(ctx: Context) -> None:
    """Every user-declared name of the project (the prelude's are Omron's and exempt)."""
    if ctx.dialect != "sysmac":
        return
    for decl, _shell, unit in ctx.type_decls:
        if getattr(unit, "in_prelude", False):
            continue
        _report(ctx, "data type", decl.name, decl.name_span)
        spec = decl.spec
        if isinstance(spec, A.StructTypeRef):
            for f in spec.fields:
                _report(ctx, "member", f.name, f.name_span)
        elif isinstance(spec, A.EnumTypeRef):
            for v in spec.values:
                _report(ctx, "enumeration value", v.name, v.name_span)
    for pou, unit in ctx.pou_units:
        if getattr(unit, "in_prelude", False):
            continue
        _report(ctx, pou.kind.replace("_", " ").lower(), pou.name, pou.name_span or pou.span)
        ladder = getattr(pou, "ladder", None)
        helpers = {h.upper() for h in (ladder.helpers if ladder is not None else [])}   # vplc's own, never exported
        for section in pou.sections:
            if section.kind == "VAR_EXTERNAL":
                continue            # the global's own declaration is checked
            for d in section.vars:
                if d.name.upper() not in helpers:
                    _report(ctx, "variable", d.name, d.name_span)
    holders: list[tuple[A.GlobalVarList | A.Configuration, Unit]] = [*ctx.global_lists, *ctx.configurations]
    for holder, gunit in holders:
        if getattr(gunit, "in_prelude", False):
            continue
        sections = list(holder.sections)
        if isinstance(holder, A.Configuration):
            for res in holder.resources:
                sections.extend(res.sections)
        for section in sections:
            for d in section.vars:
                _report(ctx, "global variable", d.name, d.name_span)
