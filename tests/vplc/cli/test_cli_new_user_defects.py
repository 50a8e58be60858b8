"""Defects a new user met writing a whole cell from the docs (issue 27, bad input): `vplc run`, its scenarios and
the paths they name. Each is a usage error with file and line before the first scan, or it works as documented
(docs/toolchain/runtime.md sections 2 and 6)."""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]

GLOBALS = """
TYPE eFormat : (Joint, Cartesian); END_TYPE
TYPE stStatus : STRUCT EStop : BOOL; Code : WORD; END_STRUCT; END_TYPE
VAR_GLOBAL
    Count : INT;
    Status : stStatus;
END_VAR
"""
PROGRAM = """
PROGRAM M
VAR_EXTERNAL
    Count : INT;
    Status : stStatus;
END_VAR
VAR
    Seg : INT;
    Format : eFormat;
    Reset : BOOL;
    Busy : BOOL;
    Move : TON;
END_VAR
Count := Count + 1;
Busy := Count > 2;
END_PROGRAM
"""


def vplc(*args) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "vplc", *map(str, args)], capture_output=True, text=True, env=env,
                          timeout=120)


@pytest.fixture
def cell(tmp_path):
    (tmp_path / "G.st").write_text(GLOBALS, encoding="utf-8")
    (tmp_path / "M.st").write_text(PROGRAM, encoding="utf-8")
    return tmp_path


def scenario(cell, text: str) -> pathlib.Path:
    path = cell / "cell.scn"
    path.write_text(text, encoding="utf-8")
    return path


def run(cell, *args) -> subprocess.CompletedProcess:
    return vplc("run", cell / "G.st", cell / "M.st", "--virtual-time", *args)


def usage_error(r: subprocess.CompletedProcess) -> str:
    """The one-line message of a usage error (exit 2, no traceback, nothing scanned)."""
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and "vplc run: OK" not in r.stdout
    return r.stderr.strip()


# ---- D1: a program's VAR_EXTERNAL is the global ---------------------------------------------------------------
def test_watch_and_set_reach_the_global_behind_an_external_variable(cell):
    r = run(cell, "--cycles", "3", "--watch", "M.Count,M.Status.EStop", "--set", "M.Count=5@1ms")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "     0.000 s  M.Count        = 1" in lines
    assert "     0.001 s  M.Count        = 6" in lines          # written before the scan at 1 ms, then counted
    assert "  M.Count        = 7" in lines


def test_a_trace_records_the_global_behind_an_external_variable(cell, tmp_path):
    out = tmp_path / "t.vcd"
    r = run(cell, "--cycles", "3", "--trace", "M.Count", "--trace-out", out)
    assert r.returncode == 0, r.stderr
    vcd = out.read_text(encoding="utf-8")
    assert "M.Count" in vcd and "b11 " in vcd                  # 3 after the third scan


def test_a_scenario_expects_and_sets_through_an_external_variable(cell):
    sc = scenario(cell, "at 2ms set M.Count 40\nexpect M.Count = 42 within 1s\nexpect M.Count >= 1 within 1s\n")
    r = run(cell, "--scenario", sc)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == "vplc run: OK: 4 scan(s), 0.003 s of controller time; 2 of 2 " \
                                        "expectation(s) held"


@pytest.mark.parametrize("option", [["--watch", "M.Counts"], ["--trace", "M.Status.Stop", "--trace-out", "x.vcd"],
                                    ["--set", "M.Nope=1"]])
def test_a_path_that_names_nothing_is_a_usage_error_naming_it(cell, option):
    if "--trace-out" in option:
        option[-1] = str(cell / option[-1])
    message = usage_error(run(cell, "--cycles", "1", *option))
    assert message.startswith("vplc run: error: ") and option[1].split("=")[0] in message


# ---- D2: a scenario of writes alone ends after its last write ------------------------------------------------
def test_a_scenario_of_writes_alone_ends_after_the_scan_that_saw_its_last_write(cell):
    sc = scenario(cell, "at 2ms set M.Count 5\nat 1ms set M.Reset TRUE\n")
    r = run(cell, "--scenario", sc, "--watch", "M.Count")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].endswith("virtual time until the scenario is decided; opens no sockets")
    assert "     0.002 s  M.Count = 6" in lines                 # written before the scan at 2 ms, then counted
    assert lines[-1] == "vplc run: OK: 3 scan(s), 0.002 s of controller time"


def test_set_options_without_a_scenario_file_leave_the_end_to_the_bounds(cell):
    r = run(cell, "--set", "M.Count=5@1ms", "--cycles", "6")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == "vplc run: OK: 6 scan(s), 0.005 s of controller time"


def test_reactions_and_always_expectations_alone_do_not_end_the_run(cell):
    sc = scenario(cell, "when M.Busy = TRUE then set M.Reset TRUE\nexpect M.Count >= 0 always\n")
    r = run(cell, "--scenario", sc, "--cycles", "8")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0].endswith("virtual time until 8 scan(s); opens no sockets")
    assert r.stdout.splitlines()[-1] == "vplc run: OK: 8 scan(s), 0.007 s of controller time; 1 of 1 " \
                                        "expectation(s) held"


# ---- D3 and D5: a value that does not fit its variable is refused before the first scan --------------------
@pytest.fixture
def plc(cell):
    from vplc.api import load_plc
    with load_plc([str(cell / "G.st"), str(cell / "M.st")]) as p:
        yield p


def scenario_error(plc, cell, text: str) -> str:
    """The message of a scenario line refused when it is checked against the loaded program."""
    from vplc.cli import scenario as scn
    with pytest.raises(scn.ScenarioError) as info:
        scn.resolve(plc, scn.load(str(scenario(cell, text))))
    return str(info.value)


@pytest.mark.parametrize(("line", "message"), [
    ("at 2s set M.Seg 99999", "99999 is outside the range -32768..32767 of M.Seg (INT)"),
    ("at 2s set M.Seg -40000", "-40000 is outside the range -32768..32767 of M.Seg (INT)"),
    ("at 2s set M.Format Foo", "'Foo' is not a value of eFormat (values: Joint, Cartesian)"),
    ("when M.Busy = TRUE then set M.Seg 16#10000", "65536 is outside the range -32768..32767 of M.Seg (INT)"),
])
def test_a_write_that_does_not_fit_is_refused_with_file_and_line(plc, cell, line, message):
    assert scenario_error(plc, cell, "# the cell\n" + line + "\n") == f"{cell / 'cell.scn'}:2: {message}"


def test_an_out_of_range_write_is_a_usage_error_before_the_first_scan(cell):
    r = run(cell, "--scenario", scenario(cell, "at 2s set M.Seg 99999\n"))
    assert usage_error(r) == f"vplc run: error: {cell / 'cell.scn'}:1: 99999 is outside the range -32768..32767 " \
                             "of M.Seg (INT)"
    assert r.stdout == ""                                        # nothing ran: no start line
    r = run(cell, "--set", "M.Seg=99999@2s")
    assert usage_error(r) == "vplc run: error: --set M.Seg=99999@2s: 99999 is outside the range -32768..32767 " \
                             "of M.Seg (INT)"


@pytest.mark.parametrize(("line", "shown", "reason"), [
    ("when M.Seg = 99999 then set M.Reset TRUE", "M.Seg = 99999",
     "99999 is outside the range -32768..32767 of M.Seg (INT)"),
    ("when M.Busy = TRUE and M.Seg >= 40000 robot 1 estop", "M.Seg >= 40000",
     "40000 is outside the range -32768..32767 of M.Seg (INT)"),
    ("expect M.Seg = 99999 within 1s", "M.Seg = 99999", "99999 is outside the range -32768..32767 of M.Seg (INT)"),
    ("at 1s expect M.Format <> Foo", "M.Format <> Foo", "'Foo' is not a value of eFormat (values: Joint, Cartesian)"),
])
def test_a_condition_or_expectation_on_a_value_the_variable_cannot_hold_is_refused(plc, cell, line, shown, reason):
    assert scenario_error(plc, cell, line + "\n") == \
        f"{cell / 'cell.scn'}:1: `{shown}` compares {shown.split()[0]} with a value it can never hold: {reason}"


def test_values_that_fit_are_still_accepted(plc, cell):
    from vplc.cli import scenario as scn
    sc = scn.load(str(scenario(cell, "at 1s set M.Seg -32768\nat 1s set M.Format Cartesian\n"
                                     "when M.Seg = 32767 then set M.Format eFormat#Joint\n"
                                     "expect M.Format = cartesian within 2s\n")))
    scn.resolve(plc, sc)
    assert [w.value for w in sc.writes] == [-32768, "Cartesian"]
    assert sc.reactions[0].terms[0].value == 32767 and sc.expects[0].value == "cartesian"


def test_a_condition_that_can_never_be_true_is_a_usage_error(cell):
    r = run(cell, "--scenario", scenario(cell, "at 1ms set M.Reset TRUE\nwhen M.Seg = 99999 then set M.Reset "
                                               "FALSE\n"))
    assert usage_error(r).startswith(f"vplc run: error: {cell / 'cell.scn'}:2: `M.Seg = 99999` compares M.Seg "
                                     "with a value it can never hold")


# ---- D4: messages that point at the mistake -------------------------------------------------------------------
@pytest.mark.parametrize(("line", "message"), [
    ("when M.Reset = TRUE or M.Busy = TRUE then set M.Seg 1",
     "`or` cannot join conditions: only `and` does (`when A = TRUE and B = FALSE ...`); for either of two "
     "conditions write one line for each"),
    ("expect M.Reset = TRUE OR M.Busy = TRUE within 1s", "`OR` cannot join conditions: only `and` does"),
    ("when M.Move = TRUE then set M.Seg 1",
     "M.Move is a TON: a condition or an expectation compares one elementary variable; name one of its members, "
     "e.g. `M.Move.Q`"),
    ("expect M.Status = TRUE within 1s", "M.Status is a stStatus: a condition or an expectation compares one "
                                         "elementary variable; name one of its members, e.g. `M.Status.EStop`"),
    ("expect M.Busy = TRUE within 60 s",
     "`within 60 s`: write the time without a blank between number and unit, like `within 60s` (2s, 250ms, 1.5s)"),
    ("when M.Busy = TRUE for 1 s then set M.Seg 1", "`for 1 s`: write the time without a blank"),
    ("when M.Busy = TRUE then set M.Seg 1 after 200 ms", "`after 200 ms`: write the time without a blank"),
    ("at 2 s set M.Seg 1", "`at 2 s`: write the time without a blank between number and unit, like `at 2s`"),
])
def test_messages_point_at_the_mistake(cell, line, message):
    from vplc.cli import scenario as scn
    path = scenario(cell, line + "\n")
    try:
        sc = scn.load(str(path))
    except scn.ScenarioError as exc:
        text = str(exc)
    else:
        from vplc.api import load_plc
        with load_plc([str(cell / "G.st"), str(cell / "M.st")]) as p, pytest.raises(scn.ScenarioError) as info:
            scn.resolve(p, sc)
        text = str(info.value)
    assert text.startswith(f"{path}:1: {message}")
    assert "is not a value" not in text


def test_set_still_takes_an_aggregate_member_by_member(plc, cell):
    assert scenario_error(plc, cell, "at 1s set M.Move TRUE\n").endswith(
        "M.Move is a TON; set its elementary members one by one")


def test_or_inside_a_quoted_text_is_a_value(cell):
    from vplc.cli import scenario as scn
    sc = scn.load(str(scenario(cell, "at 1s set M.Name 'a or'\nexpect M.Name = 'x or y' within 1s\n")))
    assert sc.writes[0].text == "'a or'" and sc.expects[0].text == "'x or y'"


def test_a_scenario_watches_an_external_variable_without_a_path_lookup_per_scan(plc, cell):
    """The global behind `M.Count` lives as long as the controller: it is sampled straight from the globals, like
    `Count`, not through plc.read every scan (what keeps `when` lines cheap, runtime.md section 7)."""
    from vplc.cli import scenario as scn
    from vplc.cli.scenario_run import Runner
    sc = scn.load(str(scenario(cell, "when M.Count >= 3 then set M.Seg 7\nexpect M.Seg = 7 within 10ms\n")))
    scn.resolve(plc, sc)
    runner = Runner(plc, sc)
    assert runner.signals["M.Count"].read is None and runner.signals["M.Count"].container is plc.globals.__dict__
    t = 0
    while not runner.finished(t):
        runner.before_scan(t)
        plc.scan(t)
        runner.after_scan(t)
        t += plc.period_ns
    assert runner.end_check(t) is None and plc.read("M.Seg") == 7
