"""The checkout's three packages (docs/toolchain/layout.md): which may import which, their console scripts, and
no code that edits sys.path."""
from __future__ import annotations

import ast
import importlib
import pathlib
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
# package -> the project packages it may import (layout.md's table)
MAY_IMPORT = {"vplc": set(), "tmsim": set(), "cbt_hmi": {"vplc", "tmsim"}}


def imported_top_level(path: pathlib.Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_the_three_packages_are_all_there_is_under_src():
    packages = {p.name for p in SRC.iterdir() if (p / "__init__.py").is_file()}
    assert packages == set(MAY_IMPORT)


def test_toolchain_and_simulator_import_neither_each_other_nor_the_application():
    wrong = []
    for package, allowed in MAY_IMPORT.items():
        for path in sorted((SRC / package).rglob("*.py")):
            for name in imported_top_level(path) & (set(MAY_IMPORT) - {package} - allowed):
                wrong.append(f"{path.relative_to(ROOT)} imports {name}")
    assert not wrong, "\n".join(wrong)


def test_every_console_script_names_a_function_that_exists():
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"]
    assert set(scripts) == {"vplc", "tmflow-sim", "cbt-demo"}
    for name, target in scripts.items():
        module, function = target.split(":")
        assert callable(getattr(importlib.import_module(module), function)), name


def test_no_code_edits_sys_path():
    """Packages are found through the install (or pytest's pythonpath), never by a module editing sys.path."""
    offenders = []
    for folder in ("src", "sim", "examples", "bench", "tests", "docs"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Attribute) and node.attr == "path" and \
                        isinstance(node.value, ast.Name) and node.value.id == "sys":
                    offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not offenders, "\n".join(offenders)
