"""ST1601 — a string literal longer than the STRING it is stored in.

In the Sysmac dialect ``STRING[n]`` holds n-1 characters (the size counts the terminating NUL).

Passing::

    VAR Msg : STRING[6]; END_VAR
    Msg := 'Hello';

Failing::

    Msg := 'Hello!';       (* ST1601: 6 characters do not fit in STRING[6] (5 characters) *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import ExprHost


def check(ck: ExprHost, value: A.Expr, want: T.Type) -> None:
    t = T.unalias(want)
    if not isinstance(t, T.StringType) or not t.explicit:
        return
    if isinstance(value, A.Literal) and value.kind in ("string", "wstring"):
        n = len(value.value)
        if n > t.capacity:
            extra = " (the size counts the terminating NUL)" if ck.ctx.dialect == "sysmac" else ""
            ck.ctx.diags.error(codes.STRING_TOO_LONG,
                               f"the text has {n} characters but {t.name} holds at most {t.capacity}"
                               f"{extra}; shorten the text or enlarge the string", value.span)
