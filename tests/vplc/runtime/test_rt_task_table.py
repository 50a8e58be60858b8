"""A compiled Program carries its task table and its PROGRAMs by name: a PLC instance sets up its tasks from
them, without the project's syntax tree (runtime/program.py, docs/toolchain/runtime.md section 1)."""
import pytest

from vplc.api import LoadError, Plc
from vplc.compiler.codegen import CodeGen
from vplc.project import load_project
from vplc.runtime.program import InstanceSpec, TaskSpec

SOURCE = """PROGRAM Main
VAR n : INT; END_VAR
n := n + 1;
END_PROGRAM
PROGRAM Slow
VAR k : INT; END_VAR
k := k + 1;
END_PROGRAM
CONFIGURATION Cfg
    RESOURCE R ON PLC
        TASK Fast (INTERVAL := T#1ms, PRIORITY := 4);
        TASK Lazy (INTERVAL := T#3ms, PRIORITY := 9);
        PROGRAM Cell1 WITH Fast : Main;
        PROGRAM Cell2 WITH Lazy : Slow;
        PROGRAM Loose : Main;
    END_RESOURCE
END_CONFIGURATION
"""


def compiled(tmp_path, text):
    path = tmp_path / "cfg.st"
    path.write_text(text)
    proj = load_project([str(path)])
    assert not proj.has_errors, proj.render_diagnostics()
    return CodeGen(proj).generate()


def test_the_configuration_compiles_to_a_task_table(tmp_path):
    program = compiled(tmp_path, SOURCE)
    assert program.configured
    assert program.resources == ((          # one RESOURCE: its tasks, its program instances
        (TaskSpec("Fast", 1_000_000, 4), TaskSpec("Lazy", 3_000_000, 9)),
        (InstanceSpec("Cell1", "Main", "MAIN", "FAST"), InstanceSpec("Cell2", "Slow", "SLOW", "LAZY"),
         InstanceSpec("Loose", "Main", "MAIN", ""))),)
    assert program.programs == ("MAIN", "SLOW")
    assert program.program_names == {"MAIN": "MAIN", "SLOW": "SLOW"}


def test_a_plc_sets_up_its_tasks_from_the_table_without_the_syntax_tree(tmp_path):
    program = compiled(tmp_path, SOURCE)
    program.project.configurations = []          # the table alone must do
    plc = Plc(program)
    try:
        assert [(t.name, t.period_ns) for t in plc.engine.tasks] == [("Fast", 1_000_000), ("Lazy", 3_000_000)]
        for k in range(6):
            plc.scan(k * 1_000_000)
        assert (plc.read("Cell1.n"), plc.read("Loose.n"), plc.read("Cell2.k")) == (6, 6, 2)
        assert plc.task_cycles == (6, 2)
    finally:
        plc.close()


def test_programs_chosen_by_name_are_found_in_the_table(tmp_path):
    program = compiled(tmp_path, SOURCE.split("CONFIGURATION")[0])
    assert not program.configured and program.resources == ()
    plc = Plc(program, task="Main@2ms", programs=["slow"])
    try:
        plc.scan(0)
        assert plc.read("Slow.k") == 1 and plc.read("Main.n") == 0    # Main has an instance, but no task
    finally:
        plc.close()
    with pytest.raises(LoadError, match="no PROGRAM named `Other`"):
        Plc(program, task="Main@1ms", programs=["Other"])


def test_a_library_program_is_found_by_its_qualified_and_its_bare_name(tmp_path):
    lib = tmp_path / "ToolsLib"
    lib.mkdir()
    (lib / "Counter.st").write_text("PROGRAM Counter\nVAR c : INT; END_VAR\nc := c + 1;\nEND_PROGRAM\n")
    proj = load_project([str(lib)])
    assert not proj.has_errors, proj.render_diagnostics()
    program = CodeGen(proj).generate()
    assert program.program_names == {"TOOLSLIB\\COUNTER": "TOOLSLIB\\COUNTER", "COUNTER": "TOOLSLIB\\COUNTER"}
    for name in ("ToolsLib\\Counter", "counter"):
        plc = Plc(program, task="Main@1ms", programs=[name])
        try:
            plc.scan(0)
            assert plc.read("Counter.c") == 1
        finally:
            plc.close()


def test_a_task_property_that_is_not_a_literal_is_refused_when_compiling(tmp_path):
    """Before the table it failed when loading, as an internal error naming a Python attribute."""
    from vplc.api import compile_program
    path = tmp_path / "cfg.st"
    path.write_text(SOURCE.replace("INTERVAL := T#1ms", "INTERVAL := T#1ms + T#1ms"))
    with pytest.raises(LoadError, match="cannot compile this program: TASK Fast: INTERVAL must be a literal"):
        compile_program([str(path)])
