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
