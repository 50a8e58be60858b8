"""Printer: parse → print → parse gives the same AST for every test file, the prelude, lib/ and examples/."""
from __future__ import annotations

import pytest
from fe_helpers import HERE, ROOT, parse_text

from vplc.frontend.printer import print_unit

FILES = sorted(
    list((HERE / "cases").glob("*.st"))
    + [p for p in (HERE / "golden").glob("*.st") if not p.name.startswith("syntax")]
    + list((ROOT / "src" / "vplc" / "prelude").glob("*.st"))
    + list((ROOT / "lib").rglob("*.st")) + list((ROOT / "examples").rglob("*.st")))


@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(ROOT)) for p in FILES])
def test_round_trip_gives_the_same_ast(path):
    text = path.read_text(encoding="utf-8")
    first, diags = parse_text(text, str(path))
    if any(d.is_error for d in diags):
        pytest.skip(f"{path.name} has syntax errors (reported by vplc check); round trip needs valid input")
    printed = print_unit(first)
    second, diags2 = parse_text(printed, str(path))
    assert [d.render() for d in diags2 if d.is_error] == []
    assert second == first, printed


def test_printer_parenthesises_only_where_precedence_requires():
    unit, _ = parse_text("PROGRAM P x := (a + b) * c - (d - e) + -f ** 2; y := NOT (a AND b); END_PROGRAM")
    text = print_unit(unit)
    assert "x := (a + b) * c - (d - e) + -(f ** 2);" in text
    assert "y := NOT (a AND b);" in text


def _snippets():
    from rule_cases import CASES
    for _code, failing, fixed in CASES:
        yield failing
        yield fixed


@pytest.mark.parametrize("text", list(_snippets()))
def test_round_trip_of_every_rule_snippet(text):
    first, diags = parse_text(text)
    assert not [d for d in diags if d.is_error]
    second, _ = parse_text(print_unit(first))
    assert second == first
