"""Bad input: each case gives a clear diagnostic and exit 1 — never a traceback or a hang."""
from __future__ import annotations

import pytest
from fe_helpers import check_text

from vplc.frontend import codes
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.project import read_source


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
