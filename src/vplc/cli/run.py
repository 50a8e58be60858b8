"""``python3 -m vplc run PATHS... [--task Main@1ms] [--virtual-time] [--cycles N | --duration T] [--stats]
[--watch VAR,...] [--set VAR=VALUE@TIME]... [--scenario FILE] [--trace VAR,... --trace-out FILE.vcd|FILE.svg
[--trace-window FROM..TO]] [--max-overruns N] [--sim-control HOST:PORT]``: run ST programs on the virtual controller.

Real time (default) scans at the task period on the wall clock until Ctrl-C, SIGTERM, --cycles, --duration or the
end of the scenario, and reports its overruns in the last line; --virtual-time scans as fast as possible with the
clock advancing one period per scan (deterministic). Values are shown in PLC notation (16#4006, enumeration
names, T#1.5s). Exit 0 when the run ended as asked and every expectation held; 1 with a one-line reason on a
major fault (watchdog included), a failed expectation, an operator stop before the scenario was decided or more
overruns than --max-overruns; 2 on usage or load errors.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from types import FrameType
from typing import TYPE_CHECKING, Any

from ..runtime.values import parse_duration
from . import scenario as scn
from . import simlink
from .scenario_run import Runner

if TYPE_CHECKING:
    from ..api import Plc
    from ..runtime.stats import OverrunCount, ScanStats
    from ..trace import Recorder


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("run", help="run ST programs on the virtual PLC",
                              description="Load, compile and run ST programs cyclically like an NJ/NX controller.")
    p.add_argument("paths", nargs="+", metavar="PATH",
                   help="ST (.st) or PLCopen / IEC 61131-10 (.xml) file, or a folder searched recursively for both")
    p.add_argument("--task",
                   help="task NAME@PERIOD running every PROGRAM when the sources have no CONFIGURATION "
                        "(default Main@1ms)")
    p.add_argument("--program", action="append", metavar="NAME", help="run only this PROGRAM (repeatable)")
    p.add_argument("--virtual-time", action="store_true", help="run as fast as possible on virtual time")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--cycles", type=int, metavar="N", help="stop after N scans")
    g.add_argument("--duration", metavar="T", help="stop after this (controller) time, e.g. 5s or 250ms")
    p.add_argument("--stats", action="store_true", help="print scan time, lateness, overruns and statements per scan")
    p.add_argument("--watch", metavar="VAR,...",
                   help="print every change of these variables with its time, and their values at the end")
    p.add_argument("--set", action="append", default=[], metavar="VAR=VALUE@TIME",
                   help="write a variable when the run reaches TIME (default 0s), e.g. Main.Start=TRUE@2s "
                        "(repeatable)")
    p.add_argument("--axes", metavar="FILE",
                   help="axis configuration (TOML) of the virtual servo axes behind _MC_AX[n] (runtime_sysmac.md §5)")
    p.add_argument("--scenario", metavar="FILE",
                   help="timed writes and expectations (`at 2s set Main.Start TRUE`, `expect Main.Placed = 24 "
                        "within 60s`); the run ends when every expectation is decided")
    p.add_argument("--sim-control", metavar="HOST:PORT",
                   help="the robot simulator's control channel, for the scenario's `robot N ...` lines "
                        "(e.g. 127.0.0.1:5889)")
    p.add_argument("--trace", metavar="VAR,...", help="variables to record every scan")
    p.add_argument("--trace-out", metavar="FILE", help="trace file: .vcd (GTKWave) or .svg (timing diagram)")
    p.add_argument("--trace-window", metavar="FROM..TO",
                   help="SVG: draw only this part of the run, e.g. 2s..2.5s (the VCD keeps everything)")
    p.add_argument("--spin-us", type=int, default=300, metavar="US",
                   help="real time: busy-wait this long before each scan for lower jitter (default 300)")
    p.add_argument("--watchdog", default="500ms", metavar="T",
                   help="major fault when one scan runs longer (default 500ms)")
    p.add_argument("--max-overruns", type=int, metavar="N",
                   help="real time: fail the run (exit 1) on more than N overruns (task periods missed because a "
                        "scan was still running when the next one was due)")
    p.set_defaults(handler=run_cmd)


def _err(msg: str) -> int:
    print(f"vplc run: error: {msg}", file=sys.stderr)
    return 2


MAX_CYCLES = 2**31                       # about 24 days of a 1 ms task
MAX_DURATION_NS = 30 * 86_400 * 10**9
MAX_WATCHDOG_NS = 60 * 10**9
MAX_SPIN_US = 10_000


def run_cmd(args: argparse.Namespace) -> int:
    if bool(args.trace) != bool(args.trace_out):
        return _err("--trace and --trace-out go together")
    for option, text in (("--trace", args.trace), ("--watch", args.watch)):
        if text is not None and not _paths(text):
            return _err(f"{option} {text!r} names no variable; give VAR,VAR,... like Main.Count,Main.Busy")
    if args.trace_out and not args.trace_out.lower().endswith((".vcd", ".svg")):
        return _err(f"--trace-out {args.trace_out!r} must end in .vcd or .svg")
    if args.trace_out:
        folder = os.path.dirname(os.path.abspath(args.trace_out))
        if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
            return _err(f"--trace-out {args.trace_out!r}: the folder {folder} does not exist or is not writable")
    window = None
    if args.trace_window:
        if not (args.trace_out or "").lower().endswith(".svg"):
            return _err("--trace-window applies to an .svg --trace-out")
        try:
            window = parse_window(args.trace_window)
        except ValueError as exc:
            return _err(str(exc))
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
    if args.max_overruns is not None:
        if args.virtual_time:
            return _err("--max-overruns applies to real time; on --virtual-time every scan gets the time it takes")
        if not 0 <= args.max_overruns <= MAX_CYCLES:
            return _err(f"--max-overruns must be 0 .. {MAX_CYCLES:,}")
    try:
        scenario = scn.load(args.scenario) if args.scenario else scn.Scenario()
        for text in args.set:
            scn.add_set_option(text, scenario)
    except scn.ScenarioError as exc:
        return _err(str(exc))
    link = None
    if scenario.robots and not args.sim_control:
        return _err(f"{scenario.robots[0].where}: `robot` lines act on the simulator: give its control channel "
                    "with --sim-control HOST:PORT (e.g. 127.0.0.1:5889)")
    if args.sim_control:
        try:
            host, port = simlink.parse_address(args.sim_control)
            link = simlink.SimControl(host, port)
            scn.check_robots(scenario, link.robot_count(), link.where)
        except (ValueError, simlink.LinkError) as exc:
            if link is not None:
                link.close()
            return _err(str(exc))
    try:
        return _load_and_run(args, scenario, link, duration, wd, window)
    finally:
        if link is not None:
            link.close()


def _load_and_run(args: argparse.Namespace, scenario: scn.Scenario, link: simlink.SimControl | None,
                  duration: int | None, wd: int, window: tuple[int, int] | None) -> int:
    from ..api import LoadError, PlcFault, load_plc, parse_task
    from ..runtime.stats import OverrunCount, ScanStats
    from ..runtime.values import PathError
    from ..trace import Recorder, write_trace
    try:
        if args.task is not None:
            parse_task(args.task)
        plc = load_plc(args.paths, task=args.task or "Main@1ms", programs=args.program, watchdog_ms=wd / 1e6,
                       count_statements=args.stats, axes=args.axes)
    except LoadError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    if args.task is not None and plc.project.configurations:
        print(f"vplc run: note: --task {args.task} is not used: the sources define their own CONFIGURATION",
              file=sys.stderr)
    rec = watch = None
    try:
        scn.resolve(plc, scenario)
        if args.trace:
            rec = Recorder(plc, _paths(args.trace))
        if args.watch:
            watch = Watch(plc, _paths(args.watch))
    except scn.ScenarioError as exc:
        plc.close()
        return _err(str(exc))
    except (PathError, ValueError) as exc:
        plc.close()
        return _err(str(exc))
    runner = Runner(plc, scenario, link, wait=args.virtual_time)
    stats: ScanStats | OverrunCount | None = ScanStats() if args.stats else None
    if stats is None and not args.virtual_time:
        stats = OverrunCount()                 # every real-time run reports its overruns in its final line
    reason = None
    hooks = Hooks(plc, runner, rec, watch, args.cycles, duration)
    previous = _on_sigterm(_terminate)
    try:
        print(start_line(plc, args, scenario, duration), flush=True)
        if args.virtual_time:
            _run_virtual(plc, hooks, stats)
        else:
            _run_realtime(plc, hooks, stats, args.spin_us * 1000)
    except PlcFault as exc:
        print(f"vplc run: controller stopped: {exc}", file=sys.stderr)
        reason = f"major fault at {scn.seconds(plc.now_ns)}: {str(exc).splitlines()[0]}"
    except KeyboardInterrupt as exc:
        who = "SIGTERM" if isinstance(exc, Terminated) else "the operator"
        print(f"vplc run: stopped by {who}", file=sys.stderr)
        if not scenario.empty and runner.failure is None and runner.end_check(plc.now_ns):
            reason = f"stopped by {who} at {scn.seconds(plc.now_ns)} before the scenario was decided"
    finally:
        _on_sigterm(previous)
        plc.close()
    if link is not None:
        link.drain()                           # the answers to the last requests decide the run too
    if reason is None:
        reason = runner.end_check(hooks.last_ns)
    overruns = None if args.virtual_time or stats is None else stats.overruns     # real time always counts them
    if reason is None and args.max_overruns is not None and overruns is not None and overruns > args.max_overruns:
        reason = (f"{overruns} overrun(s), more than --max-overruns {args.max_overruns} (task periods missed "
                  "because a scan was still running when the next one was due)")
    count, latest = plc.instruction_errors
    if count:
        print(f"vplc run: {count} instruction error(s) (ENO FALSE on the controller: the program went on, the "
              "instruction's output kept its value):", file=sys.stderr)
        for message in dict.fromkeys(latest):
            print(f"  {message}", file=sys.stderr)
    if watch is not None:
        print(watch.final(hooks.last_ns))
    if isinstance(stats, ScanStats):             # --stats
        print(stats.summary())
    if rec is not None:
        try:
            write_trace(rec, args.trace_out, window)
        except OSError as exc:
            print(f"vplc run: cannot write the trace to {args.trace_out}: {exc.strerror}", file=sys.stderr)
            return 1
        print(f"trace written to {args.trace_out}")
    held = sum(1 for e in scenario.expects if e.state == "held")
    late = f"; {overruns} overrun(s)" if overruns is not None else ""
    if reason is not None:
        unmet = runner.unmet(hooks.last_ns)
        if unmet:
            print(f"vplc run: {len(unmet)} expectation(s) not met:", *unmet, sep="\n", file=sys.stderr)
        print(f"vplc run: FAILED: {reason}{late if 'overrun' not in reason else ''}", file=sys.stderr)
        return 1
    summary = f"{hooks.scans} scan(s), {scn.seconds(hooks.last_ns)} of controller time{late}"
    if scenario.expects:
        summary += f"; {held} of {len(scenario.expects)} expectation(s) held"
    print(f"vplc run: OK: {summary}")
    return 0


class Terminated(KeyboardInterrupt):
    """SIGTERM during a run: it ends like Ctrl-C, with the final values, the statistics and the trace written."""


def _terminate(signum: int, frame: FrameType | None) -> None:
    raise Terminated()


_NOT_SET = object()


def _on_sigterm(handler: Any) -> Any:
    """Install ``handler`` for SIGTERM and return the one it replaces (``_NOT_SET`` where signals cannot be set:
    a thread other than the main one, a platform without SIGTERM; then nothing is installed or restored)."""
    if handler is _NOT_SET or not hasattr(signal, "SIGTERM"):
        return _NOT_SET
    try:
        return signal.signal(signal.SIGTERM, signal.SIG_DFL if handler is None else handler)
    except ValueError:
        return _NOT_SET


def parse_window(text: str) -> tuple[int, int]:
    """``"2s..2.5s"`` -> (FROM, TO) in ns; ``"..3s"`` starts at 0; ValueError with the reason otherwise."""
    start, sep, end = text.partition("..")
    t0 = parse_duration(start) if start.strip() else 0
    t1 = parse_duration(end) if end.strip() else None
    if not sep or t0 is None or t1 is None:
        raise ValueError(f"--trace-window {text!r} is not of the form FROM..TO, e.g. 2s..2.5s")
    if t1 <= t0:
        raise ValueError(f"--trace-window {text!r}: TO must be later than FROM")
    return t0, t1


def _paths(text: str) -> list[str]:
    return [p.strip() for p in text.split(",") if p.strip()]


def start_line(plc: Plc, args: argparse.Namespace, scenario: scn.Scenario, duration: int | None) -> str:
    tasks = "; ".join(f"task {t.name} every {_period(t.period_ns)}: "
                      f"{', '.join(inst.i__path for inst, _ in t.programs)}" for t in plc.engine.tasks)
    clock = "virtual time" if args.virtual_time else "real time"
    if args.cycles is not None:
        until = f"{args.cycles} scan(s)"
    elif duration is not None:
        until = scn.seconds(duration)
    elif scenario.ends:
        until = "the scenario is decided"
    else:
        until = "Ctrl-C" if not args.virtual_time else "Ctrl-C (virtual time never ends by itself)"
    sockets = socket_use(plc)
    socks = (f"may open {sockets} (at most {plc.engine.sockets.limit})" if sockets else "opens no sockets")
    return f"vplc run: {tasks}; {clock} until {until}; {socks}"


def _period(ns: int) -> str:
    for unit, scale in (("s", 10**9), ("ms", 10**6), ("us", 10**3)):
        if ns >= scale:
            return f"{ns / scale:g} {unit}"
    return f"{ns} ns"


_SOCKET_KINDS = {"SKTTCPCONNECT": "TCP client connections", "SKTTCPACCEPT": "TCP server connections",
                 "SKTUDPCREATE": "UDP sockets"}


def socket_use(plc: Plc) -> str:
    """Which kinds of socket the loaded program can open (the Skt* instruction instances it declares)."""
    from ..frontend import ast as A
    kinds = []
    for unit in plc.project.units:
        if getattr(unit, "in_prelude", False):
            continue
        for item in unit.items:
            for node in A.walk(item):
                if isinstance(node, A.NamedTypeRef):
                    kind = _SOCKET_KINDS.get(node.name.name.upper())
                    if kind and kind not in kinds:
                        kinds.append(kind)
    return " and ".join(kinds)


class Watch:
    """Prints each change of the watched variables as `time  VAR = value` in PLC notation, and a table at the end."""

    def __init__(self, plc: Plc, paths: list[str]) -> None:
        from ..runtime.values import plc_text
        self.plc, self.paths = plc, paths
        plc.var_type(paths[0])                                                   # PathError first
        self.text = {p: plc_text(plc.type_of(p)) for p in paths}   # PLC notation, per type
        self.values: dict[str, object] = {}
        self.width = max(len(p) for p in paths)

    def sample(self, t_ns: int) -> None:
        for p in self.paths:
            v = self.plc.read(p)
            if p not in self.values or self.values[p] != v:
                self.values[p] = v
                print(f"{t_ns / 1e9:10.3f} s  {p:<{self.width}} = {self.show(p, v)}", flush=True)

    def final(self, t_ns: int) -> str:
        lines = [f"final values at {scn.seconds(t_ns)}:"]
        for p in self.paths:
            lines.append(f"  {p:<{self.width}} = {self.show(p, self.plc.read(p))}")
        return "\n".join(lines)

    def show(self, path: str, v: Any) -> str:
        """16#4006 for a WORD, Idle for an enumeration, T#1.5s, (X := 1, Y := 16#00) ... (issue 27)."""
        return self.text[path](v)


class Hooks:
    """What happens around every scan: scenario writes before it; watch, trace and expectations after it."""

    def __init__(self, plc: Plc, runner: Runner, rec: Recorder | None, watch: Watch | None, cycles: int | None,
                 duration: int | None) -> None:
        self.plc, self.runner, self.rec, self.watch = plc, runner, rec, watch
        self.cycles, self.duration = cycles, duration
        self.scans = 0
        self.last_ns = 0

    def before(self, t_ns: int) -> bool:
        """False when the run must end before this scan."""
        if (self.cycles is not None and self.scans >= self.cycles) or \
                (self.duration is not None and t_ns >= self.duration):
            return False
        if self.scans and self.runner.finished(self.last_ns):
            return False
        self.runner.before_scan(t_ns)
        return True

    def after(self, t_ns: int) -> None:
        self.scans += 1
        self.last_ns = t_ns
        if self.rec is not None:
            self.rec.sample(t_ns)
        if self.watch is not None:
            self.watch.sample(t_ns)
        self.runner.after_scan(t_ns)


def _run_virtual(plc: Plc, hooks: Hooks, stats: ScanStats | OverrunCount | None) -> None:
    period = plc.period_ns
    t = 0
    while hooks.before(t):
        c0 = plc.statements_executed
        s0 = time.perf_counter_ns()
        plc.scan(t)
        if stats is not None:
            stats.record(0, time.perf_counter_ns() - s0, plc.statements_executed - c0)
        hooks.after(t)
        t += period


def _run_realtime(plc: Plc, hooks: Hooks, stats: ScanStats | OverrunCount | None, spin_ns: int) -> None:
    stop = threading.Event()
    pending: list[int] = []                # the scan time of a scan whose results are not judged yet

    def on_scan(now_ns: int) -> None:
        if pending:                        # the previous scan is complete: judge it
            hooks.after(pending.pop())
        if not hooks.before(now_ns):
            stop.set()
            raise _Stop()
        pending.append(now_ns)

    try:
        plc.run_realtime(stop, on_scan=on_scan, stats=stats, spin_ns=spin_ns)
    except _Stop:
        pass
    finally:
        if pending:                        # values after the last scan
            hooks.after(pending.pop())


class _Stop(Exception):
    pass
