"""Sysmac's ST where it differs from plain IEC 61131-3 (docs/toolchain/dialects.md), run on the virtual PLC with
the values the manuals document."""
from rt_helpers import plc_from, run1


def test_comparison_functions_give_the_operators_results(tmp_path):
    plc = run1(tmp_path, """a := LT(i, 5); b := LE(i, 3); c := GT(i, 3); d := GE(5, i, 3);
        e := EQ(s, 'ab'); f := NE(r, 1.5); g := LT(1, i, 2);""",
               "i : INT := 3; s : STRING[8] := 'ab'; r : REAL := 1.5; a, b, c, d, e, f, g : BOOL;")
    assert [plc.read(f"Main.{v}") for v in "abcdefg"] == [True, True, False, True, True, False, False]


def test_bool_compared_with_0_and_1_is_compared_with_false_and_true(tmp_path):
    plc = run1(tmp_path, "a := On = 1; b := On <> 0; c := Off = 1; d := 0 = Off;",
               "On : BOOL := TRUE; Off : BOOL; a, b, c, d : BOOL;")
    assert [plc.read(f"Main.{v}") for v in "abcd"] == [True, True, False, True]


def test_fb_called_positionally_with_outputs_fills_them_in_declaration_order(tmp_path):
    """W502 2-116: TON_instance(In, PT, Q, ET);"""
    plc = plc_from(tmp_path, "Timer1(Go, T#100ms, Up, Elapsed);",
                   "Timer1 : TON; Go : BOOL := TRUE; Up : BOOL; Elapsed : TIME;")
    plc.scan(0)
    plc.scan(60_000_000)
    assert plc.read("Main.Up") is False and plc.read("Main.Elapsed") == 60_000_000
    plc.scan(100_000_000)
    assert plc.read("Main.Up") is True and plc.read("Main.Elapsed") == 100_000_000


def test_ctd_load_sets_cv_and_counting_stops_at_zero(tmp_path):
    """W502 2-134: CTD_instance(CD, Load, PV, Q, CV); Load TRUE sets CV to PV and CD is ignored; after CV reaches 0
    or less it does not change when CD changes to TRUE; Q is TRUE when CV is 0 or less."""
    plc = plc_from(tmp_path, "Down(Pulse, Ld, 2, Q, CV);",
                   "Down : CTD; Pulse, Ld, Q : BOOL; CV : INT;")
    plc.write("Main.Ld", True)
    plc.scan(0)
    assert plc.read("Main.CV") == 2 and plc.read("Main.Q") is False
    plc.write("Main.Ld", False)
    values = []
    for n in range(1, 9):
        plc.write("Main.Pulse", n % 2 == 1)
        plc.scan(n * 1_000_000)
        values.append(plc.read("Main.CV"))
    assert values == [1, 1, 0, 0, 0, 0, 0, 0] and plc.read("Main.Q") is True


def test_ctd_accepts_the_iec_name_ld_for_load(tmp_path):
    plc = run1(tmp_path, "Down(CD := FALSE, LD := TRUE, PV := 7);", "Down : CTD;")
    assert plc.read("Main.Down.CV") == 7


NAMESPACED = """NAMESPACE nsAxisControl
TYPE
    eCurveType : (Linear, SCurve);
END_TYPE
NAMESPACE Profiles
FUNCTION_BLOCK Ramp
VAR_INPUT Curve : eCurveType; END_VAR
VAR_OUTPUT IsS : BOOL; END_VAR
    IsS := Curve = SCurve;
END_FUNCTION_BLOCK
END_NAMESPACE
END_NAMESPACE
"""


def test_namespaces_of_any_name_nest_and_resolve_as_sysmac_does(tmp_path):
    """nsAxisControl\\eCurveType; a name is looked up in its own namespace, then in the enclosing ones."""
    plc = run1(tmp_path, "r(Curve := c, IsS => q);",
               "c : nsAxisControl\\eCurveType := nsAxisControl\\eCurveType#SCurve; r : nsAxisControl\\Profiles\\Ramp; "
               "q : BOOL;", NAMESPACED)
    assert plc.read("Main.q") is True


def test_a_name_of_a_namespace_is_not_visible_unqualified_when_two_namespaces_have_it(tmp_path):
    from vplc.project import load_project
    (tmp_path / "t.st").write_text(NAMESPACED + NAMESPACED.replace("nsAxisControl", "nsOther")
                                   + "PROGRAM Main\nVAR r : Ramp; END_VAR\nr();\nEND_PROGRAM\n")
    assert [d.code for d in load_project([str(tmp_path / "t.st")]).diagnostics if d.severity == "error"] == ["ST1003"]


def test_constant_inputs_and_in_outs_need_no_initial_value_and_stay_read_only(tmp_path):
    """W501: CONSTANT on an input or in-out means the POU only reads it; the caller gives the value."""
    fb = """FUNCTION_BLOCK Over
VAR_INPUT CONSTANT Limit : INT; END_VAR
VAR_IN_OUT CONSTANT Buf : ARRAY[0..3] OF BYTE; END_VAR
VAR_OUTPUT Q : BOOL; END_VAR
    Q := BYTE_TO_INT(Buf[0]) > Limit;
END_FUNCTION_BLOCK
"""
    plc = run1(tmp_path, "f(Limit := 3, Buf := b);", "f : Over; b : ARRAY[0..3] OF BYTE := [5, 0, 0, 0];", fb)
    assert plc.read("Main.f.Q") is True
    from vplc.project import load_project
    (tmp_path / "w.st").write_text(fb.replace("    Q := ", "    Limit := 1;\n    Q := "))
    assert [d.code for d in load_project([str(tmp_path / "w.st")]).diagnostics if d.severity == "error"] == ["ST1301"]


UNIONS = """TYPE
    uWord : UNION
        W : WORD;
        Bits : ARRAY[0..15] OF BOOL;
        Bytes : ARRAY[0..1] OF BYTE;
        I : INT;
    END_UNION;
    uReal : UNION
        R : REAL;
        D : DWORD;
    END_UNION;
END_TYPE
"""


def test_union_members_share_one_memory_image(tmp_path):
    """W501 6-3-6 / W506 A-5-1: the members of a union overlap in the same memory locations."""
    plc = run1(tmp_path, """u.W := 16#8001; a := u.Bits[0]; b := u.Bits[15]; n := u.I;
        u.Bits[1] := TRUE; v := u; lo := v.Bytes[0]; hi := v.Bytes[1];
        r.R := 1.0; d := r.D; r.D := 16#40490FDB; x := r.R;""",
               "u, v : uWord; r : uReal; a, b : BOOL; n : INT; lo, hi : BYTE; d : DWORD; x : REAL;", UNIONS)
    assert plc.read("Main.a") is True and plc.read("Main.b") is True and plc.read("Main.n") == -32767
    assert (plc.read("Main.lo"), plc.read("Main.hi")) == (0x03, 0x80)
    assert plc.read("Main.d") == 0x3F800000 and abs(plc.read("Main.x") - 3.14159265) < 1e-6


def test_a_union_written_by_name_updates_every_member(tmp_path):
    plc = plc_from(tmp_path, "w := u.W;", "u : uWord; w : WORD;", UNIONS)
    plc.write("Main.u.Bits[2]", True)
    plc.scan(0)
    assert plc.read("Main.w") == 4 and plc.read("Main.u.I") == 4


def test_union_members_without_a_memory_image_or_with_initial_values_are_st1109(tmp_path):
    from vplc.project import load_project
    (tmp_path / "u.st").write_text("TYPE uText : UNION\n    S : STRING[8];\n    W : WORD := 1;\nEND_UNION;\nEND_TYPE\n")
    assert [d.code for d in load_project([str(tmp_path / "u.st")]).diagnostics] == ["ST1109", "ST1109"]


def test_a_union_member_passed_as_in_out_is_written_into_the_image(tmp_path):
    fb = "FUNCTION_BLOCK Bump\nVAR_IN_OUT X : WORD; END_VAR\nX := X OR 16#1000;\nEND_FUNCTION_BLOCK\n"
    plc = run1(tmp_path, "u.W := 16#0102; b(X := u.W); hi := u.Bytes[1];", "u : uWord; b : Bump; hi : BYTE;",
               UNIONS + fb)
    assert plc.read("Main.u.W") == 0x1102 and plc.read("Main.hi") == 0x11
