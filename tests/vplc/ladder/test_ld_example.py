"""examples/Commands_Example.xml (the ladder) behaves exactly like its Structured Text twin
(bench/st/Commands_Example_ST.st) over 1,000 scans of the same operator actions."""
from __future__ import annotations

import shutil

from ld_trace import ROOT, first_difference, trace

LIB = ROOT / "lib" / "CBT_Commands_Lib"


def test_ladder_example_and_its_st_twin_give_the_same_trace(tmp_path):
    st = tmp_path / "st"
    shutil.copytree(ROOT / "examples", st, ignore=shutil.ignore_patterns("*.py", "Commands_Example.xml"))
    shutil.copy(ROOT / "bench" / "st" / "Commands_Example_ST.st", st / "Commands_Example.st")
    ladder = trace([LIB, ROOT / "examples"])
    twin = trace([LIB, st])
    assert first_difference(ladder, twin) is None
    assert any(row["MoveAbs_Error"] for row in ladder), "the commands ran and ended in their error"
    assert any(row["ChangeBase_Busy"] for row in ladder) or any(row["ChangeBase_Error"] for row in ladder)
