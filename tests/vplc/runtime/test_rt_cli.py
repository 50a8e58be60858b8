"""`vplc run` and `vplc test` command lines (run in this process: what they print and return)."""
from cli_main import run_in_process

PROG = """PROGRAM Main
VAR t : TON; q : BOOL; n : INT; END_VAR
t(IN := TRUE, PT := T#5ms); q := t.Q; n := n + 1;
END_PROGRAM
"""


def test_run_virtual_time_with_stats_and_traces(tmp_path):
    src = tmp_path / "m.st"
    src.write_text(PROG)
    vcd, svg = tmp_path / "t.vcd", tmp_path / "t.svg"
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "20", "--stats", "--trace", "Main.q,Main.n",
             "--trace-out", str(vcd))
    assert r.returncode == 0, r.stderr
    assert "scan time: median" in r.stdout and "statements per scan: median 9" in r.stdout
    text = vcd.read_text()
    assert "$var wire 1 ! Main.q $end" in text and "#5000000\n1!" in text
    r = run_in_process("run", str(src), "--virtual-time", "--duration", "10ms", "--trace", "Main.q",
                       "--trace-out", str(svg))
    assert r.returncode == 0 and svg.read_text().startswith("<svg")


def test_run_reports_a_fault_without_traceback(tmp_path):
    src = tmp_path / "m.st"
    src.write_text("PROGRAM Main\nVAR a : INT; END_VAR\na := 1 / a;\nEND_PROGRAM\n")
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "3")
    assert r.returncode == 1
    assert "m.st:3: major fault in Main: integer division by zero" in r.stderr
    assert "Traceback" not in r.stderr


def test_run_usage_errors_exit_2(tmp_path):
    src = tmp_path / "m.st"
    src.write_text(PROG)
    assert run_in_process("run", str(src), "--trace", "Main.q").returncode == 2
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "1", "--trace", "Main.zz", "--trace-out", "x.vcd")
    assert r.returncode == 2 and "zz" in r.stderr


def test_run_refuses_a_malformed_task_option_cleanly(tmp_path):
    src = tmp_path / "m.st"
    src.write_text(PROG)
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "1", "--task", "Main")
    assert r.returncode == 2 and "task `Main` is not of the form Name@period" in r.stderr
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "1", "--task", "Main@0ms")
    assert r.returncode == 2 and "task period `0ms` must be greater than zero" in r.stderr
    assert "Traceback" not in r.stderr and "internal" not in r.stderr


def test_run_says_when_the_task_option_gives_way_to_a_configuration(tmp_path):
    src = tmp_path / "m.st"
    src.write_text(PROG + """CONFIGURATION Cfg
RESOURCE Res ON PLC
TASK Fast(INTERVAL := T#2ms, PRIORITY := 1);
PROGRAM Inst WITH Fast : Main;
END_RESOURCE
END_CONFIGURATION
""")
    r = run_in_process("run", str(src), "--virtual-time", "--cycles", "1", "--task", "Other@5ms")
    assert r.returncode == 0, r.stderr
    assert "--task Other@5ms is not used: the sources define their own CONFIGURATION" in r.stderr


def test_test_command_reports_failures_with_location_and_writes_junit(tmp_path):
    (tmp_path / "suite.st").write_text("""FUNCTION_BLOCK Demo_Test
VAR n : INT; END_VAR
n := n + 1;
TEST('passes');
AssertEquals_INT(2, 1 + 1, 'sum');
TEST_FINISHED();
TEST('fails_after_two_scans');
IF n = 2 THEN
    AssertEquals_STRING('abc', 'abd', 'text');
    TEST_FINISHED();
END_IF;
END_FUNCTION_BLOCK
""")
    junit = tmp_path / "r.xml"
    r = run_in_process("test", str(tmp_path), "--junit", str(junit))
    assert r.returncode == 1
    assert "suite.st:9: FAIL Demo_Test.fails_after_two_scans: text: expected 'abc', got 'abd'" in r.stdout
    assert r.stdout.strip().splitlines()[-1] == "1 passed, 1 failed"
    xml = junit.read_text()
    assert 'name="passes"' in xml and "<failure" in xml


def test_a_faulting_suite_fails_its_test_and_the_other_suites_still_run(tmp_path):
    (tmp_path / "s.st").write_text("""FUNCTION_BLOCK Faulty_Test
VAR z : INT; END_VAR
TEST('divides');
z := 10 / z;
TEST_FINISHED();
END_FUNCTION_BLOCK
FUNCTION_BLOCK Good_Test
TEST('ok');
AssertTrue(TRUE, '');
TEST_FINISHED();
END_FUNCTION_BLOCK
""")
    r = run_in_process("test", str(tmp_path))
    assert r.returncode == 1
    assert "s.st:4: FAIL Faulty_Test.divides: major fault in VPLC_TestRunner.Faulty_Test: integer division by zero" \
        in r.stdout
    assert r.stdout.strip().splitlines()[-1] == "1 passed, 1 failed"


def test_svg_time_axis_labels_read_like_a_timing_chart():
    from vplc.trace.svg import time_label
    assert [time_label(t, 600e6) for t in (2150, 600e6, 1.2e9)] == ["0 ms", "600 ms", "1200 ms"]
    assert [time_label(t, 2e9) for t in (0, 4e9)] == ["0 s", "4 s"]
    assert time_label(5e6, 2.5e6) == "5.0 ms" and time_label(3e5, 150e3) == "300 µs"
