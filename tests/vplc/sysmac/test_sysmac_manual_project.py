"""A project written the way Omron's manuals show Sysmac code (tests/vplc/sysmac/manual_project): namespaces
(nested), unions, globals AT memory areas, function blocks called with positional outputs, W502 instructions, and
a ladder function block (IEC 61131-10, LD body) with set/reset coils, edge contacts and inline ST. It checks
clean with --warnings-as-errors, runs with the values the manuals document, and its IEC 61131-10 export
validates against Omron's schemas (when present), loads back and runs the same."""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[3]
PROJECT = pathlib.Path(__file__).resolve().parent / "manual_project"
MS = 1_000_000
SCHEMAS = pathlib.Path(os.environ.get("SYSMAC_XSD_DIR") or ROOT.parent / "shared" / "sysmac_xml")


def sources(folder=PROJECT):
    return sorted(str(p) for p in folder.iterdir() if p.suffix in (".st", ".xml"))


class Line:
    """The configuration's program instance Line (task PrimaryTask, 10 ms) on virtual time."""

    def __init__(self, paths):
        self.plc = load_plc(paths, clock_base_ns=0)
        self.t = 0

    def scan(self, n=1, **values):
        for k, v in values.items():
            self.plc.write(self.path(k), v)
        for _ in range(n):
            self.plc.scan(self.t)
            self.t += 10 * MS
        return self

    @staticmethod
    def path(name: str) -> str:
        return name if name in GLOBAL_NAMES else f"Line.{name}"

    def __getitem__(self, name):
        return self.plc.read(self.path(name))


GLOBAL_NAMES = {"StatusWord", "RunLamp", "FaultLamp", "Produced", "ProducedLow", "ProducedHigh", "Recipe",
                "StartButton", "StopButton"}


def test_the_project_checks_clean_as_sysmac_code():
    r = subprocess.run([sys.executable, "-m", "vplc", "check", "--dialect", "sysmac", "--warnings-as-errors",
                        str(PROJECT)], capture_output=True, text=True, cwd=ROOT,
                       env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.strip().endswith("5 file(s) checked: 0 error(s), 0 warning(s)")


def run_documented_values(line: Line) -> None:
    line.scan()
    assert line["ModeNumber"] == 0 and line["RunLamp"] is False
    assert line["Recipe"] == [100, 200, 300, 400] and line["RecipeSize"] == 4          # AryMove, SizeOfAry
    assert line["Period"] == 10 * MS and line["FastEnough"] is True                     # GetMyTaskInterval, LT()
    assert abs(line["Received"] - 3.14159265) < 1e-6                                    # CopyDwordToReal
    assert line["RunSeconds"] == 2                                                      # SecToTime, TimeToSec
    # a rising edge of Start sets Running (latch="set"); the inline ST counts it
    line.scan(StartButton=True)
    assert line["RunLamp"] is True and line["Motor.Starts"] == 1
    assert line["ModeNumber"] == 5                                                      # EnumToNum(Running := 5)
    line.scan(StartButton=False)
    assert line["RunLamp"] is True, "a set coil keeps its value"
    # W502 2-116: Q of TON_instance(In, PT, Q, ET) after PT = 100 ms of In
    line.scan(8)
    assert line["DelayDone"] is False and line["DelayElapsed"] == 90 * MS
    line.scan()
    assert line["DelayDone"] is True and line["DelayElapsed"] == 100 * MS
    # W560 2-728: 25 % of a 200 ms period is 50 ms: HeaterOn in 5 of any 20 scans of 10 ms while RunLamp is on
    heater = []
    for _ in range(20):
        heater.append(line["HeaterOn"])
        line.scan()
    assert sum(heater) == 5 and line["HeaterErr"] is False
    # the CJ-area globals share their words: RunLamp is bit 00 of W100, FaultLamp bit 15 (CTD's Q is TRUE: CV 0)
    assert line["StatusWord"] == 0x8001 and line["FaultLamp"] is True
    cycles = line["Cycles"]
    assert line["Produced"] == cycles * 70000
    assert (line["ProducedLow"], line["ProducedHigh"]) == ((cycles * 70000) & 0xFFFF, (cycles * 70000) >> 16)
    assert line["Angle"] == (cycles * 100.0) % 360.0 and line["Message"] == ""          # ModReal, ClearString
    # W502 2-134: CTD_instance(CD, Load, PV, Q, CV): Load sets CV to PV; CD edges count down; CV stops at 0
    line.scan(Reload=True)
    assert line["BatchLeft"] == 3 and line["BatchEmpty"] is False
    line.scan(Reload=False)
    left = []
    for _ in range(5):
        line.scan(PartSeen=True)
        line.scan(PartSeen=False)
        left.append(line["BatchLeft"])
    assert left == [2, 1, 0, 0, 0] and line["BatchEmpty"] is True
    # a rising edge of Stop resets Running (latch="reset"); holding Start (no new edge) does not set it again
    line.scan(StopButton=True, StartButton=True)
    line.scan(StopButton=False)
    assert line["RunLamp"] is False and line["StatusWord"] & 1 == 0
    assert line["Motor.Starts"] == 1
    assert line["HeaterOn"] is False                                                    # Enable FALSE resets DOut
    # the empty batch raised the user-defined error 16#0100 (SetAlarm); GetAlarm reports it
    assert (line["AlarmActive"], line["AlarmLevel"], line["AlarmCode"]) == (True, 1, 0x0100)


def test_the_project_runs_with_the_documented_values():
    run_documented_values(Line(sources()))


def test_the_export_validates_against_omrons_schemas_and_runs_the_same(tmp_path):
    out = tmp_path / "manual_project.xml"
    r = subprocess.run([sys.executable, "-m", "vplc", "export", str(PROJECT), "--format", "iec61131-10", "-o",
                        str(out)], capture_output=True, text=True, cwd=ROOT,
                       env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    assert r.returncode == 0, r.stderr
    text = out.read_text(encoding="utf-8")
    assert 'overlap="true"' in text and 'xsi:type="smcext:InlineST"' in text and 'address="%W100.00"' in text
    config = tmp_path / "Config.st"
    config.write_text((PROJECT / "Config.st").read_text(encoding="utf-8"), encoding="utf-8")
    run_documented_values(Line([str(out), str(config)]))
    etree = pytest.importorskip("lxml.etree", reason="lxml is a test dependency: run `make test-deps`")
    xsd = SCHEMAS / "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
    if not xsd.exists():
        pytest.skip(f"Omron's IEC 61131-10 schemas are not in {SCHEMAS}; set SYSMAC_XSD_DIR")
    schema = etree.XMLSchema(etree.parse(str(xsd)))
    assert schema.validate(etree.parse(str(out))), [e.message for e in schema.error_log]


def test_the_plcopen_export_refuses_inline_st_by_name(tmp_path):
    r = subprocess.run([sys.executable, "-m", "vplc", "export", str(PROJECT), "--format", "plcopen", "-o",
                        str(tmp_path / "tc6.xml")], capture_output=True, text=True, cwd=ROOT,
                       env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    assert r.returncode == 1 and "smcext:InlineST" in r.stderr and "Traceback" not in r.stderr
