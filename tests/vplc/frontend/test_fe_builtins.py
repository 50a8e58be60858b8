"""Standard-function signatures: result types, implicit widening of arguments, and refusals."""
from __future__ import annotations

import pytest
from fe_helpers import check_text, codes, program

from vplc.frontend import builtins as B
from vplc.frontend import types as T

DECLS = ("i : INT; d : DINT; u : UINT; r : REAL; lr : LREAL; w : WORD; b : BYTE; s : STRING[20]; "
         "t : TIME; dt1 : DT; tod1 : TOD; day : DATE; x : BOOL; arr : ARRAY[1..4] OF INT;")

RESULTS = [
    ("ABS(i)", T.INT), ("SQRT(r)", T.REAL), ("SQRT(d)", T.LREAL), ("LN(lr)", T.LREAL), ("EXPT(r, 2)", T.REAL),
    ("ATAN2(r, lr)", T.LREAL), ("MAX(i, d, 5)", T.DINT), ("MIN(u, 1)", T.UINT), ("LIMIT(0, i, 100)", T.INT),
    ("SEL(x, i, d)", T.DINT), ("MUX(1, r, lr, 0.5)", T.LREAL), ("SHL(w, 2)", T.WORD), ("ROR(b, 1)", T.BYTE),
    ("LEN(s)", T.UINT), ("FIND(s, 'a')", T.UINT), ("INT_TO_REAL(i)", T.REAL), ("TRUNC(r)", T.DINT),
    ("REAL_TO_INT(r)", T.INT), ("DINT_TO_TIME(d)", T.TIME), ("TIME_TO_DINT(t)", T.DINT),
    ("ADD_DT_TIME(dt1, t)", T.DT), ("SUB_DT_DT(dt1, dt1)", T.TIME), ("CONCAT_DATE_TOD(day, tod1)", T.DT),
    ("UPPER_BOUND(arr, 1)", T.DINT), ("TO_INT(r)", T.INT), ("ADD(i, i, d)", T.DINT), ("MOD(d, 3)", T.DINT),
    ("dt1 - dt1", T.TIME), ("tod1 + t", T.TOD), ("t * 2", T.TIME), ("t / r", T.TIME),
    ("BCD_TO_INT(w)", T.INT), ("BCD_TO_UDINT(b)", T.UDINT), ("WORD_BCD_TO_UINT(w)", T.UINT),
    ("INT_TO_BCD(i)", T.WORD), ("DINT_TO_BCD(d)", T.DWORD), ("UINT_TO_BCD_WORD(u)", T.WORD),
    ("USINT_TO_BCD_DWORD(1)", T.DWORD),
]


@pytest.mark.parametrize("expr,ty", RESULTS, ids=[e for e, _ in RESULTS])
def test_builtin_result_types(tmp_path, expr, ty):
    proj = check_text(tmp_path, program(f"v := {expr};", DECLS + f" v : {ty.name};"))
    assert not proj.has_errors, proj.render_diagnostics()
    value = proj.programs[0].pou.body[0].value
    assert T.same_type(value.ty, ty)


@pytest.mark.parametrize("expr", ["CONCAT(s, 'x', LEFT(s, 2), RIGHT(s, 1), MID(s, 2, 3))",
                                  "INSERT(s, 'ab', 2)", "DELETE(s, 1, 1)", "REPLACE(s, 'x', 1, 1)",
                                  "UINT_TO_STRING(u)"])
def test_string_functions_return_strings(tmp_path, expr):
    proj = check_text(tmp_path, program(f"s := {expr};", DECLS))
    assert not proj.has_errors, proj.render_diagnostics()
    assert T.is_string(proj.programs[0].pou.body[0].value.ty)


@pytest.mark.parametrize("expr", ["SQRT(s)", "SHL(r, 1)", "LEN(i)", "MAX(s, i)", "INT_TO_REAL(s)", "MOD(r, 2)",
                                  "SEL(i, 1, 2)", "CONCAT(s, i)", "BCD_TO_INT(i)", "INT_TO_BCD(r)",
                                  "WORD_BCD_TO_INT(d)", "UINT_TO_BCD_BYTE(d)"])
def test_wrong_argument_types_are_refused(tmp_path, expr):
    proj = check_text(tmp_path, program(f"x := {expr} = {expr};", DECLS))
    assert "ST1103" in codes(proj), proj.render_diagnostics()


def test_conversion_names_are_generated_for_every_elementary_pair():
    assert B.lookup("usint_to_lreal").name == "USINT_TO_LREAL"
    assert B.lookup("WSTRING_TO_STRING") is not None
    assert B.lookup("FOO_TO_BAR") is None
    assert "CONCAT" in B.names() and "ROL" in B.names()


def test_bcd_names_resolve_only_for_integer_and_bit_string_sides():
    assert B.lookup("bcd_to_dint").name == "BCD_TO_DINT"
    assert B.lookup("LWORD_BCD_TO_ULINT") is not None and B.lookup("LINT_TO_BCD_LWORD") is not None
    assert B.lookup("BCD_TO_REAL") is None and B.lookup("REAL_TO_BCD") is None
    assert B.lookup("INT_TO_BCD_REAL") is None and B.lookup("BOOL_BCD_TO_INT") is None
    assert not B.is_edition3(B.lookup("BCD_TO_INT")) and not B.is_edition3(B.lookup("INT_TO_BCD"))
    assert B.is_edition3(B.lookup("WORD_BCD_TO_UINT")) and B.is_edition3(B.lookup("UINT_TO_BCD_WORD"))
