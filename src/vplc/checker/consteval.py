"""Constant folding of integer expressions (array bounds, string lengths, enum values, CASE labels)."""
from __future__ import annotations

from collections.abc import Mapping

from ..frontend import ast as A
from ..frontend import types as T
from .context import Context
from .symbols import VarSymbol


def const_int(e: A.Expr | None, ctx: Context, scope: Mapping[str, VarSymbol | None] | None,
              _depth: int = 0) -> int | None:
    """Value of a constant integer expression, or None. ``scope`` maps NAME → VarSymbol (locals) or None."""
    if _depth > 50 or e is None:
        return None
    if isinstance(e, A.Literal):
        return e.value if e.kind == "int" else None
    if isinstance(e, A.Unary) and e.op in "-+":
        v = const_int(e.operand, ctx, scope, _depth + 1)
        return None if v is None else (-v if e.op == "-" else v)
    if isinstance(e, A.Binary) and e.op in ("+", "-", "*", "/", "MOD"):
        a = const_int(e.left, ctx, scope, _depth + 1)
        b = const_int(e.right, ctx, scope, _depth + 1)
        if a is None or b is None:
            return None
        if e.op == "+":
            return a + b
        if e.op == "-":
            return a - b
        if e.op == "*":
            return a * b
        if b == 0:
            return None
        q = abs(a) // abs(b) * (1 if (a >= 0) == (b >= 0) else -1)
        return q if e.op == "/" else a - q * b
    if isinstance(e, A.EnumLiteral):
        try:
            t = ctx.tables.types.lookup(e.type_name.name, e.type_name.namespace)
        except Exception:
            return None
        if isinstance(t, T.EnumType):
            key = t.lookup(e.value)
            return t.values.get(key) if key else None
        return None
    if isinstance(e, A.Name) and not e.name.namespace:
        up = e.name.name.upper()
        sym = scope.get(up) if scope else None
        if sym is None:
            sym = ctx.tables.globals.get(up)
        if sym is not None and sym.constant and sym.decl is not None and sym.decl.init is not None:
            return const_int(sym.decl.init, ctx, scope, _depth + 1)
        vals = ctx.tables.enum_values.get(up)
        if sym is None and vals and len(vals) == 1:
            return vals[0].value
    return None
