"""Facts the code generator uses to emit cheaper code without changing what the program does.

* ``inlinable(pt)``: a small function block (R_TRIG, TON, a user's edge-and-latch FB ...) whose body the
  generator copies into the caller instead of calling it. Only bodies that cannot fault qualify, so a fault
  never needs the callee's instance path, and only bodies without loops or RETURN, so the copy needs no
  control flow of its own.
* ``loop_range(st)``: the values a FOR variable takes when its bounds are constants, so ``a[i]`` inside the
  loop needs no range check when every value is a valid index; ``unguarded(st)``: a short innermost FOR
  loop that cannot run away, so the watchdog is checked once when it ends instead of in every iteration.
"""
from __future__ import annotations

from collections.abc import Iterator
from dataclasses import fields
from typing import Any

from ..frontend import ast as A
from ..frontend import types as T

MAX_INLINE_STATEMENTS = 12         # body size (statements, nested ones included) worth copying per call site
MAX_UNGUARDED = 1000               # iterations of an innermost constant FOR loop run without a watchdog check
_SAFE_OPS = {"OR", "XOR", "AND", "=", "<>", "<", ">", "<=", ">=", "+", "-", "*", "NOT"}
_INLINE_NATIVES = {"VPLC_ScanTime"}


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}     # node class -> its dataclass fields' names (fields() is slow)


def _children(node: A.Node) -> Iterator[A.Node]:
    names = _FIELD_NAMES.get(type(node))
    if names is None:
        names = _FIELD_NAMES[type(node)] = tuple(f.name for f in fields(node))
    for name in names:
        value = getattr(node, name)
        if isinstance(value, A.Node):
            yield value
        elif isinstance(value, list):
            yield from (v for v in value if isinstance(v, A.Node))


def _safe_expr(e: A.Node) -> bool:
    if isinstance(e, (A.Literal, A.EnumLiteral, A.Name)):
        return True
    if isinstance(e, A.Member):
        return _safe_expr(e.base)
    if isinstance(e, A.BitAccess):
        return _safe_expr(e.base)
    if isinstance(e, (A.Unary, A.Binary)):
        return e.op in _SAFE_OPS and all(_safe_expr(c) for c in _children(e))
    if isinstance(e, A.Call):
        b = e.binding
        return b is not None and b.kind == "function" and b.pou.native and b.pou.name in _INLINE_NATIVES
    return False


def _count(stmts: list[A.Stmt], budget: list[int], cache: dict) -> bool:
    """False when a statement cannot be copied inline; ``budget[0]`` counts down the statements."""
    for st in stmts:
        budget[0] -= 1
        if budget[0] < 0:
            return False
        if isinstance(st, A.Assign):
            if not (_safe_expr(st.target) and _safe_expr(st.value)):
                return False
        elif isinstance(st, A.If):
            for br in st.branches:
                if not (_safe_expr(br.cond) and _count(br.body, budget, cache)):
                    return False
            if not _count(st.else_body or [], budget, cache):
                return False
        elif isinstance(st, A.Case):
            if not _safe_expr(st.selector):
                return False
            for case_br in st.branches:
                if not _count(case_br.body, budget, cache):
                    return False
            if not _count(st.else_body or [], budget, cache):
                return False
        elif isinstance(st, A.CallStmt):
            b = st.call.binding
            if b is None or b.kind != "fb" or not inlinable(b.pou, cache):
                return False
            for ba in b.args:
                if ba.param.direction == "inout" or not _safe_expr(ba.expr):
                    return False
        elif not isinstance(st, A.Empty):
            return False
    return True


def inlinable(pt: T.PouType, cache: dict) -> bool:
    """Whether calls of the function block ``pt`` may be compiled as a copy of its body (``cache``: one dict
    per compilation, id(pt) -> answer)."""
    known = cache.get(id(pt))
    if known is not None:
        return known
    cache[id(pt)] = False            # a body that (indirectly) calls itself is not copied
    ok = pt.kind == "fb" and not pt.native and pt.pou is not None and \
        all(sec.kind in ("VAR_INPUT", "VAR_OUTPUT", "VAR") for sec in pt.pou.sections) and \
        _count(pt.pou.body, [MAX_INLINE_STATEMENTS], cache)
    cache[id(pt)] = ok
    return ok


def _written(pt: T.PouType) -> set[int]:
    """Ids of the variables ``pt``'s body writes: assignment targets and what it passes to calls as an output
    or in-out (a member or element written counts as its whole variable)."""
    written = set()
    for node in pt.pou.body:
        for st in _walk(node):
            if isinstance(st, A.Assign):
                written.add(id(_root(st.target)))
            elif isinstance(st, (A.CallStmt, A.Call)):
                call = st.call if isinstance(st, A.CallStmt) else st
                if call.binding is not None:
                    written.update(id(_root(ba.expr)) for ba in call.binding.args if ba.param.direction != "in")
    return written


def readonly_inputs(pt: T.PouType, cache: dict) -> set[str]:
    """Upper names of the structure and array inputs of FUNCTION ``pt`` that its body only reads, when the body
    writes no global variable either (so nothing can change the caller's value during the call): the caller
    may hand over its value itself instead of a copy."""
    known = cache.get(("ro", id(pt)))
    if known is not None:
        return known
    written = _written(pt)
    syms = [d.sym for sec in pt.pou.sections for d in sec.vars if getattr(d, "sym", None) is not None]
    writes_global = any(id(sym) in written for sym in syms if sym.section in ("VAR_EXTERNAL", "VAR_GLOBAL")) or \
        any(sec.kind == "VAR_EXTERNAL" for sec in pt.pou.sections)
    out = set() if writes_global else {sym.name.upper() for sym in syms
                                       if sym.section == "VAR_INPUT" and id(sym) not in written}
    cache[("ro", id(pt))] = out
    return out


def kept_inputs(pt: T.PouType) -> dict[str, Any]:
    """Scalar inputs of ``pt`` (upper name -> variable symbol) that its body never writes: inside an inlined
    body they still hold the value the call just stored."""
    written = _written(pt)
    out = {}
    for sec in pt.pou.sections:
        if sec.kind == "VAR_INPUT":
            for d in sec.vars:
                sym = getattr(d, "sym", None)
                if sym is not None and id(sym) not in written and _scalar(sym.type):
                    out[d.name.upper()] = sym
    return out


def _scalar(t: T.Type) -> bool:
    return isinstance(T.base_of(t), (T.ElementaryType, T.EnumType, T.StringType))


def _root(e: A.Expr) -> Any:
    while isinstance(e, (A.Member, A.Index, A.BitAccess)):
        e = e.base
    return getattr(e, "sym", None)


def _walk(node: A.Node) -> Iterator[A.Node]:
    yield node
    for c in _children(node):
        yield from _walk(c)


def _int_literal(e: A.Expr) -> int | None:
    if isinstance(e, A.Literal) and isinstance(e.value, int) and not isinstance(e.value, bool):
        return e.value
    if isinstance(e, A.Unary) and e.op == "-" and isinstance(e.operand, A.Literal) \
            and isinstance(e.operand.value, int):
        return -e.operand.value
    return None


def _mentions(node: A.Node, sym: Any) -> bool:
    if isinstance(node, A.Name) and node.sym is sym:
        return True
    return any(_mentions(c, sym) for c in _children(node))


def constant_bounds(st: A.For) -> tuple[int, int, int] | None:
    """(start, end, step) of a FOR loop whose bounds and step are literals (step not 0), else None."""
    start, end = _int_literal(st.start), _int_literal(st.end)
    step = 1 if st.step is None else _int_literal(st.step)
    if start is None or end is None or not step:
        return None
    return start, end, step


def constant_step(st: A.For) -> int | None:
    """The literal step of a FOR loop (1 when omitted), or None."""
    return 1 if st.step is None else _int_literal(st.step)


def unguarded(st: A.For) -> bool:
    """A FOR loop that needs no watchdog check per iteration, only one when it ends: constant bounds, at most
    MAX_UNGUARDED iterations and no loop inside its body (the innermost loops of a nest keep their checks)."""
    bounds = constant_bounds(st)
    if bounds is None:
        return False
    start, end, step = bounds
    return len(range(start, end + (1 if step > 0 else -1), step)) <= MAX_UNGUARDED and \
        not any(_has_loop(node) for node in st.body)


def _has_loop(node: A.Node) -> bool:
    return isinstance(node, (A.For, A.While, A.Repeat)) or any(_has_loop(c) for c in _children(node))


def loop_range(st: A.For) -> tuple[int, int] | None:
    """(lowest, highest) value of the FOR variable inside the loop, or None when not known at compile time.

    Known means: literal bounds and step, and a local variable of the POU (VAR / VAR_TEMP) that the body
    never passes to a call (the checker already refuses assignments to it, ST1304)."""
    bounds = constant_bounds(st)
    sym = getattr(st.var, "sym", None)
    if bounds is None or not isinstance(st.var, A.Name) or sym is None or \
            getattr(sym, "section", None) not in ("VAR", "VAR_TEMP"):
        return None
    lo, hi, step = bounds
    for node in st.body:
        for call in _calls(node):
            b = call.binding
            if b is None or any(ba.param.direction != "in" and _mentions(ba.expr, sym) for ba in b.args):
                return None
    return (lo, hi) if step > 0 else (hi, lo)


def _calls(node: A.Node) -> Iterator[A.Call]:
    if isinstance(node, A.CallStmt):
        node = node.call
    if isinstance(node, A.Call):
        yield node
    for c in _children(node):
        yield from _calls(c)
