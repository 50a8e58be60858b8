"""ST1001 / ST1003 / ST1004 / ST1007 — a name or type that is not declared, is ambiguous between namespaces, or
is a real Omron Sysmac name vplc does not model.

Passing::

    VAR Count : INT; END_VAR
    Count := Count + 1;

Failing::

    Cuont := Count + 1;        (* ST1001: `Cuont` is not declared; did you mean `Count`? *)
    x : stUnknown;             (* ST1004: unknown data type *)
    Tune(Run := Go);           (* with Tune : PIDAT_HeatCool;  ST1007: Sysmac instruction `PIDAT_HeatCool` (W502,
                                  Control Instructions) is not modelled by vplc *)
"""
from __future__ import annotations

import difflib
from collections.abc import Iterable

from ..frontend import codes, sysmac_names
from ..frontend.source import Span
from .context import Context


def _suggest(name: str, candidates: Iterable[str]) -> list[str]:
    names = {c for c in candidates if c}
    close = difflib.get_close_matches(name.upper(), [n.upper() for n in names], n=1, cutoff=0.75)
    if not close:
        return []
    by_upper = {n.upper(): n for n in names}
    return [f"did you mean `{by_upper[close[0]]}`?"]


def report(ctx: Context, name: str, span: Span, candidates: Iterable[str] = ()) -> None:
    if _not_modelled(ctx, name, span):
        return
    ctx.diags.error(codes.UNDECLARED, f"`{name}` is not declared; declare it in a VAR section or check the spelling",
                    span, _suggest(name, candidates))


def _not_modelled(ctx: Context, name: str, span: Span) -> bool:
    """ST1007: a real Omron name (frontend/sysmac_names.py) that vplc does not model, in the Sysmac dialect."""
    if ctx.dialect != "sysmac":
        return False
    text = sysmac_names.describe(name)
    if text is None:
        return False
    ctx.diags.error(codes.SYSMAC_NOT_MODELLED, text, span, ["write the POU without it, or model it in vplc's prelude "
                                           "(src/vplc/prelude) and runtime"])
    return True


def report_type(ctx: Context, name: str, span: Span) -> None:
    if _not_modelled(ctx, name, span):
        return
    known = [k[1] for k in ctx.tables.types.entries] + [k[1] for k in ctx.tables.pous.entries]
    notes = _suggest(name.rsplit("\\", 1)[-1], known)
    if "\\" in name:
        ns = name.strip("\\").split("\\")[0]
        spaces = {k[0] for k in ctx.tables.types.entries} | {k[0] for k in ctx.tables.pous.entries}
        if ns.upper() not in spaces:
            notes.append(f"no library `{ns}` is loaded; add its folder (e.g. lib/{ns}) to the paths checked")
    ctx.diags.error(codes.UNKNOWN_TYPE, f"unknown data type `{name}`", span, notes)


def report_ambiguous(ctx: Context, name: str, candidates: list[str], span: Span) -> None:
    ctx.diags.error(codes.AMBIGUOUS_NAME,
                    f"`{name}` is ambiguous: it is declared in {', '.join(candidates)}; qualify it "
                    f"with its namespace (e.g. `{candidates[0]}`)", span)
