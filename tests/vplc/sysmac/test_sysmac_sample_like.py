"""A project file in the shape Sysmac Studio writes for an NJ501 (sample_like/MachineStation.xml, written by hand
with the constructs of Omron's own IEC 61131-10 sample project, which is not readable here): it validates against
Omron's schemas where they are available, loads and checks clean, and runs with the values its rungs mean."""
from __future__ import annotations

import os
import pathlib

import pytest

from vplc.api import load_plc
from vplc.project import load_project

HERE = pathlib.Path(__file__).resolve().parent
FILE = HERE / "sample_like" / "MachineStation.xml"
ROOT = HERE.parents[2]
MS = 1_000_000


def test_the_file_validates_against_omrons_schemas():
    etree = pytest.importorskip("lxml.etree", reason="lxml is a test dependency: run `make test-deps`")
    folder = pathlib.Path(os.environ.get("SYSMAC_XSD_DIR", ROOT.parent / "shared" / "sysmac_xml"))
    xsd = folder / "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
    if not xsd.exists():
        pytest.skip(f"Omron's IEC 61131-10 schemas are not in {folder}; set SYSMAC_XSD_DIR")
    schema = etree.XMLSchema(etree.parse(str(xsd)))
    ok = schema.validate(etree.parse(str(FILE)))
    assert ok, [f"{e.line}: {e.message}" for e in schema.error_log]


def test_the_file_loads_and_checks_clean():
    proj = load_project([str(FILE)])
    assert [(d.code, d.message) for d in proj.diagnostics] == []


def test_the_station_runs_with_the_meaning_of_its_rungs():
    plc = load_plc([str(FILE)], task="Main@1ms")
    t = 0

    def scan(**values):
        nonlocal t
        for k, v in values.items():
            plc.write(f"Main.{k}", v)
        plc.scan(t)
        t += MS
        return {k: plc.read(f"Main.Cell1.{k}") for k in ("Running", "Counts.Starts", "Counts.Over", "Alarm",
                                                          "Total", "Copy", "Mode")}

    first = scan()
    assert (first["Running"], first["Counts.Starts"], first["Total"], first["Copy"]) == (False, 0, 100, 100)
    for _ in range(3):                                   # three starts: Running latched, three counted
        scan(Start=True)
        scan(Start=False)
        scan(Stop=True)
        out = scan(Stop=False)
    assert out["Counts.Starts"] == 3 and out["Running"] is False and out["Mode"] == "Busy"
    out = scan(Start=True)
    assert out["Running"] is True and out["Counts.Starts"] == 4
    assert (out["Counts.Over"], out["Alarm"], out["Total"], out["Copy"]) == (True, True, 104, 104)
    plc.write("Main.Cell1.Counts.Starts", 0)
    out = scan(Start=False, Stop=True)                  # Stop: the latch resets, GT's EN is off, totals skipped
    assert out["Running"] is False and out["Counts.Over"] is True and out["Alarm"] is False
    assert (out["Total"], out["Copy"]) == (104, 104)
    out = scan(Stop=False)                              # EN still off: GT's output keeps its last value
    assert (out["Counts.Over"], out["Alarm"], out["Total"], out["Copy"]) == (True, True, 100, 100)
