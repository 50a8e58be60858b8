"""ST1401 / ST1402 — CASE labels of the wrong type, or the same value twice.

Passing::

    CASE Step OF
        eStep#Idle: ...
        eStep#Busy, eStep#Done: ...
    END_CASE;

Failing::

    CASE Count OF
        1..5: ...
        3: ...            (* ST1402: 3 is already handled by 1..5 *)
        'A': ...          (* ST1401: STRING label for an INT selector *)
    END_CASE;
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .consteval import const_int
from .context import ExprHost
from .symbols import EnumValueSymbol


def _value(ck: ExprHost, e: A.Expr) -> int | None:
    sym = getattr(e, "sym", None)
    if isinstance(sym, EnumValueSymbol):
        return sym.value
    return const_int(e, ck.ctx, ck.scope)


def check(ck: ExprHost, stmt: A.Case, sel_type: T.Type) -> None:
    ctx = ck.ctx
    sel = T.base_of(sel_type)
    ok_sel = T.is_error(sel) or T.is_int(sel) or isinstance(sel, T.EnumType) or (
        isinstance(sel, T.ElementaryType) and sel.kind == "bit")
    if not ok_sel:
        ctx.diags.error(codes.CASE_LABEL_TYPE,
                        f"the CASE selector must be an integer or enumeration, not {sel_type.name}",
                        stmt.selector.span)
    ranges: list[tuple[int, int, int, A.Expr | A.CaseRange]] = []      # lo, hi, position in the source, label
    for branch in stmt.branches:
        for label in branch.labels:
            parts = [label.lo, label.hi] if isinstance(label, A.CaseRange) else [label]
            values = []
            for p in parts:
                lt = ck.expr(p, sel_type)
                if not T.is_error(lt) and not T.is_error(sel) and ok_sel and not (
                        T.same_type(T.base_of(lt), sel) or (T.is_int(lt) and T.is_int(sel)) or
                        (T.is_int(lt) and sel.kind == "bit")):
                    ctx.diags.error(codes.CASE_LABEL_TYPE,
                                    f"CASE label of type {lt.name} does not match the selector type "
                                    f"{sel_type.name}", p.span)
                v = _value(ck, p)
                if v is None and not T.is_error(lt):
                    ctx.diags.error(codes.CASE_LABEL_TYPE, "CASE labels must be constants", p.span)
                values.append(v)
            lo, hi = values[0], values[-1]
            if lo is not None and hi is not None:
                ranges.append((lo, hi, len(ranges), label))
    _report_overlaps(ck, ranges)


def _report_overlaps(ck: ExprHost, ranges: list[tuple[int, int, int, A.Expr | A.CaseRange]]) -> None:
    """ST1402 once per label that overlaps an earlier one: sorted by value, so n log n even for 100,000 labels."""
    ranges.sort(key=lambda r: (r[0], r[2]))
    reach = None                                  # the range reaching furthest up among those sorted so far
    for current in ranges:
        if reach is not None and current[0] <= reach[1]:
            later, earlier = (current, reach) if current[2] > reach[2] else (reach, current)
            line, _ = earlier[3].span.file.line_col(earlier[3].span.start)
            ck.ctx.diags.error(codes.CASE_LABEL_TWICE,
                               f"CASE label `{ck.text(later[3])}` repeats a value already handled at "
                               f"line {line}", later[3].span)
        if reach is None or current[1] > reach[1]:
            reach = current
