"""Dependency order: every object after the objects it uses, otherwise in a stable, name-based order.

Sysmac Studio resolves names when an object is created or built, so the paste kit lists data types
before the types and POUs that use them, and functions and function blocks before their callers.
The XML export uses the same order, which keeps the file readable top to bottom.
"""
from __future__ import annotations

from collections.abc import Callable, Hashable, Iterable
from typing import TypeVar

Item = TypeVar("Item")


def dependency_order(items: list[Item], deps: Callable[[Item], Iterable[Hashable]],
                     key: Callable[[Item], Hashable]) -> list[Item]:
    """Topological order of ``items``.

    ``key(item)`` identifies an item; ``deps(item)`` yields the keys it depends on (keys of objects not in
    ``items`` — built-in or vendor types, standard functions — are ignored). Independent items keep the
    order of ``sorted(key)``, so the result depends only on the content, never on file-system order.
    A dependency cycle (which the checker reports as an error) is broken where it is found.
    """
    by_key = {key(it): it for it in items}
    done: set = set()
    active: set = set()
    out: list[Item] = []

    def visit(k) -> None:
        stack = [(k, iter(sorted(_known(by_key[k]), key=_sort_key)))]
        active.add(k)
        while stack:
            cur, pending = stack[-1]
            nxt = next(pending, None)
            if nxt is None:
                stack.pop()
                active.discard(cur)
                done.add(cur)
                out.append(by_key[cur])
            elif nxt not in done and nxt not in active:
                active.add(nxt)
                stack.append((nxt, iter(sorted(_known(by_key[nxt]), key=_sort_key))))

    def _known(item):
        own = key(item)
        return {d for d in deps(item) if d in by_key and d != own}

    for k in sorted(by_key, key=_sort_key):
        if k not in done:
            visit(k)
    return out


def _sort_key(k):
    """Sort keys that may contain None (the global namespace) before named namespaces."""
    if isinstance(k, tuple):
        return tuple(("", "") if v is None else ("~", str(v)) for v in k)
    return ("~", str(k))
