"""Parser: tokens → AST (vplc.frontend.ast) for one file, reporting syntax errors as diagnostics.

Entry point: :func:`parse`. The grammar is split by area: expressions in parser_exprs.py, statements in
parser_stmts.py, declarations and top-level items here. Recursion is depth-guarded (ST0203).
"""
from __future__ import annotations

import sys

from . import ast as A
from . import codes
from .diagnostics import DiagnosticBag
from .lexer import tokenize
from .parser_base import DepthExceeded, ParseError, ParserBase
from .parser_exprs import ExpressionsMixin
from .parser_stmts import StatementsMixin
from .source import SourceFile, Span

SECTION_WORDS = frozenset(A.SECTION_KINDS)
MAX_NAMESPACE_DEPTH = 32     # NAMESPACE blocks inside each other (Sysmac projects nest two or three)
POU_END = {"FUNCTION": "END_FUNCTION", "FUNCTION_BLOCK": "END_FUNCTION_BLOCK", "PROGRAM": "END_PROGRAM"}


class Parser(StatementsMixin, ExpressionsMixin, ParserBase):
    # grammar: unit := { type_block | pou | global_var_list | configuration | namespace_block }
    # grammar: namespace_block := NAMESPACE ident { '\' ident } { type_block | pou | namespace_block } END_NAMESPACE
    def unit(self) -> A.CompilationUnit:
        items: list[A.Item] = []
        globals_sections: list[A.VarSection] = []
        gstart = None
        spaces: list[str] = []          # the NAMESPACE blocks open here, outermost first
        current = ""                    # their joined name
        too_deep = 0                    # NAMESPACE blocks beyond MAX_NAMESPACE_DEPTH (reported once)
        while self.tok.kind != "EOF":
            t = self.tok
            start_i = self.i
            try:
                if t.kind == "IDENT" and t.up == "VAR_GLOBAL":
                    if spaces:
                        self.fail("global variables belong to no namespace; declare VAR_GLOBAL outside NAMESPACE",
                                  codes.STRAY_TEXT)
                    gstart = t.start if gstart is None else gstart
                    globals_sections.append(self.var_section())
                    continue
                if t.kind == "IDENT" and t.up == "NAMESPACE":
                    if len(spaces) >= MAX_NAMESPACE_DEPTH:
                        if not too_deep:
                            self.diags.error(codes.NESTING_TOO_DEEP,
                                             f"namespaces nested deeper than {MAX_NAMESPACE_DEPTH} "
                                             "levels", self.tok_span(t))
                        too_deep += 1
                        self.namespace_name()
                        continue
                    spaces.append(self.namespace_name())
                    current = "\\".join(spaces)
                    continue
                if t.kind == "IDENT" and t.up == "END_NAMESPACE":
                    self.advance()
                    self.accept_op(";")
                    if too_deep:
                        too_deep -= 1
                    elif not spaces:
                        self.diags.error(codes.STRAY_TEXT, "`END_NAMESPACE` without NAMESPACE", self.tok_span(t))
                    else:
                        spaces.pop()
                        current = "\\".join(spaces)
                    continue
                if t.kind == "IDENT" and t.up in POU_END:
                    items.append(self.pou())
                elif t.kind == "IDENT" and t.up == "TYPE":
                    items.append(self.type_block())
                elif t.kind == "IDENT" and t.up == "CONFIGURATION":
                    if spaces:
                        self.fail("a CONFIGURATION belongs to no namespace; declare it outside NAMESPACE",
                                  codes.STRAY_TEXT)
                    items.append(self.configuration())
                else:
                    self.fail(f"expected FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE, VAR_GLOBAL or CONFIGURATION, "
                              f"found {self.describe(t)}", codes.STRAY_TEXT)
                if spaces:
                    items[-1].declared_namespace = current
            except (ParseError, DepthExceeded):
                self.depth = 0
                if self.i == start_i:
                    self.advance()
                self.sync_item()
        if spaces:
            self.diags.error(codes.MISSING_END, f"missing `END_NAMESPACE` of `{spaces[-1]}`", self.tok_span())
        if globals_sections:
            stem = self.src.path.replace("\\", "/").rsplit("/", 1)[-1].rsplit(".", 1)[0]
            items.append(A.GlobalVarList(globals_sections, stem, span=Span(self.src, gstart, self.tok.start)))
        self.report_pragmas()
        return A.CompilationUnit(items, span=Span(self.src, 0, len(self.src.text)))

    def namespace_name(self) -> str:
        """NAMESPACE A or NAMESPACE A\\B (IEC 61131-3 3rd edition; Sysmac's namespaces, W501): the name of a
        namespace nested in the enclosing one."""
        self.advance()
        parts = [self.ident("a namespace name").text]
        while self.accept_op("\\") or self.accept_op("\\\\"):
            parts.append(self.ident("a namespace name").text)
        return "\\".join(parts)

    def report_pragmas(self) -> None:
        for p in self.pragmas:
            if p.text[1:-1].strip().lower() != "native":
                self.diags.note(codes.PRAGMA_IGNORED,
                                "pragma ignored: vplc does not interpret pragmas", self.tok_span(p))

    def pragmas_before(self, offset: int, after: int) -> list[str]:
        return [p.text[1:-1].strip() for p in self.pragmas if after <= p.start < offset]

    # grammar: pou := (FUNCTION ident ':' type | FUNCTION_BLOCK ident | PROGRAM ident) { var_section } stmts END_*
    def pou(self) -> A.Pou:
        kw = self.advance()
        kind = kw.up
        end_word = POU_END[kind]
        prev_end = self.toks[self.i - 2].end if self.i >= 2 else 0
        pragmas = self.pragmas_before(kw.start, prev_end)
        name_tok = self.ident(f"the {kind} name")
        ret = None
        if kind == "FUNCTION":
            if self.accept_op(":"):
                ret = self.type_spec()
        elif self.at_kw("EXTENDS") or self.at_kw("IMPLEMENTS"):
            self.fail(f"`{self.tok.text}` (object-oriented extension) is not supported: IEC 61131-3 2nd edition "
                      "and Sysmac function blocks have no inheritance", codes.UNSUPPORTED_EXTENSION)
        sections: list[A.VarSection] = []
        while self.at_any_kw(SECTION_WORDS):
            try:
                sections.append(self.var_section())
            except ParseError:
                self.sync_to_end_var()
        if self.at_kw("METHOD") or self.at_kw("PROPERTY"):
            self.fail(f"`{self.tok.text}` is not supported: IEC 61131-3 2nd edition and Sysmac have no "
                      "methods or properties", codes.UNSUPPORTED_EXTENSION)
        self.end_stack = [end_word]
        body = self.statement_list(frozenset((end_word,)))
        while self.tok.kind == "IDENT" and self.tok.up in ("END_IF", "END_CASE", "END_FOR", "END_WHILE",
                                                           "END_REPEAT", "ELSIF", "ELSE", "UNTIL"):
            self.diags.error(codes.UNEXPECTED_TOKEN, f"`{self.tok.text}` has no matching opening statement; remove it",
                             self.tok_span())
            self.advance()
            self.accept_op(";")
            body += self.statement_list(frozenset((end_word,)))
        if self.accept_kw(end_word):
            self.accept_op(";")
        else:
            line, _ = self.src.line_col(kw.start)
            self.diags.error(codes.MISSING_END, f"missing `{end_word}` for {kind} {name_tok.text} (line {line}); "
                             f"found {self.describe(self.tok)}", self.tok_span())
            if not (self.at_any_kw(POU_END) or self.at_kw("TYPE") or self.tok.kind == "EOF"):
                self.advance()
        pou = A.Pou(kind, name_tok.text, ret, sections, body, pragmas, span=self.span_from(kw.start),
                    name_span=self.tok_span(name_tok))
        pou.native = any(p.lower() == "native" for p in pragmas)
        return pou

    def sync_to_end_var(self) -> None:
        while self.tok.kind != "EOF" and not self.at_kw("END_VAR"):
            self.advance()
        self.accept_kw("END_VAR")

    # grammar: var_section := VAR_xxx [CONSTANT|RETAIN|NON_RETAIN|PERSISTENT] { var_decl } END_VAR
    def var_section(self) -> A.VarSection:
        kw = self.advance()
        section = A.VarSection(kw.up, [], span=None)
        while True:
            if self.accept_kw("CONSTANT"):
                section.constant = True
            elif self.accept_kw("RETAIN"):
                section.retain = True
            elif self.accept_kw("NON_RETAIN"):
                pass
            elif self.accept_kw("PERSISTENT"):
                section.persistent = True
            else:
                break
        while not self.at_kw("END_VAR"):
            if self.tok.kind == "EOF" or self.at_any_kw(POU_END) or (
                    self.tok.kind == "IDENT" and self.tok.up in SECTION_WORDS):
                self.diags.error(codes.MISSING_END, f"missing `END_VAR` for the {kw.up} section; found "
                                 f"{self.describe(self.tok)}", self.tok_span())
                section.span = self.span_from(kw.start)
                return section
            before = self.i
            try:
                section.vars.extend(self.var_decl())
            except ParseError:
                self.skip_declaration("END_VAR", before)
        self.advance()
        self.accept_op(";")
        section.span = self.span_from(kw.start)
        return section

    # grammar: var_decl := ident { ',' ident } [AT address] ':' type_spec [':=' initializer] ';'
    def var_decl(self) -> list[A.VarDecl]:
        start = self.tok.start
        names = [self.ident("a variable name")]
        while self.accept_op(","):
            names.append(self.ident("a variable name"))
        at = None
        if self.accept_kw("AT"):
            if self.tok.kind == "IOPORT":
                # W501 AT specification of an I/O port (ECAT://node#1/..., IOBus://...): vplc has no I/O ports
                port = self.advance()
                self.diags.error(codes.SYSMAC_NOT_MODELLED,
                                 f"AT `{port.text.strip()}`: Sysmac I/O ports are not modelled by vplc; "
                                 "declare the variable without AT (vplc models the memory areas %W, %H, %D, %E "
                                 "and CIO)", self.tok_span(port))
            elif self.tok.kind != "ADDRESS":
                self.fail_expected("a direct address such as `%MW10` or `%W480.00` after AT")
            else:
                at = self.advance().text
        self.expect_op(":", "after the variable name (declarations read `Name : TYPE;`)")
        spec = self.type_spec()
        init = self.initializer() if self.accept_op(":=") else None
        self.end_declaration()
        span = self.span_from(start)
        return [A.VarDecl(n.text, spec, init, at, span=Span(self.src, n.start, span.end)) for n in names]

    def end_declaration(self) -> None:
        if self.accept_op(";"):
            return
        self.diags.error(codes.MISSING_SEMICOLON,
                         f"missing `;` after this declaration (found {self.describe(self.tok)})",
                         self.tok_span(self.toks[self.i - 1]))
        if not (self.tok.kind == "IDENT" and self.peek().kind == "OP" and self.peek().text in (":", ",")):
            raise ParseError()

    # grammar: type_spec := ARRAY '[' dims ']' OF type_spec | (STRING|WSTRING) ['[' n ']' | '(' n ')']
    #                     | STRUCT {var_decl} END_STRUCT | '(' enum_values ')' [type] | qualname ['(' lo '..' hi ')']
    def type_spec(self) -> A.TypeRef:
        t = self.tok
        start = t.start
        if t.kind == "IDENT" and t.up == "ARRAY":
            self.advance()
            self.expect_op("[", "after ARRAY")
            dims = [self.dim_range()]
            while self.accept_op(","):
                dims.append(self.dim_range())
            self.expect_op("]", "to close the array bounds")
            self.expect_kw("OF", "after the array bounds")
            self.enter()
            element = self.type_spec()
            self.leave()
            return A.ArrayTypeRef(dims, element, span=self.span_from(start))
        if t.kind == "IDENT" and t.up in ("STRING", "WSTRING"):
            self.advance()
            length = None
            if self.accept_op("["):
                length = self.expression()
                self.expect_op("]", "to close the string length")
            elif self.at_op("(") :
                self.advance()
                length = self.expression()
                self.expect_op(")", "to close the string length")
            return A.StringTypeRef(t.up == "WSTRING", length, span=self.span_from(start))
        if t.kind == "IDENT" and t.up in ("STRUCT", "UNION"):
            self.advance()
            union = t.up == "UNION"          # Sysmac union (W501 6-3-6): the members overlap in memory
            end = "END_UNION" if union else "END_STRUCT"
            fields: list[A.VarDecl] = []
            while not self.at_kw(end):
                if self.tok.kind == "EOF" or self.at_kw("END_TYPE"):
                    self.diags.error(codes.MISSING_END, f"missing `{end}`; found {self.describe(self.tok)}",
                                     self.tok_span())
                    return A.StructTypeRef(fields, span=self.span_from(start), union=union)
                before = self.i
                try:
                    fields.extend(self.var_decl())
                except ParseError:
                    self.skip_declaration(end, before)
            self.advance()
            return A.StructTypeRef(fields, span=self.span_from(start), union=union)
        if t.kind == "OP" and t.text == "(":
            values = self.enum_values()
            base = None
            if self.tok.kind == "IDENT" and not self.at_op(";") and self.tok.up not in ("END_TYPE",):
                base = self.type_spec()
            return A.EnumTypeRef(values, base, span=self.span_from(start))
        if t.kind == "IDENT" and t.up in ("POINTER", "REFERENCE"):
            self.fail(f"`{t.text} TO` is not supported: the library must compile on any IEC 61131-3 2nd "
                      "edition controller, which has no pointers or references", codes.UNSUPPORTED_EXTENSION)
        name, _ = self.qualname("a type name")
        ref = A.NamedTypeRef(name, span=self.span_from(start))
        if self.at_op("("):
            if self.looks_like_subrange():
                self.advance()
                lo = self.expression()
                self.expect_op("..", "in the subrange")
                hi = self.expression()
                self.expect_op(")", "to close the subrange")
                return A.SubrangeTypeRef(ref, lo, hi, span=self.span_from(start))
            values = self.enum_values()
            return A.EnumTypeRef(values, ref, span=self.span_from(start))
        return ref

    def looks_like_subrange(self) -> bool:
        depth = 0
        j = self.i
        while j < len(self.toks):
            t = self.toks[j]
            if t.kind == "OP":
                if t.text == "(":
                    depth += 1
                elif t.text == ")":
                    depth -= 1
                    if depth == 0:
                        return False
                elif t.text == ".." and depth == 1:
                    return True
                elif t.text in (",", ";", ":="):
                    return False
            elif t.kind == "EOF":
                return False
            j += 1
        return False

    # grammar: dim := expr '..' expr | '*'
    def dim_range(self) -> A.DimRange:
        start = self.tok.start
        if self.accept_op("*"):
            return A.DimRange(None, None, span=self.span_from(start))
        lo = self.expression()
        self.expect_op("..", "in the array bounds (write `lo..hi`)")
        hi = self.expression()
        return A.DimRange(lo, hi, span=self.span_from(start))

    # grammar: enum_values := '(' ident [':=' expr] { ',' ident [':=' expr] } ')'
    def enum_values(self) -> list[A.EnumValueDecl]:
        self.expect_op("(")
        values = []
        while True:
            t = self.ident("an enumeration value")
            value = self.expression() if self.accept_op(":=") else None
            values.append(A.EnumValueDecl(t.text, value, span=self.span_from(t.start)))
            if self.accept_op(","):
                continue
            self.expect_op(")", "to close the enumeration")
            return values

    # grammar: initializer := '[' init_item { ',' init_item } ']' | '(' ident ':=' initializer {...} ')' | expr
    def initializer(self) -> A.Expr:
        start = self.tok.start
        if self.at_op("["):
            self.advance()
            items: list[A.InitItem] = []
            if not self.at_op("]"):
                while True:
                    items.append(self.init_item())
                    if not self.accept_op(","):
                        break
            self.expect_op("]", "to close the array initializer")
            return A.ArrayInit(items, span=self.span_from(start))
        if self.at_op("(") and self.peek().kind == "IDENT" and self.peek(2).kind == "OP" and \
                self.peek(2).text == ":=":
            self.advance()
            fields = []
            while True:
                name = self.ident("a member name")
                self.expect_op(":=", "in the structure initializer")
                self.enter()
                value = self.initializer()
                self.leave()
                fields.append(A.FieldInit(name.text, value, span=self.span_from(name.start)))
                if not self.accept_op(","):
                    break
            self.expect_op(")", "to close the structure initializer")
            return A.StructInit(fields, span=self.span_from(start))
        return self.expression()

    # grammar: init_item := initializer | INT '(' [initializer] ')'
    def init_item(self) -> A.InitItem:
        start = self.tok.start
        if self.tok.kind in ("INT", "BASED") and self.peek().kind == "OP" and self.peek().text == "(":
            count = self.primary()
            self.advance()
            value = None if self.at_op(")") else self.initializer()
            self.expect_op(")", "to close the repeated initializer")
            return A.InitItem(value, count, span=self.span_from(start))
        self.enter()
        value = self.initializer()
        self.leave()
        return A.InitItem(value, span=self.span_from(start))

    # grammar: type_block := TYPE { ident ':' type_spec [':=' initializer] [';'] } END_TYPE
    def type_block(self) -> A.TypeBlock:
        kw = self.advance()
        decls: list[A.TypeDecl] = []
        while not self.at_kw("END_TYPE"):
            if self.tok.kind == "EOF" or self.at_any_kw(POU_END) or self.at_kw("TYPE"):
                self.diags.error(codes.MISSING_END,
                                 f"missing `END_TYPE`; found {self.describe(self.tok)}", self.tok_span())
                return A.TypeBlock(decls, span=self.span_from(kw.start))
            before = self.i
            try:
                name = self.ident("a type name")
                self.expect_op(":", "after the type name")
                spec = self.type_spec()
                init = self.initializer() if self.accept_op(":=") else None
                if not self.accept_op(";") and not isinstance(spec, A.StructTypeRef):
                    if not self.at_kw("END_TYPE"):
                        self.end_declaration()
                decls.append(A.TypeDecl(name.text, spec, init, span=self.span_from(name.start)))
            except ParseError:
                self.skip_declaration("END_TYPE", before)
        self.advance()
        self.accept_op(";")
        return A.TypeBlock(decls, span=self.span_from(kw.start))

    # grammar: configuration := CONFIGURATION ident { var_section } { resource | task | program } END_CONFIGURATION
    def configuration(self) -> A.Configuration:
        kw = self.advance()
        name = self.ident("the configuration name")
        sections: list[A.VarSection] = []
        resources: list[A.Resource] = []
        implicit = A.Resource(None, None, [], [], [], span=self.tok_span())
        while not self.accept_kw("END_CONFIGURATION"):
            if self.tok.kind == "EOF" or self.at_any_kw(POU_END) or self.at_kw("TYPE"):
                self.diags.error(codes.MISSING_END, "missing `END_CONFIGURATION`", self.tok_span())
                break
            before = self.i
            try:
                if self.at_any_kw(SECTION_WORDS):
                    sections.append(self.var_section())
                elif self.at_kw("RESOURCE"):
                    resources.append(self.resource())
                elif not self.resource_member(implicit):
                    self.fail_expected("RESOURCE, TASK, PROGRAM, VAR_GLOBAL or END_CONFIGURATION")
            except ParseError:
                self.sync_statement()
                if self.i == before:
                    self.advance()
        self.accept_op(";")
        if implicit.tasks or implicit.programs:
            resources.append(implicit)
        return A.Configuration(name.text, sections, resources, span=self.span_from(kw.start))

    # grammar: resource := RESOURCE ident [ON ident] { var_section | task | program } END_RESOURCE
    def resource(self) -> A.Resource:
        kw = self.advance()
        name = self.ident("the resource name")
        on = self.ident("the processor name").text if self.accept_kw("ON") else None
        res = A.Resource(name.text, on, [], [], [], span=None)
        while not self.accept_kw("END_RESOURCE"):
            if self.tok.kind == "EOF" or self.at_kw("END_CONFIGURATION"):
                self.diags.error(codes.MISSING_END, "missing `END_RESOURCE`", self.tok_span())
                break
            if self.at_any_kw(SECTION_WORDS):
                res.sections.append(self.var_section())
            elif not self.resource_member(res):
                self.fail_expected("TASK, PROGRAM, VAR_GLOBAL or END_RESOURCE")
        self.accept_op(";")
        res.span = self.span_from(kw.start)
        return res

    # grammar: task := TASK ident '(' ident ':=' expr {',' ...} ')' ';'
    #          program := PROGRAM ident [WITH ident] ':' qualname ['(' args ')'] ';'
    def resource_member(self, res: A.Resource) -> bool:
        start = self.tok.start
        if self.accept_kw("TASK"):
            name = self.ident("the task name")
            props = []
            self.expect_op("(", "after the task name")
            while not self.at_op(")"):
                key = self.ident("a task property (INTERVAL, PRIORITY, SINGLE)")
                self.expect_op(":=")
                props.append(A.FieldInit(key.up, self.expression(), span=self.span_from(key.start)))
                if not self.accept_op(","):
                    break
            self.expect_op(")", "to close the task properties")
            self.end_statement()
            res.tasks.append(A.TaskDecl(name.text, props, span=self.span_from(start)))
            return True
        if self.accept_kw("PROGRAM"):
            name = self.ident("the program instance name")
            task = self.ident("the task name").text if self.accept_kw("WITH") else None
            self.expect_op(":", "before the program type")
            prog, _ = self.qualname("the program type")
            args = self.call_args() if self.at_op("(") else []
            self.end_statement()
            res.programs.append(A.ProgramInstance(name.text, task, prog, args, span=self.span_from(start)))
            return True
        return False


def parse(src: SourceFile, diags: DiagnosticBag) -> A.CompilationUnit:
    """Parse one file. Syntax errors are added to ``diags``; the returned AST holds what could be read."""
    if sys.getrecursionlimit() < 20000:
        sys.setrecursionlimit(20000)
    comments: list = []
    tokens = tokenize(src, diags, comments)
    unit = Parser(src, tokens, diags).unit()
    unit.comments = comments
    return unit
