"""Golden files: rendered diagnostics of golden/*.st, token and AST dumps of cases/*.st.

Refresh only with an explicit flag and review the diff:  UPDATE_GOLDEN=1 pytest tests/vplc/frontend
"""
from __future__ import annotations

import dataclasses
import os

import pytest
from fe_helpers import HERE, ROOT

from vplc.frontend import ast as A
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.lexer import tokenize
from vplc.frontend.source import SourceFile
from vplc.project import load_project

UPDATE = os.environ.get("UPDATE_GOLDEN") == "1"
SKIP = {"span", "ty", "conv", "sysmac_ty", "sym", "binding", "name_span", "namespace", "native", "comments"}


def compare(path, actual: str) -> None:
    if UPDATE:
        path.write_text(actual, encoding="utf-8")
        return
    assert path.exists(), f"{path.name} is missing; create it with UPDATE_GOLDEN=1 and review it"
    assert actual == path.read_text(encoding="utf-8"), f"{path.name} differs (UPDATE_GOLDEN=1 to refresh)"


def dump(node, indent: int = 0) -> list[str]:
    pad = "  " * indent
    if isinstance(node, A.Node):
        fields = [f for f in dataclasses.fields(node) if f.name not in SKIP]
        simple = [f"{f.name}={getattr(node, f.name)!r}" for f in fields
                  if not isinstance(getattr(node, f.name), (A.Node, list))]
        lines = [f"{pad}{type(node).__name__}({', '.join(simple)})"]
        for f in fields:
            value = getattr(node, f.name)
            if isinstance(value, A.Node):
                lines.append(f"{pad}  .{f.name}:")
                lines += dump(value, indent + 2)
            elif isinstance(value, list):
                lines.append(f"{pad}  .{f.name}: [{len(value)}]")
                for v in value:
                    lines += dump(v, indent + 2)
        return lines
    return [f"{pad}{node!r}"]


GOLDEN = sorted((HERE / "golden").glob("*.st"))
CASES = sorted((HERE / "cases").glob("*.st"))


@pytest.mark.parametrize("path", GOLDEN, ids=[p.name for p in GOLDEN])
def test_rendered_diagnostics_match_golden(path):
    rel = os.path.relpath(path, ROOT)
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        proj = load_project([rel])
    finally:
        os.chdir(cwd)
    compare(path.with_suffix(".expected"), proj.render_diagnostics() + "\n")


@pytest.mark.parametrize("path", CASES, ids=[p.name for p in CASES])
def test_token_dump_matches_golden(path):
    diags = DiagnosticBag()
    src = SourceFile(path.name, path.read_text(encoding="utf-8"))
    lines = []
    for t in tokenize(src, diags):
        line, col = src.line_col(t.start)
        lines.append(f"{line}:{col} {t.kind} {t.text!r}")
    assert not diags.items
    compare(path.with_suffix(".tokens"), "\n".join(lines) + "\n")


@pytest.mark.parametrize("path", CASES, ids=[p.name for p in CASES])
def test_ast_dump_matches_golden_and_file_checks_clean(path):
    cwd = os.getcwd()
    os.chdir(HERE)
    try:
        proj = load_project([os.path.relpath(path, HERE)])
    finally:
        os.chdir(cwd)
    assert not [d for d in proj.diagnostics if d.severity != "note"], proj.render_diagnostics()
    unit = [u for u in proj.units if u.span.file.path.endswith(path.name)][0]
    compare(path.with_suffix(".ast"), "\n".join(dump(unit)) + "\n")
