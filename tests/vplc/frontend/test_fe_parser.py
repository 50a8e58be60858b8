"""Parser: AST shapes for the grammar corners, precedence, recovery and depth limits."""
from __future__ import annotations

from fe_helpers import parse_text, program

from vplc.frontend import ast as A


def body_of(text: str, decls: str = "x : INT;"):
    unit, diags = parse_text(program(text, decls))
    assert [d.render() for d in diags if d.is_error] == []
    return unit.items[0].body


def expr_of(text: str):
    return body_of(f"x := {text};")[0].value


def test_precedence_follows_iec_table():
    e = expr_of("a OR b AND c = d + e * f ** 2")
    assert isinstance(e, A.Binary) and e.op == "OR"
    and_ = e.right
    assert and_.op == "AND" and and_.right.op == "="
    add = and_.right.right
    assert add.op == "+" and add.right.op == "*" and add.right.right.op == "**"


def test_binary_operators_are_left_associative_and_ampersand_is_and():
    e = expr_of("a - b - c")
    assert e.op == "-" and isinstance(e.left, A.Binary) and e.left.op == "-"
    assert expr_of("a & b").op == "AND"
    p = expr_of("2 ** 3 ** 2")
    assert p.op == "**" and isinstance(p.left, A.Binary)


def test_unary_minus_and_not_bind_tighter_than_multiplication_but_looser_than_power():
    e = expr_of("-a * b")
    assert e.op == "*" and isinstance(e.left, A.Unary)
    e = expr_of("-a ** 2")
    assert isinstance(e, A.Unary) and e.operand.op == "**"
    e = expr_of("NOT a AND b")
    assert e.op == "AND" and isinstance(e.left, A.Unary)
    e = expr_of("a < b = c < d")
    assert e.op == "=" and e.left.op == "<" and e.right.op == "<"


def test_literals_decode_to_values():
    vals = {
        "16#FF": 255, "8#17": 15, "2#1010": 10, "1_000": 1000, "T#1h2m3s4ms": 3_723_004_000_000,
        "TIME#-5s": -5_000_000_000, "T#1.5s": 1_500_000_000, "REAL#1.5": 1.5, "INT#-5": -5, "BYTE#16#41": 0x41,
        "D#1970-01-02": 86400, "TOD#00:00:01.5": 1_500_000_000, "DT#1970-01-01-00:01:00": 60_000_000_000,
        "TRUE": True, "BOOL#0": False, "1.5E3": 1500.0,
    }
    for text, value in vals.items():
        lit = expr_of(text)
        assert isinstance(lit, A.Literal) and lit.value == value, text


def test_enum_literals_plain_and_namespaced():
    e = expr_of("eColor#Red")
    assert isinstance(e, A.EnumLiteral) and e.type_name.name == "eColor" and e.value == "Red"
    e = expr_of("CBT_Commands_Lib\\eCBT_MovCmd_Movement#PTP")
    assert e.type_name.namespace == ("CBT_Commands_Lib",) and e.value == "PTP"
    e = expr_of("\\\\OmronLib\\\\Ns\\\\eX#A")
    assert e.type_name.namespace == ("OmronLib", "Ns")


def test_calls_with_formal_output_negated_and_nonformal_arguments():
    stmt = body_of("fb(Execute := TRUE, Done => d, NOT Error => e, Q =>); f(1, 2);", "")[0]
    args = stmt.call.args
    assert [(a.name, a.output, a.negated) for a in args] == [
        ("Execute", False, False), ("Done", True, False), ("Error", True, True), ("Q", True, False)]
    assert args[3].value is None


def test_calls_on_array_elements_and_struct_members():
    s1, s2 = body_of("arr[1, 2](Execute := TRUE); cell.robots[i].mover();", "")
    assert isinstance(s1.call.callee, A.Index) and len(s1.call.callee.indices) == 2
    assert isinstance(s2.call.callee, A.Member) and isinstance(s2.call.callee.base, A.Index)


def test_case_with_ranges_lists_enums_and_else():
    stmt = body_of("CASE x OF 1..5, 7: x := 1; y := 2; eColor#Red: ; -3: ; ELSE x := 0; END_CASE;")[0]
    assert isinstance(stmt, A.Case) and len(stmt.branches) == 3
    assert isinstance(stmt.branches[0].labels[0], A.CaseRange) and len(stmt.branches[0].body) == 2
    assert stmt.else_body is not None


def test_for_while_repeat_exit_continue_return_and_empty_statement():
    stmts = body_of("FOR i := 10 TO 0 BY -1 DO EXIT; END_FOR; WHILE a DO CONTINUE; END_WHILE; "
                    "REPEAT ; UNTIL b END_REPEAT; RETURN;")
    assert [type(s).__name__ for s in stmts] == ["For", "While", "Repeat", "Return"]
    assert isinstance(stmts[0].step, A.Unary)
    assert isinstance(stmts[2].body[0], A.Empty)


def test_declarations_types_and_initializers():
    unit, diags = parse_text("""
        TYPE
            stPoint : STRUCT X, Y : REAL := 1.0; Inner : STRUCT A : INT; END_STRUCT; END_STRUCT;
            eColor : (Red, Green := 5, Blue) INT;
            Pct : INT(0..100);
            Alias : DINT;
            Grid : ARRAY[-1..1, 0..2] OF stPoint;
        END_TYPE
        VAR_GLOBAL CONSTANT Max : INT := 10; END_VAR
        VAR_GLOBAL RETAIN Buf : ARRAY[0..Max] OF BYTE := [3(16#FF), 0, 2()]; s : WSTRING[20]; END_VAR
        """)
    assert not [d for d in diags if d.is_error]
    tb, gl = unit.items
    assert [d.name for d in tb.decls] == ["stPoint", "eColor", "Pct", "Alias", "Grid"]
    assert isinstance(tb.decls[0].spec, A.StructTypeRef) and len(tb.decls[0].spec.fields) == 3
    assert isinstance(tb.decls[2].spec, A.SubrangeTypeRef)
    assert isinstance(gl, A.GlobalVarList) and gl.sections[0].constant and gl.sections[1].retain
    init = gl.sections[1].vars[0].init
    assert isinstance(init, A.ArrayInit) and init.items[0].repeat.value == 3 and init.items[2].value is None


def test_configuration_resource_tasks_and_program_instances():
    unit, diags = parse_text("""
        CONFIGURATION Cfg
            VAR_GLOBAL g : INT; END_VAR
            RESOURCE Res ON PLC
                TASK Fast(INTERVAL := T#1ms, PRIORITY := 1);
                PROGRAM P1 WITH Fast : Main;
            END_RESOURCE
        END_CONFIGURATION
        """)
    cfg = unit.items[0]
    assert not diags and cfg.resources[0].tasks[0].props[0].name == "INTERVAL"
    assert cfg.resources[0].programs[0].task == "Fast"


def test_native_pragma_marks_the_following_pou_and_other_pragmas_give_a_note():
    unit, diags = parse_text("{native}\nFUNCTION F : INT\nEND_FUNCTION\n{attribute 'hide'}\nPROGRAM P\nEND_PROGRAM\n")
    assert unit.items[0].native and not unit.items[1].native
    assert [d.code for d in diags] == ["ST0107"]


def test_recovery_reports_several_independent_errors_in_one_run():
    unit, diags = parse_text(program("x := ;\ny := 1 +;\nz := 3;\nIF a THEN b := 1; END_FOR;", "x, y, z : INT;"))
    errs = [d for d in diags if d.is_error]
    assert len(errs) >= 3
    assert any("END_IF" in d.message for d in errs)
    assert unit.items[0].name == "Main"


def test_missing_end_program_and_stray_tokens_are_reported():
    _, diags = parse_text("PROGRAM P\nx := 1;\n")
    assert any(d.code == "ST0202" and "END_PROGRAM" in d.message for d in diags)
    _, diags = parse_text("garbage here\nPROGRAM P\nEND_PROGRAM\n")
    assert [d.code for d in diags] == ["ST0206"]


def test_missing_semicolon_is_named():
    _, diags = parse_text(program("x := 1\ny := 2;", "x, y : INT;"))
    assert [d.code for d in diags] == ["ST0205"]


def test_deep_nesting_gives_a_diagnostic_not_a_crash():
    text = program("x := " + "(" * 10000 + "1" + ")" * 10000 + ";", "x : INT;")
    _, diags = parse_text(text)
    assert [d.code for d in diags] == ["ST0203"]
    text = program("IF a THEN " * 5000 + "x := 1;" + " END_IF;" * 5000, "x : INT;")
    _, diags = parse_text(text)
    assert diags and diags[0].code == "ST0203"


def test_object_oriented_and_pointer_extensions_are_refused_clearly():
    _, diags = parse_text("FUNCTION_BLOCK A EXTENDS B\nEND_FUNCTION_BLOCK\n")
    assert diags[0].code == "ST0207"
    _, diags = parse_text(program("", "p : POINTER TO INT;"))
    assert diags[0].code == "ST0207"


def test_kept_tokens_give_the_tree_parse_gives_and_follow_a_changed_text(tmp_path):
    """parse_kept (the prelude: tokenized once per process, its tokens used again by every load) gives the tree and
    comments parse gives, each time; the same path with another text is tokenized again, and a text with a lexical
    problem reports it as parse does."""
    import os

    from vplc.frontend.diagnostics import DiagnosticBag
    from vplc.frontend.parser import parse, parse_kept
    from vplc.frontend.source import SourceFile
    from vplc.project import PRELUDE_DIR
    for name in sorted(n for n in os.listdir(PRELUDE_DIR) if n.endswith(".st")):
        path = os.path.join(PRELUDE_DIR, name)
        with open(path, encoding="utf-8") as fh:
            src = SourceFile(path, fh.read())
        fresh, first, again = (parse(src, DiagnosticBag()), parse_kept(src, DiagnosticBag()),
                               parse_kept(src, DiagnosticBag()))
        assert fresh == first == again and fresh.comments == again.comments and again.comments is not first.comments
    path = str(tmp_path / "kept.st")
    one = parse_kept(SourceFile(path, "FUNCTION F : INT\nF := 1;\nEND_FUNCTION\n"), DiagnosticBag())
    two = parse_kept(SourceFile(path, "FUNCTION G : INT\nG := 2; (* two *)\nEND_FUNCTION\n"), DiagnosticBag())
    assert (one.items[0].name, two.items[0].name, len(two.comments)) == ("F", "G", 1)
    bad = SourceFile(path, "FUNCTION H : INT\nH := 3 ` ;\nEND_FUNCTION\n")
    kept, plain = DiagnosticBag(), DiagnosticBag()
    parse_kept(bad, kept)
    parse(bad, plain)
    assert [d.render() for d in kept.items] == [d.render() for d in plain.items] != []
