"""One compiled program serves many PLC instances; the compile cache follows the source bytes."""
from vplc.api import Plc, compile_program, load_plc

COUNTER = """PROGRAM Main
VAR n : INT; tick : TON; END_VAR
tick(IN := TRUE, PT := T#5ms);
n := n + 1;
END_PROGRAM
"""


def test_two_instances_of_one_program_keep_their_own_variables_and_timers(tmp_path):
    path = tmp_path / "main.st"
    path.write_text(COUNTER)
    program = compile_program([str(path)])
    a, b = Plc(program), Plc(program)
    for t in range(0, 10_000_000, 1_000_000):
        a.scan(t)
    b.scan(0)
    assert (a.read("Main.n"), a.read("Main.tick.Q")) == (10, True)
    assert (b.read("Main.n"), b.read("Main.tick.Q")) == (1, False)
    assert a.module.namespace is not b.module.namespace and a.program is b.program


def test_loading_unchanged_sources_again_reuses_the_compiled_program(tmp_path):
    path = tmp_path / "main.st"
    path.write_text(COUNTER)
    assert load_plc([str(path)]).program is load_plc([str(path)]).program


def test_an_edited_file_is_compiled_afresh(tmp_path):
    path = tmp_path / "main.st"
    path.write_text(COUNTER)
    first = load_plc([str(path)])
    path.write_text(COUNTER.replace("n := n + 1;", "n := n + 2;"))
    second = load_plc([str(path)])
    second.scan(0)
    assert second.program is not first.program and second.read("Main.n") == 2


def test_statement_counting_is_a_compile_option_of_its_own(tmp_path):
    path = tmp_path / "main.st"
    path.write_text(COUNTER)
    counted = load_plc([str(path)], count_statements=True)
    counted.scan(0)
    plain = load_plc([str(path)])
    plain.scan(0)
    assert counted.statements_executed > 0 and plain.statements_executed == 0
    assert plain.program is not counted.program
