"""ST2010 (warning, only with ``--portable``) — the result of LEN or FIND used as another type than INT.

IEC 61131-3 declares `LEN` and `FIND` with an INT result; Omron Sysmac returns UINT, so Sysmac code that uses
them as UINT does not compile elsewhere. Keep the result INT (an INT variable, `INT_TO_...` conversions); Sysmac
accepts INT there through its implicit casts (W501 6-5-3).

Passing (portable)::

    Head := CONCAT('Len=', INT_TO_STRING(LEN(Data)));
    Comma := FIND(Data, ',');                   (* Comma : INT *)

Failing (portable)::

    Head := CONCAT('Len=', UINT_TO_STRING(LEN(Data)));   (* ST2010 *)
    Comma := FIND(Data, ',');                   (* Comma : UINT -> ST2010 *)
"""
from __future__ import annotations

from collections.abc import Iterator

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context
from .scope import is_generic

ARITH = ("+", "-", "*", "/", "MOD")
INT_FUNCTIONS = ("LEN", "FIND")


def _builtin(e: A.Expr) -> str | None:
    b = getattr(e, "binding", None) if isinstance(e, A.Call) else None
    return b.builtin.name if b is not None and b.kind == "builtin" else None


def _int_literal(e: A.Expr) -> bool:
    return isinstance(e, A.Literal) and e.kind == "int" and e.type_prefix is None


def _iec_int(e: A.Expr) -> bool:
    """True when ``e`` is INT under IEC typing because of a LEN / FIND result (LEN(s) - 1, ...)."""
    if _builtin(e) in INT_FUNCTIONS:
        return True
    if isinstance(e, A.Binary) and e.op in ARITH:
        sides = (e.left, e.right)
        return any(_iec_int(s) for s in sides) and all(_iec_int(s) or _int_literal(s) or _is_int_type(s)
                                                       for s in sides)
    if isinstance(e, A.Unary) and e.op == "-":
        return _iec_int(e.operand)
    return False


def _is_int_type(e: A.Expr) -> bool:
    return e.ty is not None and T.base_of(e.ty) is T.INT


def _report(ctx: Context, e: A.Expr, where: str) -> None:
    ctx.diags.warning(codes.PORTABLE_LEN_TYPE,
                      f"LEN and FIND return INT in IEC 61131-3 (UINT only in Sysmac), so this value is "
                      f"INT where {where}; use an INT variable or an INT_TO_... conversion", e.span)


def _target_ok(t: T.Type | None) -> bool:
    return t is None or T.is_error(t) or T.base_of(t) is T.INT or is_generic(t)


def _arg_uses(call: A.Call) -> Iterator[tuple[A.Expr, T.Type | None, str]]:
    """(argument expression, parameter type or None for generic) of every input argument."""
    b = call.binding
    if b is None:
        return
    for ba in b.args:
        if ba.param.direction == "out" or ba.expr is None:
            continue
        if b.kind == "builtin":
            name = b.builtin.name
            if "_TO_" in name and not name.startswith(("INT_TO_", "ANY_TO_")):
                yield ba.expr, T.ELEMENTARY.get(name.split("_TO_")[0]), f"{name} expects {name.split('_TO_')[0]}"
        else:
            yield ba.expr, ba.param.type, f"`{ba.param.name}` of {b.pou.name} is {ba.param.type.name}"


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.Assign) and _iec_int(node.value) and not _target_ok(node.target.ty):
            _report(ctx, node.value, f"`{node.target.span.file.text[node.target.span.start:node.target.span.end]}` "
                    f"is {node.target.ty.name}")
        elif isinstance(node, A.Call):
            for expr, ptype, where in _arg_uses(node):
                if _iec_int(expr) and not _target_ok(ptype):
                    _report(ctx, expr, where)
        elif isinstance(node, A.Binary) and node.op not in ("AND", "OR", "XOR", "&"):
            for a, b in ((node.left, node.right), (node.right, node.left)):
                if _iec_int(a) and not _iec_int(node) and not _int_literal(b) and not _iec_int(b) \
                        and b.ty is not None and not T.is_error(b.ty) and T.base_of(b.ty) is not T.INT:
                    _report(ctx, a, f"the other operand of `{node.op}` is {b.ty.name}")
