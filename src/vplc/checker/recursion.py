"""ST1701 — recursion: a POU that calls (or contains an instance of) itself, directly or indirectly.

IEC 61131-3 forbids recursion: every call needs statically allocated instance data.

Passing::

    FUNCTION Fact : DINT  (* loop instead of recursion *)

Failing::

    FUNCTION Fact : DINT
    VAR_INPUT n : DINT; END_VAR
    Fact := n * Fact(n - 1);        (* ST1701: Fact calls itself *)
    END_FUNCTION
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from ..frontend.source import Span
from .context import Context


def check(ctx: Context, edges: dict) -> None:
    """``edges``: PouType → list of (callee PouType, span). Reports each cycle once, at its first call."""
    color: dict[int, int] = {}
    reported: set[frozenset] = set()
    for root in list(edges):
        if color.get(id(root)):
            continue
        stack = [(root, iter(edges.get(root, ())))]
        path = [root]
        color[id(root)] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                color[id(node)] = 2
                stack.pop()
                path.pop()
                continue
            callee, span = nxt
            c = color.get(id(callee), 0)
            if c == 1:
                cycle = path[path.index(callee):] if callee in path else [callee]
                key = frozenset(id(p) for p in cycle)
                if key not in reported:
                    reported.add(key)
                    chain = " → ".join(p.name for p in cycle + [callee])
                    ctx.diags.error(codes.RECURSION, f"recursion is not allowed in IEC 61131-3: {chain}", span)
            elif c == 0:
                color[id(callee)] = 1
                path.append(callee)
                stack.append((callee, iter(edges.get(callee, ()))))


def instance_edges(pt: T.PouType, decls: list[A.VarDecl]) -> list[tuple[T.PouType, Span]]:
    """Edges from FB/program instances declared inside ``pt`` (an FB containing itself recurses)."""
    out = []
    for d in decls:
        t = T.unalias(d.sym.type) if d.sym is not None else None
        while isinstance(t, T.ArrayType):
            t = T.unalias(t.element)
        if isinstance(t, T.PouType):
            out.append((t, d.span))
    return out
