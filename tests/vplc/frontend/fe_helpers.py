"""Shared helpers of the front-end tests."""
from __future__ import annotations

import pathlib
import textwrap

from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.parser import parse
from vplc.frontend.source import SourceFile
from vplc.project import load_project

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[2]


def parse_text(text: str, path: str = "t.st"):
    diags = DiagnosticBag()
    unit = parse(SourceFile(path, textwrap.dedent(text)), diags)
    return unit, diags.items


def check_text(tmp_path, text: str, name: str = "t.st", **kw):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return load_project([str(path)], **kw)


def codes(proj, severity: str | None = None) -> list[str]:
    return [d.code for d in proj.diagnostics if severity is None or d.severity == severity]


def program(body: str, decls: str = "") -> str:
    """Wrap statements in a PROGRAM with the given VAR declarations."""
    return f"PROGRAM Main\nVAR\n{decls}\nEND_VAR\n{body}\nEND_PROGRAM\n"
