"""docs/toolchain/layout.md: imports between the toolchain's packages only point down the pipeline."""
import ast
import pathlib

SRC = pathlib.Path(__file__).resolve().parents[2] / "src" / "vplc"

# package -> packages it may import (layout.md's table)
ALLOWED = {
    "frontend": set(),
    "checker": {"frontend"},
    "ladder": {"frontend"},
    "project": {"ladder", "checker", "frontend"},
    "runtime": {"frontend"},
    "compiler": {"runtime", "frontend"},
    "trace": {"frontend"},
    "export": {"project", "ladder", "frontend"},
    "api": {"compiler", "runtime", "project", "ladder", "frontend"},
    "cli": {"api", "export", "trace", "compiler", "runtime", "project", "ladder", "checker", "frontend"},
}


def _package(path: pathlib.Path) -> str:
    rel = path.relative_to(SRC)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def _imported_packages(path: pathlib.Path):
    pkg_parts = list(path.relative_to(SRC).parent.parts)
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = pkg_parts[:len(pkg_parts) - (node.level - 1)] if node.level > 1 else pkg_parts
            target = base + (node.module.split(".") if node.module else [])
            names = [target[0]] if target else [a.name for a in node.names]
            yield [n for n in names if n != "__version__"], node.lineno
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            mods = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
            for m in mods:
                if m.startswith("vplc."):
                    yield [m.split(".")[1]], node.lineno


def test_every_import_inside_vplc_points_down_the_layers():
    wrong = []
    for path in sorted(SRC.rglob("*.py")):
        own = _package(path)
        if own in ("__init__", "__main__"):
            continue
        for names, line in _imported_packages(path):
            for name in names:
                if name != own and name not in ALLOWED[own]:
                    wrong.append(f"{path.relative_to(SRC)}:{line}: {own} imports {name}")
    assert not wrong, "\n".join(wrong)
