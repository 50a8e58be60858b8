"""ST1007: a real Omron name vplc does not model is reported as such, never as an undeclared name."""
import pathlib
import re

from fe_helpers import check_text, codes, program

from vplc.frontend.sysmac_names import SYSMAC_NAMES
from vplc.project import PRELUDE_DIR


def test_unmodelled_instruction_type_and_function_are_st1007_with_the_manual(tmp_path):
    proj = check_text(tmp_path, program("x := CheckReal(1.0); Lock(Index := 1); Tune(); e := _PLC_ErrSta;",
                                        "Tune : PIDAT_HeatCool; x : BOOL; e : WORD;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert [d.code for d in errors] == ["ST1007"] * 4
    assert "Sysmac instruction `PIDAT_HeatCool` (W502, Control Instructions) is not modelled by vplc" \
        in errors[0].message


def test_a_misspelt_name_is_still_st1001(tmp_path):
    assert codes(check_text(tmp_path, program("Cuont := 1;", "Count : INT;")), "error") == ["ST1001"]


def test_a_users_own_pou_with_an_omron_name_is_used(tmp_path):
    proj = check_text(tmp_path, program("x := CheckReal(1.0);", "x : BOOL;")
                      + "FUNCTION CheckReal : BOOL\nVAR_INPUT In : REAL; END_VAR\nCheckReal := TRUE;\nEND_FUNCTION\n")
    assert codes(proj, "error") == []


def test_iec_dialect_reports_them_as_undeclared(tmp_path):
    proj = check_text(tmp_path, program("x := CheckReal(1.0);", "x : BOOL;"), dialect="iec")
    assert codes(proj, "error") == ["ST1001"]


def test_names_of_the_table_that_the_prelude_declares_are_used_not_reported():
    """The motion prelude declares MC_Power and _sAXIS_REF's axis table: the table is only consulted for names
    nothing declares."""
    declared = set()
    for f in pathlib.Path(PRELUDE_DIR).glob("*.st"):
        declared |= {m.upper() for m in re.findall(r"^\s*(?:FUNCTION_BLOCK|FUNCTION)\s+(\w+)", f.read_text(), re.M)}
    both = sorted(set(SYSMAC_NAMES) & declared)
    assert "MC_POWER" in both


def test_a_declared_motion_instruction_checks(tmp_path):
    proj = check_text(tmp_path, program("Pwr(Axis := _MC_AX[0], Enable := TRUE);", "Pwr : MC_Power;"))
    assert "ST1007" not in codes(proj)


FB_ARRAY_OUT = """FUNCTION_BLOCK Rd
VAR_OUTPUT Data : ARRAY[0..3] OF INT; END_VAR
Data[1] := 5;
END_FUNCTION_BLOCK
"""


def test_an_element_of_an_fb_array_output_is_st1008_in_sysmac_and_accepted_in_iec(tmp_path):
    src = program("r(); x := r.Data[1]; Buf := r.Data; x := Buf[1];",
                  "r : Rd; x : INT; Buf : ARRAY[0..3] OF INT;") + FB_ARRAY_OUT
    assert codes(check_text(tmp_path, src), "error") == ["ST1008"]
    assert codes(check_text(tmp_path, src, dialect="iec"), "error") == []


def test_globals_used_without_var_external_are_one_st1009_warning_per_pou(tmp_path):
    glob = "VAR_GLOBAL Count, Limit : INT; END_VAR\n"
    proj = check_text(tmp_path, glob + program("Count := Count + Limit; Ok := P_On;", "Ok : BOOL;"))
    warnings = [d for d in proj.diagnostics if d.code == "ST1009"]
    assert len(warnings) == 1 and "`Count`, `Limit`" in warnings[0].message and "P_On" not in warnings[0].message
    fixed = glob + "PROGRAM Main\nVAR_EXTERNAL Count, Limit : INT; END_VAR\nCount := Count + Limit;\nEND_PROGRAM\n"
    assert codes(check_text(tmp_path, fixed)) == []
    assert "ST1009" not in codes(check_text(tmp_path, glob + program("Count := 1;"), dialect="iec"))


def test_portable_reports_the_sysmac_extensions_as_st2003(tmp_path):
    src = ("NAMESPACE nsA\nTYPE u : UNION W : WORD; B : BYTE; END_UNION; END_TYPE\nEND_NAMESPACE\n"
           "VAR_GLOBAL X AT %W1 : WORD; END_VAR\n"
           + program("t(TRUE, T#1s, q, e);", "t : TON; q : BOOL; e : TIME;"))
    proj = check_text(tmp_path, src, portable=True)
    texts = [d.message for d in proj.diagnostics if d.code == "ST2003"]
    assert any("NAMESPACE" in t for t in texts) and any("UNION" in t for t in texts)
    assert any("AT %W1" in t for t in texts) and sum("without `=>`" in t for t in texts) == 2
    assert "ST2003" not in codes(check_text(tmp_path, src))


def test_namespaces_nested_10000_deep_are_one_st0203_in_linear_time(tmp_path):
    src = "NAMESPACE a\n" * 10000 + "TYPE e : (A, B); END_TYPE\n" + "END_NAMESPACE\n" * 10000
    proj = check_text(tmp_path, src)
    assert [d.code for d in proj.diagnostics] == ["ST0203"] and "deeper than 32" in proj.diagnostics[0].message


def test_the_printer_keeps_namespaces_and_unions():
    from fe_helpers import parse_text

    from vplc.frontend.printer import print_unit
    src = (pathlib.Path(__file__).resolve().parents[1] / "sysmac" / "manual_project" / "Types.st").read_text()
    unit, diags = parse_text(src)
    again, diags2 = parse_text(print_unit(unit))
    assert diags == diags2 == [] and again == unit
    assert [i.declared_namespace for i in again.items] == ["nsMachine", "nsMachine\\Io"]
    assert "END_UNION" in print_unit(unit)


def test_mc_move_is_a_real_motion_instruction_not_an_unknown_type(tmp_path):
    """MC_Move (W508: positioning with a move mode) is used in published Sysmac programs; vplc does not model it."""
    proj = check_text(tmp_path, program("Mv(Axis := _MC_AX[0], Execute := TRUE);", "Mv : MC_Move;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert errors and errors[0].code == "ST1007" and "`MC_Move` (W508)" in errors[0].message


def test_deg_to_rad_is_an_omron_instruction_for_portable_and_checks_its_argument(tmp_path):
    """DegToRad / RadToDeg (W560 2-209) check in both dialects, take REAL or LREAL and give the same type back;
    --portable reports them as Omron instructions (ST2001)."""
    src = program("r := DegToRad(In := x); l := RadToDeg(y);", "x, r : REAL; y, l : LREAL;")
    assert codes(check_text(tmp_path, src), "error") == []
    assert codes(check_text(tmp_path, src, "p.st", portable=True)) == ["ST2001", "ST2001"]
    narrowing = program("r := DegToRad(y);", "r : REAL; y : LREAL;")
    assert codes(check_text(tmp_path, narrowing, "n.st"), "error") != []
    wrong = program("r := DegToRad('a');", "r : REAL;")
    assert codes(check_text(tmp_path, wrong, "w.st"), "error") != []


def test_w560_indexed_instructions_are_st1007_with_their_page(tmp_path):
    """DtToString (W560 2-481) is called in published Sysmac programs (DtToString(GetTime())); the instructions of
    the W560 index that vplc does not model name their page."""
    proj = check_text(tmp_path, program("s := DtToString(GetTime()); ok := ChkRange(x);", "s : STRING[40]; "
                                        "ok : BOOL; x : INT;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert [d.code for d in errors] == ["ST1007", "ST1007"]
    assert "Sysmac instruction `DtToString` (W560 2-481, the same instruction as W502's) is not modelled" \
        in errors[0].message


def test_system_data_types_of_unmodelled_instructions_are_st1007(tmp_path):
    """_sTimer, _sSDO_ACCESS, _eMC_COORD_SYSTEM ... appear in the variable tables of Sysmac projects."""
    proj = check_text(tmp_path, program("", "t : _sTimer; s : _sSDO_ACCESS; c : _eMC_COORD_SYSTEM;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert [d.code for d in errors] == ["ST1007"] * 3
    assert "Sysmac system-defined data type `_sTimer` (W560 2-152, Timer) is not modelled by vplc" \
        in errors[0].message


def test_names_sysmac_studio_does_not_accept_are_st1011_in_sysmac_only(tmp_path):
    """W501 6-3-12: no name may start with P_ (Studio silently renamed a PROGRAM P_SIM_ROBOT to PR_SIM_ROBOT in a
    published project) or an underline, end with an underline or hold two underlines in a row. Names with single
    underlines inside (TCP_Status_Inst) are fine; the prelude's own names are not checked."""
    src = ("TYPE eMode_ : (Idle, _Run); stP : STRUCT P_X : INT; END_STRUCT; END_TYPE\n"
           "VAR_GLOBAL Part__Count : INT; END_VAR\n"
           "PROGRAM P_Main\nVAR_EXTERNAL Part__Count : INT; END_VAR\n"
           "VAR TCP_Status_Inst : INT; _x : INT; y_ : INT; s : _sSOCKET; END_VAR\n"
           "TCP_Status_Inst := _x + y_ + Part__Count; IF P_First_Run THEN s.Handle := 0; END_IF;\nEND_PROGRAM\n")
    proj = check_text(tmp_path, src)
    found = sorted(d.message.split("`")[1] for d in proj.diagnostics if d.code == "ST1011")
    assert found == ["P_Main", "P_X", "Part__Count", "_Run", "_x", "eMode_", "y_"]
    assert codes(proj, "error") == ["ST1011"] * 7
    assert "program `P_Main` starts with `P_`" in next(d.message for d in proj.diagnostics if "P_Main" in d.message)
    assert "ST1011" not in codes(check_text(tmp_path, src, "iec.st", dialect="iec"))


def test_axes_group_type_and_its_enumeration_values_are_st1007_not_unknown(tmp_path):
    # published group code (an inline-ST rung of a Sysmac project): MC_Group000 : _sGROUP_REF and
    # TransitionMode := _mcTMCornerSuperimposed were "unknown data type" / "not declared"
    proj = check_text(tmp_path, program("m := _mcTMCornerSuperimposed; c := _mcACS;",
                                        "G : _sGROUP_REF; m : INT; c : INT;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert [d.code for d in errors] == ["ST1007"] * 3
    assert "Sysmac system-defined data type `_sGROUP_REF` (W507/W508, axes groups" in errors[0].message
    assert "Sysmac enumeration value `_mcTMCornerSuperimposed` (W508, _eMC_TRANSITION_MODE" in errors[1].message


def test_cyclic_synchronous_positioning_is_st1007_not_an_unknown_type(tmp_path):
    # a published delta-robot FB streams joint angles with MC_SyncMoveAbsolute (W508): it was "unknown data type
    # `MC_SyncMoveAbsolute`, did you mean MC_MOVEABSOLUTE?"
    proj = check_text(tmp_path, program("S(Axis := _MC_AX[0], Execute := TRUE, Position := 1.0);",
                                        "S : MC_SyncMoveAbsolute;"))
    errors = [d for d in proj.diagnostics if d.severity == "error"]
    assert errors and {d.code for d in errors} == {"ST1007"}
    assert "Sysmac motion instruction `MC_SyncMoveAbsolute` (W508) is not modelled by vplc" in errors[0].message
