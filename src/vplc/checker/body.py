"""Statement checking for one POU body (typing, call binding and the statement-level rules)."""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from . import assign_target, calls, case_labels, duplicates, external_globals, function_result, unused
from .exprs import ExprChecker
from .symbols import VarSymbol


class BodyChecker(ExprChecker):
    def __init__(self, ctx, pou: A.Pou | None, unit, scope: dict | None = None) -> None:
        self.ctx = ctx
        self.pou = pou
        self.pt = pou.sym if pou is not None else None
        self.ns = unit.namespace if unit is not None else None
        self.in_prelude = getattr(unit, "in_prelude", False)
        self.scope = scope if scope is not None else {}
        self.result_sym = None
        self.implicit_globals: dict = {}
        self.for_vars: list[VarSymbol] = []
        self.loop_depth = 0
        self.calls_made: list = []
        self.called_instances: set[str] = set()
        if pou is not None and pou.kind == "FUNCTION":
            self.result_sym = VarSymbol(pou.name, self.pt.ret or T.VOID, "RESULT", self.pt)

    # ---- declarations ---------------------------------------------------------------------------
    def check_pou(self) -> None:
        pou = self.pou
        self.scope = duplicates.check_locals(self.ctx, pou)
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
                    self.initial_value(decl.init, sym.type, f"initial value of {decl.name}")
                if section.kind == "VAR_IN_OUT" and decl.init is not None:
                    self.ctx.diags.error(codes.TYPE_MISMATCH,
                                         f"in-out parameter `{decl.name}` cannot have an initial value",
                                         decl.init.span)
        self.block(pou.body)
        function_result.check(self, pou)
        unused.check(self, pou)
        external_globals.check(self, pou)

    # ---- statements -----------------------------------------------------------------------------
    def block(self, stmts: list[A.Stmt]) -> None:
        for s in stmts:
            getattr(self, "s_" + type(s).__name__)(s)

    def s_Empty(self, s):
        pass

    def s_Assign(self, s: A.Assign):
        tt = self.expr(s.target)
        vt = self.expr(s.value, tt)
        assign_target.check_write(self, s.target)
        self.coerce(s.value, vt, tt, f"assignment to `{self.text(s.target)}`")

    def s_CallStmt(self, s: A.CallStmt):
        calls.check_call(self, s.call, None, statement=True)
        if s.call.binding is not None and s.call.binding.kind == "fb":
            self.called_instances.add(self.text(s.call.callee).upper())

    def condition(self, e: A.Expr, what: str) -> None:
        t = self.expr(e, T.BOOL)
        if not T.is_error(t) and T.base_of(t) is not T.BOOL:
            self.ctx.diags.error(codes.CONDITION_TYPE, f"the {what} condition must be BOOL, not {t.name}", e.span)

    def branches(self, bodies) -> None:
        """Check alternative statement lists: an FB called in one branch is not 'already called' in a sibling
        branch (ST1303), but may have been called after the whole construct."""
        before = set(self.called_instances)
        after = set(before)
        for body in bodies:
            self.called_instances = set(before)
            self.block(body)
            after |= self.called_instances
        self.called_instances = after

    def s_If(self, s: A.If):
        for b in s.branches:
            self.condition(b.cond, "IF")
        self.branches([b.body for b in s.branches] + [s.else_body or []])

    def s_Case(self, s: A.Case):
        st = self.expr(s.selector)
        case_labels.check(self, s, st)
        self.branches([b.body for b in s.branches] + [s.else_body or []])

    def s_For(self, s: A.For):
        vt = self.expr(s.var)
        sym = s.var.sym
        if not T.is_error(vt) and not T.is_int(vt):
            self.ctx.diags.error(codes.CONDITION_TYPE,
                                 f"the FOR variable must be an integer, not {vt.name}", s.var.span)
        elif isinstance(sym, VarSymbol):
            assign_target.check_write(self, s.var)
        for e in (s.start, s.end, s.step):
            if e is not None:
                et = self.expr(e, vt)
                self.coerce(e, et, vt, "FOR bound")
        self.for_vars.append(sym)
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1
        self.for_vars.pop()

    def s_While(self, s: A.While):
        self.condition(s.cond, "WHILE")
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1

    def s_Repeat(self, s: A.Repeat):
        self.loop_depth += 1
        self.block(s.body)
        self.loop_depth -= 1
        self.condition(s.cond, "UNTIL")

    def s_Exit(self, s):
        if self.loop_depth == 0:
            self.ctx.diags.error(codes.EXIT_OUTSIDE_LOOP, "EXIT is only allowed inside FOR, WHILE or REPEAT", s.span)

    def s_Continue(self, s):
        if self.loop_depth == 0:
            self.ctx.diags.error(codes.EXIT_OUTSIDE_LOOP,
                                 "CONTINUE is only allowed inside FOR, WHILE or REPEAT", s.span)

    def s_Return(self, s):
        pass
