"""examples/Commands_Example.xml (the ladder) behaves exactly like its Structured Text twin
(bench/st/Commands_Example_ST.st) over 1,000 scans of the same operator actions."""
from __future__ import annotations

import shutil

import pytest
from ld_trace import ROOT, example_trace, first_difference, trace

LIB = ROOT / "lib" / "CBT_Commands_Lib"


@pytest.mark.slow
def test_ladder_example_and_its_st_twin_give_the_same_trace(tmp_path):
    st = tmp_path / "st"
    shutil.copytree(ROOT / "examples", st, ignore=shutil.ignore_patterns("*.py", "Commands_Example.xml"))
    shutil.copy(ROOT / "bench" / "st" / "Commands_Example_ST.st", st / "Commands_Example.st")
    ladder = example_trace()
    twin = trace([LIB, st])
    assert first_difference(ladder, twin) is None
    assert any(row["MoveAbs_Error"] for row in ladder), "the commands ran and ended in their error"
    assert any(row["ChangeBase_Busy"] for row in ladder) or any(row["ChangeBase_Error"] for row in ladder)


def test_a_wrong_pin_in_the_example_names_file_pou_rung_and_block(tmp_path):
    """The issue's own example: `Commands_Example.xml:rung 4:block CBT_MoveAbsolute: error[ST1201] ...`."""
    from vplc.project import load_project
    examples = tmp_path / "examples"
    shutil.copytree(ROOT / "examples", examples, ignore=shutil.ignore_patterns("*.py"))
    path = examples / "Commands_Example.xml"
    text = path.read_text(encoding="utf-8")
    at = text.index('parameterName="Execute"', text.index('instanceName="fbMoveAbs"'))
    path.write_text(text[:at] + 'parameterName="Exec"' + text[at + len('parameterName="Execute"'):], encoding="utf-8")
    errors = [d for d in load_project([str(LIB), str(examples)]).diagnostics if d.severity == "error"]
    assert len(errors) == 1
    first = errors[0].render().splitlines()[0]
    assert first == (f"{path}:Commands_Example:rung 4:block CBT_MoveAbsolute: error[ST1201]: CBT_MoveAbsolute has "
                     "no parameter `Exec`")
