"""docs/toolchain/layout.md, net/: no module of tmsim/net imports one that imports it back, directly or through
others, counting the imports made only for annotations (``if TYPE_CHECKING:``); the adapters name what they
use of the server, a robot and the Ethernet Slave with Protocols instead (issue 22)."""
import ast
import pathlib

NET = pathlib.Path(__file__).resolve().parents[2] / "src" / "tmsim" / "net"


def _net_imports(path: pathlib.Path) -> set[str]:
    """The modules of tmsim/net that ``path`` imports, anywhere in the file."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("tmsim.net."):
            found.add(node.module.split(".")[2])
        elif isinstance(node, ast.Import):
            found.update(a.name.split(".")[2] for a in node.names if a.name.startswith("tmsim.net."))
    return found


def _graph() -> dict[str, set[str]]:
    return {path.stem: _net_imports(path) for path in sorted(NET.glob("*.py"))}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One circle of imports in ``graph`` (module names, the first repeated at the end), or None."""
    state: dict[str, int] = {}          # 1 = on the current path, 2 = done
    path: list[str] = []

    def visit(name: str) -> list[str] | None:
        state[name] = 1
        path.append(name)
        for target in sorted(graph.get(name, ())):
            if state.get(target) == 1:
                return path[path.index(target):] + [target]
            if target not in state and (found := visit(target)):
                return found
        path.pop()
        state[name] = 2
        return None

    for name in graph:
        if name not in state and (found := visit(name)):
            return found
    return None


def test_the_cycle_finder_finds_a_circle_through_three_modules():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_no_module_of_net_imports_one_that_imports_it_back():
    graph = _graph()
    assert {"server", "robot_ports", "ethernet_slave", "control", "fairness", "tcp_listener"} <= set(graph)
    assert _cycle(graph) is None, " -> ".join(_cycle(graph) or [])


def test_only_the_server_imports_the_server_and_the_robot_does_not_import_the_ethernet_slave():
    graph = _graph()
    assert [name for name, targets in graph.items() if "server" in targets] == []
    assert "ethernet_slave" not in graph["robot_ports"]
