"""Scan statistics for ``vplc run --stats`` and the real-time driver: scan time, lateness, overruns."""
from __future__ import annotations

from collections.abc import Sequence


def percentile(values: Sequence[float], q: float) -> float:
    if not values:
        return 0
    s = sorted(values)
    return s[min(len(s) - 1, int(q * (len(s) - 1) + 0.5))]


class ScanStats:
    def __init__(self) -> None:
        self.lateness: list[int] = []
        self.scan_ns: list[int] = []
        self.statements: list[int] = []
        self.overruns = 0

    def record(self, lateness_ns: int, scan_ns: int, statements: int = 0) -> None:
        self.lateness.append(lateness_ns)
        self.scan_ns.append(scan_ns)
        self.statements.append(statements)

    def summary(self) -> str:
        n = len(self.scan_ns)
        if not n:
            return "no scans"
        us = lambda v: f"{v / 1000:.1f} us"   # noqa: E731
        lines = [f"scans: {n}",
                 f"scan time: median {us(percentile(self.scan_ns, .5))}, p99 {us(percentile(self.scan_ns, .99))}, "
                 f"max {us(max(self.scan_ns))}",
                 f"statements per scan: median {percentile(self.statements, .5)}, max {max(self.statements)}"]
        if any(self.lateness):
            lines.append(f"lateness: median {us(percentile(self.lateness, .5))}, "
                         f"p99 {us(percentile(self.lateness, .99))}, max {us(max(self.lateness))}")
        lines.append(f"overruns: {self.overruns}")
        return "\n".join(lines)


class OverrunCount:
    """What the real-time driver records when no statistics were asked for: only the overruns (scans that ended
    after the next one was due), so every real-time run can report them."""

    def __init__(self) -> None:
        self.overruns = 0

    def record(self, lateness_ns: int, scan_ns: int, statements: int = 0) -> None:
        pass
