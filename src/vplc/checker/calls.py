"""ST1201-ST1207 — call arguments: unknown, missing, wrong direction, too many, in-out not a variable.

Passing::

    mover(CBT := Cobot, Execute := Start, Done => MoveDone);

Failing::

    mover(CBT := Cobot, Execute := Start, Done := MoveDone);
    (* ST1203: `Done` is an output of CBT_MoveAbsolute; use `=>` to read it *)
    mover(Execute := Start);
    (* ST1202: in-out parameter `CBT` of CBT_MoveAbsolute must be given *)
"""
from __future__ import annotations

import difflib

from ..frontend import ast as A
from ..frontend import builtins as B
from ..frontend import codes
from ..frontend import types as T
from . import array_bounds, assign_target
from .compatibility import compatible
from .context import ExprHost
from .scope import Ambiguous, is_generic
from .symbols import BoundArg, BuiltinSymbol, CallBinding, PouSymbol, VarSymbol

KIND_TEXT = {"function": "FUNCTION", "fb": "FUNCTION_BLOCK", "program": "PROGRAM"}
DIR_TEXT = {"in": "an input", "out": "an output", "inout": "an in-out parameter"}


def is_lvalue(e: A.Expr) -> bool:
    if isinstance(e, A.Name):
        return isinstance(e.sym, VarSymbol)
    return isinstance(e, (A.Member, A.Index, A.BitAccess))


def check_call(ck: ExprHost, e: A.Call, expected: T.Type | None, statement: bool) -> T.Type:
    """Resolve the callee of ``e`` and bind its arguments; returns the call's result type."""
    ctx = ck.ctx
    callee = e.callee
    if isinstance(callee, A.Name):
        qn = callee.name
        var = ck.lookup_var(qn.name) if not qn.namespace else None
        if var is not None and var is ck.result_sym:
            var = None      # `F(...)` inside FUNCTION F is a (recursive) call, not the result variable
        if var is None:
            try:
                pou = ctx.tables.pous.lookup(qn.name, qn.namespace, ck.ns)
            except Ambiguous as amb:
                from . import undeclared
                undeclared.report_ambiguous(ctx, qn.text(), amb.candidates, callee.span)
                return _skip_args(ck, e)
            if pou is not None:
                callee.sym = PouSymbol(pou)
                callee.ty = pou
                ctx.note_vendor(pou, callee.span)
                ck.calls_made.append((pou, e.span))
                if pou.kind == "fb":
                    ctx.diags.error(codes.NOT_CALLABLE, f"{pou.name} is a function block type; declare an instance "
                                    f"(`my{pou.name} : {pou.name};`) and call the instance", callee.span)
                    return _skip_args(ck, e)
                if pou.kind == "program" and not statement:
                    ctx.diags.error(codes.NOT_CALLABLE,
                                    f"PROGRAM {pou.name} can only be called as a statement", callee.span)
                    return _skip_args(ck, e)
                return bind_pou(ck, e, pou, "function" if pou.kind == "function" else "program", None)
            builtin = B.lookup(qn.name) if not qn.namespace else None
            if builtin is not None:
                if B.is_edition3(builtin):
                    ctx.note_edition3(f"the function {builtin.name}", callee.span)
                if builtin.vendor:
                    ctx.vendor_uses.append((callee.span, builtin.name, "instruction or type"))
                callee.sym = BuiltinSymbol(builtin)
                callee.ty = T.VOID
                return bind_builtin(ck, e, builtin, expected)
    t = T.unalias(ck.expr(callee))
    if T.is_error(t):
        return _skip_args(ck, e)
    if isinstance(t, T.PouType) and t.kind == "fb":
        if not statement:
            ctx.diags.error(codes.NOT_CALLABLE,
                            f"a function block call is a statement; call `{ck.text(callee)}(...)` on its "
                            "own line and read its outputs afterwards", e.span)
            _skip_args(ck, e)
            return T.ERROR
        ck.calls_made.append((t, e.span))
        return bind_pou(ck, e, t, "fb", callee)
    ctx.diags.error(codes.NOT_CALLABLE, f"`{ck.text(callee)}` is of type {t.name} and cannot be called", callee.span)
    return _skip_args(ck, e)


def _skip_args(ck: ExprHost, e: A.Call) -> T.Type:
    for a in e.args:
        if a.value is not None:
            ck.expr(a.value)
    return T.ERROR


def bind_pou(ck: ExprHost, e: A.Call, pt: T.PouType, kind: str, instance: A.Expr | None) -> T.Type:
    ctx = ck.ctx
    positional = [p for p in pt.params if p.direction in ("in", "inout")]
    if kind == "fb" and ctx.dialect == "sysmac":
        # a function block called with non-formal arguments takes its outputs after its inputs, in declaration
        # order (W502 2-116 `TON_instance(In, PT, Q, ET);`, 2-134 `CTD_instance(CD, Load, PV, Q, CV);`)
        positional += [p for p in pt.params if p.direction == "out"]
    bound: dict[int, BoundArg] = {}
    pos = 0
    formal_seen = False
    p: T.Param | None
    for arg in e.args:
        if arg.name is None:
            if formal_seen:
                ctx.diags.error(codes.NON_FORMAL_AFTER_FORMAL,
                                "a non-formal argument cannot follow formal ones (`Name := value`); "
                                "name every argument", arg.span)
                _type_skipped(ck, arg.value)
                continue
            if pos >= len(positional):
                ctx.diags.error(codes.ARGUMENT_COUNT, f"too many arguments: {pt.name} takes {len(positional)} "
                                f"{'inputs and outputs' if kind == 'fb' and ctx.dialect == 'sysmac' else 'input(s)'}",
                                arg.span)
                _type_skipped(ck, arg.value)
                continue
            p = positional[pos]
            pos += 1
            if p.direction == "out":
                ctx.note_edition3("an output given without `=>` (Sysmac's non-formal call)", arg.span)
        else:
            formal_seen = True
            p = pt.param(arg.name) or _iec_alias(pt, arg.name)
            if p is None:
                _unknown_param(ck, arg, pt)
                continue
            if arg.output and p.direction != "out":
                ctx.diags.error(codes.WRONG_DIRECTION,
                                f"`{p.name}` is {DIR_TEXT[p.direction]} of {pt.name}; use `:=` to pass it",
                                arg.span)
                _type_skipped(ck, arg.value)
                continue
            if not arg.output and p.direction == "out":
                ctx.diags.error(codes.WRONG_DIRECTION,
                                f"`{p.name}` is an output of {pt.name}; use `=>` to read it", arg.span)
                _type_skipped(ck, arg.value)
                continue
        if p.index in bound:
            ctx.diags.error(codes.PARAMETER_TWICE, f"parameter `{p.name}` of {pt.name} is given twice", arg.span)
        bound[p.index] = bind_arg(ck, arg, p, pt)
    for p in pt.params:
        if p.direction == "inout" and p.index not in bound:
            ctx.diags.error(codes.MISSING_IN_OUT, f"in-out parameter `{p.name}` of {pt.name} must be given "
                            f"(`{p.name} := <variable>`)", e.span)
    e.binding = CallBinding(kind, (pt.ret or T.VOID) if kind == "function" else T.VOID, pou=pt, instance=instance,
                            args=[bound[i] for i in sorted(bound)])
    return e.binding.ty


# IEC 61131-3 names of inputs that Sysmac names otherwise (W502 2-134: CTD's load input is `Load`, IEC's `LD`)
IEC_PARAM_NAMES = {("CTD", "LD"): "Load"}


def _iec_alias(pt: T.PouType, name: str) -> T.Param | None:
    sysmac = IEC_PARAM_NAMES.get((pt.name.upper(), name.upper()))
    return pt.param(sysmac) if sysmac and pt.namespace in (None, "") else None


def _type_skipped(ck: ExprHost, value: A.Expr | None) -> None:
    """Type the value of an argument that was reported and is not bound: its names are still resolved (and
    reported if undeclared) and its variables count as used."""
    if value is not None:
        ck.expr(value)


def _unknown_param(ck: ExprHost, arg: A.Arg, pt: T.PouType) -> None:
    names = [p.name for p in pt.params]
    close = difflib.get_close_matches((arg.name or "").upper(), [n.upper() for n in names], n=1, cutoff=0.7)
    notes = [f"did you mean `{names[[n.upper() for n in names].index(close[0])]}`?"] if close else []
    notes.append(f"parameters of {pt.name}: " + (", ".join(names) or "none"))
    ck.ctx.diags.error(codes.UNKNOWN_PARAMETER, f"{pt.name} has no parameter `{arg.name}`", arg.span, notes)
    _type_skipped(ck, arg.value)


def bind_arg(ck: ExprHost, arg: A.Arg, p: T.Param, pt: T.PouType) -> BoundArg:
    ctx = ck.ctx
    value = arg.value
    ba = BoundArg(p, value, arg.negated)
    if value is None:
        return ba
    what = f"argument `{p.name}` of {pt.name}"
    pty = T.unalias(p.type)
    if p.direction == "out":
        have = ck.expr(value)
        if not is_lvalue(value):
            ctx.diags.error(codes.NOT_A_VARIABLE, f"the output `{p.name}` must be read into a variable", value.span)
        elif not T.is_error(have) and not compatible(p.type, have) and not (
                ctx.dialect == "sysmac" and T.sysmac_assignable(p.type, have)):
            ctx.diags.error(codes.ARGUMENT_TYPE,
                            f"{what}: output of type {p.type.name} cannot be stored in `{ck.text(value)}` "
                            f"of type {have.name}", value.span)
        else:
            assign_target.check_write(ck, value, f"output {p.name}")
        return ba
    have = ck.expr(value, None if isinstance(pty, T.ArrayType) or is_generic(pty) else p.type)
    if isinstance(pty, T.ArrayType) and isinstance(value, A.Index) and not isinstance(T.unalias(have), T.ArrayType) \
            and not T.is_error(have) and (
                (is_generic(pty.element) and pty.element.accepts(have)) or (
                    compatible(have, pty.element) and T.same_type(T.base_of(have), T.base_of(pty.element)))):
            ba.from_element = True
            array_bounds.check_slice(ck, value, pty, p.name)
            if p.direction == "inout":
                assign_target.check_write(ck, value, f"in-out {p.name}")
            return ba
    if p.direction == "inout":
        if not is_lvalue(value):
            ctx.diags.error(codes.NOT_A_VARIABLE,
                            f"in-out parameter `{p.name}` of {pt.name} needs a variable (it is passed by "
                            "reference), not an expression", value.span)
            return ba
        if not T.is_error(have) and not _inout_compatible(have, p.type):
            ctx.diags.error(codes.ARGUMENT_TYPE, f"{what}: in-out parameter of type {p.type.name} cannot refer to "
                            f"`{ck.text(value)}` of type {have.name}; the types must be identical", value.span)
            return ba
        if getattr(T.base_of(p.type), "name", "").upper() != "_SAXIS_REF":
            # the system axis variable _MC_AX[n] is read-only, yet every motion instruction (and a user's FB
            # wrapping them) takes it as an in-out (W508)
            assign_target.check_write(ck, value, f"in-out {p.name}")
        return ba
    ck.coerce(value, have, p.type, what)
    return ba


def _inout_compatible(have: T.Type, want: T.Type) -> bool:
    if is_generic(want):
        return want.accepts(have)
    h, w = T.unalias(have), T.unalias(want)
    if isinstance(h, T.StringType) and isinstance(w, T.StringType):
        return h.wide == w.wide
    if isinstance(h, T.ArrayType) and isinstance(w, T.ArrayType):
        if is_generic(w.element):       # ARRAY[*] OF ANY: Sysmac's array instructions (W502 AryMove, SizeOfAry)
            return w.open and w.element.accepts(h.element)
        return compatible(h, w) and T.same_type(T.base_of(h.element), T.base_of(w.element))
    return T.same_type(h, w)


def bind_builtin(ck: ExprHost, e: A.Call, b: B.Builtin, expected: T.Type | None) -> T.Type:
    ctx = ck.ctx
    values: list[A.Expr] = []
    formal_names = [n.upper() for n in b.formal_names]
    by_name: dict[int, A.Expr] = {}
    for arg in e.args:
        if arg.output:
            ctx.diags.error(codes.WRONG_DIRECTION, f"{b.name} has no outputs; `=>` cannot be used", arg.span)
            continue
        value = arg.value
        assert value is not None            # only an output (`=>`) may leave its value out
        if arg.name is None:
            values.append(value)
            continue
        up = arg.name.upper()
        if up in formal_names:
            by_name[formal_names.index(up)] = value
        elif up.startswith("IN") and up[2:].isdigit() and b.max_args is None:
            by_name[int(up[2:]) - 1] = value
        else:
            ctx.diags.error(codes.UNKNOWN_PARAMETER, f"{b.name} has no parameter `{arg.name}`"
                            + (f"; its parameters are {', '.join(b.formal_names)}" if b.formal_names else ""),
                            arg.span)
            ck.expr(value)
    if by_name:
        if values:
            ctx.diags.error(codes.NON_FORMAL_AFTER_FORMAL,
                            f"mix of formal and non-formal arguments in the call of {b.name}", e.span)
        values = [by_name[i] for i in sorted(by_name)]
    n = len(values)
    if n < b.min_args or (b.max_args is not None and n > b.max_args):
        want = f"{b.min_args}" if b.max_args == b.min_args else (
            f"at least {b.min_args}" if b.max_args is None else f"{b.min_args} to {b.max_args}")
        ctx.diags.error(codes.ARGUMENT_COUNT, f"{b.name} takes {want} argument(s), {n} given", e.span)
        for v in values:
            ck.expr(v)
        return T.ERROR
    skip_first = b.name in ("SEL", "MUX")
    types_: list[T.Type | None] = [None] * n
    for i, v in enumerate(values):
        if not ck.needs_context(v) or (skip_first and i == 0):
            types_[i] = ck.expr(v, T.DINT if (skip_first and i == 0) else None)
    hint = next((t for i, t in enumerate(types_) if t is not None and not (skip_first and i == 0)), None)
    if b.name in ("SHL", "SHR", "ROL", "ROR", "LOWER_BOUND", "UPPER_BOUND") or T.is_string(hint or T.VOID):
        hint = None
    if hint is None and "_TO_" in b.name:
        hint = T.ELEMENTARY.get(b.name.split("_TO_")[0])
    if hint is None and expected is not None and b.name in ("MAX", "MIN", "LIMIT", "SEL", "MUX", "ABS", "ADD",
                                                            "MUL", "SUB", "DIV", "MOD", "MOVE"):
        hint = expected
    arg_types: list[T.Type] = []
    for i, v in enumerate(values):
        t = types_[i]
        arg_types.append(t if t is not None else ck.expr(v, hint))
    try:
        ret, convs = b.resolve(arg_types, ctx.dialect)
    except B.SignatureError as err:
        span = values[err.arg_index].span if err.arg_index is not None and err.arg_index < n else e.span
        ctx.diags.error(codes.ARGUMENT_TYPE, f"{b.name}: {err}", span)
        return T.ERROR
    args = []
    for i, (v, conv) in enumerate(zip(values, convs, strict=False)):
        if conv is not None and v.conv is None and not T.is_error(conv):
            v.conv = conv
        name = b.formal_names[i] if i < len(b.formal_names) else f"IN{i + 1}"
        args.append(BoundArg(T.Param(name, "in", arg_types[i], i), v))
    e.binding = CallBinding("builtin", ret, builtin=b, args=args)
    return ret
