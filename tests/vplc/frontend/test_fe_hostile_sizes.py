"""Hostile sizes (issue 23 item 9): a huge string literal, deeply nested comments and data types too large to hold
cost the front end memory and time in proportion to the input, never more, and end in a diagnostic.

Memory is measured in a subprocess (tracemalloc peak); work is counted, never timed."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest
from fe_helpers import check_text, codes, program

from vplc.frontend import lexer

_MEASURE = r"""
import json, sys, tracemalloc
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.lexer import tokenize
from vplc.frontend.source import SourceFile
n, quote = int(sys.argv[1]), sys.argv[2]
body = sys.argv[3] * (n // len(sys.argv[3]))
text = "PROGRAM Main VAR s : STRING[10]; END_VAR s := " + quote + body + quote + "; END_PROGRAM"
tracemalloc.start()
tokens = tokenize(SourceFile("x.st", text), DiagnosticBag())
peak = tracemalloc.get_traced_memory()[1]
print(json.dumps({"peak": peak, "n": len(body), "kinds": [t.kind for t in tokens]}))
"""


def _lex_peak(n: int, quote: str, unit: str) -> dict:
    out = subprocess.run([sys.executable, "-c", _MEASURE, str(n), quote, unit],
                         capture_output=True, text=True, check=True, timeout=120)
    return json.loads(out.stdout)


def test_a_long_string_literal_is_lexed_in_memory_proportional_to_nothing_but_its_text():
    # was ~650 bytes of regular-expression backtracking state per character (10 MB -> MemoryError)
    for quote, unit in (("'", "a"), ("'", "$$"), ('"', "ab$N")):
        r = _lex_peak(400_000, quote, unit)
        assert "STRING" in r["kinds"] or "WSTRING" in r["kinds"]
        assert r["peak"] < 4 * r["n"] + 200_000, (quote, unit, r["peak"])


_MEASURE_TEXT = r"""
import json, sys, tracemalloc
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.lexer import tokenize
from vplc.frontend.source import SourceFile
text = sys.argv[1] + sys.argv[2] * int(sys.argv[3]) + sys.argv[4]
tracemalloc.start()
tokens = tokenize(SourceFile("x.st", text), DiagnosticBag())
print(json.dumps({"peak": tracemalloc.get_traced_memory()[1], "n": len(text), "kinds": [t.kind for t in tokens]}))
"""


def test_long_duration_and_address_literals_are_lexed_in_memory_proportional_to_their_text():
    # a T# literal of 200,000 units took ~500 bytes per character, a %IX address of 200,000 parts ~330
    for head, unit, tail, kind in (("T#", "1s", ";", "TIME"), ("%IX1", ".1", ";", "ADDRESS")):
        out = subprocess.run([sys.executable, "-c", _MEASURE_TEXT, head, unit, "200000", tail],
                             capture_output=True, text=True, check=True, timeout=120)
        r = json.loads(out.stdout)
        assert r["kinds"][0] == kind and r["peak"] < 4 * r["n"] + 200_000, (kind, r["peak"])


def test_a_long_string_literal_too_long_for_its_variable_is_reported_where_it_is(tmp_path):
    proj = check_text(tmp_path, program("s := '" + "a" * 200_000 + "';", "s : STRING[10];"))
    d = [d for d in proj.diagnostics if d.code == "ST1601"]
    assert len(d) == 1 and d[0].span.line == 5 and "200000 characters" in d[0].message


class _CountingText(str):
    """A source text that counts how many characters its ``find`` calls pass over."""
    scanned = 0

    def find(self, sub, start=0, end=None):
        hit = str.find(self, sub, start) if end is None else str.find(self, sub, start, end)
        _CountingText.scanned += (hit if hit >= 0 else len(self)) - start
        return hit


def _scanned(text: str) -> tuple[int, int]:
    _CountingText.scanned = 0
    stop = lexer.comment_end(_CountingText(text), 0)
    return stop, _CountingText.scanned


def test_nested_comments_are_read_once_not_once_per_level():
    # 100,000 nested comments took over a minute: each level searched the rest of the text again
    for depth in (1_000, 4_000):
        text = "(*" * depth + "*)" * depth + " x"
        stop, scanned = _scanned(text)
        assert stop == 4 * depth
        assert scanned <= 2 * len(text), (depth, scanned)


def _reference_skip(text: str, pos: int) -> int:
    """Character by character: the meaning the linear scan must keep."""
    opener = text[pos:pos + 2]
    closer = "*)" if opener == "(*" else "*/"
    depth, i = 0, pos
    while i < len(text):
        if text.startswith(opener, i):
            depth, i = depth + 1, i + 2
        elif text.startswith(closer, i):
            depth, i = depth - 1, i + 2
            if depth == 0:
                return i
        else:
            i += 1
    return -1


def test_the_linear_comment_scan_ends_every_comment_where_the_nesting_rules_end_it():
    import random
    rng = random.Random(23)
    for _ in range(3000):
        body = "".join(rng.choice(["(", "*", ")", "/", "a", "(*", "*)", "/*", "*/"]) for _ in range(rng.randint(0, 14)))
        for opener in ("(*", "/*"):
            text = opener + body
            assert lexer.comment_end(text, 0) == _reference_skip(text, 0), text


@pytest.mark.slow
def test_a_deeply_nested_comment_closes_and_an_unclosed_one_is_reported(tmp_path):
    depth = 5_000
    proj = check_text(tmp_path, program("(*" * depth + " note " + "*)" * depth + "\nx := 1;", "x : INT;"))
    assert codes(proj, "error") == []
    proj = check_text(tmp_path, program("(*" * depth + "*)" * (depth - 1) + "\nx := 1;", "x : INT;"))
    assert "ST0102" in codes(proj, "error")


def _nested(levels: int, element: str = "INT") -> str:
    t = element
    for _ in range(levels):
        t = f"ARRAY[0..1] OF {t}"
    return t


def test_a_variable_too_large_to_hold_is_an_error_at_its_declaration(tmp_path):
    # ARRAY[0..1] OF ... nested 30 deep checked clean, then `run` grew past 2.2 GB
    proj = check_text(tmp_path, program("g[0][0][0] := g[1][1][1];", f"g : {_nested(30)};"))
    d = [d for d in proj.diagnostics if d.code == "ST1502"]
    assert len(d) == 1 and (d[0].span.line, d[0].span.column) == (3, 1)
    assert "`g` holds more than 4,194,304 cells" in d[0].message
    proj = check_text(tmp_path, program("b[0, 0] := 1;", "b : ARRAY[0..99999, 0..99999] OF BYTE;"))
    assert codes(proj, "error") == ["ST1502"]


def test_containers_count_and_large_but_modelled_data_checks_clean(tmp_path):
    # 2^21 values in 2^21 - 1 arrays: 4,194,303 cells, just under the limit; 2^22 values are over it
    assert codes(check_text(tmp_path, program("g" + "[0]" * 21 + " := 1;", f"g : {_nested(21)};")), "error") == []
    assert codes(check_text(tmp_path, program("g" + "[0]" * 22 + " := 1;", f"g : {_nested(22)};")), "error") \
        == ["ST1502"]
    assert codes(check_text(tmp_path, program("b[0] := 1;", "b : ARRAY[0..4194301] OF BYTE;")), "error") == []


def test_instances_structures_and_globals_count_towards_the_limit(tmp_path):
    src = """
    TYPE stBig : STRUCT a : ARRAY[0..2999999] OF INT; END_STRUCT; END_TYPE
    FUNCTION_BLOCK FbBig
    VAR d : stBig; END_VAR
    d.a[0] := 1;
    END_FUNCTION_BLOCK
    PROGRAM Main
    VAR one : FbBig; two : FbBig; END_VAR
    one(); two();
    END_PROGRAM
    VAR_GLOBAL
      G1 : ARRAY[0..2999999] OF BYTE;
      G2 : ARRAY[0..2999999] OF BYTE;
    END_VAR
    """
    proj = check_text(tmp_path, src)
    found = {(d.code, d.span.line) for d in proj.diagnostics if d.severity == "error"}
    assert found == {("ST1502", 7), ("ST1502", 13)}
    messages = " ".join(d.message for d in proj.diagnostics if d.code == "ST1502")
    assert "instance data of PROGRAM `Main`" in messages and "global variables up to `G2`" in messages
