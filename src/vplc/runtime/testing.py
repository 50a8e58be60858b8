"""TcUnit-style test functions (prelude/tcunit.st) and the result collector used by ``vplc test``.

Each suite instance (an FB instance path) has tests opened by TEST('name'); asserts are recorded against the
suite's current test until TEST_FINISHED(). A failing assert is recorded once per ST location and test,
even when the test runs over many scans.
"""
from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from types import FrameType
from typing import Any, Protocol

from ..frontend import types as T
from .faults import GEN_FILE


@dataclass
class Failure:
    file: str
    line: int
    message: str


@dataclass
class TestCase:
    suite: str
    name: str
    finished: bool = False
    failures: list[Failure] = field(default_factory=list)
    seen: set = field(default_factory=set)
    scans: int = 0


class Collector:
    def __init__(self) -> None:
        self.tests: dict[tuple[str, str], TestCase] = {}
        self.current: dict[str, TestCase] = {}

    def order(self) -> list[TestCase]:
        return list(self.tests.values())


class Engine(Protocol):
    """What the test functions use of the engine that runs them (runtime/engine.py's Engine, which holds the
    collector): declared here so that this module does not import the engine that imports it."""

    tests: Collector | None

    @property
    def module(self) -> Any: ...


def _where(rt: Engine) -> tuple[str, int, str]:
    f: FrameType | None = sys._getframe(2)
    while f is not None and f.f_code.co_filename != GEN_FILE:
        f = f.f_back
    if f is None:
        return "<unknown>", 0, "<unknown>"
    file, line = rt.module.linemap.get(f.f_lineno, ("<unknown>", 0))
    s = f.f_locals.get("s")
    return file, line, getattr(s, "i__path", "<unknown>")


def _collector(rt: Engine) -> Collector:
    c = rt.tests
    if c is None:
        c = rt.tests = Collector()
    return c


def TEST(rt: Engine, Name: str) -> bool:
    _file, _line, suite = _where(rt)
    col = _collector(rt)
    tc = col.tests.get((suite, Name))
    if tc is None:
        tc = col.tests[(suite, Name)] = TestCase(suite, Name)
    tc.scans += 1
    col.current[suite] = tc
    return not tc.finished


def TEST_FINISHED(rt: Engine) -> bool:
    _file, _line, suite = _where(rt)
    tc = _collector(rt).current.get(suite)
    if tc is not None:
        tc.finished = True
    return True


def IS_TEST_FINISHED(rt: Engine, Name: str) -> bool:
    _file, _line, suite = _where(rt)
    tc = _collector(rt).tests.get((suite, Name))
    return bool(tc and tc.finished)


def _record(rt: Engine, ok: bool, text: str) -> bool:
    if ok:
        return True
    file, line, suite = _where(rt)
    tc = _collector(rt).current.get(suite)
    if tc is None or tc.finished:
        return False
    if (file, line) not in tc.seen:
        tc.seen.add((file, line))
        tc.failures.append(Failure(file, line, text))
    return False


def _msg(message: str, detail: str) -> str:
    return f"{message}: {detail}" if message else detail


def AssertTrue(rt: Engine, Condition: bool, Message: str) -> bool:
    return _record(rt, bool(Condition), _msg(Message or "", "expected TRUE, got FALSE"))


def AssertFalse(rt: Engine, Condition: bool, Message: str) -> bool:
    return _record(rt, not Condition, _msg(Message or "", "expected FALSE, got TRUE"))


def _fmt(v: object) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, str):
        return repr(v)
    return str(v)


def _equals(rt: Engine, Expected: object, Actual: object, Message: str) -> bool:
    return _record(rt, Expected == Actual, _msg(Message or "", f"expected {_fmt(Expected)}, got {_fmt(Actual)}"))


def _equals_bits(bits: int) -> Callable[[Engine, int, int, str], bool]:
    """AssertEquals_BYTE .. _LWORD: the values in the notation the controller shows them, 16#4006 (not 16390)."""
    def equals(rt: Engine, Expected: int, Actual: int, Message: str) -> bool:
        return _record(rt, Expected == Actual, _msg(Message or "", f"expected {T.bits_literal(Expected, bits)}, "
                                                                   f"got {T.bits_literal(Actual, bits)}"))
    return equals


def _equals_real(rt: Engine, Expected: float, Actual: float, Delta: float, Message: str) -> bool:
    ok = not (math.isnan(Expected) or math.isnan(Actual)) and abs(Expected - Actual) <= abs(Delta or 0.0)
    return _record(rt, ok, _msg(Message or "", f"expected {Expected:g} (+/- {Delta:g}), got {Actual:g}"))


_BITS = {"BYTE": 8, "WORD": 16, "DWORD": 32, "LWORD": 64}
_TYPES = ("BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT",
          "TIME", "LTIME", "DATE", "TIME_OF_DAY", "DATE_AND_TIME", "STRING")

FUNCTIONS: dict[str, Callable[..., bool]] = {
    "TEST": TEST, "TEST_FINISHED": TEST_FINISHED, "IS_TEST_FINISHED": IS_TEST_FINISHED,
    "AssertTrue": AssertTrue, "AssertFalse": AssertFalse,
    "AssertEquals_REAL": _equals_real, "AssertEquals_LREAL": _equals_real,
    **{f"AssertEquals_{t}": _equals for t in _TYPES},
    **{f"AssertEquals_{t}": _equals_bits(bits) for t, bits in _BITS.items()}}
