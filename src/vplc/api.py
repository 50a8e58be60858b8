"""Python API of the virtual PLC (Contract A): load ST sources, scan, read and write variables.

    plc = load_plc(["lib/", "main.st"], task="Main@1ms")
    plc.run_until(lambda: plc.read("Main.conn.Connected"), timeout_ns=5_000_000_000)
"""
from __future__ import annotations

import gc
import hashlib
import os
import re
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .compiler.codegen import CodeGen
from .frontend import types as T
from .frontend.source import MAX_SOURCE_BYTES, FileRefused, read_file_bytes
from .ladder.model import LadderBody
from .runtime import abi, sysmac_system
from .runtime.engine import Engine, Task
from .runtime.faults import PlcFault
from .runtime.program import Program, program_key
from .runtime.stats import OverrunCount, ScanStats
from .runtime.values import PathError, Resolver, Slot, parse_duration

if TYPE_CHECKING:
    from .runtime.motion import MotionController
    from .runtime.motion_config import AxisConfig

# what load_plc and compile_program take: a file or folder, or several (``.st``, PLCopen / IEC 61131-10 ``.xml``)
SourcePaths = str | Iterable[str | os.PathLike[str]]
# a virtual axis configuration: its file (TOML), or the axes runtime.motion_config.load_axes read from one
Axes = str | os.PathLike[str] | Iterable["AxisConfig"]

__all__ = ["load_plc", "compile_program", "LoadError", "PlcFault", "Plc", "LadderProgram", "integer_ranges"]


class LoadError(Exception):
    """The sources could not be loaded: ``str()`` is the rendered diagnostics."""


def integer_ranges() -> dict[str, tuple[int, int]]:
    """(lowest, highest) value of every IEC 61131-3 integer and bit-string type by name (SINT .. ULINT,
    BYTE .. LWORD): the type model the checker, compiler and runtime use, for a tool that judges a value before
    it writes it (the HMI's value checks)."""
    return {name: (t.lo, t.hi) for name, t in T.ELEMENTARY.items()
            if t.kind in ("int", "uint", "bit") and isinstance(t.lo, int) and isinstance(t.hi, int)}


@dataclass(frozen=True)
class LadderProgram:
    """A ladder (LD) PROGRAM the PLC runs, for a monitor that draws it and shows its power flow."""

    name: str                   # as declared
    instance: str               # the instance its own variables are read under (Plc.read("<instance>.<name>"))
    ladder: LadderBody          # the LD model (vplc.ladder): rungs of elements (id, kind, var ...) and wires
    own_names: frozenset[str]   # upper-case names it declares itself; a VAR_EXTERNAL is read as the global

    def svg(self) -> str:
        """The drawing as one SVG document; elements and wires carry the ids the power flow names."""
        from .ladder.svg import svg_document
        return svg_document(self.ladder)


def parse_task(task: str | None) -> tuple[str, int]:
    """``"Main@1ms"`` -> ("Main", 1_000_000); LoadError with the reason for anything else."""
    m = re.fullmatch(r"\s*([A-Za-z_]\w*)\s*@\s*(.+)", task or "")
    if not m:
        raise LoadError(f"error: task `{task}` is not of the form Name@period (e.g. Main@1ms)")
    period = parse_duration(m.group(2))
    if period is None:
        raise LoadError(f"error: task period `{m.group(2)}` is not a duration like 1ms, 500us or 0.01s")
    if period <= 0:
        raise LoadError(f"error: task period `{m.group(2)}` must be greater than zero")
    return m.group(1), period


def load_plc(paths: SourcePaths, task: str | None = "Main@1ms", programs: Iterable[str] | None = None, *,
             dialect: str = "sysmac", watchdog_ms: float = 500.0, socket_limit: int = 30, socket_latency_ns: int = 0,
             count_statements: bool = False, clock_base_ns: int | None = None, axes: Axes | None = None) -> Plc:
    """A new PLC instance (its own variables, tasks and sockets) running the compiled ``paths``; ``axes``: the
    axis configuration file of its virtual servo axes (docs/toolchain/runtime_sysmac.md section 5)."""
    program = compile_program(paths, dialect=dialect, count_statements=count_statements)
    return Plc(program, task, programs, watchdog_ms=watchdog_ms, socket_limit=socket_limit,
               socket_latency_ns=socket_latency_ns, clock_base_ns=clock_base_ns, axes=axes)


_COMPILED: OrderedDict = OrderedDict()      # source fingerprint -> Program, most recently used last
_COMPILED_MAX = 8
_COMPILE_LOCK = threading.Lock()


def compile_program(paths: SourcePaths, *, dialect: str = "sysmac", count_statements: bool = False) -> Program:
    """Parse, check and compile ``paths`` once: the result serves any number of PLC instances.

    Programs are kept by a fingerprint of every source file's name and bytes (prelude included), so loading
    unchanged sources again costs a file read, and an edited file is always compiled afresh."""
    from .project import gc_paused, load_project
    if isinstance(paths, str):
        paths = [paths]
    paths = list(paths)
    key = _fingerprint(paths, dialect, count_statements)
    with _COMPILE_LOCK:
        if key is not None and key in _COMPILED:
            _COMPILED.move_to_end(key)
            return _COMPILED[key]
    proj = load_project(paths, dialect=dialect)
    if proj.has_errors:
        raise LoadError(proj.render_diagnostics())
    try:
        with gc_paused():
            program = CodeGen(proj, count_statements).generate()
    except (NotImplementedError, RecursionError, SyntaxError, MemoryError) as exc:
        raise LoadError(f"error: the runtime cannot compile this program: {getattr(exc, 'msg', None) or exc}") from None
    except Exception as exc:    # noqa: BLE001 - a code generator defect must not show a traceback
        raise LoadError(f"error: internal error of the code generator ({type(exc).__name__}: {exc}); "
                        "please report it with the ST source") from None
    if key is not None:
        with _COMPILE_LOCK:
            _COMPILED[key] = program
            while len(_COMPILED) > _COMPILED_MAX:
                _COMPILED.popitem(last=False)
    return program


def _fingerprint(paths: list[str | os.PathLike[str]], dialect: str, count_statements: bool) -> bytes | None:
    """Digest of the files ``load_project`` would read, or None when any of them is unreadable (the front
    end then reports it)."""
    from .frontend.diagnostics import DiagnosticBag
    from .project import PRELUDE_DIR, collect_files
    diags = DiagnosticBag()
    files = collect_files(paths, diags)
    if diags.items:
        return None
    digest = hashlib.blake2b(f"{dialect}|{count_statements}|{PRELUDE_DIR}".encode())
    try:
        prelude = sorted(n for n in os.listdir(PRELUDE_DIR) if n.endswith(".st"))
        for path in [os.path.join(PRELUDE_DIR, n) for n in prelude] + files:
            data = read_file_bytes(path, MAX_SOURCE_BYTES, pipes=False)   # a pipe is read once, by the loader
            digest.update(f"\0{path}\0{len(data)}\0".encode())
            digest.update(data)
    except (OSError, FileRefused):         # a pipe, a device, a file over the limit: the loader says which
        return None
    return digest.digest()


_HEAP_FROZEN: list = []      # once per process: see Plc.run_realtime


class Plc:
    """One virtual controller: its own copy of a compiled program's variables, its tasks and its sockets."""

    def __init__(self, program: Program, task: str | None = "Main@1ms", programs: Iterable[str] | None = None, *,
                 watchdog_ms: float = 500.0, socket_limit: int = 30, socket_latency_ns: int = 0,
                 clock_base_ns: int | None = None, axes: Axes | None = None) -> None:
        from .project import gc_paused
        # The collector paused while the instance is built: everything built here lives as long as the PLC, and
        # a collection in between only walks it again (and the compiled programs beside it). A new PLC of the
        # library's test program: 12.2 -> 7.8 ms; with its byte buffers as bytearrays, 6.4-12.1 -> 3.1-4.7 ms.
        # Not frozen afterwards (project.LongLived): a PLC dropped goes with the next collection.
        with gc_paused(long_lived=False):
            self._build(program, task, programs, watchdog_ms, socket_limit, socket_latency_ns, clock_base_ns, axes)

    def _build(self, program: Program, task: str | None, programs: Iterable[str] | None, watchdog_ms: float,
               socket_limit: int, socket_latency_ns: int, clock_base_ns: int | None, axes: Axes | None) -> None:
        """The instance: its image of the program, engine, variables, tasks and axes (``__init__``'s arguments)."""
        self.program = program
        self.project = program.project
        self.module = module = program.load()
        self.engine = Engine(module, watchdog_ns=int(watchdog_ms * 1e6), socket_limit=socket_limit,
                             socket_latency_ns=socket_latency_ns, clock_base_ns=clock_base_ns)
        ns = module.namespace
        module.bind_natives(self.engine)
        self.lock = threading.RLock()
        try:
            self.globals = module.globals_cls()
            ns[abi.GLOBALS] = self.globals
            self.engine.before_task = sysmac_system.task_hook(self.engine, self.globals)
            self.instances: dict[str, Any] = ns[abi.PROGRAMS]     # instances of generated classes
            self.type_named_instances: dict[str, list[str]] = {}   # see _setup_tasks
            self._setup_tasks(task, programs)
        except LoadError:
            raise
        except MemoryError:
            raise LoadError("error: the program's variables do not fit in this computer's memory; look for very "
                            "large arrays") from None
        except Exception as exc:   # noqa: BLE001 - an initial value that faults
            raise LoadError(f"error: initialising the variables failed: {self.engine.make_fault(exc)}") from None
        self.motion = self._attach_axes(axes) if axes is not None else None
        self._resolver = Resolver(self)

    def _attach_axes(self, axes: Axes) -> MotionController:
        """Virtual servo axes behind _MC_AX: ``axes`` is the path of an axis configuration file (or the tuple
        ``runtime.motion_config.load_axes`` returns). Their motion processing runs after the programs of the
        highest-priority task, in each of its periods (the NJ/NX primary periodic task)."""
        from .runtime.motion import MotionController
        from .runtime.motion_config import AxisConfigError, load_axes
        try:
            configs = load_axes(axes) if isinstance(axes, (str, os.PathLike)) else tuple(axes)
            ctl = MotionController(self.engine, configs, self.globals)
        except AxisConfigError as exc:
            raise LoadError(f"error: {exc}") from None
        except ValueError as exc:
            raise LoadError(f"error: {os.fspath(axes) if isinstance(axes, (str, os.PathLike)) else 'axes'}: "
                            f"{exc}") from None
        self.engine.motion = ctl
        self.engine.tasks[0].programs.append((ctl, type(ctl).cycle))
        return ctl

    # ---- tasks --------------------------------------------------------------------------------
    # The compiled program carries its task table and its PROGRAMs by name (runtime/program.py): setting up the
    # tasks reads no syntax tree and finds every POU by its key.
    def _program(self, name: str) -> str:
        key = self.program.program_names.get(program_key(name))
        if key is None:
            raise LoadError(f"error: no PROGRAM named `{name}` in the loaded sources")
        return key

    def _instance(self, inst_name: str, key: str) -> tuple[Any, Callable[..., Any]]:
        """A new instance of the PROGRAM ``key`` named ``inst_name`` and its body function (a task's entry)."""
        inst = self.module.classes[key](inst_name)
        self.instances[inst_name.upper()] = inst
        return inst, self.module.bodies[key]

    def _setup_tasks(self, task: str | None, programs: Iterable[str] | None) -> None:
        program = self.program
        if program.configured:
            wanted = {p.upper() for p in programs or ()}      # --program: instance or PROGRAM type names
            found: set[str] = set()
            for task_specs, instance_specs in program.resources:
                by_name = {}
                for spec in task_specs:
                    t = Task(spec.name, spec.period_ns, spec.priority)
                    by_name[spec.name.upper()] = t
                    self.engine.tasks.append(t)
                for pi in instance_specs:
                    names = {pi.name.upper(), pi.type_text.upper()}
                    if programs and not names & wanted:
                        continue
                    found.update(names & wanted)
                    runs_it = by_name.get(pi.task)
                    if runs_it is None:
                        if not self.engine.tasks:
                            self.engine.tasks.append(Task("Default", 10_000_000, 0))
                        runs_it = self.engine.tasks[0]
                    if pi.key is None:
                        raise LoadError(f"error: no PROGRAM named `{pi.type_text}` in the loaded sources")
                    runs_it.programs.append(self._instance(pi.name, pi.key))
            missing = [p for p in programs or () if p.upper() not in found]
            if missing:
                raise LoadError(f"error: the CONFIGURATION runs no PROGRAM named `{missing[0]}` (give a program "
                                f"instance or PROGRAM type that one of its tasks runs)")
        else:
            t = Task(*parse_task(task), 0)
            keys = [self._program(p) for p in programs] if programs else list(program.programs)
            if not keys:
                raise LoadError("error: the sources contain no PROGRAM to run")
            for key in keys:
                t.programs.append(self._instance(program.pous[key].pou.name, key))
            self.engine.tasks.append(t)
        self.engine.tasks.sort(key=lambda t: t.priority)
        scheduled: dict[str, list[str]] = {}        # PROGRAM type -> names of its instances in the tasks
        for each in self.engine.tasks:
            for inst, _body in each.programs:
                scheduled.setdefault(inst.i__type.name.upper(), []).append(inst.i__path)
        for key in program.programs:                # programs called from other programs need an instance
            name = program.pous[key].pou.name
            if name.upper() not in self.instances:
                self._instance(name, key)
                if name.upper() in scheduled:       # reading it by the type name is a mistake: say so
                    self.type_named_instances[name.upper()] = scheduled[name.upper()]

    # ---- Contract A -----------------------------------------------------------------------------
    @property
    def period_ns(self) -> int:
        return self.engine.period_ns

    @property
    def now_ns(self) -> int:
        return self.engine.now_ns

    @property
    def task_cycles(self) -> tuple[int, ...]:
        """Completed cycles of every task, in task order. A scan call runs only the tasks that are due, so
        code that must know its writes were seen by the programs waits until every count has advanced."""
        return tuple(task.cycles for task in self.engine.tasks)

    @property
    def instruction_errors(self) -> tuple[int, list[str]]:
        """(count, the latest 100 messages) of instructions that ended in error without stopping the controller
        (ENO FALSE on an NJ/NX, e.g. LrealToFormatString with DecPlace > MinLen: Out is not changed)."""
        return self.engine.instruction_error_count, list(self.engine.instruction_errors)

    @property
    def fault(self) -> PlcFault | None:
        """The major fault the controller stopped on, None while it scans. From that scan on the PLC no longer
        scans, its variables keep the values of that moment and its sockets are closed."""
        return self.engine.fault

    def ladder_programs(self) -> list[LadderProgram]:
        """The ladder (LD) PROGRAMs of the loaded sources, in source order, each with the instance it runs as
        (its own name when no task runs it)."""
        found = []
        for unit in self.project.units:
            for item in unit.items:
                if getattr(item, "ladder", None) is None or item.kind != "PROGRAM":
                    continue
                instance = next((inst.i__path for inst in self.instances.values()
                                 if inst.i__type.name.upper() == item.name.upper()), item.name)
                own = frozenset(d.name.upper() for s in item.sections if s.kind != "VAR_EXTERNAL" for d in s.vars)
                found.append(LadderProgram(item.name, instance, item.ladder, own))
        return found

    @property
    def statements_executed(self) -> int:
        return self.engine.stmt_counter[0]

    def scan(self, now_ns: int) -> None:
        with self.lock:
            self.engine.scan(now_ns if type(now_ns) is int else int(now_ns))

    def read(self, path: str) -> Any:
        with self.lock:
            return self._resolver.read(path)

    def write(self, path: str, value: Any, raw: bool = False) -> None:
        """Type-checked write of one elementary variable; ``raw=True`` also lets an enumeration variable
        take an integer that is not one of its values (fault tests: an HMI or memory copy writing a number)."""
        with self.lock:
            self._resolver.write(path, value, raw)

    def var_type(self, path: str) -> str:
        """The IEC type text of the variable at ``path`` (``BOOL``, ``STRING[50]``, ``ARRAY[1..3] OF INT``)."""
        return self._resolver.type_text(path)

    def type_of(self, path: str) -> T.Type:
        """The declared type of the variable at ``path`` (a ``vplc.frontend.types`` type: what a tool needs to
        judge or show a value before it reads or writes one); ``PathError`` for a bad path, as ``read`` gives."""
        with self.lock:
            return self._resolver.type_of(path)

    def lasting_slot(self, path: str) -> Slot | None:
        """``(container, key, type)`` of a variable declared directly in a program instance or a global list:
        ``container[key]`` is its runtime value (before conversion to the API value) for as long as the
        controller exists, so a tool sampling it every scan may read it there without walking the path.
        None for a member or an array element (an assignment may replace what holds them); ``PathError`` for
        a bad path, as ``read`` gives."""
        with self.lock:
            return self._resolver.lasting_slot(path)

    def run_until(self, pred: Callable[[], object], timeout_ns: int,
                  on_scan: Callable[[int], object] | None = None) -> bool:
        eng = self.engine
        t = eng.now_ns + self.period_ns if eng.started else eng.now_ns
        end = t + max(int(timeout_ns), 1)
        while t < end:
            if on_scan is not None:
                on_scan(t)
            self.scan(t)
            if pred():
                return True
            t += self.period_ns
        return False

    def run_realtime(self, stop_event: threading.Event, on_scan: Callable[[int], object] | None = None,
                     stats: ScanStats | OverrunCount | None = None, spin_ns: int = 300_000) -> None:
        """Scan at the task period on the monotonic wall clock until ``stop_event`` is set.

        The driver sleeps until ``spin_ns`` before the due time, then spins: a longer spin lowers the
        lateness on a busy machine at the cost of CPU time (``spin_ns`` = period gives a busy-waiting task)."""
        if not _HEAP_FROZEN:                   # what loading built lives for good: keep it out of every later
            gc.collect()                       # collection, so the collector's pauses stay short while scanning
            gc.freeze()
            _HEAP_FROZEN.append(True)
        period = self.period_ns
        base = time.monotonic_ns() - (self.engine.now_ns + period if self.engine.started else 0)
        due = time.monotonic_ns()
        while not stop_event.is_set():
            now = time.monotonic_ns()
            wait = due - now
            if wait > spin_ns:
                time.sleep((wait - spin_ns + 100_000) / 1e9)      # coarse sleep, then spin to the due time
                continue
            while time.monotonic_ns() < due:
                pass
            start = time.monotonic_ns()
            tick = due - base          # the task clock is the scheduled tick: lateness never makes a task skip
            if on_scan is not None:
                on_scan(tick)
            c0 = self.statements_executed
            self.scan(tick)
            end = time.monotonic_ns()
            if stats is not None:
                stats.record(start - due, end - start, self.statements_executed - c0)
            due += period
            if end > due:                       # overrun: skip the missed periods
                missed = (end - due) // period + 1
                if stats is not None:
                    stats.overruns += missed
                due += missed * period

    def close(self) -> None:
        self.engine.sockets.close_all()

    def __enter__(self) -> Plc:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ += ["PathError", "T"]
