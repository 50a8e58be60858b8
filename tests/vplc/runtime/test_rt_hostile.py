"""Hostile programs (issue 23 item 9): a scan made of large copies and no loop meets the watchdog; a ladder rung of
thousands of contacts in series compiles and runs in memory proportional to its length.

Nothing here is timed: the watchdog test only needs a scan far longer than a small watchdog; memory is measured in
a subprocess."""
from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest
from rt_helpers import plc_from

from vplc.api import PlcFault, compile_program

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_a_scan_of_large_array_copies_without_a_loop_is_stopped_by_the_watchdog(tmp_path):
    # 400 whole-array copies of 500,000 DINTs: no ST loop, so no loop check ever ran (a 5 s scan went on)
    plc = plc_from(tmp_path, "a := b; b := a;\n" * 200, "a, b : ARRAY[0..499999] OF DINT;", watchdog_ms=5)
    with pytest.raises(PlcFault) as exc:
        plc.scan(0)
    assert exc.value.kind == "watchdog"
    assert "watchdog: scan exceeded 5 ms (still copying large arrays or structures)" in str(exc.value)
    assert exc.value.file.endswith("main.st") and exc.value.line >= 5


def test_only_statements_moving_large_values_carry_the_watchdog_check(tmp_path):
    src = tmp_path / "m.st"
    src.write_text("TYPE stP : STRUCT x, y : REAL; END_STRUCT; END_TYPE\n"
                   "PROGRAM Main\nVAR p, q : stP; s, t : ARRAY[0..99] OF INT; a, b : ARRAY[0..4095] OF BYTE; "
                   "END_VAR\np := q;\ns := t;\na := b;\nEND_PROGRAM\n", encoding="utf-8")
    code = compile_program([str(src)]).source
    assert code.count("still copying large arrays or structures") == 1



_BIG_POUS = """
TYPE stBig : STRUCT x : INT; arr : ARRAY[0..2047] OF INT; END_STRUCT; END_TYPE
FUNCTION_BLOCK FbRef
VAR_IN_OUT Big : stBig; END_VAR
VAR_INPUT Small : INT; END_VAR
VAR_OUTPUT Seen : INT; END_VAR
Seen := Big.x + Small;
END_FUNCTION_BLOCK
FUNCTION FnRef : INT
VAR_IN_OUT Big : stBig; END_VAR
FnRef := Big.arr[1];
END_FUNCTION
FUNCTION FnArr : INT
VAR_INPUT In : ARRAY[0..1023] OF INT; END_VAR
FnArr := In[0];
END_FUNCTION
FUNCTION_BLOCK FbVal
VAR_INPUT BigIn : stBig; END_VAR
VAR_OUTPUT BigOut : stBig; END_VAR
BigOut.x := BigIn.x;
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("body, checked", [
    ("c.x := 1;", False), ("y := c.arr[3];", False), ("c.arr[4] := y;", False),   # reached through, not copied
    ("r(Big := c, Small := 3);", False), ("y := FnRef(Big := c);", False),          # in-outs: references
    ("d := c;", True), ("v(BigIn := c);", True), ("v(BigOut => d);", True),         # whole values moved
    ("y := FnArr(In := k[5]);", True), ("y := FnArr(In := c.arr[5]);", True),       # the array from that element
])
def test_the_large_copy_check_follows_what_a_statement_copies_not_what_it_reaches_through(tmp_path, body, checked):
    src = tmp_path / "m.st"
    src.write_text("PROGRAM Main\nVAR c, d : stBig; y : INT; r : FbRef; v : FbVal; k : ARRAY[0..1999] OF INT; "
                   f"END_VAR\n{body}\nEND_PROGRAM\n{_BIG_POUS}", encoding="utf-8")
    code = compile_program([str(src)]).source
    assert code.count("still copying large arrays or structures") == int(checked)


def test_large_copies_inside_a_function_block_given_large_in_outs_are_stopped_by_the_watchdog(tmp_path):
    # the call hands the arrays over by reference (no check after it); the copies in the body carry their own
    churn = ("FUNCTION_BLOCK Churn\nVAR_IN_OUT a, b : ARRAY[0..499999] OF DINT; END_VAR\n"
             + "a := b; b := a;\n" * 100 + "END_FUNCTION_BLOCK\n")
    plc = plc_from(tmp_path, "ch(a := x, b := z);\n" * 2, "x, z : ARRAY[0..499999] OF DINT; ch : Churn;",
                   extra=churn, watchdog_ms=5)
    with pytest.raises(PlcFault) as exc:
        plc.scan(0)
    assert exc.value.kind == "watchdog"
    assert "watchdog: scan exceeded 5 ms (still copying large arrays or structures)" in str(exc.value)
    assert exc.value.instance is not None and "ch" in exc.value.instance.lower()

def test_a_member_of_a_large_function_result_is_a_copy_the_watchdog_checks(tmp_path):
    # MkBig(3).x builds the whole 100,000-cell result in every call: the functions' frames carry the check
    make = ("TYPE stHuge : STRUCT x : INT; arr : ARRAY[0..99999] OF INT; END_STRUCT; END_TYPE\n"
            "FUNCTION MkBig : stHuge\nVAR_INPUT v : INT; END_VAR\nMkBig.x := v;\nEND_FUNCTION\n"
            "FUNCTION MkArr : ARRAY[0..99999] OF INT\nVAR_INPUT v : INT; END_VAR\nMkArr[0] := v;\nEND_FUNCTION\n")
    src = tmp_path / "m.st"
    src.write_text(f"PROGRAM Main\nVAR y : INT; END_VAR\ny := MkBig(3).x;\ny := MkArr(4)[0];\nEND_PROGRAM\n{make}",
                   encoding="utf-8")
    assert compile_program([str(src)]).source.count("still copying large arrays or structures") == 2
    plc = plc_from(tmp_path, "y := MkBig(3).x;\ny := MkArr(4)[0];\n" * 300, "y : INT;", extra=make, watchdog_ms=5)
    with pytest.raises(PlcFault) as exc:
        plc.scan(0)
    assert exc.value.kind == "watchdog"
    assert "watchdog: scan exceeded 5 ms (still copying large arrays or structures)" in str(exc.value)


@pytest.mark.parametrize("call, decls, pou", [
    ("y := FnLocal(1);", "y : INT;",
     "FUNCTION FnLocal : INT\nVAR_INPUT v : INT; END_VAR\n"
     "VAR tmp : ARRAY[0..99999] OF INT; END_VAR\nFnLocal := tmp[v] + v;\nEND_FUNCTION\n"),
    ("f(v := 1);", "f : FbTemp;",
     "FUNCTION_BLOCK FbTemp\nVAR_INPUT v : INT; END_VAR\nVAR_OUTPUT o : INT; END_VAR\n"
     "VAR_TEMP tmp : ARRAY[0..99999] OF INT; END_VAR\no := tmp[v] + v;\nEND_FUNCTION_BLOCK\n"),
    ("y := FnOmit(v := 1);", "y : INT;",                  # an input the call leaves out: its default is built
     "FUNCTION FnOmit : INT\nVAR_INPUT v : INT; In : ARRAY[0..99999] OF INT; END_VAR\nFnOmit := In[v];\n"
     "END_FUNCTION\n"),
])
def test_a_call_that_builds_large_variables_of_its_own_is_checked_by_the_watchdog(tmp_path, call, decls, pou):
    # a function's variables and an FB's VAR_TEMP are built afresh by every call (100,000 cells here), though the
    # statements only reach through them: the call's frame, or the call leaving out a large input, carries the check
    plc = plc_from(tmp_path, (call + "\n") * 300, decls, extra=pou, watchdog_ms=5)
    with pytest.raises(PlcFault) as exc:
        plc.scan(0)
    assert exc.value.kind == "watchdog"
    assert "watchdog: scan exceeded 5 ms (still copying large arrays or structures)" in str(exc.value)


@pytest.mark.parametrize("statement", [
    "IF FnW(In := k) > 0 THEN n := 5; END_IF;", "CASE FnW(In := k) OF 1: n := 5; END_CASE;",
    "WHILE FnW(In := k) < 0 DO n := 5; END_WHILE;",             # (no iteration: no loop check)
])
def test_a_large_copy_in_a_condition_is_checked_by_the_watchdog(tmp_path, statement):
    # FnW writes its input: every call copies the 100,000-cell array into it
    fn = ("FUNCTION FnW : INT\nVAR_INPUT In : ARRAY[0..99999] OF INT; END_VAR\n"
          "In[0] := In[0] + 1; FnW := In[0];\nEND_FUNCTION\n")
    plc = plc_from(tmp_path, (statement + "\n") * 300, "n, i : INT; k : ARRAY[0..99999] OF INT;", extra=fn,
                   watchdog_ms=5)
    with pytest.raises(PlcFault) as exc:
        plc.scan(0)
    assert exc.value.kind == "watchdog"
    assert "watchdog: scan exceeded 5 ms (still copying large arrays or structures)" in str(exc.value)


def test_whole_array_assignment_copies_every_element(tmp_path):
    plc = plc_from(tmp_path, """
        b[7] := 7; b[99999] := -1; a := b;
        n[0].k[2] := 5; m := n;
        """, """
        a, b : ARRAY[0..99999] OF DINT;
        m, n : ARRAY[0..2] OF stK;
        """, extra="TYPE stK : STRUCT k : ARRAY[0..3] OF INT; END_STRUCT; END_TYPE\n")
    plc.scan(0)
    assert plc.read("Main.a[7]") == 7 and plc.read("Main.a[99999]") == -1 and plc.read("Main.a[8]") == 0
    assert plc.read("Main.m[0].k[2]") == 5
    plc.write("Main.a[7]", 1)
    assert plc.read("Main.b[7]") == 7                 # a copy, not the same array


def _series_rung_xml(n: int) -> str:
    """A PLCopen XML program with one rung: the left rail, ``n`` contacts on A in series, a coil Q."""
    parts = ['<leftPowerRail localId="1"><position x="0" y="0"/><connectionPointOut/></leftPowerRail>']
    prev = 1
    for i in range(n):
        lid = 10 + i
        parts.append(f'<contact localId="{lid}"><position x="{i}" y="0"/><connectionPointIn>'
                     f'<connection refLocalId="{prev}"/></connectionPointIn><connectionPointOut/>'
                     f'<variable>{"B" if i == n // 2 else "A"}</variable></contact>')
        prev = lid
    parts.append(f'<coil localId="5"><position x="{n}" y="0"/><connectionPointIn><connection refLocalId="{prev}"/>'
                 '</connectionPointIn><connectionPointOut/><variable>Q</variable></coil>')
    parts.append('<rightPowerRail localId="6"><position x="0" y="0"/><connectionPointIn>'
                 '<connection refLocalId="5"/></connectionPointIn></rightPowerRail>')
    variables = "".join(f'<variable name="{v}"><type><BOOL/></type></variable>' for v in "ABQ")
    return ('<?xml version="1.0" encoding="utf-8"?>\n<project xmlns="http://www.plcopen.org/xml/tc6_0201">'
            '<fileHeader companyName="t" productName="t" productVersion="1" creationDateTime="2024-01-01T00:00:00"/>'
            '<contentHeader name="t"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/>'
            '</ld><sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader><types><dataTypes/><pous>'
            '<pou name="Main" pouType="program"><interface><localVars>' + variables + '</localVars></interface>'
            '<body><LD>' + "".join(parts) + '</LD></body></pou></pous></types><instances><configurations/>'
            '</instances></project>\n')


def test_a_rung_of_a_thousand_contacts_in_series_runs_with_the_meaning_of_the_drawing(tmp_path):
    path = tmp_path / "series.xml"
    path.write_text(_series_rung_xml(1000), encoding="utf-8")
    from vplc.api import load_plc
    plc = load_plc([str(path)])
    for a, b, q in ((True, True, True), (True, False, False), (False, True, False), (True, True, True)):
        plc.write("Main.A", a)
        plc.write("Main.B", b)
        plc.scan(plc.now_ns + 1_000_000)
        assert plc.read("Main.Q") is q


_MEASURE = r"""
import json, sys, tracemalloc
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.parser import parse
from vplc.ladder import plcopen_read
from vplc.ladder.translate import unit_source
from vplc.ladder.xmlsafe import read
out = {}
for n in (400, 1600):
    path = sys.argv[1] + f"/s{n}.xml"                # written by the test before this process starts
    units = list(plcopen_read.read(read(path)[1]))
    tracemalloc.start()
    diags = DiagnosticBag()
    for unit in units:                      # the rung into ST, the ST into a syntax tree
        parse(unit_source(path, unit), diags)
    out[n] = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert not diags.items, [d.message for d in diags.items]
print(json.dumps(out))
"""


def test_a_long_series_rung_is_translated_in_memory_linear_in_its_length(tmp_path):
    # 10,000 contacts in series took 1.96 GB (20,000: out of memory): each contact's power was a copy of the whole
    # expression before it, and every copy was kept
    for n in (400, 1600):
        (tmp_path / f"s{n}.xml").write_text(_series_rung_xml(n), encoding="utf-8")
    out = subprocess.run([sys.executable, "-c", _MEASURE, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    peak = {int(k): v for k, v in json.loads(out.stdout).items()}
    assert peak[1600] < 5 * peak[400], peak            # linear (4x contacts), not quadratic (16x)
    assert peak[1600] < 16_000_000, peak


def test_thousands_of_elsif_branches_compile_as_chains_with_first_match_semantics(tmp_path):
    # 6,000 ELSIF branches ended in "the runtime cannot compile this program:" (Python nests each elif one level
    # deeper): the chain is now cut every 200 branches, as a long CASE is; 450 branches make three chains
    n = 450
    branches = "".join(f"ELSIF x = {i} THEN y := {i};\n" for i in range(1, n))
    body = f"IF x = 0 THEN y := 0;\n{branches}ELSIF x >= 0 THEN y := -2;\nELSE y := -1;\nEND_IF;\nz := z + 1;\n"
    plc = plc_from(tmp_path, body, "x, y, z : DINT;")
    code = compile_program([str(tmp_path / "main.st")]).source
    runs, run = [], 0
    for line in code.splitlines():
        run = run + 1 if line.lstrip().startswith("elif ") else 0
        runs.append(run)
    assert max(runs) < 200
    for scan, (x, y) in enumerate([(0, 0), (199, 199), (200, 200), (201, 201), (449, 449), (450, -2), (-7, -1)]):
        plc.write("Main.x", x)
        plc.scan(scan * 1_000_000)
        assert plc.read("Main.y") == y, x
    assert plc.read("Main.z") == 7


def test_drawing_a_long_rung_looks_at_each_element_a_bounded_number_of_times(tmp_path, monkeypatch):
    # `vplc draw` of 10,000 contacts in series took 16 s: fitting each name looked at every element before it.
    # Counted here: how often a name is measured while the rung is laid out
    from vplc.ladder import layout
    from vplc.project import load_project
    calls = [0]
    measure = layout.text_width

    def counting(text, scale=1.0):
        calls[0] += 1
        return measure(text, scale)
    monkeypatch.setattr(layout, "text_width", counting)
    counts = {}
    for n in (200, 800):
        path = tmp_path / f"s{n}.xml"
        path.write_text(_series_rung_xml(n), encoding="utf-8")
        rung = load_project([str(path)]).lookup_pou("Main").pou.ladder.rungs[0]
        calls[0] = 0
        lay = layout.layout_rung(rung, 1)
        counts[n] = calls[0]
        xs = [lay.placed[e.id].x for e in rung.elements if e.kind == "contact"]
        assert xs == sorted(xs) and len(set(xs)) == n          # one contact after the other, none on another
    assert counts[800] <= 4 * counts[200] + 50, counts           # linear, not quadratic (16x)
