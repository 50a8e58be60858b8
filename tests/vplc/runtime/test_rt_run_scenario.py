"""`vplc run` for commissioning: start line, --watch, --set, scenario files and the exit status."""
import os

import pytest
from cli_main import run_in_process

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

PROG = """PROGRAM Main
VAR Start : BOOL; Count : INT; Level : REAL; Mode : STRING[10] := 'auto'; Wait : TIME := T#20ms; t : TON; END_VAR
t(IN := Start, PT := Wait);
IF t.Q AND Count < 5 THEN Count := Count + 1; END_IF;
Level := INT_TO_REAL(Count) * 1.5;
END_PROGRAM
"""


def vplc(*args):
    """`vplc args...` in this process (these tests are about what a run says and returns, not the process)."""
    return run_in_process(*args)


def run(tmp_path, *args, scenario=None):
    src = tmp_path / "m.st"
    src.write_text(PROG)
    extra = []
    if scenario is not None:
        (tmp_path / "s.scn").write_text(scenario)
        extra = ["--scenario", str(tmp_path / "s.scn")]
    return vplc("run", str(src), "--virtual-time", *extra, *args)


def test_start_line_names_task_period_clock_end_and_sockets(tmp_path):
    r = run(tmp_path, "--cycles", "3")
    assert r.returncode == 0, r.stderr
    first = r.stdout.splitlines()[0]
    assert first == ("vplc run: task Main every 1 ms: Main; virtual time until 3 scan(s); opens no sockets")
    assert r.stdout.splitlines()[-1] == "vplc run: OK: 3 scan(s), 0.002 s of controller time"


def test_watch_prints_each_change_with_its_time_and_the_final_values(tmp_path):
    r = run(tmp_path, "--duration", "40ms", "--watch", "Main.Start,Main.Count", "--set", "Main.Start=TRUE@10ms")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "     0.000 s  Main.Start = FALSE" in lines
    assert "     0.010 s  Main.Start = TRUE" in lines           # the write is seen by the scan at 10 ms
    assert "     0.030 s  Main.Count = 1" in lines              # TON of 20 ms from 10 ms
    assert lines[lines.index("final values at 0.039 s:") + 1:][:2] == ["  Main.Start = TRUE", "  Main.Count = 5"]


def test_scenario_that_holds_ends_by_itself_with_exit_0(tmp_path):
    r = run(tmp_path, scenario="# start, then five counts\n"
                               "at 10ms set Main.Start TRUE   # push button\n"
                               "at 5ms expect Main.Count = 0\n"
                               "expect Main.Count = 5 within 1s\n"
                               "expect Main.Level >= 7.5 within 1s\n"
                               "expect Main.Mode = 'auto' always\n")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == ("vplc run: OK: 35 scan(s), 0.034 s of controller time; "
                                         "4 of 4 expectation(s) held")


def test_failed_expectation_exits_1_with_one_line_reason(tmp_path):
    r = run(tmp_path, scenario="at 0s set Main.Wait T#500ms\nat 0s set Main.Start TRUE\n"
                               "expect Main.Count = 5 within 100ms\n")
    assert r.returncode == 1
    assert r.stderr.strip().splitlines() == [
        "vplc run: FAILED: expectation failed at 0.100 s: expect Main.Count = 5 within 100ms (" +
        str(tmp_path / "s.scn") + ":3); Main.Count is 0"]


def test_always_expectation_fails_at_the_first_scan_it_does_not_hold(tmp_path):
    r = run(tmp_path, "--set", "Main.Start=1@2ms", scenario="expect Main.Count < 3 always\nat 1s stop\n")
    assert r.returncode == 1
    assert "expectation failed at 0.024 s: expect Main.Count < 3 always" in r.stderr


def test_run_ended_before_the_scenario_was_decided_is_a_failure(tmp_path):
    r = run(tmp_path, "--cycles", "10", scenario="at 0s set Main.Start TRUE\nexpect Main.Count = 5 within 1s\n")
    assert r.returncode == 1
    assert "expectation not decided: the run ended at 0.009 s before `expect Main.Count = 5 within 1s`" in r.stderr


def test_a_fault_is_a_one_line_reason_after_the_details(tmp_path):
    src = tmp_path / "m.st"
    src.write_text("PROGRAM Main\nVAR a, b : INT; END_VAR\na := 10 / b;\nEND_PROGRAM\n")
    r = vplc("run", str(src), "--virtual-time", "--set", "Main.b=0@0s", "--duration", "1s")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.strip().splitlines()[-1].startswith("vplc run: FAILED: major fault at 0.000 s: ")


@pytest.mark.slow
def test_scenario_mistakes_are_usage_errors_naming_file_and_line(tmp_path):
    cases = {"at 2 set Main.Start TRUE\n": ":1: time `2` is not a time like 2s",
             "\nat 1s set Main.Nope TRUE\n": ":2: `Nope` is not a variable of Main",
             "at 1s set Main.Count TRUE\n": ":1: `TRUE` is not a value for Main.Count (INT)",
             "at 1s set Main.Mode auto\n": ":1: `auto`: write a text for Main.Mode (STRING[10]) in quotes",
             "expect Main.Start > TRUE within 1s\n": ":1: `>` compares numbers; Main.Start is a BOOL",
             "set Main.Start TRUE\n": ":1: `set` needs a time: `at 0s set Main.Start TRUE`",
             "press Main.Start\n": ":1: cannot read `press Main.Start`"}
    for text, message in cases.items():
        r = run(tmp_path, scenario=text)
        assert r.returncode == 2, text
        assert message in r.stderr, (text, r.stderr)
        assert "Traceback" not in r.stderr


def test_set_option_takes_st_literals(tmp_path):
    r = run(tmp_path, "--cycles", "2", "--watch", "Main.Count,Main.Wait,Main.Mode",
            "--set", "Main.Count=16#3", "--set", "Main.Wait=T#1s", "--set", "Main.Mode='hand'")
    assert r.returncode == 0, r.stderr
    assert "  Main.Count = 3" in r.stdout and "  Main.Wait  = T#1s" in r.stdout
    assert "  Main.Mode  = hand" in r.stdout
    bad = run(tmp_path, "--cycles", "1", "--set", "Main.Count")
    assert bad.returncode == 2 and "--set 'Main.Count' is not of the form VAR=VALUE@TIME" in bad.stderr


def test_trace_window_goes_with_an_svg_trace(tmp_path):
    svg = tmp_path / "t.svg"
    r = run(tmp_path, "--duration", "50ms", "--trace", "Main.Count,Main.Level", "--trace-out", str(svg),
            "--trace-window", "10ms..40ms", "--set", "Main.Start=TRUE")
    assert r.returncode == 0, r.stderr
    assert ">10 ms<" in svg.read_text() and ">40 ms<" in svg.read_text()
    r = run(tmp_path, "--cycles", "1", "--trace", "Main.Count", "--trace-out", str(tmp_path / "t.vcd"),
            "--trace-window", "0s..1s")
    assert r.returncode == 2 and "--trace-window applies to an .svg --trace-out" in r.stderr


def test_watch_shows_a_negative_time_with_its_sign(tmp_path):
    """TIME is signed (IEC 61131-3 duration literal `T#-5ms`); --watch must not show -5 ms as zero."""
    src = tmp_path / "late.st"
    src.write_text("PROGRAM Main\nVAR Wait : TIME := T#20ms; Late : TIME; Zero : TIME; END_VAR\n"
                   "Late := Wait - T#25ms;\nEND_PROGRAM\n")
    r = vplc("run", str(src), "--virtual-time", "--cycles", "2", "--watch", "Main.Late,Main.Zero")
    assert r.returncode == 0, r.stderr
    assert "     0.000 s  Main.Late = T#-5ms" in r.stdout.splitlines()
    assert "  Main.Late = T#-5ms" in r.stdout.splitlines() and "  Main.Zero = T#0s" in r.stdout.splitlines()


def test_set_takes_a_time_literal_with_several_units_as_st_writes_it(tmp_path):
    """`T#1s500ms` and `TIME#-2s` are ST TIME literals (IEC 61131-3, W501 time literals): --set read only one unit
    and refused them. Single units and bare durations keep working."""
    for literal, shown in (("T#1s500ms", "T#1.5s"), ("TIME#1m_30s", "T#90s"), ("T#-2s", "T#-2s"),
                           ("250ms", "T#250ms")):
        r = run(tmp_path, "--cycles", "1", "--set", f"Main.Wait={literal}", "--watch", "Main.Wait")
        assert r.returncode == 0, r.stderr
        assert f"Main.Wait = {shown}" in r.stdout.splitlines()[-2]
    r = run(tmp_path, "--cycles", "1", "--set", "Main.Wait=T#1s5")
    assert r.returncode == 2 and "`T#1s5` is not a value for Main.Wait (TIME)" in r.stderr


def test_a_scenario_that_is_a_device_is_a_usage_error_before_it_is_read(tmp_path):
    """A link to /dev/zero was read until memory ran out."""
    src = tmp_path / "m.st"
    src.write_text(PROG)
    os.symlink("/dev/zero", tmp_path / "zero.scn")
    r = vplc("run", str(src), "--virtual-time", "--scenario", str(tmp_path / "zero.scn"))
    assert r.returncode == 2
    assert f"cannot read scenario {tmp_path / 'zero.scn'}: it is not a regular file or a pipe" in r.stderr
