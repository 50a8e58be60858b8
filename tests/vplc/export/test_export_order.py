"""Dependency ordering: dependencies first, stable name order otherwise, cycles broken, unknown keys ignored."""
from __future__ import annotations

from vplc.export.order import dependency_order


def _order(graph: dict[str, list[str]]) -> list[str]:
    return dependency_order(list(graph), lambda k: graph[k], key=lambda k: k)


def test_dependencies_come_first_and_independent_items_sort_by_name():
    assert _order({"c": [], "b": ["c"], "a": ["b", "INT"], "d": []}) == ["c", "b", "a", "d"]


def test_input_order_does_not_matter():
    g = {"x": ["y"], "y": ["z"], "z": [], "w": ["z"]}
    assert _order(g) == _order(dict(reversed(list(g.items())))) == ["z", "w", "y", "x"]


def test_a_cycle_is_broken_and_every_item_appears_once():
    out = _order({"a": ["b"], "b": ["a"], "c": ["a"]})
    assert sorted(out) == ["a", "b", "c"] and out.index("c") > out.index("a")


def test_global_namespace_keys_sort_before_library_keys():
    items = [("Lib", "A"), (None, "Z")]
    assert dependency_order(items, lambda k: [], key=lambda k: k) == [(None, "Z"), ("Lib", "A")]
