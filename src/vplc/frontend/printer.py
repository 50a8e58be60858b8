"""Printer: AST → Structured Text. ``parse(print(ast)) == ast`` (spans and annotations aside).

Comments and pragmas other than ``{native}`` are not kept. Expressions get parentheses only where
precedence requires them.
"""
from __future__ import annotations

from . import ast as A

PREC = {"OR": 1, "XOR": 2, "AND": 3, "=": 4, "<>": 4, "<": 5, ">": 5, "<=": 5, ">=": 5, "+": 6, "-": 6,
        "*": 7, "/": 7, "MOD": 7, "**": 9}
UNARY_PREC = 8
IND = "    "


def expr(e: A.Expr) -> str:
    """Text of an expression (iterative enough for the parser's depth limit)."""
    return _expr(e)


def _prec(e: A.Expr) -> int:
    if isinstance(e, A.Binary):
        return PREC[e.op]
    if isinstance(e, A.Unary):
        return UNARY_PREC
    return 10


def _wrap(e: A.Expr, need: bool) -> str:
    s = _expr(e)
    return f"({s})" if need else s


def _expr(e: A.Expr | None) -> str:
    if isinstance(e, A.Literal):
        return e.text or repr(e.value)
    if isinstance(e, A.Name):
        return e.name.text()
    if isinstance(e, A.EnumLiteral):
        return f"{e.type_name.text()}#{e.value}"
    if isinstance(e, A.Member):
        return f"{_wrap(e.base, _prec(e.base) < 10)}.{e.member}"
    if isinstance(e, A.BitAccess):
        return f"{_wrap(e.base, _prec(e.base) < 10)}.{e.bit}"
    if isinstance(e, A.Index):
        return f"{_wrap(e.base, _prec(e.base) < 10)}[{', '.join(_expr(i) for i in e.indices)}]"
    if isinstance(e, A.Call):
        return f"{_wrap(e.callee, _prec(e.callee) < 10)}({', '.join(arg(a) for a in e.args)})"
    if isinstance(e, A.Unary):
        inner = _wrap(e.operand, _prec(e.operand) < 10 or (isinstance(e.operand, A.Literal)
                                                         and e.operand.text.startswith(("-", "+"))))
        return f"NOT {inner}" if e.op == "NOT" else f"{e.op}{inner}"
    if isinstance(e, A.Binary):
        p = PREC[e.op]
        if e.op == "**":
            left = _wrap(e.left, _prec(e.left) < 10)
            right = _wrap(e.right, _prec(e.right) < 10 and not isinstance(e.right, A.Unary))
        else:
            left = _wrap(e.left, _prec(e.left) < p)
            right = _wrap(e.right, _prec(e.right) <= p)
        return f"{left} {e.op} {right}"
    if isinstance(e, A.ArrayInit):
        items = []
        for it in e.items:
            if it.repeat is not None:
                items.append(f"{_expr(it.repeat)}({_expr(it.value) if it.value is not None else ''})")
            else:
                items.append(_expr(it.value))
        return "[" + ", ".join(items) + "]"
    if isinstance(e, A.StructInit):
        return "(" + ", ".join(f"{f.name} := {_expr(f.value)}" for f in e.fields) + ")"
    raise TypeError(f"cannot print {type(e).__name__}")


def arg(a: A.Arg) -> str:
    if a.name is None:
        return _expr(a.value)
    if a.output:
        target = _expr(a.value) if a.value is not None else ""
        return f"{'NOT ' if a.negated else ''}{a.name} => {target}".rstrip()
    return f"{a.name} := {_expr(a.value)}"


def type_ref(t: A.TypeRef, level: int = 0) -> str:
    if isinstance(t, A.NamedTypeRef):
        return t.name.text()
    if isinstance(t, A.StringTypeRef):
        base = "WSTRING" if t.wide else "STRING"
        return f"{base}[{_expr(t.length)}]" if t.length is not None else base
    if isinstance(t, A.ArrayTypeRef):
        dims = ", ".join("*" if d.lo is None else f"{_expr(d.lo)}..{_expr(d.hi)}" for d in t.dims)
        return f"ARRAY[{dims}] OF {type_ref(t.element, level)}"
    if isinstance(t, A.SubrangeTypeRef):
        return f"{type_ref(t.base)}({_expr(t.lo)}..{_expr(t.hi)})"
    if isinstance(t, A.EnumTypeRef):
        vals = ", ".join(v.name + (f" := {_expr(v.value)}" if v.value is not None else "") for v in t.values)
        return f"({vals})" + (f" {type_ref(t.base)}" if t.base is not None else "")
    if isinstance(t, A.StructTypeRef):
        pad = IND * (level + 1)
        word = "UNION" if t.union else "STRUCT"
        lines = [word] + [pad + IND + var_decl(f, level + 1) for f in t.fields] + [pad + "END_" + word]
        return "\n".join(lines)
    raise TypeError(f"cannot print {type(t).__name__}")


def var_decl(d: A.VarDecl, level: int = 0) -> str:
    at = f" AT {d.at}" if d.at else ""
    init = f" := {_expr(d.init)}" if d.init is not None else ""
    return f"{d.name}{at} : {type_ref(d.type, level)}{init};"


def section(s: A.VarSection, level: int) -> list[str]:
    pad = IND * level
    quals = "".join(q for q, on in ((" CONSTANT", s.constant), (" RETAIN", s.retain),
                                    (" PERSISTENT", s.persistent)) if on)
    return [f"{pad}{s.kind}{quals}"] + [pad + IND + var_decl(d, level) for d in s.vars] + [f"{pad}END_VAR"]


def statements(stmts: list[A.Stmt], level: int) -> list[str]:
    out: list[str] = []
    for s in stmts:
        out.extend(statement(s, level))
    return out


def statement(s: A.Stmt, level: int) -> list[str]:
    pad = IND * level
    if isinstance(s, A.Assign):
        return [f"{pad}{_expr(s.target)} := {_expr(s.value)};"]
    if isinstance(s, A.CallStmt):
        return [f"{pad}{_expr(s.call)};"]
    if isinstance(s, A.If):
        out = []
        for i, b in enumerate(s.branches):
            out.append(f"{pad}{'IF' if i == 0 else 'ELSIF'} {_expr(b.cond)} THEN")
            out += statements(b.body, level + 1)
        if s.else_body is not None:
            out.append(f"{pad}ELSE")
            out += statements(s.else_body, level + 1)
        return out + [f"{pad}END_IF;"]
    if isinstance(s, A.Case):
        out = [f"{pad}CASE {_expr(s.selector)} OF"]
        for cb in s.branches:
            labels = ", ".join(f"{_expr(lb.lo)}..{_expr(lb.hi)}" if isinstance(lb, A.CaseRange) else _expr(lb)
                               for lb in cb.labels)
            out.append(f"{pad}{IND}{labels}:")
            out += statements(cb.body, level + 2)
        if s.else_body is not None:
            out.append(f"{pad}ELSE")
            out += statements(s.else_body, level + 2)
        return out + [f"{pad}END_CASE;"]
    if isinstance(s, A.For):
        by = f" BY {_expr(s.step)}" if s.step is not None else ""
        return ([f"{pad}FOR {_expr(s.var)} := {_expr(s.start)} TO {_expr(s.end)}{by} DO"] +
                statements(s.body, level + 1) + [f"{pad}END_FOR;"])
    if isinstance(s, A.While):
        return [f"{pad}WHILE {_expr(s.cond)} DO"] + statements(s.body, level + 1) + [f"{pad}END_WHILE;"]
    if isinstance(s, A.Repeat):
        return ([f"{pad}REPEAT"] + statements(s.body, level + 1) + [f"{pad}UNTIL {_expr(s.cond)}",
                                                                     f"{pad}END_REPEAT;"])
    if isinstance(s, A.Exit):
        return [f"{pad}EXIT;"]
    if isinstance(s, A.Continue):
        return [f"{pad}CONTINUE;"]
    if isinstance(s, A.Return):
        return [f"{pad}RETURN;"]
    if isinstance(s, A.Empty):
        return [f"{pad};"]
    raise TypeError(f"cannot print {type(s).__name__}")


def item(it: A.Item) -> list[str]:
    if isinstance(it, A.TypeBlock):
        out = ["TYPE"]
        for d in it.decls:
            init = f" := {_expr(d.init)}" if d.init is not None else ""
            out.append(f"{IND}{d.name} : {type_ref(d.spec, 0)}{init};")
        return out + ["END_TYPE"]
    if isinstance(it, A.Pou):
        out = [f"{{{p}}}" for p in it.pragmas]
        ret = f" : {type_ref(it.return_type)}" if it.return_type is not None else ""
        out.append(f"{it.kind} {it.name}{ret}")
        for s in it.sections:
            out += section(s, 0)
        out += statements(it.body, 1)
        return out + ["END_" + it.kind]
    if isinstance(it, A.GlobalVarList):
        out = []
        for s in it.sections:
            out += section(s, 0)
        return out
    if isinstance(it, A.Configuration):
        out = [f"CONFIGURATION {it.name}"]
        for s in it.sections:
            out += section(s, 1)
        for r in it.resources:
            level = 1
            if r.name is not None:
                out.append(f"{IND}RESOURCE {r.name}" + (f" ON {r.on}" if r.on else ""))
                level = 2
            pad = IND * level
            for s in r.sections:
                out += section(s, level)
            for t in r.tasks:
                props = ", ".join(f"{p.name} := {_expr(p.value)}" for p in t.props)
                out.append(f"{pad}TASK {t.name}({props});")
            for p in r.programs:
                args = f"({', '.join(arg(a) for a in p.args)})" if p.args else ""
                task = f" WITH {p.task}" if p.task else ""
                out.append(f"{pad}PROGRAM {p.name}{task} : {p.program.text()}{args};")
            if r.name is not None:
                out.append(f"{IND}END_RESOURCE")
        return out + ["END_CONFIGURATION"]
    raise TypeError(f"cannot print {type(it).__name__}")


def print_unit(unit: A.CompilationUnit) -> str:
    """The whole file as ST text; items of NAMESPACE blocks inside their blocks again."""
    blocks: list[str] = []
    open_: list[str] = []
    for it in unit.items:
        path = getattr(it, "declared_namespace", None)
        want = path.split("\\") if path else []
        keep = 0
        while keep < min(len(open_), len(want)) and open_[keep] == want[keep]:
            keep += 1
        blocks.extend("END_NAMESPACE" for _ in open_[keep:])
        blocks.extend(f"NAMESPACE {name}" for name in want[keep:])
        open_ = want
        blocks.append("\n".join(item(it)))
    blocks.extend("END_NAMESPACE" for _ in open_)
    return "\n\n".join(blocks) + "\n"
