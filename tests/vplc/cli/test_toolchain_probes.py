"""Toolchain probes of the adversarial review: each input once ended in a traceback, a lost result or
quadratic time; each now gets a clean diagnostic or a defined result (issue "Nobody moves the robot ...")."""
from __future__ import annotations

import subprocess
import sys

import pytest

from vplc.api import load_plc
from vplc.runtime.values import PathError

LONG = "9" * 5000                                     # Python's int() refuses more than 4,300 digits


def vplc(*args, cwd=None):
    done = subprocess.run([sys.executable, "-m", "vplc", *args], capture_output=True, text=True, timeout=120,
                          cwd=cwd)
    return done.returncode, done.stdout + done.stderr


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_a_5000_digit_integer_literal_is_a_diagnostic(tmp_path):
    src = write(tmp_path, "big.st", f"PROGRAM P\nVAR x : LINT; b : BOOL; END_VAR\nx := {LONG};\nx := LINT#{LONG};\n"
                                    f"b := x.{LONG};\nEND_PROGRAM\n")
    for command in ("check", "run"):
        code, out = vplc(command, src, *(["--virtual-time", "--cycles", "1"] if command == "run" else []))
        assert code != 0 and "Traceback" not in out
        assert out.count("error[ST0106]: integer literal of 5,000 digits") == 3


def test_temporal_literals_with_thousands_of_digits_are_diagnostics(tmp_path):
    src = write(tmp_path, "time.st", f"PROGRAM P\nVAR t : TIME; d : TOD; END_VAR\nt := T#{LONG}s;\n"
                                     f"t := T#{'9' * 400}.5s;\nd := TOD#{LONG}:00:00;\nEND_PROGRAM\n")
    code, out = vplc("check", src)
    assert code == 1 and "Traceback" not in out
    assert out.count("error[ST0106]") == 3
    assert "…" in out and max(len(line) for line in out.splitlines() if "error[" in line) < 300


@pytest.mark.slow
def test_a_case_with_8000_labels_checks_and_runs(tmp_path):
    labels = "\n".join(f"{i}: y := {i * 3};" for i in range(8000))
    src = write(tmp_path, "case.st", f"PROGRAM P\nVAR x : DINT; y : DINT; z : DINT; END_VAR\n"
                                     f"CASE x OF\n{labels}\nELSE\n y := -1;\nEND_CASE;\nz := z + 1;\nEND_PROGRAM\n")
    code, out = vplc("check", src)
    assert code == 0, out
    plc = load_plc([src], task="Main@1ms")
    try:
        for scan, (x, expected) in enumerate(((0, 0), (4321, 12963), (7999, 23997), (8000, -1), (-5, -1))):
            with plc.lock:
                plc.write("P.x", x)
            plc.scan(scan * 1_000_000)
            with plc.lock:
                assert plc.read("P.y") == expected, x
        with plc.lock:
            assert plc.read("P.z") == 5                  # the statement after the CASE runs every time
    finally:
        plc.close()


def test_overlapping_labels_in_a_long_case_are_each_reported_once(tmp_path):
    labels = "\n".join(f"{i}: y := 1;" for i in range(3000)) + "\n10..12: y := 2;\n2999: y := 3;"
    src = write(tmp_path, "dup.st", f"PROGRAM P\nVAR x : DINT; y : DINT; END_VAR\nCASE x OF\n{labels}\n"
                                    f"END_CASE;\nEND_PROGRAM\n")
    code, out = vplc("check", src)
    assert code == 1
    assert out.count("error[ST1402]") == 4                # 10..12 overlaps three labels, 2999 one
    assert "`2999` repeats a value already handled at line 3003" in out


def test_trace_into_a_missing_folder_is_refused_before_the_run(tmp_path):
    src = write(tmp_path, "p.st", "PROGRAM P\nVAR x : DINT; END_VAR\nx := x + 1;\nEND_PROGRAM\n")
    code, out = vplc("run", src, "--virtual-time", "--cycles", "5", "--trace", "P.x",
                     "--trace-out", str(tmp_path / "missing" / "t.vcd"))
    assert code == 2 and "does not exist or is not writable" in out and "Traceback" not in out


def test_absurd_run_and_test_limits_are_refused_with_their_range(tmp_path):
    src = write(tmp_path, "p.st", "PROGRAM P\nVAR x : DINT; END_VAR\nx := x + 1;\nEND_PROGRAM\n")
    for flags, expected in ((["--duration", "99999999d"], "from 1ns to 30d"),
                            (["--duration", "0s"], "from 1ns to 30d"),
                            (["--cycles", "999999999999"], "--cycles must be 0 .. 2,147,483,648"),
                            (["--watchdog", "3650d"], "from 1ns to 60s"),
                            (["--spin-us", "-5"], "--spin-us must be 0 .. 10,000")):
        code, out = vplc("run", src, "--virtual-time", *flags)
        assert code == 2 and expected in out and "Traceback" not in out, (flags, out)
    code, out = vplc("test", src, "--timeout", "1000000d")
    assert code == 2 and "from 1ns to 1d of virtual time" in out


def test_a_duration_without_a_unit_is_refused(tmp_path):
    """`--duration 5` ran 5 ms (a silent default unit); a duration now needs its unit."""
    src = write(tmp_path, "p.st", "PROGRAM P\nVAR x : DINT; END_VAR\nx := x + 1;\nEND_PROGRAM\n")
    code, out = vplc("run", src, "--virtual-time", "--duration", "5")
    assert code == 2 and "like 5s or 250ms" in out
    code, out = vplc("run", src, "--virtual-time", "--cycles", "1", "--task", "Main@0ms")
    assert code == 2 and "must be greater than zero" in out


def test_program_selection_applies_to_a_configuration_too(tmp_path):
    """`--program Nope` was ignored when the sources had a CONFIGURATION (exit 0, everything ran)."""
    src = write(tmp_path, "cfg.st", "PROGRAM A\nVAR n : DINT; END_VAR\nn := n + 1;\nEND_PROGRAM\n"
                                    "PROGRAM B\nVAR n : DINT; END_VAR\nn := n + 1;\nEND_PROGRAM\n"
                                    "CONFIGURATION C\nRESOURCE R ON PLC\nTASK T(INTERVAL := T#1ms, PRIORITY := 1);\n"
                                    "PROGRAM IA WITH T : A;\nPROGRAM IB WITH T : B;\nEND_RESOURCE\nEND_CONFIGURATION\n")
    code, out = vplc("run", src, "--virtual-time", "--cycles", "1", "--program", "Nope")
    assert code == 2 and "runs no PROGRAM named `Nope`" in out
    plc = load_plc([src], programs=["B"])
    try:
        plc.scan(0)
        with plc.lock:
            assert plc.read("IB.n") == 1
        with pytest.raises(PathError):                     # IA is not instantiated: it does not run
            plc.read("IA.n")
    finally:
        plc.close()
