"""Golden file of the generated Python for a small program (review changes as diffs).

Refresh only on purpose: VPLC_UPDATE_GOLDEN=1 pytest tests/vplc/runtime/test_rt_golden.py
"""
import os
import re

from vplc.compiler.codegen import CodeGen
from vplc.project import load_project

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "golden")


def generated_main(path: str) -> str:
    """The class and body function generated for PROGRAM Main, with numbering normalised."""
    lines = CodeGen(load_project([path])).generate().source.splitlines()
    start = next(i for i, line in enumerate(lines) if re.match(r"class P\d+_Main:", line))
    body = next(i for i in range(start, len(lines)) if re.match(r"def B\d+_Main\(s\):", lines[i]))
    end = next(i for i in range(body, len(lines)) if lines[i] == "    return")
    text = "\n".join(lines[start:end + 1])
    text = re.sub(r"\b(_cv|_w|_ty|_d|_k|_i|_a|_z|_c|_v|_e|_s|_x)\d+\b", r"\1N", text)
    return re.sub(r"\b([PB])\d+_", r"\1_", text) + "\n"


def test_generated_python_matches_the_golden_file():
    src = os.path.join(HERE, "sequence.st")
    expected_path = os.path.join(HERE, "sequence.py.expected")
    text = generated_main(src)
    if os.environ.get("VPLC_UPDATE_GOLDEN") == "1":
        with open(expected_path, "w") as f:
            f.write(text)
    assert os.path.exists(expected_path), "golden file missing: run with VPLC_UPDATE_GOLDEN=1 and review it"
    with open(expected_path) as f:
        assert text == f.read()
