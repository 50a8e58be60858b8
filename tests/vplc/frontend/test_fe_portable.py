"""--portable rules ST2004-ST2011: each construct that IEC 61131-3 2nd edition compilers reject is reported
with its own code (failing example), and the portable rewrite is not (passing example)."""
import pytest
from fe_helpers import check_text, codes

FN = """
FUNCTION Bump : BOOL
VAR_INPUT N : INT; END_VAR
Bump := N > 0;
END_FUNCTION
FUNCTION Now0 : INT
Now0 := 1;
END_FUNCTION
FUNCTION Fill : BOOL
VAR_IN_OUT Buf : ARRAY[0..3] OF BYTE; END_VAR
Fill := TRUE;
END_FUNCTION
TYPE stBuf : STRUCT Bytes : ARRAY[0..3] OF BYTE; END_STRUCT; END_TYPE
FUNCTION FillS : BOOL
VAR_IN_OUT Buf : stBuf; END_VAR
FillS := TRUE;
END_FUNCTION
"""

CASES = [
    ("ST2004", "TYPE eM : (Idle := 0, Busy := 1); END_TYPE", "TYPE eM : (Idle, Busy); END_TYPE"),
    ("ST2005", "PROGRAM P VAR Step : INT; END_VAR Step := 1; END_PROGRAM",
     "PROGRAM P VAR ConnStep : INT; END_VAR ConnStep := 1; END_PROGRAM"),
    ("ST2006", "PROGRAM P VAR c : UINT; t : INT; END_VAR CASE c OF 16#10: t := 1; END_CASE; END_PROGRAM",
     "PROGRAM P VAR c : UINT; t : INT; END_VAR CASE c OF 16: t := 1; END_CASE; END_PROGRAM"),
    ("ST2007", FN + "PROGRAM P VAR b : BOOL; END_VAR Bump(N := 1); END_PROGRAM",
     FN + "PROGRAM P VAR b : BOOL; END_VAR b := Bump(N := 1); END_PROGRAM"),
    ("ST2008", "TYPE eM : (Idle, Busy); END_TYPE PROGRAM P VAR m : eM; b : BOOL; END_VAR b := m >= Busy; END_PROGRAM",
     "TYPE eM : (Idle, Busy); END_TYPE PROGRAM P VAR m : eM; b : BOOL; END_VAR b := m = Busy; END_PROGRAM"),
    ("ST2009", FN + "PROGRAM P VAR i : INT; END_VAR i := Now0(); END_PROGRAM",
     FN + "PROGRAM P VAR b : BOOL; END_VAR b := Bump(N := 1); END_PROGRAM"),
    ("ST2010", "PROGRAM P VAR s : STRING[9]; t : STRING[9]; END_VAR t := UINT_TO_STRING(LEN(s)); END_PROGRAM",
     "PROGRAM P VAR s : STRING[9]; t : STRING[9]; END_VAR t := INT_TO_STRING(LEN(s)); END_PROGRAM"),
    ("ST2011", FN + "PROGRAM P VAR a : ARRAY[0..3] OF BYTE; b : BOOL; END_VAR b := Fill(Buf := a); END_PROGRAM",
     FN + "PROGRAM P VAR a : stBuf; b : BOOL; END_VAR b := FillS(Buf := a); END_PROGRAM"),
]


@pytest.mark.parametrize("code, failing, passing", CASES, ids=[c[0] for c in CASES])
def test_portable_rule_reports_the_failing_example_and_not_the_fixed_one(tmp_path, code, failing, passing):
    bad = check_text(tmp_path, failing, "bad.st", portable=True)
    good = check_text(tmp_path, passing, "good.st", portable=True)
    assert code in codes(bad, "warning"), bad.render_diagnostics()
    assert code not in codes(good), good.render_diagnostics()
    assert not bad.has_errors and not good.has_errors


def test_portable_rules_are_silent_without_portable_and_under_platform(tmp_path):
    failing = CASES[0][1] + "\n" + CASES[1][1]
    assert not {"ST2004", "ST2005"} & set(codes(check_text(tmp_path, failing, "plain.st")))
    (tmp_path / "platform").mkdir()
    assert not {"ST2004", "ST2005"} & set(codes(check_text(tmp_path, failing, "platform/p.st", portable=True)))


def test_portable_warning_points_at_file_line_col_with_a_fix(tmp_path):
    proj = check_text(tmp_path, CASES[1][1], "kw.st", portable=True)
    text = proj.render_diagnostics()
    assert "kw.st:1:" in text and "warning[ST2005]" in text and "rename it" in text


def test_st2004_and_st2008_messages_come_out_whole_in_text_and_json(tmp_path):
    """Two quoted names in one message: the prose between them is not a quote and is never shortened."""
    import json

    from vplc.frontend.diagnostics import to_json
    proj = check_text(tmp_path, "TYPE eColor : (Red := 0, Green := 1); END_TYPE\n"
                      "PROGRAM P VAR c : eColor; b : BOOL; END_VAR b := c > Red; END_PROGRAM", portable=True)
    messages = {(d.code, d.message) for d in proj.diagnostics}
    assert ("ST2004", "enumeration value `Red` has an explicit number, which is IEC 61131-3 3rd edition only; "
            "write `Red` without `:= ...`; the values are already in number order from 0") in messages
    assert ("ST2008", "`>` on values of the enumeration eColor: IEC 61131-3 enumerations have no order; "
            "compare with `=` / `<>` for each state") in messages
    rendered = proj.render_diagnostics()
    assert "…" not in rendered
    assert {d["message"] for d in json.loads(to_json(proj.diagnostics))["diagnostics"]} == {m for _, m in messages}


def test_a_long_quoted_name_is_shown_by_its_ends_and_the_prose_stays_whole(tmp_path):
    name = "Very" + "Long" * 30 + "Name"
    proj = check_text(tmp_path, f"PROGRAM P VAR x : INT; END_VAR x := {name}; END_PROGRAM")
    (diag,) = [d for d in proj.diagnostics if d.code == "ST1001"]
    assert diag.message == (f"`{name[:28]}…{name[-28:]}` is not declared; declare it in a VAR section or check "
                            "the spelling")
