"""Ladder benchmarks (issue 16): per-scan cost of the LD example against its ST twin, and the time to load a
1,000-rung ladder program.

Run alone: ``python3 bench/bench_ladder.py`` (prints human-readable figures, exits 0).
"""
from __future__ import annotations

import gc
import os
import shutil
import sys
import tempfile
import time

from vplc.api import load_plc
from vplc.project import load_project

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

LIB = os.path.join(ROOT, "lib", "CBT_Commands_Lib")
EXAMPLES = os.path.join(ROOT, "examples")
SCANS = 3000


def per_scan_us(sources) -> float:
    """Best of 3 runs of SCANS virtual scans, commands toggling (no robot: each ends in its error)."""
    plc = load_plc(sources)
    names = ["ChangeBase_Execute", "MoveAbs_Execute", "SetOutput_Execute", "Stop_Execute"]
    best = float("inf")
    t = 0
    try:
        for _ in range(3):
            gc.collect()
            start = time.perf_counter()
            for n in range(SCANS):
                if n % 50 == 0:
                    for name in names:
                        plc.write(name, (n // 50) % 2 == 1)
                plc.scan(t)
                t += plc.period_ns
            best = min(best, (time.perf_counter() - start) / SCANS * 1e6)
    finally:
        plc.close()
    return best


def rung_xml(i: int, y: int) -> str:
    base = 10 + i * 10
    cp = '<connectionPointIn><connection refLocalId="{}"/></connectionPointIn>'
    return (f'<contact localId="{base + 1}"><position x="40" y="{y}"/>{cp.format(1)}<connectionPointOut/>'
            f'<variable>In{i % 50}</variable></contact>'
            f'<contact localId="{base + 2}" negated="true"><position x="140" y="{y}"/>{cp.format(base + 1)}'
            f'<connectionPointOut/><variable>Stop</variable></contact>'
            f'<coil localId="{base + 3}"><position x="400" y="{y}"/>{cp.format(base + 2)}<connectionPointOut/>'
            f'<variable>Out{i}</variable></coil>')


def thousand_rungs(path: str, rungs: int = 1000) -> None:
    variables = "".join(f'<variable name="In{i}"><type><BOOL/></type></variable>' for i in range(50))
    variables += "".join(f'<variable name="Out{i}"><type><BOOL/></type></variable>' for i in range(rungs))
    variables += '<variable name="Stop"><type><BOOL/></type></variable>'
    body = "".join(rung_xml(i, 40 + 60 * i) for i in range(rungs))
    doc = ('<?xml version="1.0" encoding="utf-8"?>\n<project xmlns="http://www.plcopen.org/xml/tc6_0201">'
           '<fileHeader companyName="b" productName="b" productVersion="1" creationDateTime="2024-01-01T00:00:00"/>'
           '<contentHeader name="b"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/></ld>'
           '<sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader><types><dataTypes/><pous>'
           f'<pou name="Main" pouType="program"><interface><localVars>{variables}</localVars></interface><body><LD>'
           f'<leftPowerRail localId="1"><position x="0" y="0"/><connectionPointOut formalParameter=""/></leftPowerRail>'
           f'{body}</LD></body></pou></pous></types><instances><configurations/></instances></project>\n')
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(doc)


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        twin = os.path.join(tmp, "st_examples")
        shutil.copytree(EXAMPLES, twin, ignore=shutil.ignore_patterns("*.py", "Commands_Example.xml"))
        shutil.copy(os.path.join(ROOT, "bench", "st", "Commands_Example_ST.st"),
                    os.path.join(twin, "Commands_Example.st"))
        ld = per_scan_us([LIB, EXAMPLES])
        st = per_scan_us([LIB, twin])
        print("Per-scan cost, examples (PnP_Example + Commands_Example) on virtual time, best of 3 x "
              f"{SCANS} scans:")
        print(f"  Commands_Example as ladder (LD)   {ld:8.1f} us/scan")
        print(f"  Commands_Example as ST twin       {st:8.1f} us/scan")
        print(f"  ladder / ST                       {ld / st * 100:8.1f} %   (target: within 110 %)")

        path = os.path.join(tmp, "thousand.xml")
        thousand_rungs(path)
        size = os.path.getsize(path)
        times = []
        for _ in range(3):
            gc.collect()
            start = time.perf_counter()
            proj = load_project([path])
            times.append(time.perf_counter() - start)
            assert not proj.has_errors, proj.render_diagnostics()
        start = time.perf_counter()
        load_plc([path]).close()
        full = time.perf_counter() - start
        print(f"\nLoading a 1,000-rung ladder program ({size / 1024:.0f} KiB PLCopen XML):")
        print(f"  read, translate, parse and check  {min(times):8.2f} s   (best of 3; target: under 2 s)")
        print(f"  ... and compile to a runnable PLC {full:8.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
