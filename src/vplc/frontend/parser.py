"""Parser: tokens → AST (vplc.frontend.ast) for one file, reporting syntax errors as diagnostics.

Entry point: :func:`parse`. The grammar is split by area, one parser object each, all reading one
:class:`TokenCursor` (parser_base.py): expressions in parser_exprs.py, statements in parser_stmts.py (holding
the expression parser), declarations and top-level items here (holding both). Recursion is depth-guarded
(ST0203).
"""
from __future__ import annotations

import sys

from . import ast as A
from . import codes
from .diagnostics import DiagnosticBag
from .lexer import Token, tokenize
from .parser_base import DepthExceeded, ParseError, TokenCursor
from .parser_exprs import ExpressionParser
from .parser_stmts import StatementParser
from .source import SourceFile, Span

SECTION_WORDS = frozenset(A.SECTION_KINDS)
MAX_NAMESPACE_DEPTH = 32     # NAMESPACE blocks inside each other (Sysmac projects nest two or three)
POU_END = {"FUNCTION": "END_FUNCTION", "FUNCTION_BLOCK": "END_FUNCTION_BLOCK", "PROGRAM": "END_PROGRAM"}


class Parser:
    """Declarations and top-level items of one file; statement bodies go to ``stmts``, expressions (initial
    values, bounds, task properties) to ``exprs``. All three read ``cursor``."""

    def __init__(self, cursor: TokenCursor, exprs: ExpressionParser, stmts: StatementParser) -> None:
        self.cur = cursor
        self.exprs = exprs
        self.stmts = stmts

    @classmethod
    def for_tokens(cls, src: SourceFile, tokens: list[Token], diags: DiagnosticBag) -> Parser:
        """The parser of one file's tokens, with its cursor, expression and statement parsers."""
        cursor = TokenCursor(src, tokens, diags)
        exprs = ExpressionParser(cursor)
        return cls(cursor, exprs, StatementParser(cursor, exprs))

    # grammar: unit := { type_block | pou | global_var_list | configuration | namespace_block }
    # grammar: namespace_block := NAMESPACE ident { '\' ident } { type_block | pou | namespace_block } END_NAMESPACE
    def unit(self) -> A.CompilationUnit:
        cur = self.cur
        items: list[A.Item] = []
        globals_sections: list[A.VarSection] = []
        gstart: int | None = None       # where the first VAR_GLOBAL section starts
        spaces: list[str] = []          # the NAMESPACE blocks open here, outermost first
        current = ""                    # their joined name
        too_deep = 0                    # NAMESPACE blocks beyond MAX_NAMESPACE_DEPTH (reported once)
        while cur.tok.kind != "EOF":
            t = cur.tok
            start_i = cur.i
            try:
                if t.kind == "IDENT" and t.up == "VAR_GLOBAL":
                    if spaces:
                        cur.fail("global variables belong to no namespace; declare VAR_GLOBAL outside NAMESPACE",
                                 codes.STRAY_TEXT)
                    gstart = t.start if gstart is None else gstart
                    globals_sections.append(self.var_section())
                    continue
                if t.kind == "IDENT" and t.up == "NAMESPACE":
                    if len(spaces) >= MAX_NAMESPACE_DEPTH:
                        if not too_deep:
                            cur.diags.error(codes.NESTING_TOO_DEEP,
                                            f"namespaces nested deeper than {MAX_NAMESPACE_DEPTH} "
                                            "levels", cur.tok_span(t))
                        too_deep += 1
                        self.namespace_name()
                        continue
                    spaces.append(self.namespace_name())
                    current = "\\".join(spaces)
                    continue
                if t.kind == "IDENT" and t.up == "END_NAMESPACE":
                    cur.advance()
                    cur.accept_op(";")
                    if too_deep:
                        too_deep -= 1
                    elif not spaces:
                        cur.diags.error(codes.STRAY_TEXT, "`END_NAMESPACE` without NAMESPACE", cur.tok_span(t))
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
                        cur.fail("a CONFIGURATION belongs to no namespace; declare it outside NAMESPACE",
                                 codes.STRAY_TEXT)
                    items.append(self.configuration())
                else:
                    cur.fail(f"expected FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE, VAR_GLOBAL or CONFIGURATION, "
                             f"found {cur.describe(t)}", codes.STRAY_TEXT)
                if spaces:
                    items[-1].declared_namespace = current
            except (ParseError, DepthExceeded):
                cur.depth = 0
                if cur.i == start_i:
                    cur.advance()
                cur.sync_item()
        if spaces:
            cur.diags.error(codes.MISSING_END, f"missing `END_NAMESPACE` of `{spaces[-1]}`", cur.tok_span())
        if globals_sections:
            stem = cur.src.path.replace("\\", "/").rsplit("/", 1)[-1].rsplit(".", 1)[0]
            assert gstart is not None                 # set when the first section was read
            items.append(A.GlobalVarList(globals_sections, stem, span=Span(cur.src, gstart, cur.tok.start)))
        self.report_pragmas()
        return A.CompilationUnit(items, span=Span(cur.src, 0, len(cur.src.text)))

    def namespace_name(self) -> str:
        """NAMESPACE A or NAMESPACE A\\B (IEC 61131-3 3rd edition; Sysmac's namespaces, W501): the name of a
        namespace nested in the enclosing one."""
        cur = self.cur
        cur.advance()
        parts = [cur.ident("a namespace name").text]
        while cur.accept_op("\\") or cur.accept_op("\\\\"):
            parts.append(cur.ident("a namespace name").text)
        return "\\".join(parts)

    def report_pragmas(self) -> None:
        cur = self.cur
        for p in cur.pragmas:
            if p.text[1:-1].strip().lower() != "native":
                cur.diags.note(codes.PRAGMA_IGNORED,
                               "pragma ignored: vplc does not interpret pragmas", cur.tok_span(p))

    def pragmas_before(self, offset: int, after: int) -> list[str]:
        cur = self.cur
        return [p.text[1:-1].strip() for p in cur.pragmas if after <= p.start < offset]

    # grammar: pou := (FUNCTION ident ':' type | FUNCTION_BLOCK ident | PROGRAM ident) { var_section } stmts END_*
    def pou(self) -> A.Pou:
        cur = self.cur
        kw = cur.advance()
        kind = kw.up
        end_word = POU_END[kind]
        prev_end = cur.toks[cur.i - 2].end if cur.i >= 2 else 0
        pragmas = self.pragmas_before(kw.start, prev_end)
        name_tok = cur.ident(f"the {kind} name")
        ret = None
        if kind == "FUNCTION":
            if cur.accept_op(":"):
                ret = self.type_spec()
        elif cur.at_kw("EXTENDS") or cur.at_kw("IMPLEMENTS"):
            cur.fail(f"`{cur.tok.text}` (object-oriented extension) is not supported: IEC 61131-3 2nd edition "
                     "and Sysmac function blocks have no inheritance", codes.UNSUPPORTED_EXTENSION)
        sections: list[A.VarSection] = []
        while cur.at_any_kw(SECTION_WORDS):
            try:
                sections.append(self.var_section())
            except ParseError:
                self.sync_to_end_var()
        if cur.at_kw("METHOD") or cur.at_kw("PROPERTY"):
            cur.fail(f"`{cur.tok.text}` is not supported: IEC 61131-3 2nd edition and Sysmac have no "
                     "methods or properties", codes.UNSUPPORTED_EXTENSION)
        cur.end_stack = [end_word]
        body = self.stmts.statement_list(frozenset((end_word,)))
        while cur.tok.kind == "IDENT" and cur.tok.up in ("END_IF", "END_CASE", "END_FOR", "END_WHILE",
                                                         "END_REPEAT", "ELSIF", "ELSE", "UNTIL"):
            cur.diags.error(codes.UNEXPECTED_TOKEN, f"`{cur.tok.text}` has no matching opening statement; remove it",
                            cur.tok_span())
            cur.advance()
            cur.accept_op(";")
            body += self.stmts.statement_list(frozenset((end_word,)))
        if cur.accept_kw(end_word):
            cur.accept_op(";")
        else:
            line, _ = cur.src.line_col(kw.start)
            cur.diags.error(codes.MISSING_END, f"missing `{end_word}` for {kind} {name_tok.text} (line {line}); "
                            f"found {cur.describe(cur.tok)}", cur.tok_span())
            if not (cur.at_any_kw(POU_END) or cur.at_kw("TYPE") or cur.tok.kind == "EOF"):
                cur.advance()
        pou = A.Pou(kind, name_tok.text, ret, sections, body, pragmas, span=cur.span_from(kw.start),
                    name_span=cur.tok_span(name_tok))
        pou.native = any(p.lower() == "native" for p in pragmas)
        return pou

    def sync_to_end_var(self) -> None:
        cur = self.cur
        while cur.tok.kind != "EOF" and not cur.at_kw("END_VAR"):
            cur.advance()
        cur.accept_kw("END_VAR")

    # grammar: var_section := VAR_xxx [CONSTANT|RETAIN|NON_RETAIN|PERSISTENT] { var_decl } END_VAR
    def var_section(self) -> A.VarSection:
        cur = self.cur
        kw = cur.advance()
        section = A.VarSection(kw.up, [])
        while True:
            if cur.accept_kw("CONSTANT"):
                section.constant = True
            elif cur.accept_kw("RETAIN"):
                section.retain = True
            elif cur.accept_kw("NON_RETAIN"):
                pass
            elif cur.accept_kw("PERSISTENT"):
                section.persistent = True
            else:
                break
        while not cur.at_kw("END_VAR"):
            if cur.tok.kind == "EOF" or cur.at_any_kw(POU_END) or (
                    cur.tok.kind == "IDENT" and cur.tok.up in SECTION_WORDS):
                cur.diags.error(codes.MISSING_END, f"missing `END_VAR` for the {kw.up} section; found "
                                f"{cur.describe(cur.tok)}", cur.tok_span())
                section.span = cur.span_from(kw.start)
                return section
            before = cur.i
            try:
                section.vars.extend(self.var_decl())
            except ParseError:
                cur.skip_declaration("END_VAR", before)
        cur.advance()
        cur.accept_op(";")
        section.span = cur.span_from(kw.start)
        return section

    # grammar: var_decl := ident { ',' ident } [AT address] ':' type_spec [':=' initializer] ';'
    def var_decl(self) -> list[A.VarDecl]:
        cur = self.cur
        start = cur.tok.start
        names = [cur.ident("a variable name")]
        while cur.accept_op(","):
            names.append(cur.ident("a variable name"))
        at = None
        if cur.accept_kw("AT"):
            if cur.tok.kind == "IOPORT":
                # W501 AT specification of an I/O port (ECAT://node#1/..., IOBus://...): vplc has no I/O ports
                port = cur.advance()
                cur.diags.error(codes.SYSMAC_NOT_MODELLED,
                                f"AT `{port.text.strip()}`: Sysmac I/O ports are not modelled by vplc; "
                                "declare the variable without AT (vplc models the memory areas %W, %H, %D, %E "
                                "and CIO)", cur.tok_span(port))
            elif cur.tok.kind != "ADDRESS":
                cur.fail_expected("a direct address such as `%MW10` or `%W480.00` after AT")
            else:
                at = cur.advance().text
        cur.expect_op(":", "after the variable name (declarations read `Name : TYPE;`)")
        spec = self.type_spec()
        init = self.initializer() if cur.accept_op(":=") else None
        self.end_declaration()
        span = cur.span_from(start)
        return [A.VarDecl(n.text, spec, init, at, span=Span(cur.src, n.start, span.end)) for n in names]

    def end_declaration(self) -> None:
        cur = self.cur
        if cur.accept_op(";"):
            return
        cur.diags.error(codes.MISSING_SEMICOLON,
                        f"missing `;` after this declaration (found {cur.describe(cur.tok)})",
                        cur.tok_span(cur.toks[cur.i - 1]))
        if not (cur.tok.kind == "IDENT" and cur.peek().kind == "OP" and cur.peek().text in (":", ",")):
            raise ParseError()

    # grammar: type_spec := ARRAY '[' dims ']' OF type_spec | (STRING|WSTRING) ['[' n ']' | '(' n ')']
    #                     | STRUCT {var_decl} END_STRUCT | '(' enum_values ')' [type] | qualname ['(' lo '..' hi ')']
    def type_spec(self) -> A.TypeRef:
        cur = self.cur
        t = cur.tok
        start = t.start
        if t.kind == "IDENT" and t.up == "ARRAY":
            cur.advance()
            cur.expect_op("[", "after ARRAY")
            dims = [self.dim_range()]
            while cur.accept_op(","):
                dims.append(self.dim_range())
            cur.expect_op("]", "to close the array bounds")
            cur.expect_kw("OF", "after the array bounds")
            cur.enter()
            element = self.type_spec()
            cur.leave()
            return A.ArrayTypeRef(dims, element, span=cur.span_from(start))
        if t.kind == "IDENT" and t.up in ("STRING", "WSTRING"):
            cur.advance()
            length = None
            if cur.accept_op("["):
                length = self.exprs.expression()
                cur.expect_op("]", "to close the string length")
            elif cur.at_op("(") :
                cur.advance()
                length = self.exprs.expression()
                cur.expect_op(")", "to close the string length")
            return A.StringTypeRef(t.up == "WSTRING", length, span=cur.span_from(start))
        if t.kind == "IDENT" and t.up in ("STRUCT", "UNION"):
            cur.advance()
            union = t.up == "UNION"          # Sysmac union (W501 6-3-6): the members overlap in memory
            end = "END_UNION" if union else "END_STRUCT"
            fields: list[A.VarDecl] = []
            while not cur.at_kw(end):
                if cur.tok.kind == "EOF" or cur.at_kw("END_TYPE"):
                    cur.diags.error(codes.MISSING_END, f"missing `{end}`; found {cur.describe(cur.tok)}",
                                    cur.tok_span())
                    return A.StructTypeRef(fields, span=cur.span_from(start), union=union)
                before = cur.i
                try:
                    fields.extend(self.var_decl())
                except ParseError:
                    cur.skip_declaration(end, before)
            cur.advance()
            return A.StructTypeRef(fields, span=cur.span_from(start), union=union)
        if t.kind == "OP" and t.text == "(":
            values = self.enum_values()
            base = None
            if cur.tok.kind == "IDENT" and not cur.at_op(";") and cur.tok.up not in ("END_TYPE",):
                base = self.type_spec()
            return A.EnumTypeRef(values, base, span=cur.span_from(start))
        if t.kind == "IDENT" and t.up in ("POINTER", "REFERENCE"):
            cur.fail(f"`{t.text} TO` is not supported: the library must compile on any IEC 61131-3 2nd "
                     "edition controller, which has no pointers or references", codes.UNSUPPORTED_EXTENSION)
        name, _ = self.exprs.qualname("a type name")
        ref = A.NamedTypeRef(name, span=cur.span_from(start))
        if cur.at_op("("):
            if self.looks_like_subrange():
                cur.advance()
                lo = self.exprs.expression()
                cur.expect_op("..", "in the subrange")
                hi = self.exprs.expression()
                cur.expect_op(")", "to close the subrange")
                return A.SubrangeTypeRef(ref, lo, hi, span=cur.span_from(start))
            values = self.enum_values()
            return A.EnumTypeRef(values, ref, span=cur.span_from(start))
        return ref

    def looks_like_subrange(self) -> bool:
        cur = self.cur
        depth = 0
        j = cur.i
        while j < len(cur.toks):
            t = cur.toks[j]
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
        cur = self.cur
        start = cur.tok.start
        if cur.accept_op("*"):
            return A.DimRange(None, None, span=cur.span_from(start))
        lo = self.exprs.expression()
        cur.expect_op("..", "in the array bounds (write `lo..hi`)")
        hi = self.exprs.expression()
        return A.DimRange(lo, hi, span=cur.span_from(start))

    # grammar: enum_values := '(' ident [':=' expr] { ',' ident [':=' expr] } ')'
    def enum_values(self) -> list[A.EnumValueDecl]:
        cur = self.cur
        cur.expect_op("(")
        values = []
        while True:
            t = cur.ident("an enumeration value")
            value = self.exprs.expression() if cur.accept_op(":=") else None
            values.append(A.EnumValueDecl(t.text, value, span=cur.span_from(t.start)))
            if cur.accept_op(","):
                continue
            cur.expect_op(")", "to close the enumeration")
            return values

    # grammar: initializer := '[' init_item { ',' init_item } ']' | '(' ident ':=' initializer {...} ')' | expr
    def initializer(self) -> A.Expr:
        cur = self.cur
        start = cur.tok.start
        if cur.at_op("["):
            cur.advance()
            items: list[A.InitItem] = []
            if not cur.at_op("]"):
                while True:
                    items.append(self.init_item())
                    if not cur.accept_op(","):
                        break
            cur.expect_op("]", "to close the array initializer")
            return A.ArrayInit(items, span=cur.span_from(start))
        if cur.at_op("(") and cur.peek().kind == "IDENT" and cur.peek(2).kind == "OP" and \
                cur.peek(2).text == ":=":
            cur.advance()
            fields = []
            while True:
                name = cur.ident("a member name")
                cur.expect_op(":=", "in the structure initializer")
                cur.enter()
                value = self.initializer()
                cur.leave()
                fields.append(A.FieldInit(name.text, value, span=cur.span_from(name.start)))
                if not cur.accept_op(","):
                    break
            cur.expect_op(")", "to close the structure initializer")
            return A.StructInit(fields, span=cur.span_from(start))
        return self.exprs.expression()

    # grammar: init_item := initializer | INT '(' [initializer] ')'
    def init_item(self) -> A.InitItem:
        cur = self.cur
        start = cur.tok.start
        if cur.tok.kind in ("INT", "BASED") and cur.peek().kind == "OP" and cur.peek().text == "(":
            count = self.exprs.primary()
            cur.advance()
            value = None if cur.at_op(")") else self.initializer()
            cur.expect_op(")", "to close the repeated initializer")
            return A.InitItem(value, count, span=cur.span_from(start))
        cur.enter()
        value = self.initializer()
        cur.leave()
        return A.InitItem(value, span=cur.span_from(start))

    # grammar: type_block := TYPE { ident ':' type_spec [':=' initializer] [';'] } END_TYPE
    def type_block(self) -> A.TypeBlock:
        cur = self.cur
        kw = cur.advance()
        decls: list[A.TypeDecl] = []
        while not cur.at_kw("END_TYPE"):
            if cur.tok.kind == "EOF" or cur.at_any_kw(POU_END) or cur.at_kw("TYPE"):
                cur.diags.error(codes.MISSING_END,
                                f"missing `END_TYPE`; found {cur.describe(cur.tok)}", cur.tok_span())
                return A.TypeBlock(decls, span=cur.span_from(kw.start))
            before = cur.i
            try:
                name = cur.ident("a type name")
                cur.expect_op(":", "after the type name")
                spec = self.type_spec()
                init = self.initializer() if cur.accept_op(":=") else None
                if not cur.accept_op(";") and not isinstance(spec, A.StructTypeRef) and not cur.at_kw("END_TYPE"):
                    self.end_declaration()
                decls.append(A.TypeDecl(name.text, spec, init, span=cur.span_from(name.start)))
            except ParseError:
                cur.skip_declaration("END_TYPE", before)
        cur.advance()
        cur.accept_op(";")
        return A.TypeBlock(decls, span=cur.span_from(kw.start))

    # grammar: configuration := CONFIGURATION ident { var_section } { resource | task | program } END_CONFIGURATION
    def configuration(self) -> A.Configuration:
        cur = self.cur
        kw = cur.advance()
        name = cur.ident("the configuration name")
        sections: list[A.VarSection] = []
        resources: list[A.Resource] = []
        implicit = A.Resource(None, None, [], [], [], span=cur.tok_span())
        while not cur.accept_kw("END_CONFIGURATION"):
            if cur.tok.kind == "EOF" or cur.at_any_kw(POU_END) or cur.at_kw("TYPE"):
                cur.diags.error(codes.MISSING_END, "missing `END_CONFIGURATION`", cur.tok_span())
                break
            before = cur.i
            try:
                if cur.at_any_kw(SECTION_WORDS):
                    sections.append(self.var_section())
                elif cur.at_kw("RESOURCE"):
                    resources.append(self.resource())
                elif not self.resource_member(implicit):
                    cur.fail_expected("RESOURCE, TASK, PROGRAM, VAR_GLOBAL or END_CONFIGURATION")
            except ParseError:
                cur.sync_statement()
                if cur.i == before:
                    cur.advance()
        cur.accept_op(";")
        if implicit.tasks or implicit.programs:
            resources.append(implicit)
        return A.Configuration(name.text, sections, resources, span=cur.span_from(kw.start))

    # grammar: resource := RESOURCE ident [ON ident] { var_section | task | program } END_RESOURCE
    def resource(self) -> A.Resource:
        cur = self.cur
        kw = cur.advance()
        name = cur.ident("the resource name")
        on = cur.ident("the processor name").text if cur.accept_kw("ON") else None
        res = A.Resource(name.text, on, [], [], [])
        while not cur.accept_kw("END_RESOURCE"):
            if cur.tok.kind == "EOF" or cur.at_kw("END_CONFIGURATION"):
                cur.diags.error(codes.MISSING_END, "missing `END_RESOURCE`", cur.tok_span())
                break
            if cur.at_any_kw(SECTION_WORDS):
                res.sections.append(self.var_section())
            elif not self.resource_member(res):
                cur.fail_expected("TASK, PROGRAM, VAR_GLOBAL or END_RESOURCE")
        cur.accept_op(";")
        res.span = cur.span_from(kw.start)
        return res

    # grammar: task := TASK ident '(' ident ':=' expr {',' ...} ')' ';'
    #          program := PROGRAM ident [WITH ident] ':' qualname ['(' args ')'] ';'
    def resource_member(self, res: A.Resource) -> bool:
        cur = self.cur
        start = cur.tok.start
        if cur.accept_kw("TASK"):
            name = cur.ident("the task name")
            props = []
            cur.expect_op("(", "after the task name")
            while not cur.at_op(")"):
                key = cur.ident("a task property (INTERVAL, PRIORITY, SINGLE)")
                cur.expect_op(":=")
                props.append(A.FieldInit(key.up, self.exprs.expression(), span=cur.span_from(key.start)))
                if not cur.accept_op(","):
                    break
            cur.expect_op(")", "to close the task properties")
            self.stmts.end_statement()
            res.tasks.append(A.TaskDecl(name.text, props, span=cur.span_from(start)))
            return True
        if cur.accept_kw("PROGRAM"):
            name = cur.ident("the program instance name")
            task = cur.ident("the task name").text if cur.accept_kw("WITH") else None
            cur.expect_op(":", "before the program type")
            prog, _ = self.exprs.qualname("the program type")
            args = self.exprs.call_args() if cur.at_op("(") else []
            self.stmts.end_statement()
            res.programs.append(A.ProgramInstance(name.text, task, prog, args, span=cur.span_from(start)))
            return True
        return False


def parse(src: SourceFile, diags: DiagnosticBag) -> A.CompilationUnit:
    """Parse one file. Syntax errors are added to ``diags``; the returned AST holds what could be read."""
    comments: list = []
    tokens = tokenize(src, diags, comments)
    return _parse_tokens(src, tokens, comments, diags)


# path -> (text, tokens, comments) of the files parse_kept has tokenized (the prelude: a few hundred kB at most)
_KEPT_TOKENS: dict[str, tuple[str, list[Token], list]] = {}


def parse_kept(src: SourceFile, diags: DiagnosticBag) -> A.CompilationUnit:
    """``parse`` for a file every project loads again unchanged (the prelude): its tokens are kept by path and
    used again while its text is the same, so it is tokenized once per process (a third of its parse time). The
    parser only reads tokens. A file whose tokenizing reports a problem is not kept: ``parse`` reads it."""
    kept = _KEPT_TOKENS.get(src.path)
    if kept is not None and kept[0] == src.text:
        _text, tokens, comments = kept
    else:
        comments = []
        problems = DiagnosticBag()
        tokens = tokenize(src, problems, comments)
        if problems.items:
            return parse(src, diags)
        _KEPT_TOKENS[src.path] = (src.text, tokens, comments)
    return _parse_tokens(src, tokens, list(comments), diags)


def _parse_tokens(src: SourceFile, tokens: list[Token], comments: list, diags: DiagnosticBag) -> A.CompilationUnit:
    if sys.getrecursionlimit() < 20000:
        sys.setrecursionlimit(20000)
    unit = Parser.for_tokens(src, tokens, diags).unit()
    unit.comments = comments
    return unit
