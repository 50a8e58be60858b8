"""Behaviour traces: run a program scan by scan on virtual time with a fixed stimulus and record every
variable of interest after each scan, so two builds of one program can be compared value for value."""
from __future__ import annotations

import functools
import json
import pathlib

from vplc.api import load_plc
from vplc.runtime.values import converter

ROOT = pathlib.Path(__file__).resolve().parents[3]
MAPPING = json.loads((ROOT / "src" / "cbt_hmi" / "pages" / "mapping.json").read_text(encoding="utf-8"))
EXECUTES = sorted(n for n in MAPPING["variables"] if n.endswith("_Execute") and n != "Connect_Execute")
WATCHED = sorted(MAPPING["variables"])


def example_stimulus(scan: int) -> dict:
    """Each command's Execute goes TRUE and FALSE on its own rhythm; nothing is connected, so every command
    ends in its own error (deterministic: no robot timing in the trace)."""
    return {name: (scan // (7 + 3 * i)) % 2 == 1 for i, name in enumerate(EXECUTES)}


def trace(sources, scans: int = 1000, stimulus=example_stimulus, watched=WATCHED, task: str = "Main@1ms",
          programs=None):
    plc = load_plc([str(s) for s in sources], task=task, programs=programs)
    rows = []
    try:
        readers = [(name, reader(plc, name)) for name in watched]
        for n in range(scans):
            for name, value in stimulus(n).items():
                plc.write(name, value)
            plc.scan(n * plc.period_ns)
            rows.append({name: read() for name, read in readers})
    finally:
        plc.close()
    return rows


def reader(plc, path: str):
    """What ``plc.read(path)`` returns, as a function: a variable declared directly in a program instance or a
    global list is read where the controller keeps it (``Plc.lasting_slot``: the path is walked once, not after
    every scan), anything deeper through ``plc.read``."""
    slot = plc.lasting_slot(path)
    if slot is None:
        return lambda: plc.read(path)
    container, key, conv = slot.container, slot.key, converter(slot.type)
    return lambda: conv(container[key])


@functools.cache
def example_trace() -> list:
    """The trace of the example project (examples/ with the library), which several tests compare against: run
    once per process. Its rows are shared: read them, never change them."""
    return trace([ROOT / "lib" / "CBT_Commands_Lib", ROOT / "examples"])


def first_difference(a, b) -> str | None:
    for n, (ra, rb) in enumerate(zip(a, b, strict=False)):
        for name in ra:
            if ra[name] != rb[name]:
                return f"scan {n}: {name} = {ra[name]!r} vs {rb[name]!r}"
    return None if len(a) == len(b) else f"{len(a)} vs {len(b)} scans"
