"""Fixtures of the export tests: the real library exported once per session, parsed back with ElementTree."""
from __future__ import annotations

import pathlib
import xml.etree.ElementTree as ET

import pytest

from vplc.cli import main as cli
from vplc.project import load_project

ROOT = pathlib.Path(__file__).resolve().parents[3]
LIB = ROOT / "lib" / "CBT_Commands_Lib"
NS = "www.iec.ch/public/TC65SC65BWG7TF10"
XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"


def q(tag: str) -> str:
    """Qualified tag name in the IEC 61131-10 namespace."""
    return f"{{{NS}}}{tag}"


def local(el: ET.Element) -> str:
    return el.tag.split("}", 1)[-1]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    """``python -m vplc ARGV`` in process: (exit code, stdout, stderr)."""
    try:
        code = cli.main(list(argv))
    except SystemExit as exc:          # argparse usage errors
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="session")
def lib_project():
    proj = load_project([str(LIB)])
    assert not proj.has_errors, proj.render_diagnostics()
    return proj


@pytest.fixture(scope="session")
def lib_xml(tmp_path_factory):
    out = tmp_path_factory.mktemp("xml") / "CBT_Commands_Lib.xml"
    assert cli.main(["export", str(LIB), "--format", "iec61131-10", "-o", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def lib_root(lib_xml):
    return ET.parse(lib_xml).getroot()


@pytest.fixture(scope="session")
def lib_paste(tmp_path_factory):
    out = tmp_path_factory.mktemp("paste") / "kit"
    assert cli.main(["export", str(LIB), "--format", "paste", "-o", str(out)]) == 0
    return out
