"""The one table of diagnostic codes (src/vplc/frontend/diagnostic_codes.tsv) and the code agree.

Every code emitted anywhere in src/vplc is in the table, every code of the table is emitted somewhere (or marked
reserved), every row has a failing and a fixed example, the generated codes.py and docs table are up to date, and
the codes of the lexer and the parser are produced by their failing examples and not by the fixed ones.
"""
from __future__ import annotations

import re
import subprocess
import sys

import pytest
from fe_helpers import ROOT, parse_text, program

from docs.toolchain import make_diagnostics as table
from vplc.frontend import codes as C

SRC = ROOT / "src" / "vplc"
LITERAL = re.compile(r"""["'](ST[0-9]{4})["']""")
NAMED = re.compile(r"\bcodes\.([A-Z][A-Z0-9_]+)\b")


def sources():
    """(path relative to src/vplc, text) of every Python module of vplc but the generated codes.py."""
    for path in sorted(SRC.rglob("*.py")):
        if path != table.CODES_PY:
            yield path.relative_to(SRC).as_posix(), path.read_text(encoding="utf-8")


def emitted() -> dict[str, set[str]]:
    """{code: modules that emit or test it}, by constant name or by literal."""
    found: dict[str, set[str]] = {}
    for rel, text in sources():
        for code in LITERAL.findall(text):
            found.setdefault(code, set()).add(rel)
        for name in NAMED.findall(text):
            found.setdefault(C.BY_NAME.get(name, f"unknown name codes.{name}"), set()).add(rel)
    return found


def test_generated_files_agree_with_the_table():
    result = subprocess.run([sys.executable, str(table.HERE / "make_diagnostics.py"), "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def test_codes_module_matches_the_table():
    rows = table.load()
    assert {row["name"]: code for code, row in rows.items()} == C.BY_NAME
    assert all(getattr(C, name) == code for name, code in C.BY_NAME.items())


def test_every_emitted_code_is_in_the_table():
    rows = table.load()
    unknown = {code: sorted(where) for code, where in emitted().items() if code not in rows}
    assert unknown == {}


def test_every_code_of_the_table_is_emitted_or_reserved():
    found = emitted()
    silent = [code for code, row in table.load().items() if row["severity"] != table.RESERVED and code not in found]
    assert silent == []


def test_every_code_has_a_meaning_a_failing_and_a_fixed_example():
    rows = table.load()
    assert len(rows) >= 76
    for code, row in rows.items():
        assert row["meaning"] and row["failing"] and row["fixed"], code
        assert row["failing"] != row["fixed"], code


def test_a_malformed_table_is_refused_with_its_line(tmp_path):
    bad = tmp_path / "codes.tsv"
    text = table.TABLE.read_text(encoding="utf-8").splitlines()
    bad.write_text("\n".join(text[:3] + [text[2]] + text[3:]) + "\n", encoding="utf-8")
    with pytest.raises(table.TableError, match=r"codes\.tsv:4: code ST\d{4} appears twice"):
        table.load(bad)
    bad.write_text(text[0] + "\nST0001\tFILE_NOT_FOUND\terror\tno such file\t\tfix\n", encoding="utf-8")
    with pytest.raises(table.TableError, match="codes.tsv:2: ST0001 has no failing"):
        table.load(bad)


# The codes of the lexer (ST01xx) and the parser (ST02xx): a failing and a fixed source each.
DEEP = "(" * 300 + "1" + ")" * 300
FRONT_END = {
    C.BAD_CHARACTER: (program("x := a ? b;", "x, a, b : INT;"), program("x := SEL(c, b, a);", "x, a, b : INT;")),
    C.UNCLOSED_COMMENT: ("PROGRAM Main (* note\nEND_PROGRAM\n", "PROGRAM Main (* note *)\nEND_PROGRAM\n"),
    C.UNCLOSED_STRING: (program("s := 'abc;", "s : STRING;"), program("s := 'abc';", "s : STRING;")),
    C.BAD_ESCAPE: (program("s := '5 $Q';", "s : STRING;"), program("s := '5 $$Q';", "s : STRING;")),
    C.UNCLOSED_PRAGMA: ("{attribute 'x'\n" + program(""), "{attribute 'x'}\n" + program("")),
    C.BAD_LITERAL: (program("x := 16#FG;", "x : INT;"), program("x := 16#FF;", "x : INT;")),
    C.PRAGMA_IGNORED: ("{attribute 'hide'}\n" + program(""), program("")),
    C.UNEXPECTED_TOKEN: (program("x := ;", "x : INT;"), program("x := 0;", "x : INT;")),
    C.MISSING_END: ("PROGRAM Main\nIF a THEN b := 1;\nEND_PROGRAM\n",
                    "PROGRAM Main\nIF a THEN b := 1; END_IF;\nEND_PROGRAM\n"),
    C.NESTING_TOO_DEEP: (program(f"x := {DEEP};", "x : INT;"), program("x := 1;", "x : INT;")),
    C.EQUALS_TO_ASSIGN: (program("y = 3;", "y : INT;"), program("y := 3;", "y : INT;")),
    C.MISSING_SEMICOLON: (program("x := 1\ny := 2;", "x, y : INT;"), program("x := 1;\ny := 2;", "x, y : INT;")),
    C.STRAY_TEXT: ("garbage\n" + program(""), program("")),
    C.UNSUPPORTED_EXTENSION: ("FUNCTION_BLOCK A EXTENDS B\nEND_FUNCTION_BLOCK\n",
                              "FUNCTION_BLOCK A\nVAR Base : B; END_VAR\nEND_FUNCTION_BLOCK\n"),
}


def test_the_lexer_and_parser_codes_are_all_covered():
    in_table = {code for code in table.load() if code.startswith(("ST01", "ST02"))}
    assert set(FRONT_END) == in_table and len(in_table) == 14


@pytest.mark.parametrize("code", sorted(FRONT_END))
def test_lexer_and_parser_codes_come_from_their_failing_example(code):
    failing, fixed = FRONT_END[code]
    assert code in [d.code for d in parse_text(failing)[1]]
    assert code not in [d.code for d in parse_text(fixed)[1]]


def test_no_module_writes_a_code_as_a_literal():
    literals = {rel: sorted(set(LITERAL.findall(text))) for rel, text in sources() if LITERAL.search(text)}
    assert literals == {}, "use the names of vplc.frontend.codes"
