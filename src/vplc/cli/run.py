"""``python -m vplc run PATHS... [--task Main@1ms] [--virtual-time] [--cycles N | --duration T] [--stats]
[--trace VAR,... --trace-out FILE.vcd|FILE.svg]``: run ST programs on the virtual controller.

Real time (default) scans at the task period on the wall clock until Ctrl-C, --cycles or --duration;
--virtual-time scans as fast as possible with the clock advancing one period per scan (deterministic).
Exit 0 on a clean stop, 1 on a major fault, 2 on usage or load errors.
"""
from __future__ import annotations

import os
import sys
import threading
import time

from ..runtime.values import parse_duration


def register(subparsers) -> None:
    p = subparsers.add_parser("run", help="run ST programs on the virtual PLC",
                              description="Load, compile and run ST programs cyclically like an NJ/NX controller.")
    p.add_argument("paths", nargs="+", metavar="PATH", help="ST file or folder (recursive *.st)")
    p.add_argument("--task",
                   help="task NAME@PERIOD running every PROGRAM when the sources have no CONFIGURATION "
                        "(default Main@1ms)")
    p.add_argument("--program", action="append", metavar="NAME", help="run only this PROGRAM (repeatable)")
    p.add_argument("--virtual-time", action="store_true", help="run as fast as possible on virtual time")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--cycles", type=int, metavar="N", help="stop after N scans")
    g.add_argument("--duration", metavar="T", help="stop after this (controller) time, e.g. 5s or 250ms")
    p.add_argument("--stats", action="store_true", help="print scan time, lateness, overruns and statements per scan")
    p.add_argument("--trace", metavar="VAR,...", help="variables to record every scan")
    p.add_argument("--trace-out", metavar="FILE", help="trace file: .vcd (GTKWave) or .svg (timing diagram)")
    p.add_argument("--spin-us", type=int, default=300, metavar="US",
                   help="real time: busy-wait this long before each scan for lower jitter (default 300)")
    p.add_argument("--watchdog", default="500ms", metavar="T", help="major fault when one scan runs longer (default 500ms)")
    p.set_defaults(handler=run_cmd)


def _err(msg: str) -> int:
    print(f"vplc run: error: {msg}", file=sys.stderr)
    return 2


MAX_CYCLES = 2**31                       # about 24 days of a 1 ms task
MAX_DURATION_NS = 30 * 86_400 * 10**9
MAX_WATCHDOG_NS = 60 * 10**9
MAX_SPIN_US = 10_000


def run_cmd(args) -> int:
    from ..api import LoadError, PlcFault, load_plc, parse_task
    from ..runtime.stats import ScanStats
    from ..runtime.values import PathError
    from ..trace import Recorder, write_trace
    if bool(args.trace) != bool(args.trace_out):
        return _err("--trace and --trace-out go together")
    if args.trace_out and not args.trace_out.lower().endswith((".vcd", ".svg")):
        return _err(f"--trace-out {args.trace_out!r} must end in .vcd or .svg")
    if args.trace_out:
        folder = os.path.dirname(os.path.abspath(args.trace_out))
        if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
            return _err(f"--trace-out {args.trace_out!r}: the folder {folder} does not exist or is not writable")
    if args.cycles is not None and not 0 <= args.cycles <= MAX_CYCLES:
        return _err(f"--cycles must be 0 .. {MAX_CYCLES:,}")
    duration = parse_duration(args.duration) if args.duration else None
    if args.duration and (duration is None or not 0 < duration <= MAX_DURATION_NS):
        return _err(f"--duration {args.duration!r} must be a duration from 1ns to 30d, like 5s or 250ms")
    wd = parse_duration(args.watchdog)
    if wd is None or not 0 < wd <= MAX_WATCHDOG_NS:
        return _err(f"--watchdog {args.watchdog!r} must be a duration from 1ns to 60s, like 500ms")
    if not 0 <= args.spin_us <= MAX_SPIN_US:
        return _err(f"--spin-us must be 0 .. {MAX_SPIN_US:,} microseconds")
    try:
        if args.task is not None:
            parse_task(args.task)
        plc = load_plc(args.paths, task=args.task or "Main@1ms", programs=args.program, watchdog_ms=wd / 1e6,
                       count_statements=args.stats)
    except LoadError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    if args.task is not None and plc.project.configurations:
        print(f"vplc run: note: --task {args.task} is not used: the sources define their own CONFIGURATION",
              file=sys.stderr)
    rec = None
    if args.trace:
        try:
            rec = Recorder(plc, [p.strip() for p in args.trace.split(",") if p.strip()])
        except (PathError, ValueError) as exc:
            return _err(str(exc))
    stats = ScanStats() if args.stats else None
    status = 0
    try:
        if args.virtual_time:
            _run_virtual(plc, args.cycles, duration, rec, stats)
        else:
            _run_realtime(plc, args.cycles, duration, rec, stats, args.spin_us * 1000)
    except PlcFault as exc:
        print(f"vplc run: controller stopped: {exc}", file=sys.stderr)
        status = 1
    except KeyboardInterrupt:
        print("vplc run: stopped by the operator", file=sys.stderr)
    finally:
        plc.close()
    if stats is not None:
        print(stats.summary())
    if rec is not None:
        try:
            write_trace(rec, args.trace_out)
        except OSError as exc:
            print(f"vplc run: cannot write the trace to {args.trace_out}: {exc.strerror}", file=sys.stderr)
            return 1
        print(f"trace written to {args.trace_out}")
    return status


def _run_virtual(plc, cycles, duration, rec, stats) -> None:
    period = plc.period_ns
    n, t = 0, 0
    while (cycles is None or n < cycles) and (duration is None or t < duration):
        c0 = plc.statements_executed
        s0 = time.perf_counter_ns()
        plc.scan(t)
        if stats is not None:
            stats.record(0, time.perf_counter_ns() - s0, plc.statements_executed - c0)
        if rec is not None:
            rec.sample(t)
        n += 1
        t += period


def _run_realtime(plc, cycles, duration, rec, stats, spin_ns) -> None:
    stop = threading.Event()
    count = [0]

    def on_scan(now_ns):
        if rec is not None and count[0]:
            rec.sample(plc.now_ns)
        count[0] += 1
        if (cycles is not None and count[0] > cycles) or (duration is not None and now_ns >= duration):
            stop.set()
            raise _Stop()

    try:
        plc.run_realtime(stop, on_scan=on_scan, stats=stats, spin_ns=spin_ns)
    except _Stop:
        pass
    finally:
        if rec is not None and count[0] > 1:
            rec.sample(plc.now_ns)                # values after the last scan


class _Stop(Exception):
    pass
