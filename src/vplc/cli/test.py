"""``python3 -m vplc test PATHS... [--junit FILE]``: run TcUnit-style ST test suites on virtual time.

A test suite is any FUNCTION_BLOCK (outside the prelude) whose body calls TEST('name'). All suites are
instantiated in one generated runner program and called once per 1 ms scan until every test called
TEST_FINISHED() (or ``--timeout`` of virtual time passed). Output: each failing assert with its ST location,
then ``N passed, N failed``. Exit 0 when nothing failed, 1 otherwise, 2 for usage/load errors.
"""
from __future__ import annotations

import argparse
import functools
import os
import sys
import tempfile
import time
from typing import TYPE_CHECKING
from xml.sax.saxutils import escape, quoteattr

from ..frontend import ast as A
from ..runtime.values import parse_duration

if TYPE_CHECKING:
    from ..api import Plc
    from ..project import Project
    from ..runtime.faults import PlcFault
    from ..runtime.testing import Failure, TestCase

RUNNER = "VPLC_TestRunner"

MAX_TIMEOUT_NS = 86_400 * 10**9          # one day of virtual time


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("test", help="run ST unit-test suites (TcUnit style)",
                              description="Run every test-suite FB (a FUNCTION_BLOCK calling TEST('name')) found in "
                                          "PATHS on virtual time and report the results.")
    p.add_argument("paths", nargs="+", metavar="PATH",
                   help="ST (.st) or PLCopen / IEC 61131-10 (.xml) file, or a folder searched recursively for both")
    p.add_argument("--junit", metavar="FILE", help="also write the results as JUnit XML")
    p.add_argument("--axes", metavar="FILE",
                   help="axis configuration (TOML) of the virtual servo axes behind _MC_AX[n] (runtime_sysmac.md §5)")
    p.add_argument("--timeout", default="10s", help="virtual time allowed for all tests to finish (default 10s)")
    p.add_argument("-v", "--verbose", action="store_true", help="list passing tests too")
    p.set_defaults(handler=run_tests)


def find_suites(proj: Project) -> list[str]:
    suites = []
    for unit in proj.units:
        if getattr(unit, "in_prelude", False):
            continue
        for item in unit.items:
            if isinstance(item, A.Pou) and item.kind == "FUNCTION_BLOCK" and _calls_test(item):
                suites.append(f"{item.namespace}\\{item.name}" if item.namespace else item.name)
    return suites


def _calls_test(pou: A.Pou) -> bool:
    for stmt in pou.body:
        for node in A.walk(stmt):
            if isinstance(node, A.Call) and isinstance(node.callee, A.Name) and node.callee.name.name.upper() == "TEST":
                return True
    return False


def runner_source(suites: list[str]) -> str:
    decls = "\n".join(f"    {_inst(s)} : {s};" for s in suites)
    calls = "\n".join(f"{_inst(s)}();" for s in suites)
    return f"PROGRAM {RUNNER}\nVAR\n{decls}\nEND_VAR\n{calls}\nEND_PROGRAM\n"


def _inst(suite: str) -> str:
    return suite.rsplit("\\", 1)[-1]


def run_tests(args: argparse.Namespace) -> int:
    from ..api import LoadError, PlcFault, load_plc
    from ..project import load_project
    timeout = parse_duration(args.timeout)
    if timeout is None or not 0 < timeout <= MAX_TIMEOUT_NS:
        print(f"vplc test: error: --timeout {args.timeout!r} must be a duration from 1ns to 1d of virtual time, "
              f"like 10s or 500ms", file=sys.stderr)
        return 2
    if args.junit:
        folder = os.path.dirname(os.path.abspath(args.junit))
        if os.path.isdir(args.junit):
            print(f"vplc test: error: --junit {args.junit!r} is a folder; give a file name such as "
                  f"{os.path.join(args.junit, 'report.xml')}", file=sys.stderr)
            return 2
        if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
            print(f"vplc test: error: --junit {args.junit!r}: give a file name in an existing, writable folder "
                  f"({folder} does not exist or is not writable)", file=sys.stderr)
            return 2
    proj = load_project(args.paths)
    if proj.has_errors:
        print(proj.render_diagnostics(), file=sys.stderr)
        return 2
    suites = find_suites(proj)
    if not suites:
        print("no test suites found (a test suite is a FUNCTION_BLOCK that calls TEST('name'))")
        print("0 passed, 0 failed")
        return 1
    t0 = time.perf_counter()
    results: list[TestCase] = []
    errors: list[tuple[str | None, PlcFault]] = []
    remaining = list(suites)
    while remaining:
        with tempfile.TemporaryDirectory() as tmp:
            runner = os.path.join(tmp, "vplc_test_runner.st")
            with open(runner, "w", encoding="utf-8") as f:
                f.write(runner_source(remaining))
            try:
                plc = load_plc(list(args.paths) + [runner], task=f"{RUNNER}@1ms", programs=[RUNNER], axes=args.axes)
            except LoadError as exc:
                print(str(exc), file=sys.stderr)
                return 2
        faulted = None
        try:
            plc.run_until(functools.partial(_all_finished, plc), timeout)
        except PlcFault as exc:
            faulted = exc
        finally:
            plc.close()
        col = getattr(plc.engine, "tests", None)
        cases = col.order() if col else []
        if faulted is None:
            results.extend(cases)
            break
        bad = _inst_of(faulted.instance)
        for c in cases:
            if c.suite.split(".")[1:2] == [bad]:
                if col is not None and c is col.current.get(c.suite) and not c.finished:
                    c.failures.append(_fault_failure(faulted))
                    c.finished = True
                results.append(c)
        errors.append((bad, faulted))
        remaining = [s for s in remaining if _inst(s) != bad]
        if bad is None:
            break
    elapsed = time.perf_counter() - t0
    return report(results, errors, args, elapsed)


def _inst_of(path: str | None) -> str | None:
    if not path or "." not in path:
        return None
    return path.split(".")[1].split("[")[0]


def _fault_failure(fault: PlcFault) -> Failure:
    from ..runtime.testing import Failure
    text = str(fault).split(": major fault in ", 1)[-1]
    return Failure(fault.file or "<unknown>", fault.line or 0, f"major fault in {text}")


def _all_finished(plc: Plc) -> bool:
    col = plc.engine.tests                            # the TEST() collector, once a suite has run (runtime/testing)
    if col is None or not col.tests:
        return False
    return all(t.finished for t in col.tests.values())


def report(results: list[TestCase], errors: list[tuple[str | None, PlcFault]], args: argparse.Namespace,
           elapsed: float) -> int:
    passed = failed = 0
    for tc in results:
        label = f"{tc.suite.split('.', 1)[-1]}.{tc.name}"
        if not tc.finished:
            tc.failures.append(_unfinished(tc))
        if tc.failures:
            failed += 1
            for f in tc.failures:
                print(f"{f.file}:{f.line}: FAIL {label}: {f.message}")
        else:
            passed += 1
            if args.verbose:
                print(f"ok   {label}")
    for suite, fault in errors:
        if not any(tc.suite.split(".")[1:2] == [suite] for tc in results):
            failed += 1
            print(f"FAIL {suite}: {fault}")
    print(f"{passed} passed, {failed} failed")
    if args.junit:
        try:
            write_junit(args.junit, results, elapsed)
        except OSError as exc:
            print(f"vplc test: error: cannot write the JUnit report {args.junit}: {exc.strerror or exc}",
                  file=sys.stderr)
            return 1
    return 0 if failed == 0 else 1


def _unfinished(tc: TestCase) -> Failure:
    from ..runtime.testing import Failure
    return Failure("<runner>", 0, "test did not call TEST_FINISHED() before the timeout")


def write_junit(path: str, results: list[TestCase], elapsed: float) -> None:
    by_suite: dict[str, list] = {}
    for tc in results:
        by_suite.setdefault(tc.suite.split(".", 1)[-1], []).append(tc)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<testsuites tests="{len(results)}" failures="{sum(1 for t in results if t.failures)}" '
             f'time="{elapsed:.3f}">']
    for suite, cases in by_suite.items():
        lines.append(f'  <testsuite name={quoteattr(suite)} tests="{len(cases)}" '
                     f'failures="{sum(1 for t in cases if t.failures)}">')
        for tc in cases:
            lines.append(f'    <testcase classname={quoteattr(suite)} name={quoteattr(tc.name)}>')
            for f in tc.failures:
                text = escape(f"{f.file}:{f.line}: {f.message}")
                lines.append(f'      <failure message={quoteattr(f.message)}>{text}</failure>')
            lines.append("    </testcase>")
        lines.append("  </testsuite>")
    lines.append("</testsuites>")
    with open(path, "w", encoding="utf-8") as out:
        out.write("\n".join(lines) + "\n")
