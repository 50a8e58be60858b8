"""Command lines under hostile conditions (issue 23 item 9): a report folder that does not exist, a full disk,
an option naming nothing. Each ends with one line saying what went wrong and a non-zero exit, never a traceback
and never a success message."""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]

PROGRAM = "PROGRAM Main\nVAR c : INT; END_VAR\nc := c + 1;\nEND_PROGRAM\n"
SUITE = ("FUNCTION_BLOCK S_Test\nTEST('one');\nAssertEquals_INT(Expected := 1, Actual := 1, Message := 'x');\n"
         "TEST_FINISHED();\nEND_FUNCTION_BLOCK\n")


def vplc(*args, stdout=subprocess.PIPE, cwd=None) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "vplc", *map(str, args)], stdout=stdout, stderr=subprocess.PIPE,
                          text=True, env=env, cwd=cwd, timeout=120)


@pytest.fixture
def files(tmp_path):
    (tmp_path / "main.st").write_text(PROGRAM, encoding="utf-8")
    (tmp_path / "suite.st").write_text(SUITE, encoding="utf-8")
    return tmp_path


def test_a_junit_report_into_a_missing_folder_is_a_usage_error_before_anything_runs(files):
    r = vplc("test", files / "suite.st", "--junit", files / "nodir" / "x.xml")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.startswith("vplc test: error: --junit") and "does not exist or is not writable" in r.stderr
    assert r.stdout == ""
    (files / "report.xml").mkdir()                 # a folder: named as one (its folder exists and is writable)
    r = vplc("test", files / "suite.st", "--junit", files / "report.xml")
    assert r.returncode == 2 and f"--junit '{files / 'report.xml'}' is a folder; give a file name such as" in r.stderr


full = pytest.mark.skipif(not os.path.exists("/dev/full"), reason="this system has no /dev/full")


@full
@pytest.mark.parametrize("args", [("check", "main.st"), ("run", "main.st", "--virtual-time", "--cycles", "2"),
                                  ("test", "suite.st")])
def test_output_to_a_full_disk_fails_the_command_with_one_line(files, args):
    with open("/dev/full", "w") as sink:
        r = vplc(*args, stdout=sink, cwd=files)
    assert r.returncode == 1, r.stderr
    assert r.stderr.strip().splitlines()[-1] == "vplc: error: cannot write the output: No space left on device"
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr


@full
def test_a_junit_report_that_cannot_be_written_fails_the_run(files):
    r = vplc("test", files / "suite.st", "--junit", "/dev/full")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "vplc test: error: cannot write the JUnit report /dev/full: No space left on device" in r.stderr


@full
def test_a_trace_that_cannot_be_written_fails_the_run(files):
    os.symlink("/dev/full", files / "full.vcd")
    r = vplc("run", files / "main.st", "--virtual-time", "--cycles", "2", "--trace", "Main.c",
             "--trace-out", files / "full.vcd")
    assert r.returncode == 1 and "trace written" not in r.stdout and "OK" not in r.stdout
    assert "cannot write the trace" in r.stderr and "No space left on device" in r.stderr


@pytest.mark.parametrize("option", ["--watch", "--trace"])
def test_a_variable_list_of_nothing_but_commas_is_a_usage_error(files, option):
    extra = ["--trace-out", files / "t.vcd"] if option == "--trace" else []
    r = vplc("run", files / "main.st", "--virtual-time", "--cycles", "2", option, ",,,", *extra)
    assert r.returncode == 2 and "max()" not in r.stderr
    assert r.stderr.strip() == f"vplc run: error: {option} ',,,' names no variable; give VAR,VAR,... like " \
                               "Main.Count,Main.Busy"
    assert not (files / "t.vcd").exists()
