"""The contract between generated code and the runtime: every name one writes and the other reads.

The code generator (``vplc.compiler``) emits Python that runs in a namespace :meth:`Program.load` builds; the
engine and ``vplc.api`` reach into that namespace and into the objects the code creates. Every such name is
declared here, once, with its meaning; both sides import the constant instead of spelling the string, and
``tests/vplc/runtime/test_rt_abi.py`` compiles the library and the examples and proves the generated source uses
no reserved name that is missing here.

Reserved shapes (ST identifiers can take none of them, so generated names never collide with ST names):

* a bare name starting with ``_`` (ST variables are always reached as attributes: ``s.X``, ``G.X``);
* a bare name starting with ``N_`` / ``NF_`` (native function blocks and functions, bound per PLC);
* an attribute starting with ``i__`` (ST names never contain ``__``);
* the bare names ``G`` (the globals object) and ``s`` (the instance a body runs on).
"""
from __future__ import annotations

import re
from typing import Any, Protocol

# ---- cells the runtime creates in each image's namespace (one-element lists: shared, mutable) ---------------
DEADLINE = "_DL"               # [perf_counter() deadline of the running scan]; math.inf between scans
PROBATION = "_WDP"             # [deadline the watchdog's probation set, thread CPU time when it started]
WATCHDOG_LIMIT = "_WDS"        # [watchdog limit in seconds] (the engine writes its watchdog_ms here)
STATEMENTS = "_NST"            # [statements executed] (generated only with count_statements)
SCAN_TIME = "_NOW"             # [scan time in ns] the engine sets once per scan (VPLC_ScanTime())
PROGRAMS = "_PROGRAMS"         # upper program type name -> program instance (filled by vplc.api.Plc)
WATCHDOG = "_watchdog"         # the check a loop calls once the deadline has passed (raises WatchdogError)
STORES_OUT = "_stores_out"     # sysmac_fns.stores_out bound to the PLC: may an instruction's result be stored?

# ---- names the generated code defines and the runtime reads ----------------------------------------------
GLOBALS = "G"                  # the globals object (an instance of GLOBALS_CLASS); Plc replaces it with its own
GLOBALS_CLASS = "Globals"      # the class of the global variables
SELF = "s"                     # the instance a body function runs on (a local of every body)

# ---- prefixes of per-PLC bindings: prefix + the POU's name ---------------------------------------------------
NATIVE_FB = "N_"               # a native function block class, bound to the PLC (natives.NATIVE_FBS)
NATIVE_FUNCTION = "NF_"        # a native function, bound to the PLC (natives.NATIVE_FUNCTIONS)

# ---- helpers (program.HELPERS, stdlib.NAMESPACE): plain functions, the same for every PLC ------------------
F32 = "_f32"                   # round to IEEE single precision (REAL)
IDIV = "_idiv"                 # integer division truncating toward zero; faults on zero
IMOD = "_imod"                 # integer MOD with the sign of the dividend; faults on zero
RDIV = "_rdiv"                 # real division (inf/NaN like the FPU)
EXPT = "_expt"                 # EXPT with its faults
IX1 = "_ix1"                   # checked index of a one-dimensional array
IXN = "_ixn"                   # checked index of a multi-dimensional array
IXO = "_ixo"                   # checked index with an offset (array views)
VIEW = "_View"                 # an array view (ARRAY[*] parameters, sub-arrays)
ASSIGN = "_assign"             # assign a structured value into an existing one
COPY = "_copy"                 # deep copy of a structured value
PERF_COUNTER = "_pc"           # time.perf_counter, compared with the DEADLINE cell
FAULT = "_fault"               # raise a runtime fault with a message
NEW = "_new"                   # object.__new__: an instance without running __init__
HELPER_NAMES = frozenset({F32, IDIV, IMOD, RDIV, EXPT, IX1, IXN, IXO, VIEW, ASSIGN, COPY, PERF_COUNTER, FAULT,
                          NEW})
STDLIB_NAMES = frozenset({      # stdlib.NAMESPACE: standard functions the generated code calls
    "_fmod", "_mux", "_bcd_decode", "_bcd_encode", "_left", "_right", "_mid", "_insert", "_delete", "_replace",
    "_find", "_sinit", "_fill", "_round", "_trunc", "_shl", "_shr", "_rol", "_ror", "_lbound", "_ubound",
    "_atan2"})
STDLIB_MATH_PREFIX = "_m"      # "_m" + the name of a math function (stdlib.MATH): _mSIN, _mSQRT, ...
IMPORTED_NAMES = frozenset({    # runtime names a generated module imports itself (unions, memory areas)
    "_uprop", "_umembers", "_AreaMemory", "_aprop"})

# ---- names of generated things: prefix + a counter (the module defines them itself) ------------------------
TEMP_PREFIXES = ("_t", "_p", "_c", "_v", "_e", "_s", "_f", "_i", "_a", "_x", "_z")   # locals (CodeGen.tmp)
CONST_PREFIXES = ("_k", "_w", "_d", "_ty", "_cv")   # constants of the generated code (Program.consts)
LOCAL_NAMES = frozenset({"_", "_k", "_j"})     # single locals: unused loop variable, a converted value, an index

# ---- attributes of generated classes and instances ---------------------------------------------------------
PATH = "i__path"               # instance path ("Main.mover"), how faults name the instance
RUN = "i__run"                 # method of a native FB instance: execute one call
VARS = "i__vars"               # class attribute: upper variable name -> (attribute, type)
TYPE = "i__type"               # class attribute: the checked PouType / StructType
NAME = "i__name"               # class attribute: the POU's qualified name
UNION_CELL = "i__m"            # a union's memory image (one cell)
MEMBERS = "i__members"         # descriptor giving a union's / memory-area globals' members as a mapping
MEMORY = "i__mem"              # the globals' memory areas (at_memory.AreaMemory)
ATTRIBUTES = frozenset({PATH, RUN, VARS, TYPE, NAME, UNION_CELL, MEMBERS, MEMORY})
REF_CELL = "__r"               # attribute suffix of a scalar VAR_IN_OUT: the container it refers to
REF_KEY = "__k"                # attribute suffix of a scalar VAR_IN_OUT: the key (index / name) in that container

NAMESPACE_CELLS = frozenset({DEADLINE, PROBATION, WATCHDOG_LIMIT, STATEMENTS, SCAN_TIME, PROGRAMS})
BOUND_NAMES = frozenset({WATCHDOG, STORES_OUT})

_COUNTED = re.compile(r"(?P<prefix>_[A-Za-z]+?)\d+")


def is_declared(name: str) -> bool:
    """Is the bare name ``name`` of generated code part of this contract (or not of a reserved shape at all)?"""
    if name in NAMESPACE_CELLS or name in BOUND_NAMES or name in HELPER_NAMES or name in STDLIB_NAMES \
            or name in IMPORTED_NAMES or name in LOCAL_NAMES or name in (GLOBALS, GLOBALS_CLASS, SELF):
        return True
    if name.startswith((NATIVE_FUNCTION, NATIVE_FB)):
        return True
    if name.startswith(STDLIB_MATH_PREFIX) and name[len(STDLIB_MATH_PREFIX):].isupper():
        return True
    m = _COUNTED.fullmatch(name)
    if m is not None:
        return m["prefix"] in TEMP_PREFIXES or m["prefix"] in CONST_PREFIXES
    return not name.startswith("_")


class LoadedCode(Protocol):
    """What the engine needs of one loaded copy of generated code (``program.Image``): the namespace it runs in
    (the cells above live there) and the map from generated line numbers to ST ``(file, line)``."""
    namespace: dict[str, Any]

    @property
    def linemap(self) -> dict: ...
