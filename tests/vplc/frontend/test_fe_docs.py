"""Docs stay in step with the code: every diagnostic code the front end emits is in the table."""
from __future__ import annotations

import re

from fe_helpers import ROOT


def test_every_emitted_code_is_documented_with_examples():
    src = ROOT / "src" / "vplc"
    files = [p for p in src.glob("*.py")] + list((src / "checker").glob("*.py")) + list((src / "ladder").glob("*.py"))
    emitted = set()
    for p in files:
        emitted |= set(re.findall(r'"(ST[0-9]{4})"', p.read_text(encoding="utf-8")))
    table = (ROOT / "docs" / "toolchain" / "diagnostics.md").read_text(encoding="utf-8")
    rows = {m.group(1): m.group(0) for m in re.finditer(r"^\| (ST[0-9]{4}) \|.*$", table, re.M)}
    assert emitted - set(rows) == set()
    for code, row in rows.items():
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert len(cells) == 5 and cells[3] and cells[4], code
