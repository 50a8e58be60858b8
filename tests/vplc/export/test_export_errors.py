"""Error handling: sources with errors, missing paths, bad format, unwritable output. Never a traceback."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.vplc.export.conftest import LIB, ROOT, run

BAD = "FUNCTION_BLOCK Broken\nVAR\n    x : INT;\nEND_VAR\nx := y;\nEND_FUNCTION_BLOCK\n"


def _one_line(err: str) -> None:
    assert err.count("\n") == 1 and err.startswith("vplc export: error: ") and "Traceback" not in err


def test_source_with_an_error_prints_diagnostics_and_writes_nothing(tmp_path, capsys):
    src = tmp_path / "broken.st"
    src.write_text(BAD, encoding="utf-8")
    for fmt, out in (("iec61131-10", tmp_path / "out.xml"), ("paste", tmp_path / "kit")):
        code, stdout, err = run(capsys, "export", str(src), "--format", fmt, "-o", str(out))
        assert code == 1 and not out.exists()
        assert f"{src}:5:6: error[ST1001]: `y` is not declared" in err
        assert err.rstrip().endswith("1 error(s) in the sources; nothing written")


def test_missing_path_is_a_usage_error(tmp_path, capsys):
    code, _, err = run(capsys, "export", str(tmp_path / "nope"), "-o", str(tmp_path / "x.xml"))
    assert code == 2
    _one_line(err)
    assert "does not exist" in err


def test_unknown_format_is_a_usage_error(tmp_path, capsys):
    code, _, err = run(capsys, "export", str(LIB), "--format", "tc6", "-o", str(tmp_path / "x.xml"))
    assert code == 2
    _one_line(err)
    assert "unknown format `tc6`; use iec61131-10, plcopen or paste" in err


def test_unwritable_output_is_a_usage_error(tmp_path, capsys):
    code, _, err = run(capsys, "export", str(LIB), "-o", str(tmp_path / "no" / "such" / "dir" / "x.xml"))
    assert code == 2
    _one_line(err)
    code, _, err = run(capsys, "export", str(LIB), "-o", str(tmp_path))
    assert code == 2 and "is a folder" in err
    _one_line(err)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, _, err = run(capsys, "export", str(LIB), "--format", "paste", "-o", str(blocker / "kit"))
    assert code == 2
    _one_line(err)


def test_an_output_that_is_one_of_the_sources_is_refused_and_the_source_kept(tmp_path, capsys):
    src = tmp_path / "fb.st"
    src.write_text(BAD.replace("x := y;", "x := 1;"), encoding="utf-8")
    before = src.read_bytes()
    for fmt in ("iec61131-10", "plcopen"):
        for given in (src, tmp_path):           # named, or found in the folder given
            code, _, err = run(capsys, "export", str(given), "--format", fmt, "-o", str(src))
            assert code == 2 and "is one of the sources" in err and src.read_bytes() == before
            _one_line(err)


def test_an_empty_option_value_is_a_usage_error_not_an_absent_option(tmp_path, capsys):
    """--only '' exported everything, as if the option were absent (a script's unset variable)."""
    for option in ("--only", "--device"):
        code, _, err = run(capsys, "export", str(LIB), option, "", "-o", str(tmp_path / "x.xml"))
        assert code == 2 and f"argument {option}: empty value; give one or leave the option out" in err
        assert not (tmp_path / "x.xml").exists()


def test_missing_output_is_a_usage_error(capsys):
    code, _, err = run(capsys, "export", str(LIB))
    assert code == 2 and "-o" in err
    _one_line(err)


def test_folder_without_sources_exports_nothing(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    code, _, err = run(capsys, "export", str(tmp_path / "empty"), "-o", str(tmp_path / "x.xml"))
    assert code == 2 and "nothing to export" in err and not (tmp_path / "x.xml").exists()


@pytest.mark.slow
def test_command_is_registered_with_python_m_vplc(tmp_path):
    env_path = f"{ROOT / 'src'}"
    r = subprocess.run([sys.executable, "-m", "vplc", "export", "--help"], capture_output=True, text=True,
                       env={"PYTHONPATH": env_path, "PATH": "/usr/bin:/bin"}, cwd=ROOT)
    assert r.returncode == 0 and "--format" in r.stdout and "--flat" in r.stdout
    r = subprocess.run([sys.executable, "-m", "vplc", "export", str(LIB), "-o", str(tmp_path / "l.xml")],
                       capture_output=True, text=True, env={"PYTHONPATH": env_path, "PATH": "/usr/bin:/bin"},
                       cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert "data type(s)" in r.stdout and "POU(s)" in r.stdout


REFUSED = {   # what Omron's IEC 61131-10 schemas cannot express is refused, never written with another meaning
    "type initial value": ("TYPE\n    aT : ARRAY[0..1] OF INT := [1, 2];\nEND_TYPE\n",
                           "data type `aT` has an initial value of its own"),
    "VAR_TEMP in an FB": ("FUNCTION_BLOCK F\nVAR_TEMP\n    t : INT;\nEND_VAR\nt := 1;\nEND_FUNCTION_BLOCK\n",
                          "FUNCTION_BLOCK `F`: VAR_TEMP has no counterpart"),
    "own EN": ("FUNCTION F : INT\nVAR_INPUT\n    EN : BOOL;\n    X : INT;\nEND_VAR\nF := X;\nEND_FUNCTION\n",
               "FUNCTION `F`: declares its own `EN`"),
    "VAR_INPUT in a program": ("PROGRAM P\nVAR_INPUT\n    i : INT;\nEND_VAR\n;\nEND_PROGRAM\n",
                               "PROGRAM `P`: VAR_INPUT in a program has no counterpart"),
}


def test_what_the_sysmac_schema_cannot_express_is_refused(tmp_path, capsys):
    for name, (text, message) in REFUSED.items():
        src = tmp_path / f"{name.replace(' ', '_')}.st"
        src.write_text(text, encoding="utf-8")
        out = tmp_path / "out.xml"
        code, _, err = run(capsys, "export", str(src), "-o", str(out))
        assert code == 1 and not out.exists(), name
        _one_line(err)
        assert message in err, (name, err)


def test_negated_data_source_and_in_out_variable_in_a_rung_are_refused(tmp_path, capsys):
    from tests.vplc.ladder.ld_xml import coil, contact, inoutvar, invar, outvar, program, rail, right
    cases = {"inout": ([rail(1), contact(2, "A", 1), inoutvar(3, "X", 2), coil(4, "Q", 3), right(5, 4)],
                       "rung 1: variable X is written and read on"),
             "negated": ([rail(1), invar(2, "A"), outvar(3, "Q", 2)], "rung 1: variable Q is negated")}
    for name, (body, message) in cases.items():
        src = program(tmp_path, {"A": "BOOL", "X": "BOOL", "Q": "BOOL"}, body, file=f"{name}.xml")
        if name == "negated":
            src.write_text(src.read_text(encoding="utf-8").replace("<outVariable ", '<outVariable negated="true" '),
                           encoding="utf-8")
        code, _, err = run(capsys, "export", str(src), "-o", str(tmp_path / "out.xml"))
        assert code == 1 and message in err, (name, err)


@pytest.mark.slow
def test_only_writes_the_named_objects_and_names_a_missing_one(tmp_path, capsys):
    out = tmp_path / "one.xml"
    code, stdout, err = run(capsys, "export", str(LIB), str(ROOT / "examples"), "--only", "Commands_Example",
                            "-o", str(out))
    assert code == 0 and "0 data type(s), 1 POU(s)" in stdout, err
    text = out.read_text(encoding="utf-8")
    assert text.count('<Program name="Commands_Example">') == 1 and "<DataTypeDecl" not in text
    assert '<ContentHeader name="Commands_Example"' in text
    code, _, err = run(capsys, "export", str(LIB), "--only", "NoSuchThing", "-o", str(out))
    assert code == 2 and "--only: no data type or POU named NOSUCHTHING" in err


def test_a_device_target_is_written_in_place_and_a_full_device_is_an_error(tmp_path, capsys):
    """`-o /dev/full` once renamed a temporary file over the device (as root) and reported success; a target that
    is not a regular file is now written in place, so the device's own error reaches the user. Reached through a
    symbolic link, so that a regression replaces the link, never the machine's device."""
    if not os.path.exists("/dev/full"):
        pytest.skip("this system has no /dev/full")
    target = tmp_path / "out.xml"
    target.symlink_to("/dev/full")
    code, _out, err = run(capsys, "export", str(LIB), "--format", "iec61131-10", "-o", str(target))
    assert code != 0 and "No space left on device" in err, err
    assert target.is_symlink() and not target.is_file()


def test_a_folder_target_is_refused(tmp_path, capsys):
    code, _out, err = run(capsys, "export", str(LIB), "--format", "iec61131-10", "-o", str(tmp_path))
    assert code == 2 and "is a folder" in err and "Traceback" not in err, err
