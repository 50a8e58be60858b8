"""Command line: rendering, exit codes, JSON, --portable, --warnings-as-errors, subcommand registry."""
from __future__ import annotations

import json

from cli_main import run_in_process
from fe_helpers import program

from vplc.cli import main as cli


def test_clean_file_exits_0_and_error_file_exits_1_with_rendered_caret(tmp_path):
    good = tmp_path / "good.st"
    good.write_text(program("x := 1;", "x : INT;"))
    assert run_in_process("check", str(good)).returncode == 0
    bad = tmp_path / "bad.st"
    bad.write_text(program("x := y;", "x : INT;"))
    r = run_in_process("check", str(bad))
    assert r.returncode == 1
    lines = r.stdout.splitlines()
    assert lines[0] == (f"{bad}:5:6: error[ST1001]: `y` is not declared; declare it in a VAR section or check the "
                        "spelling")
    assert lines[1].endswith("| x := y;") and lines[2].strip() == "^"
    assert lines[2].index("^") == lines[1].index("y;")


def test_usage_error_exits_2():
    assert run_in_process("check").returncode == 2
    assert run_in_process("frobnicate").returncode == 2


def test_json_format_lists_diagnostics(tmp_path):
    bad = tmp_path / "bad.st"
    bad.write_text(program("x := y;", "x : INT;"))
    r = run_in_process("check", "--format", "json", str(bad))
    data = json.loads(r.stdout)
    d = data["diagnostics"][0]
    assert (d["code"], d["line"], d["column"], d["severity"]) == ("ST1001", 5, 6, "error")


def test_warnings_as_errors_and_portable(tmp_path):
    f = tmp_path / "w.st"
    f.write_text(program("x := 1;", "x, unused : INT;"))
    assert run_in_process("check", str(f)).returncode == 0
    assert run_in_process("check", "--warnings-as-errors", str(f)).returncode == 1
    v = tmp_path / "v.st"
    v.write_text(program("t := GetTime();", "t : DT;"))
    r = run_in_process("check", "--portable", str(v))
    assert r.returncode == 0 and "warning[ST2001]" in r.stdout


def test_folders_are_searched_recursively_and_many_errors_reported(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.st").write_text(program("x := a; y := b;", "x, y : INT;"))
    (tmp_path / "b.st").write_text(program("z := c;", "z : INT;"))
    r = run_in_process("check", str(tmp_path))
    assert r.returncode == 1 and r.stdout.count("error[ST1001]") == 3


def test_subcommand_registry_includes_check_and_optional_backend_modules(monkeypatch):
    import sys
    import types

    fake = types.ModuleType("vplc.cli.run")

    def register(sub):
        p = sub.add_parser("run")
        p.set_defaults(handler=lambda args: 0)

    fake.register = register
    monkeypatch.setitem(sys.modules, "vplc.cli.run", fake)
    parser = cli.build_parser()
    assert cli.main(["run"]) == 0
    assert "check" in parser.format_help()
