"""Round trip: `vplc export` writes ladder POUs in both XML formats (IEC 61131-10 with Sysmac's LdSection,
PLCopen XML TC6 with <LD>), and loading the export gives the same program: the same values in every scan
of a 1,000-scan run. ST POUs are written unchanged."""
from __future__ import annotations

import functools
import re

import pytest
from ld_trace import ROOT, example_trace, first_difference, trace
from ld_xml import ALL_BODY, ALL_KINDS, program

from vplc.cli.main import main

LIB = ROOT / "lib" / "CBT_Commands_Lib"
FORMATS = ["iec61131-10", "plcopen"]


def configured_programs(path) -> list[str]:
    """The POU types of a configuration's PROGRAM lines, in their order."""
    return re.findall(r"^\s*PROGRAM\s+\w+\s+WITH\s+\w+\s*:\s*(\w+)\s*;", path.read_text(encoding="utf-8"), re.M)


def export(tmp_path, fmt, *paths) -> str:
    out = tmp_path / f"export-{fmt}.xml"
    assert main(["export", *map(str, paths), "--format", fmt, "-o", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def example_export(tmp_path_factory):
    """`vplc export` of the library with the example project, run once per format for the tests that read it."""
    folder = tmp_path_factory.mktemp("example_export")
    return functools.cache(lambda fmt: export(folder, fmt, LIB, ROOT / "examples"))


@pytest.mark.slow
@pytest.mark.parametrize("fmt", FORMATS)
def test_exported_example_project_runs_the_same_1000_scans(example_export, fmt):
    out = example_export(fmt)
    text = out.read_text(encoding="utf-8")
    assert ("smcext:LdSection" in text) if fmt == "iec61131-10" else ("<LD>" in text)
    assert "_ldP" not in text and "_ldM" not in text, "the translation's helper variables are not exported"
    programs = configured_programs(ROOT / "examples" / "Examples_Configuration.st")    # an export has no configuration
    original = example_trace()
    again = trace([out], programs=programs)
    assert first_difference(original, again) is None


def all_kinds_stimulus(n: int) -> dict:
    return {"Main.A": n % 3 == 0, "Main.B": n % 5 < 2, "Main.C": n % 7 > 3, "Main.Run": n % 50 < 35,
            "Main.Skip": n % 11 < 4, "Main.Stop": n % 13 == 0, "Main.N": n % 100}


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_element_kind_survives_the_round_trip(tmp_path, fmt):
    src = program(tmp_path, ALL_KINDS, ALL_BODY)
    watched = [f"Main.{n}" for n, t in ALL_KINDS.items() if t != "TON"]
    original = trace([src], stimulus=all_kinds_stimulus, watched=watched)
    out = export(tmp_path, fmt, src)
    again = trace([out], stimulus=all_kinds_stimulus, watched=watched)
    assert first_difference(original, again) is None
    assert any(r["Main.Latch"] for r in original) and any(r["Main.Up"] for r in original)
    assert any(r["Main.Mid"] for r in original) and not all(r["Main.Mid"] == r["Main.A"] for r in original)


def test_st_pous_are_written_unchanged_next_to_ladders(example_export):
    out = example_export("plcopen")
    text = out.read_text(encoding="utf-8")
    body = (ROOT / "examples" / "PnP_Example.st").read_text(encoding="utf-8")
    assert "PnP_Segment := PnP_Segment + 1;" in body
    assert "PnP_Segment := PnP_Segment + 1;" in text
