"""Bad input for the back end: deeply nested expressions, many FB instances, restart after a fault."""
from vplc.api import load_plc


def test_deeply_nested_expressions_compile_in_assignments_conditions_and_loops(tmp_path):
    deep = "(" * 180 + "a + 1" + " + 1)" * 180
    chain = " + 1" * 100
    src = (f"PROGRAM Main\nVAR a : DINT; b : BOOL; n : INT; END_VAR\na := {deep};\n"
           f"IF a{chain} < 0 THEN b := FALSE; ELSIF a{chain} > 0 THEN b := TRUE; END_IF;\n"
           f"WHILE n{chain} < 105 DO n := n + 1; END_WHILE;\n"
           f"REPEAT n := n + 1; UNTIL n{chain} > 110 END_REPEAT;\nEND_PROGRAM\n")
    p = tmp_path / "deep.st"
    p.write_text(src)
    plc = load_plc([str(p)])
    plc.scan(0)
    assert (plc.read("Main.a"), plc.read("Main.b"), plc.read("Main.n")) == (181, True, 11)


def test_a_new_load_restarts_a_faulted_program_from_its_initial_values(tmp_path):
    p = tmp_path / "m.st"
    p.write_text("PROGRAM Main\nVAR n : INT := 5; z : INT; END_VAR\nn := n + 1;\nIF n > 6 THEN n := n / z; END_IF;\n"
                 "END_PROGRAM\n")
    plc = load_plc([str(p)])
    plc.scan(0)
    assert plc.read("Main.n") == 6
    again = load_plc([str(p)])
    assert again.read("Main.n") == 5
