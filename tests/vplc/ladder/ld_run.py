"""A ladder program on the virtual PLC, one 1 ms scan at a time: ``scan(A=True)`` writes Main variables and runs
one scan, ``r["Q"]`` reads a Main variable. ``Run(path)`` loads a file; ``Run.of(tmp_path, variables, body)``
writes the program of ld_xml first."""
from __future__ import annotations

from ld_xml import program

from vplc.api import load_plc

MS = 1_000_000


class Run:
    def __init__(self, path, extra=()):
        self.plc = load_plc([str(path), *map(str, extra)], task="Main@1ms")
        self.t = 0

    @classmethod
    def of(cls, tmp_path, variables, body, extra=()) -> Run:
        return cls(program(tmp_path, variables, body), extra)

    def scan(self, **values):
        for k, v in values.items():
            self.plc.write(f"Main.{k}", v)
        self.plc.scan(self.t)
        self.t += MS
        return self

    def __getitem__(self, name):
        return self.plc.read(f"Main.{name}")
