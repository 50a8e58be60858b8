"""Bad input: each case gives a clear diagnostic and exit 1 — never a traceback or a hang."""
from __future__ import annotations

import os
import threading

import pytest
from fe_helpers import check_text

from vplc import project as vplc_project
from vplc.frontend import codes
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.project import load_project, read_source


def _write(tmp_path, name, data):
    p = tmp_path / name
    if isinstance(data, bytes):
        p.write_bytes(data)
    else:
        p.write_text(data, encoding="utf-8")
    return str(p)


CASES = {
    "binary": (b"\x7fELF\x00\x01\x02" + bytes(range(256)), "ST0003"),
    "latin1": (b"PROGRAM P (* caf\xe9 *) END_PROGRAM", "ST0002"),
    "empty": ("", "ST0004"),
    "deep_parens": ("PROGRAM P VAR x : INT; END_VAR x := " + "(" * 10000 + "1" + ")" * 10000 + "; END_PROGRAM",
                    "ST0203"),
    "deep_unary": ("PROGRAM P VAR x : INT; END_VAR x := " + "-" * 10000 + "1; END_PROGRAM", "ST0203"),
    "long_line": ("PROGRAM P VAR x : INT; END_VAR x := " + "y" * 1_000_000 + "; END_PROGRAM", "ST1001"),
    "unclosed_comment": ("PROGRAM P (* " + "x" * 1000, "ST0102"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_file_gives_diagnostic_and_exit_1(tmp_path, name, run_cli):
    data, code = CASES[name]
    result = run_cli("check", _write(tmp_path, f"{name}.st", data))
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"error[{code}]" in result.stdout
    assert "Traceback" not in result.stdout + result.stderr
    assert max(len(line) for line in result.stdout.splitlines()) < 1000


def test_a_link_to_nothing_and_a_link_loop_are_named_as_links(tmp_path):
    os.symlink(tmp_path / "gone.st", tmp_path / "dangling.st")
    os.symlink(tmp_path / "b.st", tmp_path / "a.st")
    os.symlink(tmp_path / "a.st", tmp_path / "b.st")
    for name in ("dangling.st", "a.st"):
        [d] = load_project([str(tmp_path / name)]).diagnostics
        assert d.code == codes.FILE_NOT_FOUND and "is a symbolic link to nothing" in d.message


def test_missing_file_gives_diagnostic_and_exit_1(tmp_path, run_cli):
    result = run_cli("check", str(tmp_path / "nope.st"))
    assert result.returncode == 1 and "error[ST0001]" in result.stdout and "does not exist" in result.stdout


def test_one_million_character_line_of_valid_code_checks(tmp_path, run_cli):
    path = _write(tmp_path, "wide.st",
                  "PROGRAM P VAR x : INT; END_VAR x := 1;" + " " * 1_000_000 + "x := x; END_PROGRAM")
    result = run_cli("check", path)
    assert result.returncode == 0, result.stdout


def test_a_path_that_cannot_be_read_gives_st0005(tmp_path):
    """A directory handed to the reader as a file: the OS refuses to read it; an error, not a traceback."""
    diags = DiagnosticBag()
    assert read_source(str(tmp_path), diags) is None
    [d] = diags.items
    assert d.code == codes.FILE_UNREADABLE == "ST0005" and d.is_error
    assert d.message.startswith("cannot read `") and "`: " in d.message   # then the OS's reason


OPEN_ARRAY = """
FUNCTION_BLOCK Fixed
VAR_IN_OUT Data : ARRAY[0..3] OF INT; END_VAR
Data[0] := 1;
END_FUNCTION_BLOCK

FUNCTION_BLOCK Open
VAR_IN_OUT Data : ARRAY[*] OF INT; END_VAR
VAR Copy : ARRAY[0..3] OF INT; Inner : Fixed; END_VAR
Copy := Data;
Inner(Data := Data);
Data := Copy;
END_FUNCTION_BLOCK
"""


def test_an_open_array_where_a_fixed_size_array_is_expected_is_a_type_error_not_a_traceback(tmp_path):
    """The length of an ARRAY[*] in-out is the caller's: it fits no fixed-size array (copying into the open array
    is allowed). The checker compared the bounds of both and stopped on the open one's missing bounds."""
    proj = check_text(tmp_path, OPEN_ARRAY)
    errors = [(d.code, d.span.file.line_col(d.span.start)[0]) for d in proj.diagnostics if d.is_error]
    assert errors == [(codes.TYPE_MISMATCH, 10), (codes.ARGUMENT_TYPE, 11)]
    assert "cannot use a value of type ARRAY[*] OF INT where ARRAY[0..3] OF INT is expected" in \
        proj.diagnostics[0].message


def test_a_pipe_a_device_and_a_utf16_file_are_named_for_what_they_are(tmp_path):
    """A named pipe nobody writes to is read at once as an empty file (a plain open would wait for a writer for
    ever), a link to /dev/zero is refused before anything is read (it never ends), a UTF-16 file is named as
    UTF-16 (not as a binary file)."""
    os.mkfifo(tmp_path / "pipe.st")
    os.symlink("/dev/zero", tmp_path / "zero.st")
    (tmp_path / "wide.st").write_bytes("PROGRAM P END_PROGRAM".encode("utf-16"))
    for name, code, words in (("pipe.st", codes.FILE_EMPTY, "is empty"),
                              ("zero.st", codes.FILE_UNREADABLE, "is not a regular file or a pipe"),
                              ("wide.st", codes.FILE_NOT_UTF8, "is UTF-16 text; save the file as UTF-8")):
        diags = DiagnosticBag()
        assert read_source(str(tmp_path / name), diags) is None
        [d] = diags.items
        assert words in d.message and d.code == code, d.message
    project = load_project([str(tmp_path)])          # the folder: each file named, no wait, no traceback
    assert sorted(d.code for d in project.diagnostics) == ["ST0002", "ST0004", "ST0005"]


def test_a_folder_given_as_a_file_leaves_no_descriptor_open(tmp_path):
    """os.open takes a folder; the reader must close it (a long-running caller lost one descriptor a call)."""
    before = len(os.listdir("/proc/self/fd"))
    for _ in range(20):
        diags = DiagnosticBag()
        assert read_source(str(tmp_path), diags) is None
        assert "is not a regular file or a pipe" in diags.items[0].message
    assert len(os.listdir("/proc/self/fd")) == before


def test_a_pipe_with_a_writer_is_read_like_a_file(tmp_path):
    """`vplc check /dev/stdin` and `vplc check <(command)`: what the writer sends, to its end."""
    read_end, write_end = os.pipe()
    text = "PROGRAM P\nVAR x : INT; END_VAR\nx := x + 1;\nEND_PROGRAM\n" * 2000     # more than a pipe holds

    def writer():
        with os.fdopen(write_end, "w") as fh:
            fh.write(text)
    thread = threading.Thread(target=writer)
    thread.start()
    try:
        diags = DiagnosticBag()
        src = read_source(f"/dev/fd/{read_end}", diags)
    finally:
        thread.join(timeout=10)
        os.close(read_end)
    assert diags.items == [] and src is not None and src.text == text


def test_a_pipe_is_read_once_when_a_program_is_compiled_from_it():
    """`vplc run <(command)`: the compiled-program cache's fingerprint read the pipe to its end before the loader,
    which then found it empty (ST0004)."""
    from vplc.api import load_plc
    read_end, write_end = os.pipe()
    with os.fdopen(write_end, "w") as fh:
        fh.write("PROGRAM Main\nVAR x : INT; END_VAR\nx := x + 1;\nEND_PROGRAM\n")
    try:
        plc = load_plc([f"/dev/fd/{read_end}"])
    finally:
        os.close(read_end)
    plc.scan(plc.period_ns)
    assert plc.read("Main.x") == 1
    plc.close()


def test_a_file_over_the_size_limit_is_refused_without_reading_it_all(tmp_path, monkeypatch):
    monkeypatch.setattr(vplc_project, "MAX_SOURCE_BYTES", 100)
    path = _write(tmp_path, "big.st", "PROGRAM P END_PROGRAM " + " " * 200)
    diags = DiagnosticBag()
    assert read_source(path, diags) is None
    [d] = diags.items
    assert d.code == codes.FILE_UNREADABLE and d.message.endswith("big.st`: it is larger than 100 bytes")


@pytest.mark.parametrize("statement", [
    "x := " + "**".join(["1.0"] * 12000) + ";",           # ** had no limit of its own
    "x := y" + ".a" * 15000 + ";", "x := y" + "[0]" * 15000 + ";", "x := y" + "[0]()" * 15000 + ";",
    "y" + ".a" * 15000 + " := 1.0;",
], ids=["power", "members", "indexes", "calls", "assigned_members"])
def test_long_chains_of_power_members_indexes_and_calls_are_st0203_not_a_traceback(tmp_path, statement):
    proj = check_text(tmp_path, f"PROGRAM P\nVAR x : LREAL; y : LREAL; END_VAR\n{statement}\nEND_PROGRAM\n")
    errors = [d for d in proj.diagnostics if d.is_error]
    assert [d.code for d in errors] == ["ST0203"] and "split" in errors[0].message
