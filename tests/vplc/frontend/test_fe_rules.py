"""Every check rule: a failing snippet reports the code, the fixed snippet does not."""
from __future__ import annotations

import pytest
from fe_helpers import check_text, codes, program
from rule_cases import CASES, FB


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
