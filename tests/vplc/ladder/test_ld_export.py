"""Round trip: `vplc export` writes ladder POUs in both XML formats (IEC 61131-10 with Sysmac's LdSection,
PLCopen XML TC6 with <LD>), and loading the export gives the same program: the same values in every scan
of a 1,000-scan run. ST POUs are written unchanged."""
from __future__ import annotations

import pytest

from ld_trace import ROOT, first_difference, trace
from ld_xml import block, coil, comment, contact, invar, jump, label, outvar, program, rail, ret, right
from vplc.cli.main import main

LIB = ROOT / "lib" / "CBT_Commands_Lib"
FORMATS = ["iec61131-10", "plcopen"]


def export(tmp_path, fmt, *paths) -> str:
    out = tmp_path / f"export-{fmt}.xml"
    assert main(["export", *map(str, paths), "--format", fmt, "-o", str(out)]) == 0
    return out


@pytest.mark.parametrize("fmt", FORMATS)
def test_exported_example_project_runs_the_same_1000_scans(tmp_path, fmt):
    out = export(tmp_path, fmt, LIB, ROOT / "examples")
    text = out.read_text(encoding="utf-8")
    assert ("smcext:LdSection" in text) if fmt == "iec61131-10" else ("<LD>" in text)
    assert "_ldP" not in text and "_ldM" not in text, "the translation's helper variables are not exported"
    programs = ["PnP_Example", "Commands_Example"]            # the order of Examples_Configuration.st
    original = trace([LIB, ROOT / "examples"])
    again = trace([out], programs=programs)
    assert first_difference(original, again) is None


ALL_KINDS = {"A": "BOOL", "B": "BOOL", "C": "BOOL", "Q1": "BOOL", "Q2": "BOOL", "Latch": "BOOL", "Pulse": "BOOL",
             "Up": "BOOL", "Down": "BOOL", "Run": "BOOL", "T": "TON", "Et": "TIME", "N": "INT", "Sum": "INT",
             "Skip": "BOOL", "Mid": "BOOL", "Stop": "BOOL", "Last": "BOOL", "Eno": "BOOL"}
ALL_BODY = [comment(90, "series, parallel, NC", y=-20), rail(1), contact(2, "A", 1), contact(3, "B", 1, y=20),
            contact(4, "C", 2, 3, negated="true"), coil(5, "Q1", 4), coil(6, "Q2", 4, y=20, negated="true"),
            right(7, 5, 6),
            contact(10, "A", 1, y=100, edge="rising"), coil(11, "Latch", 10, y=100, storage="set"),
            contact(12, "B", 1, y=120, edge="falling"), coil(13, "Latch", 12, y=120, storage="reset"),
            contact(14, "C", 1, y=140), coil(15, "Pulse", 14, y=140, edge="rising"),
            contact(20, "Run", 1, y=200), contact(21, "C", 1, y=220),
            block(22, "TON", {"EN": 20, "IN": 21, "PT": 23}, ["ENO", "Q", "ET"], instance="T", y=200),
            invar(23, "T#2ms", y=240), coil(24, "Eno", (22, "ENO"), y=200), coil(25, "Up", (22, "Q"), y=220),
            outvar(26, "Et", (22, "ET"), y=240),
            invar(30, "N", y=300), invar(31, "7", y=310), block(32, "ADD", {"IN1": 30, "IN2": 31}, ["OUT"], y=300),
            outvar(33, "Sum", (32, "OUT"), y=300),
            contact(40, "Skip", 1, y=400), jump(41, "After", 40, y=400),
            contact(42, "A", 1, y=420), coil(43, "Mid", 42, y=420),
            label(44, "After", y=440), contact(45, "Stop", 1, y=460), ret(46, 45, y=460),
            contact(47, "B", 1, y=480), coil(48, "Last", 47, y=480), coil(49, "Down", 47, y=490, negated="true")]


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


def test_st_pous_are_written_unchanged_next_to_ladders(tmp_path):
    out = export(tmp_path, "plcopen", LIB, ROOT / "examples")
    text = out.read_text(encoding="utf-8")
    body = (ROOT / "examples" / "PnP_Example.st").read_text(encoding="utf-8")
    assert "PnP_Segment := PnP_Segment + 1;" in body
    assert "PnP_Segment := PnP_Segment + 1;" in text
