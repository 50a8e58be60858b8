"""Scan loop: tasks (period, priority, program instances), the watchdog and fault reporting.

``Engine.scan(now_ns)`` reads the time once, runs the programs of every task that is due (highest
priority first, i.e. lowest PRIORITY number) and records statistics. Time is an argument: the virtual and
the real-time drivers (``run_until`` / ``run_realtime`` in vplc.api) call the same ``scan``.
"""
from __future__ import annotations

import collections
import contextlib
import gc
import math
import sys
import time
import traceback
import weakref
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from types import FrameType
from typing import TYPE_CHECKING, Any

from ..frontend.types import StructType
from . import abi
from .faults import GEN_FILE, PlcFault, RuntimeFaultError, WatchdogError
from .sockets import SocketManager

if TYPE_CHECKING:
    from .motion import MotionController
    from .testing import Collector


@dataclass
class Task:
    name: str
    period_ns: int
    priority: int
    programs: list = field(default_factory=list)      # (instance, body function)
    next_due: int | None = None
    cycles: int = 0                                   # completed executions of the task's programs


_perf_counter = time.perf_counter


def gc_pause_callback(deadline: list[float], probation: list[float]) -> Callable[[str, dict], None]:
    """A ``gc.callbacks`` entry for one engine. Python's garbage collector is the host's time, not the program's:
    a collection during a scan moves the engine's watchdog deadline (and a probation it started) by its duration,
    so it does not look like an endless loop. The callback holds the engine's two cells, not the engine, so an
    engine nobody uses any more can still be collected; :func:`_forget` then removes the callback."""
    started = [0.0]

    def callback(phase: str, _info: dict) -> None:
        if phase == "start":
            started[0] = _perf_counter()
        elif started[0]:
            pause = _perf_counter() - started[0]
            started[0] = 0.0
            if deadline[0] != math.inf:
                if probation[0] == deadline[0]:
                    probation[0] += pause
                deadline[0] += pause
    return callback


def _forget(callback: Callable[[str, dict], None]) -> None:
    with contextlib.suppress(ValueError):
        gc.callbacks.remove(callback)


class Engine:
    def __init__(self, module: abi.LoadedCode, *, watchdog_ns: int = 500_000_000, socket_limit: int = 30,
                 socket_latency_ns: int = 0, clock_base_ns: int | None = None) -> None:
        self.module = module
        self.tasks: list[Task] = []
        self.now_ns = 0
        self.started = False
        self.watchdog_ns = watchdog_ns
        self.watchdog_s = watchdog_ns / 1e9
        self.sockets = SocketManager(socket_limit, socket_latency_ns)
        self.clock_base_ns = clock_base_ns
        self.fault: PlcFault | None = None
        self.scan_count = 0
        self.deadline = module.namespace[abi.DEADLINE]
        self.probation = module.namespace[abi.PROBATION]       # watchdog probation: [deadline it set, CPU time]
        module.namespace[abi.WATCHDOG_LIMIT][0] = self.watchdog_s
        pause = gc_pause_callback(self.deadline, self.probation)       # owned by this engine: gone with it
        gc.callbacks.append(pause)
        weakref.finalize(self, _forget, pause)
        self.stmt_counter = module.namespace[abi.STATEMENTS]
        self.now_cell = module.namespace[abi.SCAN_TIME]          # what VPLC_ScanTime() returns in generated code
        # hook(task, now_ns) run before every task execution (a dialect's system variables:
        # runtime/sysmac_system.py), or None
        self.before_task: Callable[[Task, int], None] | None = None
        self.current_task: Task | None = None     # the task whose programs are running
        self.motion: MotionController | None = None   # the virtual axes (Plc attaches them), read by MC_* FBs
        self.instruction_errors: collections.deque[str] = collections.deque(maxlen=100)   # the latest, located
        self.instruction_error_count = 0
        self.tests: Collector | None = None     # the TEST() results (runtime/testing.py), once a suite has run

    def instruction_error(self, message: str) -> None:
        """An instruction ended in error where the controller goes on (ENO FALSE, Out unchanged, e.g. W502 2-269):
        recorded with its ST location (``file:line: instruction error in Main.x: message``), never a fault."""
        self.instruction_error_count += 1
        frames = []
        frame: FrameType | None = sys._getframe(1)
        while frame is not None:
            frames.append((frame, frame.f_lineno))
            frame = frame.f_back
        loc, inst = self.st_location(reversed(frames))
        where = f"{loc[0]}:{loc[1]}" if loc and loc[0] else "<unknown location>"
        self.instruction_errors.append(f"{where}: instruction error in {inst or '<unknown instance>'}: {message}")

    def st_location(self, frames: Iterable[tuple[FrameType, int]]) -> tuple[tuple | None, str | None]:
        """((file, line), instance path) of the innermost generated-code frame of ``frames`` (outermost first)."""
        loc, inst = None, None
        for frame, lineno in frames:
            if frame.f_code.co_filename == GEN_FILE:
                loc = self.module.linemap.get(lineno, loc)
                s = frame.f_locals.get("s")
                inst = getattr(s, "i__path", inst) if s is not None else inst
        return loc, inst

    # ---- services used by native POUs -----------------------------------------------------------
    def new_struct(self, name: str) -> Any:
        """A fresh value of the structure type ``name`` (used by native FBs for _sSOCKET outputs)."""
        cache = self.__dict__.setdefault("_struct_classes", {})
        cls = cache.get(name.upper())
        if cls is None:
            for c in self.module.namespace.values():
                t = getattr(c, "i__type", None) if isinstance(c, type) else None
                if isinstance(t, StructType) and t.name.upper() == name.upper():
                    cls = cache[name.upper()] = c
                    break
            else:
                raise RuntimeFaultError(f"system type {name} is not loaded")
        return cls()

    def clock_dt_ns(self) -> int:
        """Controller calendar clock (DT): wall clock in real time, or a fixed base + scan time."""
        if self.clock_base_ns is None:
            return time.time_ns()
        return self.clock_base_ns + self.now_ns

    # ---- scanning -----------------------------------------------------------------------------
    @property
    def period_ns(self) -> int:
        return min(t.period_ns for t in self.tasks) if self.tasks else 1_000_000

    def scan(self, now_ns: int) -> None:
        if self.fault is not None:
            raise self.fault
        if now_ns < self.now_ns and self.started:
            raise ValueError(f"scan time must not go backwards ({now_ns} ns < {self.now_ns} ns)")
        self.started = True
        self.now_ns = self.now_cell[0] = now_ns
        deadline = self.deadline
        before_task = self.before_task
        deadline[0] = _perf_counter() + self.watchdog_s
        try:
            for task in self.tasks:
                due = task.next_due
                if due is None:
                    due = now_ns
                elif now_ns < due:
                    continue
                if before_task is not None:
                    before_task(task, now_ns)
                self.current_task = task          # GetMyTaskInterval (W502) reads the period of the running task
                for inst, body in task.programs:
                    body(inst)
                task.cycles += 1
                period = task.period_ns
                task.next_due = due + ((now_ns - due) // period + 1) * period
        except Exception as exc:          # noqa: BLE001 - every Python error becomes a PLC major fault
            self.fault = self.make_fault(exc)
            self.sockets.close_all()
            raise self.fault from None
        finally:
            deadline[0] = math.inf
        self.scan_count += 1

    def make_fault(self, exc: BaseException) -> PlcFault:
        loc, inst = self.st_location(traceback.walk_tb(exc.__traceback__))
        if isinstance(exc, WatchdogError):
            kind, what = "watchdog", f"watchdog: scan exceeded {self.watchdog_ns / 1e6:g} ms ({exc})"
        elif isinstance(exc, RuntimeFaultError):
            kind, what = "runtime", str(exc)
        elif isinstance(exc, RecursionError):
            kind, what = "runtime", "call nesting too deep"
        else:
            kind, what = "internal", f"internal runtime error ({type(exc).__name__}: {exc})"
        where = f"{loc[0]}:{loc[1]}" if loc and loc[0] else "<unknown location>"
        msg = f"{where}: major fault in {inst or '<unknown instance>'}: {what}"
        return PlcFault(msg, file=loc[0] if loc else None, line=loc[1] if loc else None, instance=inst, kind=kind)

