"""Omron Sysmac implicit casts (W501 6-5-3, pages 6-106 and 6-107) in the checker and the runtime."""
from rt_helpers import run1

from vplc.project import load_project


def test_len_result_passes_to_int_to_string_as_w501_6_107_allows(tmp_path):
    plc = run1(tmp_path, "S := INT_TO_STRING(LEN(Txt));", "S : STRING[10]; Txt : STRING[10] := 'abcd';")
    assert plc.read("Main.S") == "4"


def test_uint_times_a_large_literal_is_a_dint_expression_w501_6_106(tmp_path):
    plc = run1(tmp_path, "T1 := NanoSecToTime(Sec * 100000000); D := Sec * 100000000;",
               "Sec : UINT := 2; T1 : TIME; D : DINT;")
    assert plc.read("Main.T1") == 200_000_000 and plc.read("Main.D") == 200_000_000


def test_int_to_uint_assignment_keeps_the_bits_w501_6_107(tmp_path):
    plc = run1(tmp_path, "U := I; L := S;", "I : INT := -1; U : UINT; S : SINT := 5; L : ULINT;")
    assert plc.read("Main.U") == 0xFFFF and plc.read("Main.L") == 5   # the SINT -> USINT -> ... -> ULINT chain


def test_unsigned_wins_at_equal_rank_w501_6_106(tmp_path):
    """INT + UINT is a UINT expression on Sysmac: -1 + 3 computes as 16#FFFF + 3 = 2 (wrapped)."""
    plc = run1(tmp_path, "R := I + U; B := I < U;", "I : INT := -1; U : UINT := 3; R : UDINT; B : BOOL;")
    assert plc.read("Main.R") == 2 and plc.read("Main.B") is False


def test_dint_with_real_is_a_warning_naming_the_sysmac_rank_rule(tmp_path):
    path = tmp_path / "m.st"
    path.write_text("PROGRAM Main\nVAR D : DINT := 3; R : REAL := 0.5; X : LREAL; END_VAR\nX := D * R;\nEND_PROGRAM\n")
    proj = load_project([str(path)])
    warns = [d for d in proj.diagnostics if d.code == "ST1108"]
    assert not proj.has_errors and len(warns) == 1 and "W501" in warns[0].message


def test_narrowing_stays_a_build_error_as_on_the_controller(tmp_path):
    path = tmp_path / "m.st"
    path.write_text("PROGRAM Main\nVAR D : DINT; I : INT; END_VAR\nI := D;\nEND_PROGRAM\n")
    assert load_project([str(path)]).has_errors


def _warnings(tmp_path, decls, body):
    path = tmp_path / "m.st"
    path.write_text(f"PROGRAM Main\nVAR {decls} END_VAR\n{body}\nEND_PROGRAM\n")
    proj = load_project([str(path)])
    return proj, [d.message for d in proj.diagnostics if d.code == "ST1108"]


def test_real_times_dint_into_a_dint_builds_as_on_sysmac_w501_6_106(tmp_path):
    """W501 6-106 rank table: DINT (rank 4) ranks above REAL (rank 3), so `d := r * d` is a DINT expression that
    Sysmac Studio builds. vplc accepts it with the ST1108 warning naming both types, and rounds the LREAL result."""
    proj, warns = _warnings(tmp_path, "R : REAL := 2.5; D : DINT := 3;", "D := R * D;")
    assert not proj.has_errors, proj.render_diagnostics()
    assert warns == ["Sysmac types this REAL * DINT expression as DINT (W501 6-106: DINT ranks above REAL) and "
                     "computes it in DINT; vplc computes it in LREAL (stored into an integer, the result is rounded "
                     "to nearest): convert explicitly so both agree"]
    plc = run1(tmp_path, "D := R * D;", "R : REAL := 2.5; D : DINT := 3;")
    assert plc.read("Main.D") == 8                                  # 7.5 rounded half to even


def test_lreal_times_lint_into_a_lint_builds_and_the_warning_names_lreal_w501_6_106(tmp_path):
    """W501 6-106: LINT (rank 6) ranks above LREAL (rank 5): the message names LREAL, not REAL."""
    proj, warns = _warnings(tmp_path, "LR : LREAL := 1.5; LI : LINT := 3;", "LI := LR * LI;")
    assert not proj.has_errors, proj.render_diagnostics()
    assert len(warns) == 1 and "LREAL * LINT expression as LINT (W501 6-106: LINT ranks above LREAL)" in warns[0]
    plc = run1(tmp_path, "LI := LR * LI;", "LR : LREAL := 1.5; LI : LINT := 3;")
    assert plc.read("Main.LI") == 4                                 # 4.5 rounded half to even


def test_sysmac_integer_type_carries_through_a_larger_expression_w501_6_106(tmp_path):
    """(R * D) is DINT on Sysmac, so (R * D) + D and -(R * D) are DINT too; one warning, at the REAL operand."""
    proj, warns = _warnings(tmp_path, "R : REAL := 0.5; D : DINT := 3; E : DINT;", "E := -(R * D) + D;")
    assert not proj.has_errors and len(warns) == 1, proj.render_diagnostics()
    plc = run1(tmp_path, "E := -(R * D) + D;", "R : REAL := 0.5; D : DINT := 3; E : DINT;")
    assert plc.read("Main.E") == 2                                  # -1.5 + 3 = 1.5 -> 2


def test_real_times_int_stays_real_and_narrowing_it_is_still_an_error_w501_6_107(tmp_path):
    """REAL (rank 3) ranks above INT (rank 2): the expression is REAL, and REAL -> DINT has no arrow in 6-107."""
    proj, warns = _warnings(tmp_path, "R : REAL; I : INT; D : DINT;", "D := R * I;")
    assert proj.has_errors and not warns
    assert "cannot use a value of type REAL where DINT is expected" in proj.render_diagnostics()
