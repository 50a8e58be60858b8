"""Statement grammar, with recovery at `;` and at the next block keyword.

:class:`StatementParser` reads statement lists from a :class:`TokenCursor`, handing expressions to the
:class:`ExpressionParser` it is given; the declaration parser (parser.py) holds both.
"""
from __future__ import annotations

from . import ast as A
from . import codes
from .parser_base import BLOCK_END, ITEM_START, ParseError, TokenCursor
from .parser_exprs import ExpressionParser


class StatementParser:
    """Statements at the cursor's position; expressions inside them are read by ``exprs`` (same cursor)."""

    def __init__(self, cursor: TokenCursor, exprs: ExpressionParser) -> None:
        self.cur = cursor
        self.exprs = exprs

    # grammar: statement_list := { statement }   (until one of `terminators`)
    def statement_list(self, terminators: frozenset[str], case_labels: bool = False) -> list[A.Stmt]:
        cur = self.cur
        body: list[A.Stmt] = []
        while True:
            t = cur.tok
            if t.kind == "EOF":
                return body
            if t.kind == "IDENT" and (t.up in terminators or t.up in BLOCK_END or
                                      (t.up in ITEM_START and t.up != "VAR_GLOBAL")):
                return body
            if case_labels and self.looks_like_case_label():
                return body
            before = cur.i
            try:
                stmt = self.statement()
                if stmt is not None:
                    body.append(stmt)
            except ParseError:
                cur.sync_statement()
                if cur.i == before:
                    if cur.at_any_kw(terminators) or cur.at_any_kw(BLOCK_END):
                        return body
                    cur.advance()

    # grammar: statement := assignment | call | if | case | for | while | repeat | EXIT | CONTINUE | RETURN | ';'
    def statement(self) -> A.Stmt | None:
        cur = self.cur
        t = cur.tok
        start = t.start
        if t.kind == "OP" and t.text == ";":
            cur.advance()
            return A.Empty(span=cur.span_from(start))
        if t.kind == "IDENT":
            handler = self._STMT_DISPATCH.get(t.up)
            if handler is not None:
                cur.enter()
                cur.end_stack.append(self._END_WORD.get(t.up, ""))
                try:
                    return handler(self)
                finally:
                    cur.end_stack.pop()
                    cur.leave()
        target = self.exprs.postfix()
        if isinstance(target, (A.Literal, A.EnumLiteral)):
            text = cur.src.text[target.span.start:target.span.end]
            cur.fail(f"a statement cannot start with the value `{text}`; if it is a CASE label, put `:` after it",
                     codes.UNEXPECTED_TOKEN, t)
        if cur.at_op(":="):
            cur.advance()
            value = self.exprs.expression()
            self.end_statement()
            return A.Assign(target, value, span=cur.span_from(start))
        if isinstance(target, A.Call):
            self.end_statement()
            return A.CallStmt(target, span=cur.span_from(start))
        if cur.at_op("=") :
            cur.fail("`=` compares values; use `:=` to assign", codes.EQUALS_TO_ASSIGN)
        if isinstance(target, (A.Name, A.Member, A.Index)) and cur.tok.kind in ("IDENT", "INT", "REAL"):
            cur.fail_expected("`:=` or `;`", f"after `{cur.src.text[target.span.start:target.span.end]}` "
                              "(missing `;` on the previous line?)")
        cur.fail_expected("`:=` or a call", "to make a statement")

    def end_statement(self) -> None:
        cur = self.cur
        if cur.at_op(";"):
            cur.advance()
            return
        prev = cur.toks[cur.i - 1]
        cur.diags.error(codes.MISSING_SEMICOLON, f"missing `;` after this statement (found {cur.describe(cur.tok)})",
                        cur.tok_span(prev))
        raise ParseError()

    # grammar: if := IF expr THEN stmts { ELSIF expr THEN stmts } [ ELSE stmts ] END_IF [';']
    def if_statement(self) -> A.If:
        cur = self.cur
        start = cur.advance().start
        branches = []
        bstart = start
        cond = self.exprs.expression()
        cur.expect_kw("THEN", "after the IF condition")
        body = self.statement_list(frozenset(("ELSIF", "ELSE", "END_IF")))
        branches.append(A.IfBranch(cond, body, span=cur.span_from(bstart)))
        else_body = None
        while True:
            if cur.at_kw("ELSIF"):
                bstart = cur.advance().start
                cond = self.exprs.expression()
                cur.expect_kw("THEN", "after the ELSIF condition")
                body = self.statement_list(frozenset(("ELSIF", "ELSE", "END_IF")))
                branches.append(A.IfBranch(cond, body, span=cur.span_from(bstart)))
            elif cur.at_kw("ELSE"):
                cur.advance()
                else_body = self.statement_list(frozenset(("END_IF",)))
            else:
                break
        self.expect_end("END_IF", "IF", start)
        return A.If(branches, else_body, span=cur.span_from(start))

    def expect_end(self, word: str, opener: str, start: int) -> None:
        cur = self.cur
        if cur.accept_kw(word):
            cur.accept_op(";")
            return
        line, col = cur.src.line_col(start)
        t = cur.tok
        cur.diags.error(codes.MISSING_END, f"missing `{word}` for the {opener} at line {line}; found "
                        f"{cur.describe(t)}", cur.tok_span())
        if t.kind == "IDENT" and t.up.startswith("END_") and t.up not in cur.end_stack:
            cur.advance()          # a mistyped END_xxx that nothing encloses: take it as this one's end
            cur.accept_op(";")

    # grammar: case := CASE expr OF { labels ':' stmts } [ ELSE stmts ] END_CASE [';']
    def case_statement(self) -> A.Case:
        cur = self.cur
        start = cur.advance().start
        selector = self.exprs.expression()
        cur.expect_kw("OF", "after the CASE selector")
        branches = []
        else_body = None
        while True:
            if cur.at_kw("ELSE"):
                cur.advance()
                cur.accept_op(":")
                else_body = self.statement_list(frozenset(("END_CASE",)))
                break
            if cur.at_kw("END_CASE") or cur.tok.kind == "EOF" or cur.at_any_kw(BLOCK_END):
                break
            bstart = cur.tok.start
            try:
                labels = [self.case_label()]
                while cur.accept_op(","):
                    labels.append(self.case_label())
                cur.expect_op(":", "after the CASE labels")
            except ParseError:
                cur.sync_statement()
                continue
            body = self.statement_list(frozenset(("ELSE", "END_CASE")), case_labels=True)
            branches.append(A.CaseBranch(labels, body, span=cur.span_from(bstart)))
        self.expect_end("END_CASE", "CASE", start)
        return A.Case(selector, branches, else_body, span=cur.span_from(start))

    # grammar: case_label := expr [ '..' expr ]
    def case_label(self) -> A.Expr | A.CaseRange:
        cur = self.cur
        start = cur.tok.start
        lo = self.exprs.expression()
        if cur.accept_op(".."):
            hi = self.exprs.expression()
            return A.CaseRange(lo, hi, span=cur.span_from(start))
        return lo

    def looks_like_case_label(self) -> bool:
        """True when the next tokens are `label {, label} :` (a new CASE branch, not a statement)."""
        cur = self.cur
        j = cur.i
        toks = cur.toks
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
        cur = self.cur
        start = cur.advance().start
        vt = cur.ident("the FOR loop variable")
        var = A.Name(A.QualName(vt.text, span=cur.tok_span(vt)), span=cur.tok_span(vt))
        cur.expect_op(":=", "after the FOR loop variable")
        first = self.exprs.expression()
        cur.expect_kw("TO", "in the FOR statement")
        last = self.exprs.expression()
        step = self.exprs.expression() if cur.accept_kw("BY") else None
        cur.expect_kw("DO", "in the FOR statement")
        body = self.statement_list(frozenset(("END_FOR",)))
        self.expect_end("END_FOR", "FOR", start)
        return A.For(var, first, last, step, body, span=cur.span_from(start))

    # grammar: while := WHILE expr DO stmts END_WHILE [';']
    def while_statement(self) -> A.While:
        cur = self.cur
        start = cur.advance().start
        cond = self.exprs.expression()
        cur.expect_kw("DO", "after the WHILE condition")
        body = self.statement_list(frozenset(("END_WHILE",)))
        self.expect_end("END_WHILE", "WHILE", start)
        return A.While(cond, body, span=cur.span_from(start))

    # grammar: repeat := REPEAT stmts UNTIL expr END_REPEAT [';']
    def repeat_statement(self) -> A.Repeat:
        cur = self.cur
        start = cur.advance().start
        body = self.statement_list(frozenset(("UNTIL", "END_REPEAT")))
        cur.expect_kw("UNTIL", "to end the REPEAT body")
        cond = self.exprs.expression()
        self.expect_end("END_REPEAT", "REPEAT", start)
        return A.Repeat(body, cond, span=cur.span_from(start))

    # grammar: EXIT ';' | CONTINUE ';' | RETURN ';'
    def simple_statement(self) -> A.Stmt:
        cur = self.cur
        t = cur.advance()
        node = {"EXIT": A.Exit, "CONTINUE": A.Continue, "RETURN": A.Return}[t.up](span=cur.tok_span(t))
        self.end_statement()
        return node

    _END_WORD = {"IF": "END_IF", "CASE": "END_CASE", "FOR": "END_FOR", "WHILE": "END_WHILE",
                 "REPEAT": "END_REPEAT"}

    _STMT_DISPATCH = {
        "IF": if_statement, "CASE": case_statement, "FOR": for_statement, "WHILE": while_statement,
        "REPEAT": repeat_statement, "EXIT": simple_statement, "CONTINUE": simple_statement,
        "RETURN": simple_statement,
    }
