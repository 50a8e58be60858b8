"""Statement checking for one POU body (typing, call binding and the statement-level rules)."""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from . import assign_target, calls, case_labels, duplicates, external_globals, function_result, unused
from .context import Context, Flow, Unit
from .exprs import ExprChecker
from .symbols import VarSymbol


class BodyChecker:
    """Checks one POU: its declarations' initial values, then its statements, handing every expression to
    ``exprs`` (the POU's expression checker) and keeping ``flow`` (FOR variables, instances called) that
    ``exprs`` reads when a call writes an argument. ``in_prelude``: the POU is the prelude's (no ST1901/ST1009)."""

    def __init__(self, ctx: Context, pou: A.Pou, exprs: ExprChecker, flow: Flow, in_prelude: bool = False) -> None:
        self.ctx = ctx
        self.pou = pou
        self.exprs = exprs
        self.flow = flow
        self.in_prelude = in_prelude
        self.loop_depth = 0

    @classmethod
    def for_pou(cls, ctx: Context, pou: A.Pou, unit: Unit | None) -> BodyChecker:
        """The checker of ``pou``, declared in ``unit``, with its expression checker."""
        result_sym = None
        if pou.kind == "FUNCTION":
            result_sym = VarSymbol(pou.name, pou.sym.ret or T.VOID, "RESULT", pou.sym)
        flow = Flow()
        exprs = ExprChecker(ctx, unit.namespace if unit is not None else None, result_sym=result_sym, in_pou=True,
                            flow=flow)
        return cls(ctx, pou, exprs, flow, unit.in_prelude if unit is not None else False)

    # ---- declarations ---------------------------------------------------------------------------
    def check_pou(self) -> None:
        pou = self.pou
        exprs = self.exprs
        exprs.scope = duplicates.check_locals(self.ctx, pou)
        for section in pou.sections:
            for decl in section.vars:
                sym = decl.sym
                if sym is None:
                    continue
                if section.kind == "VAR_EXTERNAL":
                    g = self.ctx.tables.globals.get(decl.name.upper())
                    if g is None:
                        self.ctx.diags.error(codes.UNDECLARED, f"VAR_EXTERNAL `{decl.name}` has no matching VAR_GLOBAL",
                                             decl.name_span)
                    else:
                        sym.target = g
                        g.used = True
                        if not T.same_type(g.type, sym.type) and not T.is_error(g.type):
                            self.ctx.diags.error(codes.TYPE_MISMATCH,
                                                 f"VAR_EXTERNAL `{decl.name}` is declared {sym.type.name} "
                                                 f"but the global is {g.type.name}", decl.name_span)
                # a CONSTANT input or in-out is a parameter the POU only reads: its value comes from the caller
                # (W501, variable attributes: Constant for input and in-out variables)
                if section.constant and decl.init is None and section.kind not in ("VAR_EXTERNAL", "VAR_INPUT",
                                                                                   "VAR_IN_OUT"):
                    self.ctx.diags.error(codes.WRITE_CONSTANT,
                                         f"CONSTANT `{decl.name}` needs an initial value", decl.name_span)
                if decl.init is not None:
                    exprs.initial_value(decl.init, sym.type, f"initial value of {decl.name}")
                if section.kind == "VAR_IN_OUT" and decl.init is not None:
                    self.ctx.diags.error(codes.TYPE_MISMATCH,
                                         f"in-out parameter `{decl.name}` cannot have an initial value",
                                         decl.init.span)
        self.block(pou.body)
        function_result.check(self.ctx, pou, exprs.result_sym)
        unused.check(self.ctx, pou, self.in_prelude)
        external_globals.check(self.ctx, pou, exprs.implicit_globals, self.in_prelude)

    # ---- statements -----------------------------------------------------------------------------
    def block(self, stmts: list[A.Stmt]) -> None:
        for s in stmts:
            getattr(self, "s_" + type(s).__name__)(s)

    def s_Empty(self, s: A.Empty) -> None:
        pass

    def s_Assign(self, s: A.Assign) -> None:
        exprs = self.exprs
        tt = exprs.expr(s.target)
        vt = exprs.expr(s.value, tt)
        assign_target.check_write(exprs, s.target)
        exprs.coerce(s.value, vt, tt, f"assignment to `{exprs.text(s.target)}`")

    def s_CallStmt(self, s: A.CallStmt) -> None:
        calls.check_call(self.exprs, s.call, None, statement=True)
        if s.call.binding is not None and s.call.binding.kind == "fb":
            self.flow.called_instances.add(self.exprs.text(s.call.callee).upper())

    def condition(self, e: A.Expr, what: str) -> None:
        t = self.exprs.expr(e, T.BOOL)
        if not T.is_error(t) and T.base_of(t) is not T.BOOL:
            self.ctx.diags.error(codes.CONDITION_TYPE, f"the {what} condition must be BOOL, not {t.name}", e.span)

    def branches(self, bodies: list[list[A.Stmt]]) -> None:
        """Check alternative statement lists: an FB called in one branch is not 'already called' in a sibling
        branch (ST1303), but may have been called after the whole construct."""
        flow = self.flow
        before = set(flow.called_instances)
        after = set(before)
        for body in bodies:
            flow.called_instances = set(before)
            self.block(body)
            after |= flow.called_instances
        flow.called_instances = after

    def s_If(self, s: A.If) -> None:
        for b in s.branches:
            self.condition(b.cond, "IF")
        self.branches([b.body for b in s.branches] + [s.else_body or []])

    def s_Case(self, s: A.Case) -> None:
        st = self.exprs.expr(s.selector)
        case_labels.check(self.exprs, s, st)
        self.branches([b.body for b in s.branches] + [s.else_body or []])

    def s_For(self, s: A.For) -> None:
        exprs = self.exprs
        vt = exprs.expr(s.var)
        sym = s.var.sym
        if not T.is_error(vt) and not T.is_int(vt):
            self.ctx.diags.error(codes.CONDITION_TYPE,
                                 f"the FOR variable must be an integer, not {vt.name}", s.var.span)
        elif isinstance(sym, VarSymbol):
            assign_target.check_write(exprs, s.var)
        for e in (s.start, s.end, s.step):
            if e is not None:
                et = exprs.expr(e, vt)
                exprs.coerce(e, et, vt, "FOR bound")
        self.flow.for_vars.append(sym)
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1
        self.flow.for_vars.pop()

    def s_While(self, s: A.While) -> None:
        self.condition(s.cond, "WHILE")
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1

    def s_Repeat(self, s: A.Repeat) -> None:
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1
        self.condition(s.cond, "UNTIL")

    def s_Exit(self, s: A.Exit) -> None:
        if self.loop_depth == 0:
            self.ctx.diags.error(codes.EXIT_OUTSIDE_LOOP, "EXIT is only allowed inside FOR, WHILE or REPEAT", s.span)

    def s_Continue(self, s: A.Continue) -> None:
        if self.loop_depth == 0:
            self.ctx.diags.error(codes.EXIT_OUTSIDE_LOOP,
                                 "CONTINUE is only allowed inside FOR, WHILE or REPEAT", s.span)

    def s_Return(self, s: A.Return) -> None:
        pass
