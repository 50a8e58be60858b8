"""A compiled program and its loaded images.

The compiler produces a :class:`Program` once: the generated Python source, its code object, the map from
generated lines to ST lines and the variable tables of every class. A PLC instance loads it with
:meth:`Program.load`, which runs the code object in a fresh namespace: each instance gets its own classes,
globals, program instances, watchdog deadline and sockets, and none of the front end or code generator runs
again. One compile serves any number of instances.
"""
from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from types import CodeType
from typing import TYPE_CHECKING, Any

from . import abi, iec, natives, stdlib, sysmac_fns
from .faults import GEN_FILE, RuntimeFaultError, WatchdogError

if TYPE_CHECKING:
    from .engine import Engine

__all__ = ["GEN_FILE", "HELPERS", "Image", "InstanceSpec", "PouClass", "Program", "TaskSpec", "program_key"]


def make_watchdog(deadline: list, probation: list, limit_s: list) -> Callable[..., None]:
    """The check generated loops call once the scan's wall-clock deadline ``deadline[0]`` (start + ``limit_s[0]``)
    has passed. Wall time alone would fault a scan whose thread the host did not run (a loaded machine, parallel
    tests), so the first pass starts a probation instead: the deadline moves by ``limit_s[0]`` and the thread's CPU
    time is noted (``probation`` = [the deadline set, CPU time]); the fault comes when the program has used
    ``limit_s[0]`` of CPU time since. A scan that needs less CPU than the limit always finishes first; an endless
    loop faults after at most twice the limit of its own CPU time. Nothing of this costs a normal scan anything."""
    def watchdog(what: str = "a loop did not finish") -> None:
        cpu = time.thread_time()
        if probation[0] == deadline[0] and cpu - probation[1] >= limit_s[0]:
            raise WatchdogError(what)
        if probation[0] != deadline[0]:               # first pass in this scan
            probation[1] = cpu
        deadline[0] = probation[0] = time.perf_counter() + limit_s[0] - (cpu - probation[1])
    return watchdog


def fault(message: str) -> None:
    raise RuntimeFaultError(message)


# helpers every generated module calls by these names
HELPERS = {
    abi.F32: iec.f32, abi.IDIV: iec.idiv, abi.IMOD: iec.imod, abi.RDIV: iec.rdiv, abi.EXPT: iec.expt,
    abi.IX1: iec.ix1, abi.IXN: iec.ixn, abi.IXO: iec.ixo, abi.VIEW: iec.ArrView,
    abi.ASSIGN: iec.assign_into, abi.COPY: iec.copy_value,
    abi.PERF_COUNTER: time.perf_counter, abi.FAULT: fault, abi.NEW: object.__new__,
}


@dataclass
class PouClass:
    """What the generated module defines for one POU (native POUs have no class of their own)."""
    pou: object               # the checked PouType
    cls_name: str
    body_name: str | None
    vars: dict                # upper variable name -> (attribute, type)
    native: bool = False


@dataclass(frozen=True)
class TaskSpec:
    """A TASK of the CONFIGURATION: what the scan loop needs of it."""
    name: str
    period_ns: int
    priority: int


@dataclass(frozen=True)
class InstanceSpec:
    """``PROGRAM name WITH task : type;`` of the CONFIGURATION, its type resolved when compiling."""
    name: str                 # the instance name as declared
    type_text: str            # the PROGRAM type as written (messages, --program matching)
    key: str | None           # upper POU qualified name of the PROGRAM type; None when it names no PROGRAM
    task: str                 # upper task name ("" without WITH)


def program_key(text: str) -> str:
    """The form of a POU name ``Lib\\Name`` / ``Name`` under which :attr:`Program.program_names` holds it."""
    return "\\".join(p for p in text.replace("\\\\", "\\").split("\\") if p).upper()


@dataclass
class Program:
    project: Any            # the checked vplc.project.Project it was compiled from (a layer above the runtime)
    source: str
    code: CodeType
    linemap: dict                                       # python line -> (st file, st line)
    consts: dict                                        # constant names of the generated code -> values
    pous: dict = field(default_factory=dict)            # upper POU qualified name -> PouClass
    structs: list = field(default_factory=list)         # (class name, vars, StructType)
    globals_vars: dict = field(default_factory=dict)
    # what a PLC instance needs to set up its tasks, without the project's syntax tree:
    configured: bool = False                            # the sources have a CONFIGURATION
    resources: tuple = ()                               # per RESOURCE: (tuple of TaskSpec, tuple of InstanceSpec)
    programs: tuple = ()                                # POU keys of the user's PROGRAMs in source order
    program_names: dict = field(default_factory=dict)   # program_key(name as a user may write it) -> POU key

    def load(self) -> Image:
        """Run the compiled code in a fresh namespace: the classes and state of one PLC instance."""
        ns = dict(stdlib.NAMESPACE)
        ns.update(HELPERS)
        ns.update(self.consts)
        ns.update({abi.DEADLINE: [math.inf], abi.PROBATION: [math.nan, 0.0], abi.WATCHDOG_LIMIT: [0.5],
                   abi.STATEMENTS: [0], abi.SCAN_TIME: [0], abi.PROGRAMS: {}})
        ns[abi.WATCHDOG] = make_watchdog(ns[abi.DEADLINE], ns[abi.PROBATION], ns[abi.WATCHDOG_LIMIT])
        exec(self.code, ns)
        image = Image(self, ns)
        cls: Any        # a native FB's class or a generated one: both get their variables and POU type
        for key, info in self.pous.items():
            if info.native:
                cls = natives.NATIVE_FBS.get(info.pou.name)
                if cls is not None:
                    cls.i__vars, cls.i__type = info.vars, info.pou
                continue
            cls = ns.get(info.cls_name)
            if cls is None:
                continue
            cls.i__vars, cls.i__type = info.vars, info.pou
            image.classes[key] = cls
            if info.body_name is not None:
                image.bodies[key] = ns[info.body_name]
        for name, fields, t in self.structs:
            ns[name].i__vars, ns[name].i__type = fields, t
        image.globals_cls = globals_cls = ns[abi.GLOBALS_CLASS]
        globals_cls.i__vars = self.globals_vars
        return image


@dataclass
class Image:
    """One loaded copy of a program: the namespace its code runs in, per PLC instance."""
    program: Program
    namespace: dict
    classes: dict = field(default_factory=dict)          # upper POU qualified name -> class
    bodies: dict = field(default_factory=dict)           # upper POU qualified name -> body function
    globals_cls: Any = None         # the generated class of the global variables (set by Program.load)

    @property
    def source(self) -> str:
        return self.program.source

    @property
    def linemap(self) -> dict:
        return self.program.linemap

    def bind_natives(self, rt: Engine) -> None:
        """Make the native POUs of this image use the controller ``rt`` (sockets, clock)."""
        ns = self.namespace
        for name, cls in natives.NATIVE_FBS.items():
            ns[abi.NATIVE_FB + name] = functools.partial(cls, rt)
        for name, fn in natives.NATIVE_FUNCTIONS.items():
            ns[abi.NATIVE_FUNCTION + name] = functools.partial(fn, rt)
        ns[abi.STORES_OUT] = functools.partial(sysmac_fns.stores_out, rt)
