"""`vplc run` results an engineer can act on (issue 27, deliverable 3): values in PLC notation in --watch and in
the SVG timing diagram, the overrun count in the final line with --max-overruns, and the trace written when the
run is stopped by SIGTERM or Ctrl-C."""
from __future__ import annotations

import os
import pathlib
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]

TYPES = """
TYPE eMode : (Idle, Running := 5, Stopped); END_TYPE
TYPE stPoint : STRUCT X : REAL; Flags : WORD; Mode : eMode; Name : STRING[8]; END_STRUCT; END_TYPE
"""
PROGRAM = TYPES + """
PROGRAM Main
VAR
  Status : WORD := 16#4006; Small : BYTE := 16#A; Wide : DWORD; Long : LWORD := 16#FF;
  Mode : eMode := Running; Point : stPoint; Table : ARRAY[0..2] OF WORD; Many : ARRAY[0..99] OF BYTE;
  Count : INT; Wait : TIME := T#1500ms; Level : REAL := 2.0;
END_VAR
Count := Count + 1;
Wide := Wide OR 16#10000;
Point.Flags := 16#2008; Point.Name := 'it$'s';
Table[1] := 16#FFFF;
IF Count >= 2 THEN Mode := Stopped; Status := 16#200B; END_IF;
END_PROGRAM
"""


def vplc(*args, cwd=None, **kw) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "vplc", *map(str, args)], capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=120, **kw)


@pytest.fixture
def program(tmp_path):
    path = tmp_path / "main.st"
    path.write_text(PROGRAM, encoding="utf-8")
    return path


def test_watch_shows_bit_strings_in_16_notation_and_enumerations_by_name(program):
    r = vplc("run", program, "--virtual-time", "--cycles", "3", "--watch",
             "Main.Status,Main.Small,Main.Wide,Main.Long,Main.Mode,Main.Point,Main.Table,Main.Wait,Main.Level,"
             "Main.Count")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "     0.000 s  Main.Status = 16#4006" in lines              # not 16390
    assert "     0.001 s  Main.Status = 16#200B" in lines
    final = lines[lines.index("final values at 0.002 s:") + 1:]
    assert final[:10] == [
        "  Main.Status = 16#200B",
        "  Main.Small  = 16#0A",
        "  Main.Wide   = 16#00010000",
        "  Main.Long   = 16#00000000000000FF",
        "  Main.Mode   = Stopped",
        "  Main.Point  = (X := 0.0, Flags := 16#2008, Mode := Idle, Name := 'it$'s')",
        "  Main.Table  = [16#0000, 16#FFFF, 16#0000]",
        "  Main.Wait   = T#1.5s",
        "  Main.Level  = 2.0",
        "  Main.Count  = 3"]


def test_watch_of_a_long_array_writes_the_first_elements_and_counts_the_rest(program):
    r = vplc("run", program, "--virtual-time", "--cycles", "1", "--watch", "Main.Many")
    assert r.returncode == 0, r.stderr
    assert "  Main.Many = [" + "16#00, " * 32 + "… 68 more]" in r.stdout.splitlines()


@pytest.mark.slow
def test_the_svg_timing_diagram_writes_bit_strings_in_16_notation(program, tmp_path):
    svg = tmp_path / "t.svg"
    r = vplc("run", program, "--virtual-time", "--cycles", "4", "--trace", "Main.Status,Main.Count,Main.Mode",
             "--trace-out", svg)
    assert r.returncode == 0, r.stderr
    texts = [t.text for t in ET.parse(svg).iter("{http://www.w3.org/2000/svg}text")]
    assert "16#4006" in texts and "16#200B" in texts and "16390" not in texts
    assert "Stopped" in texts                                       # enumerations by name, as before
    vcd = tmp_path / "t.vcd"
    assert vplc("run", program, "--virtual-time", "--cycles", "4", "--trace", "Main.Status",
                "--trace-out", vcd).returncode == 0
    assert "$var wire 16 ! Main.Status $end" in vcd.read_text() and "b100000000000110 !" in vcd.read_text()


BUSY = "PROGRAM Main\nVAR i, n : DINT; END_VAR\nFOR i := 1 TO 100000 DO n := n + 1; END_FOR;\nEND_PROGRAM\n"


def test_a_real_time_run_reports_its_overruns_and_fails_above_max_overruns(tmp_path):
    # every scan of this program takes several 1 ms periods: each run overruns, however fast the machine
    path = tmp_path / "busy.st"
    path.write_text(BUSY, encoding="utf-8")
    ok = vplc("run", path, "--duration", "30ms")
    assert ok.returncode == 0, ok.stderr
    final = ok.stdout.strip().splitlines()[-1]
    assert final.startswith("vplc run: OK: ") and final.endswith(" overrun(s)")
    assert int(final.rsplit("; ", 1)[1].split()[0]) > 0
    bad = vplc("run", path, "--duration", "30ms", "--max-overruns", "1")
    assert bad.returncode == 1
    last = bad.stderr.strip().splitlines()[-1]
    assert last.startswith("vplc run: FAILED: ") and "overrun(s), more than --max-overruns 1 (task periods missed" \
        in last


@pytest.mark.slow
def test_max_overruns_is_a_real_time_option(tmp_path):
    path = tmp_path / "busy.st"
    path.write_text(BUSY, encoding="utf-8")
    r = vplc("run", path, "--virtual-time", "--cycles", "1", "--max-overruns", "0")
    assert r.returncode == 2 and "--max-overruns applies to real time" in r.stderr
    r = vplc("run", path, "--duration", "5ms", "--max-overruns", "-1")
    assert r.returncode == 2 and "--max-overruns must be 0 .." in r.stderr
    r = vplc("run", path, "--virtual-time", "--cycles", "1")
    assert r.returncode == 0 and "overrun" not in r.stdout          # virtual time has none to report


def _default_sigint():
    """Ctrl-C as at a terminal: a test run started in the background (a non-interactive shell's `&`) hands its
    children SIGINT ignored, and Python keeps an ignored SIGINT, so the child would never see the operator's key."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("sig, who", [(signal.SIGTERM, "SIGTERM"), (signal.SIGINT, "the operator")])
def test_a_run_stopped_by_a_signal_still_writes_its_trace(program, tmp_path, sig, who):
    svg = tmp_path / "stop.svg"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "vplc", "run", str(program), "--trace", "Main.Status,Main.Count",
                             "--trace-out", str(svg), "--watch", "Main.Mode"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, preexec_fn=_default_sigint)
    try:
        assert proc.stdout.readline().startswith("vplc run: task Main")
        assert "Main.Mode = Running" in proc.stdout.readline()      # scanning
        assert "Main.Mode = Stopped" in proc.stdout.readline()      # two scans recorded
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert f"vplc run: stopped by {who}" in err and "Traceback" not in err
    assert f"trace written to {svg}" in out and "vplc run: OK: " in out
    texts = [t.text for t in ET.parse(svg).iter("{http://www.w3.org/2000/svg}text")]
    # Status is 16#4006 in the first scan and 16#200B from the second to the signal; a value is written where it
    # fits, so which of the two gets its text depends on how long the run lasted before the signal (the load)
    assert "Main.Status" in texts and {"16#4006", "16#200B"} & set(texts)


def test_a_failed_bit_string_assert_shows_both_values_in_16_notation(tmp_path):
    suite = tmp_path / "suite.st"
    suite.write_text("FUNCTION_BLOCK Status_Test\nVAR w : WORD := 16#200B; END_VAR\nTEST('status');\n"
                     "AssertEquals_WORD(Expected := 16#4006, Actual := w, Message := 'error code');\n"
                     "AssertEquals_BYTE(Expected := 16#0A, Actual := 16#0A, Message := 'same');\n"
                     "TEST_FINISHED();\nEND_FUNCTION_BLOCK\n", encoding="utf-8")
    r = vplc("test", suite)
    assert r.returncode == 1
    assert f"{suite}:4: FAIL Status_Test.status: error code: expected 16#4006, got 16#200B" in r.stdout.splitlines()
