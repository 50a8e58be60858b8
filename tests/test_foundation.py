"""Standing promises of the repository: two README commands, CI = `make test`, stdlib-only runtime, and the three
packages under src/ (docs/toolchain/layout.md): which may import which, their console scripts, no sys.path edits."""
from __future__ import annotations

import ast
import importlib
import pathlib
import re
import sys
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
# package -> the project packages it may import (layout.md's table); of vplc, cbt_hmi uses only the public API
MAY_IMPORT = {"vplc": set(), "tmsim": set(), "cbt_hmi": {"vplc", "tmsim"}}
PUBLIC_MODULES = {"vplc": {"vplc.api"}}
RUNTIME_TREES = [SRC / package for package in MAY_IMPORT] + [ROOT / "sim", ROOT / "examples"]
OWN_PACKAGES = set(MAY_IMPORT)


def _imported_top_level_modules(path: pathlib.Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_readme_shows_demo_and_test_commands_first():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    first_block = re.search(r"```\n(.*?)```", text, re.S)
    assert first_block, "README.md has no command block"
    commands = [line.split("#")[0].strip() for line in first_block.group(1).splitlines()]
    assert commands[:2] == ["make demo", "make test"]


def test_ci_runs_exactly_the_readme_test_command():
    script = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    commands = [line.strip() for line in script.splitlines()
                if line.strip() and not line.lstrip().startswith("#")]
    assert "make test" in commands
    assert not [c for c in commands if c.startswith(("pytest", "python"))], "CI must not bypass make test"


def test_makefile_has_the_documented_targets():
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    for target in ("demo", "test", "bench", "check", "clean"):
        assert re.search(rf"^{target}:", makefile, re.M), f"Makefile lacks target '{target}'"


def test_runtime_code_imports_only_the_standard_library():
    offenders = []
    for tree in RUNTIME_TREES:
        for path in sorted(tree.rglob("*.py")):
            for module in _imported_top_level_modules(path):
                if module not in sys.stdlib_module_names and module not in OWN_PACKAGES:
                    offenders.append(f"{path.relative_to(ROOT)} imports {module}")
    assert offenders == []


def test_stdlib_guard_detects_a_third_party_import(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text("import os\nfrom selenium import webdriver\nfrom . import sibling\n", encoding="utf-8")
    assert _imported_top_level_modules(sample) == {"os", "selenium"}


def test_the_vplc_launcher_runs_the_toolchain_from_the_checkout():
    """Docs say `./vplc check ...`: the launcher needs no install and no PYTHONPATH."""
    import os
    import subprocess
    root = pathlib.Path(__file__).resolve().parents[1]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run([str(root / "vplc"), "check", "lib/CBT_Commands_Lib"], cwd=root, env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "0 error(s)" in done.stdout, done.stdout + done.stderr


def test_the_three_packages_are_all_there_is_under_src():
    packages = {p.name for p in SRC.iterdir() if (p / "__init__.py").is_file()}
    assert packages == set(MAY_IMPORT)


def test_toolchain_and_simulator_import_neither_each_other_nor_the_application():
    wrong = []
    for package, allowed in MAY_IMPORT.items():
        for path in sorted((SRC / package).rglob("*.py")):
            for name in _imported_top_level_modules(path) & (set(MAY_IMPORT) - {package} - allowed):
                wrong.append(f"{path.relative_to(ROOT)} imports {name}")
    assert not wrong, "\n".join(wrong)


def _imported_modules(path: pathlib.Path) -> set[str]:
    """Dotted names of the absolute imports of one file (``from vplc import api`` is vplc.api)."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            top = node.module.split(".")[0]
            if node.module == top and top in PUBLIC_MODULES:
                names.update(f"{top}.{alias.name}" for alias in node.names)
            else:
                names.add(node.module)
    return names


def test_the_application_uses_only_the_toolchains_public_api():
    wrong = []
    for path in sorted((SRC / "cbt_hmi").rglob("*.py")):
        for module in _imported_modules(path):
            top = module.split(".")[0]
            if top in PUBLIC_MODULES and module not in PUBLIC_MODULES[top]:
                wrong.append(f"{path.relative_to(ROOT)} imports {module}")
    assert not wrong, "\n".join(wrong)


def test_the_public_api_guard_names_a_reach_into_the_toolchain(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text("from vplc.api import load_plc\nfrom vplc import api, ladder\nimport vplc.runtime.values\n",
                      encoding="utf-8")
    assert _imported_modules(sample) == {"vplc.api", "vplc.ladder", "vplc.runtime.values"}


def test_the_hmi_pages_are_package_data_of_the_application():
    """The pages are found through the package: an install from a wheel or a checkout serves the same files."""
    import importlib.resources

    import cbt_hmi
    pages = importlib.resources.files("cbt_hmi") / "pages"
    assert (pages / "index.html").is_file() and (pages / "mapping.json").is_file()
    assert pathlib.Path(str(pages)).resolve() == cbt_hmi.PAGES
    package_data = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    assert "pages/*" in package_data["package-data"]["cbt_hmi"]


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
            text = path.read_text(encoding="utf-8")
            if "sys" not in text or "path" not in text:
                continue
            for node in ast.walk(ast.parse(text)):
                if isinstance(node, ast.Attribute) and node.attr == "path" and \
                        isinstance(node.value, ast.Name) and node.value.id == "sys":
                    offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not offenders, "\n".join(offenders)
