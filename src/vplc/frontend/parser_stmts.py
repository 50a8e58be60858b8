"""Statement grammar, with recovery at `;` and at the next block keyword."""
from __future__ import annotations

from . import ast as A
from . import codes
from .parser_base import BLOCK_END, ITEM_START, ParseError


class StatementsMixin:
    # grammar: statement_list := { statement }   (until one of `terminators`)
    def statement_list(self, terminators: frozenset[str], case_labels: bool = False) -> list[A.Stmt]:
        body: list[A.Stmt] = []
        while True:
            t = self.tok
            if t.kind == "EOF":
                return body
            if t.kind == "IDENT" and (t.up in terminators or t.up in BLOCK_END or
                                      (t.up in ITEM_START and t.up != "VAR_GLOBAL")):
                return body
            if case_labels and self.looks_like_case_label():
                return body
            before = self.i
            try:
                stmt = self.statement()
                if stmt is not None:
                    body.append(stmt)
            except ParseError:
                self.sync_statement()
                if self.i == before:
                    if self.at_any_kw(terminators) or self.at_any_kw(BLOCK_END):
                        return body
                    self.advance()

    # grammar: statement := assignment | call | if | case | for | while | repeat | EXIT | CONTINUE | RETURN | ';'
    def statement(self) -> A.Stmt | None:
        t = self.tok
        start = t.start
        if t.kind == "OP" and t.text == ";":
            self.advance()
            return A.Empty(span=self.span_from(start))
        if t.kind == "IDENT":
            handler = self._STMT_DISPATCH.get(t.up)
            if handler is not None:
                self.enter()
                self.end_stack.append(self._END_WORD.get(t.up, ""))
                try:
                    return handler(self)
                finally:
                    self.end_stack.pop()
                    self.leave()
        target = self.postfix()
        if isinstance(target, (A.Literal, A.EnumLiteral)):
            text = self.src.text[target.span.start:target.span.end]
            self.fail(f"a statement cannot start with the value `{text}`; if it is a CASE label, put `:` after it",
                      codes.UNEXPECTED_TOKEN, t)
        if self.at_op(":="):
            self.advance()
            value = self.expression()
            self.end_statement()
            return A.Assign(target, value, span=self.span_from(start))
        if isinstance(target, A.Call):
            self.end_statement()
            return A.CallStmt(target, span=self.span_from(start))
        if self.at_op("=") :
            self.fail("`=` compares values; use `:=` to assign", codes.EQUALS_TO_ASSIGN)
        if isinstance(target, (A.Name, A.Member, A.Index)) and self.tok.kind in ("IDENT", "INT", "REAL"):
            self.fail_expected("`:=` or `;`", f"after `{self.src.text[target.span.start:target.span.end]}` "
                               "(missing `;` on the previous line?)")
        self.fail_expected("`:=` or a call", "to make a statement")

    def end_statement(self) -> None:
        if self.at_op(";"):
            self.advance()
            return
        prev = self.toks[self.i - 1]
        self.diags.error(codes.MISSING_SEMICOLON, f"missing `;` after this statement (found {self.describe(self.tok)})",
                         self.tok_span(prev))
        raise ParseError()

    # grammar: if := IF expr THEN stmts { ELSIF expr THEN stmts } [ ELSE stmts ] END_IF [';']
    def if_statement(self) -> A.If:
        start = self.advance().start
        branches = []
        bstart = start
        cond = self.expression()
        self.expect_kw("THEN", "after the IF condition")
        body = self.statement_list(frozenset(("ELSIF", "ELSE", "END_IF")))
        branches.append(A.IfBranch(cond, body, span=self.span_from(bstart)))
        else_body = None
        while True:
            if self.at_kw("ELSIF"):
                bstart = self.advance().start
                cond = self.expression()
                self.expect_kw("THEN", "after the ELSIF condition")
                body = self.statement_list(frozenset(("ELSIF", "ELSE", "END_IF")))
                branches.append(A.IfBranch(cond, body, span=self.span_from(bstart)))
            elif self.at_kw("ELSE"):
                self.advance()
                else_body = self.statement_list(frozenset(("END_IF",)))
            else:
                break
        self.expect_end("END_IF", "IF", start)
        return A.If(branches, else_body, span=self.span_from(start))

    def expect_end(self, word: str, opener: str, start: int) -> None:
        if self.accept_kw(word):
            self.accept_op(";")
            return
        line, col = self.src.line_col(start)
        t = self.tok
        self.diags.error(codes.MISSING_END, f"missing `{word}` for the {opener} at line {line}; found "
                         f"{self.describe(t)}", self.tok_span())
        if t.kind == "IDENT" and t.up.startswith("END_") and t.up not in self.end_stack:
            self.advance()          # a mistyped END_xxx that nothing encloses: take it as this one's end
            self.accept_op(";")

    # grammar: case := CASE expr OF { labels ':' stmts } [ ELSE stmts ] END_CASE [';']
    def case_statement(self) -> A.Case:
        start = self.advance().start
        selector = self.expression()
        self.expect_kw("OF", "after the CASE selector")
        branches = []
        else_body = None
        while True:
            if self.at_kw("ELSE"):
                self.advance()
                self.accept_op(":")
                else_body = self.statement_list(frozenset(("END_CASE",)))
                break
            if self.at_kw("END_CASE") or self.tok.kind == "EOF" or self.at_any_kw(BLOCK_END):
                break
            bstart = self.tok.start
            try:
                labels = [self.case_label()]
                while self.accept_op(","):
                    labels.append(self.case_label())
                self.expect_op(":", "after the CASE labels")
            except ParseError:
                self.sync_statement()
                continue
            body = self.statement_list(frozenset(("ELSE", "END_CASE")), case_labels=True)
            branches.append(A.CaseBranch(labels, body, span=self.span_from(bstart)))
        self.expect_end("END_CASE", "CASE", start)
        return A.Case(selector, branches, else_body, span=self.span_from(start))

    # grammar: case_label := expr [ '..' expr ]
    def case_label(self):
        start = self.tok.start
        lo = self.expression()
        if self.accept_op(".."):
            hi = self.expression()
            return A.CaseRange(lo, hi, span=self.span_from(start))
        return lo

    def looks_like_case_label(self) -> bool:
        """True when the next tokens are `label {, label} :` (a new CASE branch, not a statement)."""
        j = self.i
        toks = self.toks
        n = len(toks)
        while j < n:
            t = toks[j]
            if t.kind == "OP" and t.text in ("-", "+"):
                j += 1
                t = toks[j]
            if t.kind in ("INT", "BASED", "REAL", "STRING", "WSTRING", "TIME"):
                j += 1
            elif t.kind == "TYPED":
                j += 2
            elif t.kind == "IDENT" and t.up not in BLOCK_END:
                j += 1
                while j + 1 < n and toks[j].kind == "OP" and toks[j].text in ("\\", "\\\\"):
                    j += 2 if toks[j + 1].kind == "IDENT" else 3
            else:
                return False
            if j >= n:
                return False
            t = toks[j]
            if t.kind != "OP":
                return False
            if t.text == ":":
                return True
            if t.text in (",", ".."):
                j += 1
                continue
            return False
        return False

    # grammar: for := FOR ident ':=' expr TO expr [ BY expr ] DO stmts END_FOR [';']
    def for_statement(self) -> A.For:
        start = self.advance().start
        vt = self.ident("the FOR loop variable")
        var = A.Name(A.QualName(vt.text, span=self.tok_span(vt)), span=self.tok_span(vt))
        self.expect_op(":=", "after the FOR loop variable")
        first = self.expression()
        self.expect_kw("TO", "in the FOR statement")
        last = self.expression()
        step = self.expression() if self.accept_kw("BY") else None
        self.expect_kw("DO", "in the FOR statement")
        body = self.statement_list(frozenset(("END_FOR",)))
        self.expect_end("END_FOR", "FOR", start)
        return A.For(var, first, last, step, body, span=self.span_from(start))

    # grammar: while := WHILE expr DO stmts END_WHILE [';']
    def while_statement(self) -> A.While:
        start = self.advance().start
        cond = self.expression()
        self.expect_kw("DO", "after the WHILE condition")
        body = self.statement_list(frozenset(("END_WHILE",)))
        self.expect_end("END_WHILE", "WHILE", start)
        return A.While(cond, body, span=self.span_from(start))

    # grammar: repeat := REPEAT stmts UNTIL expr END_REPEAT [';']
    def repeat_statement(self) -> A.Repeat:
        start = self.advance().start
        body = self.statement_list(frozenset(("UNTIL", "END_REPEAT")))
        self.expect_kw("UNTIL", "to end the REPEAT body")
        cond = self.expression()
        self.expect_end("END_REPEAT", "REPEAT", start)
        return A.Repeat(body, cond, span=self.span_from(start))

    # grammar: EXIT ';' | CONTINUE ';' | RETURN ';'
    def simple_statement(self) -> A.Stmt:
        t = self.advance()
        node = {"EXIT": A.Exit, "CONTINUE": A.Continue, "RETURN": A.Return}[t.up](span=self.tok_span(t))
        self.end_statement()
        return node

    _END_WORD = {"IF": "END_IF", "CASE": "END_CASE", "FOR": "END_FOR", "WHILE": "END_WHILE",
                 "REPEAT": "END_REPEAT"}

    _STMT_DISPATCH = {
        "IF": if_statement, "CASE": case_statement, "FOR": for_statement, "WHILE": while_statement,
        "REPEAT": repeat_statement, "EXIT": simple_statement, "CONTINUE": simple_statement,
        "RETURN": simple_statement,
    }
