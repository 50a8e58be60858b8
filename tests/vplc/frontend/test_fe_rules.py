"""Every check rule: a failing snippet reports the code, the fixed snippet does not."""
from __future__ import annotations

import pytest

from fe_helpers import check_text, codes, program

FB = """
FUNCTION_BLOCK Mover
VAR_IN_OUT CBT : INT; END_VAR
VAR_INPUT Execute : BOOL; Speed : INT; END_VAR
VAR_OUTPUT Done : BOOL; END_VAR
Done := Execute AND CBT > Speed;
END_FUNCTION_BLOCK
"""

# (code, failing source, fixed source)
CASES = [
    ("ST1001", program("Cuont := 1;", "Count : INT;"), program("Count := 1;", "Count : INT;")),
    ("ST1002", program("Speed := 1;", "Speed : INT; Speed : REAL;"), program("Speed := 1;", "Speed : INT;")),
    ("ST1004", program("", "p : stUnknown;"), program("p := 1;", "p : INT;")),
    ("ST1005", "TYPE stP : STRUCT X : REAL; END_STRUCT; END_TYPE\n" + program("p.Z := 1.0;", "p : stP;"),
     "TYPE stP : STRUCT X : REAL; END_STRUCT; END_TYPE\n" + program("p.X := 1.0;", "p : stP;")),
    ("ST1101", program("i := r;", "i : INT; r : REAL;"), program("i := REAL_TO_INT(r);", "i : INT; r : REAL;")),
    ("ST1101", program("s := d;", "s : INT; d : DINT;"), program("d := s;", "s : INT; d : DINT;")),
    ("ST1102", program("b := s + 1;", "b : INT; s : STRING;"), program("b := LEN(s) + 1;", "b : DINT; s : STRING;")),
    ("ST1103", program("r := SQRT('x');", "r : LREAL;"), program("r := SQRT(2.0);", "r : LREAL;")),
    ("ST1105", program("IF i THEN i := 0; END_IF;", "i : INT;"), program("IF i > 0 THEN i := 0; END_IF;", "i : INT;")),
    ("ST1106", program("i := i[0];", "i : INT;"), program("i := a[0];", "i : INT; a : ARRAY[0..1] OF INT;")),
    ("ST1107", program("s := 300;", "s : SINT;"), program("s := 100;", "s : SINT;")),
    ("ST1107", program("r := 1.0E39;", "r : REAL;"), program("r := 3.4028235E38;", "r : REAL;")),
    ("ST1107", program("l := 1.0E309;", "l : LREAL;"), program("l := 1.0E308;", "l : LREAL;")),
    ("ST1107", program("r := REAL#-4.0E38;", "r : REAL;"), program("r := REAL#-3.0E38;", "r : REAL;")),
    ("ST1004", "TYPE A : STRUCT b : ARRAY[1..2] OF B; END_STRUCT; B : STRUCT a : A; END_STRUCT; END_TYPE\n"
     + program("x.b[1] := x.b[2];", "x : A;"),
     "TYPE A : STRUCT b : ARRAY[1..2] OF B; END_STRUCT; B : STRUCT n : INT; END_STRUCT; END_TYPE\n"
     + program("x.b[1].n := 1;", "x : A;")),
    ("ST1201", FB + program("m(CBT := c, Exec := TRUE);", "m : Mover; c : INT;"),
     FB + program("m(CBT := c, Execute := TRUE);", "m : Mover; c : INT;")),
    ("ST1202", FB + program("m(Execute := TRUE);", "m : Mover;"),
     FB + program("m(CBT := c, Execute := TRUE);", "m : Mover; c : INT;")),
    ("ST1203", FB + program("m(CBT := c, Done := d);", "m : Mover; c : INT; d : BOOL;"),
     FB + program("m(CBT := c, Done => d);", "m : Mover; c : INT; d : BOOL;")),
    ("ST1203", FB + program("m(CBT := c, Execute => d);", "m : Mover; c : INT; d : BOOL;"),
     FB + program("m(CBT := c, Execute := d);", "m : Mover; c : INT; d : BOOL;")),
    ("ST1204", program("i := ABS(1, 2);", "i : DINT;"), program("i := ABS(-2);", "i : DINT;")),
    ("ST1205", FB + program("m(CBT := 5);", "m : Mover;"), FB + program("m(CBT := c);", "m : Mover; c : INT;")),
    ("ST1206", program("i := LIMIT(MN := 0, i, 5);", "i : INT;"), program("i := LIMIT(0, i, 5);", "i : INT;")),
    ("ST1207", FB + program("m(CBT := c, Speed := 1, Speed := 2);", "m : Mover; c : INT;"),
     FB + program("m(CBT := c, Speed := 1);", "m : Mover; c : INT;")),
    ("ST1208", program("EXIT;", ""), program("WHILE TRUE DO EXIT; END_WHILE;", "")),
    ("ST1006", program("TON_X(IN := TRUE);", "") + "FUNCTION_BLOCK TON_X VAR_INPUT IN : BOOL; END_VAR END_FUNCTION_BLOCK\n",
     program("t(IN := TRUE);", "t : TON_X;") + "FUNCTION_BLOCK TON_X VAR_INPUT IN : BOOL; END_VAR END_FUNCTION_BLOCK\n"),
    ("ST1301", program("Max := 5;", "END_VAR VAR CONSTANT Max : INT := 10;"),
     program("i := Max;", "i : INT; END_VAR VAR CONSTANT Max : INT := 10;")),
    ("ST1302", FB + program("m.Done := FALSE;", "m : Mover;"), FB + program("d := m.Done;", "m : Mover; d : BOOL;")),
    ("ST1303", FB + program("m(CBT := c); m.Execute := TRUE;", "m : Mover; c : INT;"),
     FB + program("m.Execute := TRUE; m(CBT := c);", "m : Mover; c : INT;")),
    ("ST1304", program("FOR i := 0 TO 9 DO i := i + 1; END_FOR;", "i : INT;"),
     program("FOR i := 0 TO 9 DO j := i + 1; END_FOR;", "i, j : INT;")),
    ("ST1401", program("CASE i OF 'a': i := 1; END_CASE;", "i : INT;"), program("CASE i OF 1: i := 1; END_CASE;", "i : INT;")),
    ("ST1402", program("CASE i OF 1..5: i := 1; 3: i := 2; END_CASE;", "i : INT;"),
     program("CASE i OF 1..5: i := 1; 6: i := 2; END_CASE;", "i : INT;")),
    ("ST1501", program("a[10] := 1;", "a : ARRAY[0..9] OF INT;"), program("a[9] := 1;", "a : ARRAY[0..9] OF INT;")),
    ("ST1601", program("s := 'Hello!';", "s : STRING[6];"), program("s := 'Hello';", "s : STRING[6];")),
    ("ST1701", "FUNCTION Fact : DINT VAR_INPUT n : DINT; END_VAR Fact := n * Fact(n - 1); END_FUNCTION\n",
     "FUNCTION Fact : DINT VAR_INPUT n : DINT; END_VAR VAR i : DINT; END_VAR Fact := 1; "
     "FOR i := 2 TO n DO Fact := Fact * i; END_FOR; END_FUNCTION\n"),
    ("ST1801", "FUNCTION Clamp : INT VAR_INPUT x : INT; END_VAR IF x > 100 THEN Clamp := 100; END_IF; END_FUNCTION\n",
     "FUNCTION Clamp : INT VAR_INPUT x : INT; END_VAR IF x > 100 THEN Clamp := 100; ELSE Clamp := x; END_IF; "
     "END_FUNCTION\n"),
    ("ST1901", program("Count := 1;", "Count, Spare : INT;"), program("Count := 1;", "Count : INT;")),
]


@pytest.mark.parametrize("code,failing,fixed", CASES, ids=[c[0] + f"-{i}" for i, c in enumerate(CASES)])
def test_rule_fails_then_passes_when_fixed(tmp_path, code, failing, fixed):
    bad = check_text(tmp_path, failing, "bad.st")
    assert code in codes(bad), bad.render_diagnostics()
    good = check_text(tmp_path, fixed, "good.st")
    assert code not in codes(good), good.render_diagnostics()
    assert not good.has_errors, good.render_diagnostics()


def test_messages_name_the_thing_and_the_fix(tmp_path):
    proj = check_text(tmp_path, FB + program("m(CBT := c, Done := d);", "m : Mover; c : INT; d : BOOL;"))
    msg = [d.message for d in proj.diagnostics if d.code == "ST1203"][0]
    assert msg == "`Done` is an output of Mover; use `=>` to read it"


def test_recursion_through_two_functions_and_fb_containing_itself(tmp_path):
    proj = check_text(tmp_path, """
        FUNCTION A : INT  A := B(); END_FUNCTION
        FUNCTION B : INT  B := A(); END_FUNCTION
        FUNCTION_BLOCK Self VAR inner : Self; END_VAR END_FUNCTION_BLOCK
        """)
    assert codes(proj).count("ST1701") == 2


def test_portable_mode_warns_on_vendor_constructs_except_under_platform(tmp_path):
    src = program("n := ToAryByte(In := s, Order := _eBYTE_ORDER#_LOW_HIGH, AryOut := buf[0]);",
                  "n : UINT; s : STRING[10]; buf : ARRAY[0..9] OF BYTE;")
    plain = check_text(tmp_path, src, "a.st")
    assert not plain.has_errors and "ST2001" not in codes(plain)
    port = check_text(tmp_path, src, "b.st", portable=True)
    assert "ST2001" in codes(port, "warning")
    (tmp_path / "platform").mkdir()
    exempt = check_text(tmp_path, src, "platform/c.st", portable=True)
    assert "ST2001" not in codes(exempt)


def test_portable_mode_warns_on_namespace_qualifiers_and_continue(tmp_path):
    lib = tmp_path / "My_Lib"
    lib.mkdir()
    (lib / "t.st").write_text("TYPE eX : (A, B); END_TYPE\n")
    user = tmp_path / "u.st"
    user.write_text(program("x := My_Lib\\eX#A; WHILE FALSE DO CONTINUE; END_WHILE;", "x : My_Lib\\eX;"))
    from vplc.project import load_project
    proj = load_project([str(lib), str(user)], portable=True)
    assert not proj.has_errors, proj.render_diagnostics()
    assert {"ST2002", "ST2003"} <= set(codes(proj))


def test_portable_mode_warns_on_vendor_types_in_declarations(tmp_path):
    proj = check_text(tmp_path, program("s.Handle := 0; c(Execute := FALSE);", "s : _sSOCKET; c : SktClose;"),
                      portable=True)
    assert codes(proj).count("ST2001") == 2


def test_portable_mode_warns_on_third_edition_syntax(tmp_path):
    src = ("// line comment\n/* block */\nFUNCTION_BLOCK F\nVAR_IN_OUT a : ARRAY[*] OF BYTE; END_VAR\n"
           "VAR x : LTIME; n : DINT; END_VAR\nx := x; n := TO_DINT(UPPER_BOUND(a, 1));\nEND_FUNCTION_BLOCK\n")
    proj = check_text(tmp_path, src, portable=True)
    msgs = [d.message for d in proj.diagnostics if d.code == "ST2003"]
    assert len(msgs) == 6, msgs
    plain = check_text(tmp_path, src, "plain.st")
    assert not plain.diagnostics, plain.render_diagnostics()


def test_fb_input_written_in_a_sibling_branch_is_not_after_the_call(tmp_path):
    for body in ("CASE s OF 0: m(CBT := c); 1: m.Execute := TRUE; END_CASE;",
                 "IF s = 2 THEN m(CBT := c); ELSE m.Speed := 1; END_IF;"):
        proj = check_text(tmp_path, FB + program(body, "m : Mover; c : INT; s : INT;"))
        assert "ST1303" not in codes(proj), proj.render_diagnostics()
    proj = check_text(tmp_path, FB + program("IF s = 2 THEN m(CBT := c); END_IF; m.Speed := 1;",
                                             "m : Mover; c : INT; s : INT;"), "after.st")
    assert "ST1303" in codes(proj)


def test_array_element_passed_to_fixed_array_parameter_needs_enough_elements(tmp_path):
    fn = ("FUNCTION Sum : DINT VAR_INPUT Data : ARRAY[0..3] OF INT; END_VAR Sum := Data[0]; END_FUNCTION\n")
    bad = check_text(tmp_path, fn + program("d := Sum(Data := buf[8]);", "d : DINT; buf : ARRAY[0..9] OF INT;"))
    assert "ST1501" in codes(bad)
    good = check_text(tmp_path, fn + program("d := Sum(Data := buf[6]);", "d : DINT; buf : ARRAY[0..9] OF INT;"),
                      "good.st")
    assert not good.has_errors, good.render_diagnostics()


def test_time_literal_beyond_64_bit_nanoseconds_is_refused(tmp_path):
    assert "ST0106" in codes(check_text(tmp_path, program("t := T#200000d;", "t : TIME;")))
    assert "ST0106" not in codes(check_text(tmp_path, program("t := T#100000d;", "t : TIME;")))
