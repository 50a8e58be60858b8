"""Statements and calls: loops, CASE on enums, VAR_IN_OUT by reference, VAR_TEMP, FB outputs, structs."""
from rt_helpers import plc_from, run1

TYPES = """
TYPE
    eStep : (Idle, Moving, Done);
    stPoint : STRUCT X : REAL; Y : REAL; END_STRUCT;
END_TYPE
"""


def test_for_bounds_are_evaluated_once_and_exit_continue_work(tmp_path):
    plc = run1(tmp_path, """n := 3;
        FOR i := 1 TO n DO n := 10; IF i = 2 THEN CONTINUE; END_IF; sum := sum + i; END_FOR;
        FOR i := 10 TO 0 BY -2 DO IF i < 5 THEN EXIT; END_IF; cnt := cnt + 1; END_FOR;""",
               "i, n, sum, cnt : INT;")
    assert (plc.read("Main.sum"), plc.read("Main.cnt")) == (4, 3)


def test_repeat_runs_once_and_while_checks_first(tmp_path):
    plc = run1(tmp_path, "REPEAT a := a + 1; UNTIL TRUE END_REPEAT; WHILE FALSE DO b := 1; END_WHILE;", "a, b : INT;")
    assert (plc.read("Main.a"), plc.read("Main.b")) == (1, 0)


def test_case_on_enum_with_qualified_and_bare_values(tmp_path):
    plc = plc_from(tmp_path, """CASE step OF
        eStep#Idle: step := Moving;
        Moving: step := eStep#Done;
        ELSE n := n + 1;
        END_CASE;""", "step : eStep; n : INT;", TYPES)
    plc.scan(0)
    assert plc.read("Main.step") == "Moving"
    plc.scan(1_000_000)
    plc.scan(2_000_000)
    assert (plc.read("Main.step"), plc.read("Main.n")) == ("Done", 1)


def test_var_in_out_passes_scalars_structs_and_arrays_by_reference(tmp_path):
    extra = TYPES + """
FUNCTION_BLOCK Bump
VAR_IN_OUT Count : INT; P : stPoint; Arr : ARRAY[0..2] OF INT; END_VAR
    Count := Count + 1; P.X := 5.0; Arr[2] := 7;
END_FUNCTION_BLOCK
"""
    plc = run1(tmp_path, "b(Count := c, P := pt, Arr := a);",
               "b : Bump; c : INT := 1; pt : stPoint; a : ARRAY[0..2] OF INT;", extra)
    assert (plc.read("Main.c"), plc.read("Main.pt"), plc.read("Main.a")) == (2, {"X": 5.0, "Y": 0.0}, [0, 0, 7])


def test_array_element_passed_to_an_array_parameter_starts_the_array_there(tmp_path):
    plc = run1(tmp_path, "n := ToAryByte(In := w, Order := _HIGH_LOW, AryOut := buf[2]);",
               "buf : ARRAY[0..5] OF BYTE; w : WORD := 16#1234; n : UINT;")
    assert plc.read("Main.buf") == [0, 0, 0x12, 0x34, 0, 0]
    assert plc.read("Main.n") == 2


def test_var_temp_is_reinitialised_on_every_call_and_outputs_stay_readable(tmp_path):
    extra = """
FUNCTION_BLOCK Acc
VAR_OUTPUT Out : INT; END_VAR
VAR_TEMP t : INT := 10; END_VAR
VAR kept : INT; END_VAR
    t := t + 1; kept := kept + 1; Out := t + kept;
END_FUNCTION_BLOCK
"""
    plc = plc_from(tmp_path, "a(); a(); r := a.Out;", "a : Acc; r : INT;", extra)
    plc.scan(0)
    assert plc.read("Main.r") == 13


def test_struct_assignment_copies_values(tmp_path):
    plc = run1(tmp_path, "b := a; b.X := 9.0;", "a : stPoint := (X := 1.0, Y := 2.0); b : stPoint;", TYPES)
    assert plc.read("Main.a") == {"X": 1.0, "Y": 2.0}
    assert plc.read("Main.b") == {"X": 9.0, "Y": 2.0}



NESTED = """
TYPE
    stPose : STRUCT X, Y : REAL; Tag : STRING[8]; J : ARRAY[0..2] OF INT; END_STRUCT;
    stCmd : STRUCT Speed : INT; Target : stPose; Via : stPose; Done : BOOL; END_STRUCT;
END_TYPE
FUNCTION_BLOCK Mover
VAR_INPUT P : stCmd; END_VAR
VAR_OUTPUT Seen : stCmd; END_VAR
Seen := P;
P.Target.X := P.Target.X + 100.0;
END_FUNCTION_BLOCK
"""


def test_nested_structures_are_copied_by_value_through_assignments_and_fb_inputs(tmp_path):
    # the small inner structures are copied inside the outer one's assigner: values, never the inner objects
    plc = run1(tmp_path, """
        a.Speed := 5; a.Target.X := 1.0; a.Target.Tag := 'T'; a.Target.J[2] := 7; a.Via.Y := 2.0; a.Done := TRUE;
        b := a; b.Target.X := 9.0; b.Target.J[2] := 8;
        a := a;
        m(P := a); a.Target.X := 3.0;
        m2(P := a, Seen => c);
        """, "a, b, c : stCmd; m, m2 : Mover;", NESTED)
    assert plc.read("Main.b.Speed") == 5 and plc.read("Main.b.Via.Y") == 2.0 and plc.read("Main.b.Done") is True
    assert plc.read("Main.b.Target.Tag") == "T"
    assert plc.read("Main.a.Target.X") == 3.0 and plc.read("Main.a.Target.J[2]") == 7     # b's writes stay in b
    assert plc.read("Main.m.Seen.Target.X") == 1.0 and plc.read("Main.m.P.Target.X") == 101.0
    assert plc.read("Main.c.Target.X") == 3.0 and plc.read("Main.m2.P.Target.X") == 103.0
    plc.write("Main.m2.Seen.Via.Y", 5.0)
    assert plc.read("Main.c.Via.Y") == 2.0 and plc.read("Main.a.Via.Y") == 2.0

def test_arrays_of_structs_and_of_fb_instances(tmp_path):
    plc = plc_from(tmp_path, """FOR i := 1 TO 3 DO
            pts[i].X := INT_TO_REAL(i);
            trig[i](CLK := TRUE);
            IF trig[i].Q THEN n := n + 1; END_IF;
        END_FOR;""", "pts : ARRAY[1..3] OF stPoint; trig : ARRAY[1..3] OF R_TRIG; i, n : INT;", TYPES)
    plc.scan(0)
    plc.scan(1_000_000)
    assert plc.read("Main.n") == 3
    assert plc.read("Main.pts[3].X") == 3.0


def test_functions_with_return_and_early_return(tmp_path):
    extra = """
FUNCTION Clamp : INT
VAR_INPUT v : INT; END_VAR
    Clamp := v;
    IF v > 10 THEN Clamp := 10; RETURN; END_IF;
    Clamp := Clamp * 2;
END_FUNCTION
"""
    plc = run1(tmp_path, "a := Clamp(50); b := Clamp(v := 3);", "a, b : INT;", extra)
    assert (plc.read("Main.a"), plc.read("Main.b")) == (10, 6)


def test_globals_and_configuration_tasks(tmp_path):
    (tmp_path / "gvl.st").write_text("VAR_GLOBAL\n    Counter : DINT;\nEND_VAR\n")
    (tmp_path / "cfg.st").write_text("""
PROGRAM Fast
VAR_EXTERNAL Counter : DINT; END_VAR
    Counter := Counter + 1;
END_PROGRAM
CONFIGURATION Cfg
RESOURCE Res ON PLC
    TASK T1(INTERVAL := T#2ms, PRIORITY := 1);
    PROGRAM Inst WITH T1 : Fast;
END_RESOURCE
END_CONFIGURATION
""")
    from vplc.api import load_plc
    plc = load_plc([str(tmp_path)])
    assert plc.period_ns == 2_000_000
    plc.run_until(lambda: False, 9_000_000)
    assert plc.read("Counter") == 5
    assert plc.read("gvl.Counter") == 5


def test_open_array_in_out_keeps_the_actual_bounds_and_function_outputs_are_stored(tmp_path):
    extra = """
FUNCTION SumAll : DINT
VAR_IN_OUT A : ARRAY[*] OF INT; END_VAR
VAR_OUTPUT First : DINT; END_VAR
VAR i : DINT; END_VAR
FOR i := LOWER_BOUND(A, 1) TO UPPER_BOUND(A, 1) DO SumAll := SumAll + A[i]; END_FOR;
First := LOWER_BOUND(A, 1);
END_FUNCTION
"""
    plc = run1(tmp_path, "total := SumAll(A := arr, First => lo); part := SumAll(A := arr[3]);",
               "arr : ARRAY[2..5] OF INT := [1, 2, 3, 4]; total, part, lo : DINT;", extra)
    assert (plc.read("Main.total"), plc.read("Main.lo"), plc.read("Main.part")) == (10, 2, 9)


def test_in_out_passed_on_to_a_nested_fb_still_refers_to_the_callers_variable(tmp_path):
    extra = TYPES + """
FUNCTION_BLOCK Inner
VAR_IN_OUT V : INT; END_VAR
V := V * 2;
END_FUNCTION_BLOCK
FUNCTION_BLOCK Outer
VAR_IN_OUT X : INT; END_VAR
VAR inn : Inner; END_VAR
inn(V := X);
END_FUNCTION_BLOCK
"""
    plc = run1(tmp_path, "o(X := x); o(X := grid[2, 3]);",
               "o : Outer; x : INT := 3; grid : ARRAY[1..2, 1..3] OF INT := [6(1)];", extra)
    assert plc.read("Main.x") == 6
    assert plc.read("Main.grid") == [1, 1, 1, 1, 1, 2] and plc.read("Main.grid[2,3]") == 2


def test_array_element_given_to_an_array_input_copies_the_array_from_there(tmp_path):
    extra = """
FUNCTION Sum3 : INT
VAR_INPUT A : ARRAY[1..3] OF INT; END_VAR
Sum3 := A[1] + A[2] + A[3];
END_FUNCTION
"""
    plc = run1(tmp_path, "r := Sum3(A := arr[2]); arr[3] := 0;", "arr : ARRAY[1..4] OF INT := [1, 2, 3, 4]; r : INT;",
               extra)
    assert plc.read("Main.r") == 9
