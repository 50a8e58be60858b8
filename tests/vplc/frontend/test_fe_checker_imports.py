"""The checker's modules import one another without a cycle (a rule module never needs the expression checker back),
counting imports inside functions too: a deferred import is still a dependency."""
from __future__ import annotations

import ast

from fe_helpers import ROOT

CHECKER = ROOT / "src" / "vplc" / "checker"


def module_imports() -> dict[str, set[str]]:
    """{module of vplc.checker: modules of vplc.checker it imports anywhere in its text}."""
    graph: dict[str, set[str]] = {}
    for path in sorted(CHECKER.glob("*.py")):
        deps: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                deps |= {node.module.split(".")[0]} if node.module else {a.name for a in node.names}
        graph[path.stem] = deps
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every cycle a depth-first walk meets, as the path that closes it."""
    found: list[list[str]] = []
    state: dict[str, str] = {}

    def visit(name: str, path: list[str]) -> None:
        state[name] = "open"
        path.append(name)
        for dep in sorted(graph.get(name, ())):
            if state.get(dep) == "open":
                found.append(path[path.index(dep):] + [dep])
            elif dep not in state:
                visit(dep, path)
        path.pop()
        state[name] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [])
    return found


def test_the_cycle_finder_sees_a_deferred_import_cycle():
    assert cycles({"calls": {"exprs"}, "exprs": {"calls", "scope"}, "scope": set()}) == [["calls", "exprs", "calls"]]


def test_checker_modules_have_no_import_cycle():
    graph = module_imports()
    assert {"calls", "exprs", "compatibility"} <= set(graph)
    assert cycles(graph) == []
