"""The one table of the TM script language the simulator knows: functions (overloads with parameter and
return types, queued or immediate), data formats, Robot[0] attributes and IO points, each with the TMflow
versions that have it. The checker (tmsim.tmscript.static_check) and the interpreter (tmsim.tmscript.interp) read
only this table; docs/simulator.md lists it ("Version profiles").

Sources: TMscript 2.24 manual (ch. 11 parameterized objects, ch. 13 motion functions, ch. 15 Listen Node);
"1.8" is what TMflow 1.68-1.84 offer to external scripts (../shared/tm_protocol.md §7), i.e. everything
below except what the 2.24 manual added (marked V224).
"""
from __future__ import annotations

V18, V224 = "1.8", "2.24"
ALL = (V18, V224)
NEW = (V224,)                    # only in the 2.x function set

# one letter per type keeps the table below readable (I is int)
F, I, S, B, FA, IA, ANY, VOID, BYTE, BA = (  # noqa: E741
    "float", "int", "string", "bool", "float[]", "int[]", "any", "void", "byte", "byte[]")
P6 = (F,) * 6

# function -> (queued on the motion FIFO?, [(parameter types, return type, versions), ...])
FUNCTIONS: dict[str, tuple[bool, list[tuple[tuple[str, ...], str, tuple[str, ...]]]]] = {
    "PTP": (True, [((S, FA, I, I, I, B), B, ALL), ((S, FA, I, I, I, B, IA), B, ALL),        # §13.8
                   ((S,) + P6 + (I, I, I, B), B, ALL), ((S,) + P6 + (I, I, I, B, I, I, I), B, ALL)]),
    "Line": (True, [((S, FA, I, I, I, B), B, ALL), ((S,) + P6 + (I, I, I, B), B, ALL)]),    # §13.10
    "Circle": (True, [((S, FA, FA, I, I, I, I, B), B, ALL), ((S,) + P6 * 2 + (I, I, I, I, B), B, ALL)]),
    "PLine": (True, [((S, FA, I, I, I), B, ALL), ((S,) + P6 + (I, I, I), B, ALL)]),
    "Move_PTP": (True, [((S, FA, I, I, I, B), B, ALL), ((S,) + P6 + (I, I, I, B), B, ALL)]),
    "Move_Line": (True, [((S, FA, I, I, I, B), B, ALL), ((S,) + P6 + (I, I, I, B), B, ALL)]),
    "Move_PLine": (True, [((S, FA, I, I, I), B, ALL), ((S,) + P6 + (I, I, I), B, ALL)]),
    # §13.5 syntax 1 (name, base index; 2.24 only: TMflow 1.84 lists the name alone) .. syntax 4
    "ChangeBase": (True, [((S, I), B, NEW), ((S,), B, ALL), ((FA,), B, ALL), (P6, B, ALL)]),
    "ChangeTCP": (True, [((S,), B, ALL), ((FA,), B, ALL), ((FA, F), B, ALL), ((FA, F, FA), B, ALL),
                         (P6, B, ALL), (P6 + (F,), B, ALL), ((F,) * 16, B, ALL)]),           # §13.6
    "ChangeLoad": (True, [((F,), B, ALL)]),                                                  # §13.7
    "PVTEnter": (True, [((), B, ALL), ((I,), B, ALL)]),                                      # §13.17
    "PVTPoint": (True, [((FA, FA, F), B, ALL), ((FA, FA, F, B), B, NEW),                    # §13.19
                        ((F,) * 13, B, ALL), ((F,) * 13 + (B,), B, NEW)]),
    "PVTExit": (True, [((), B, ALL)]),
    "PVTPause": (False, [((), B, ALL)]),
    "PVTResume": (False, [((), B, ALL)]),
    "QueueTag": (True, [((I,), B, ALL), ((I, I), B, ALL)]),                                  # §13.1
    "WaitQueueTag": (False, [((), VOID, NEW), ((I,), I, ALL), ((I, I), I, ALL)]),            # §13.2
    "CheckQueueTag": (False, [((I,), I, NEW)]),                                              # §13.3
    # §13.4 defines no parameter. The priority forms StopAndClearBuffer(0|1|2) (§15.8) are no function: the
    # session acts on a line that is literally one of them before the script is checked; with any other
    # argument (a variable, an expression) the line is invalid, ERROR;line, and nothing of the packet runs
    "StopAndClearBuffer": (False, [((), B, ALL)]),
    "Pause": (False, [((), B, ALL)]),
    "Resume": (False, [((), B, ALL)]),
    # §15.7 defines no parameter; ScriptExit(0|1) are priority commands (§15.8), taken by the session from a line that
    # is literally one of them. ScriptExit(var) or any other argument is invalid, as StopAndClearBuffer(var) is
    "ScriptExit": (False, [((), B, ALL)]),
    "ListenSend": (False, [((I, ANY), I, ALL), ((S, I, ANY), I, ALL)]),
    "ListenPacket": (False, [((S,), S, ALL), ((S, S), S, ALL)]),
    "GetString": (False, [((ANY,), S, ALL), ((ANY, I), S, ALL), ((ANY, I, I), S, ALL)]),
    "Sleep": (False, [((I,), VOID, NEW)]),
    # vision (tmsim/robot/camera.py). The jobs run in order with the motions (§13.33, §13.34 "queue with the motion
    # commands"); the script waits for the result, the bool they return. Not queued here: the interpreter
    # waits for the queue itself. Flying Trigger / Inspection forms (§14.2 second halves) are not simulated
    "Vision_DoJob": (False, [((S,), B, ALL)]),                                               # §13.32
    "Vision_DoJob_PTP": (False, [((S, I, I, B), B, ALL), ((S, I, I), B, ALL)]),             # §13.33
    "Vision_DoJob_Line": (False, [((S, I), B, ALL), ((S, I, I, B), B, ALL), ((S, I, I), B, ALL)]),  # §13.34
    "Vision_IsJobAvailable": (False, [((S,), B, ALL)]),                                      # §14.1
    "Vision_GetOutputArraySize": (False, [((S,), I, NEW), ((S, I), I, NEW)]),                # §14.2.1
    "Vision_GetOutputArrayValue": (False, [((S, I), "string[]", NEW), ((S, I, I), S, NEW)]),  # §14.2.2
}

# data format (first argument) of the motion functions -> versions. "D": absolute speed not scaled by the
# project speed (TMscript 2.24 §13.10 Line, §13.11 Move_Line, §13.12 Circle)
FORMATS: dict[str, dict[str, tuple[str, ...]]] = {
    "PTP": {"JPP": ALL, "CPP": ALL},
    "Line": {"CPP": ALL, "CPR": ALL, "CAP": ALL, "CAR": ALL, "CDP": NEW, "CDR": NEW},
    "Circle": {"CPP": ALL, "CAP": ALL, "CDP": NEW},
    "PLine": {"CAP": ALL, "JAP": ALL},
    "Move_PTP": {"CPP": ALL, "TPP": ALL, "JPP": ALL},
    "Move_Line": {"CPP": ALL, "CPR": ALL, "CAP": ALL, "CAR": ALL, "CDP": NEW, "CDR": NEW,
                  "TPP": ALL, "TPR": ALL, "TAP": ALL, "TAR": ALL, "TDP": NEW, "TDR": NEW},
    "Move_PLine": {"CAP": ALL, "TAP": ALL, "JAP": ALL},
}

# Robot[0].attribute (TMscript 2.24 §11.6) -> (type, writable, versions)
ROBOT: dict[str, tuple[str, bool, tuple[str, ...]]] = {
    "CoordRobot": (FA, False, ALL), "CoordBase": (FA, False, ALL), "Joint": (FA, False, ALL),
    "BaseName": (S, False, ALL), "TCPName": (S, False, ALL), "CameraLight": (I, True, ALL),
    "TCPForce3D": (F, False, ALL), "TCPSpeed3D": (F, False, ALL),
    "Payload": (F, False, NEW), "InstantCameraLight": (I, True, NEW),
}

IO_MODULES = ("ControlBox", "EndModule", "Safety") + tuple(f"ExtModule{n}" for n in range(16))
# IO["module"].attribute (TMscript 2.24 §11.5) -> (element type, writable); one point IO[..].DO[n] or, read
# only, the whole array IO[..].DI (2.x)
IO_POINTS: dict[str, tuple[str, bool]] = {
    "DI": (I, False), "DO": (I, True), "AI": (F, False), "AO": (F, True), "SI": (I, False), "SO": (I, False),
    "InstantDI": (I, False), "InstantDO": (I, True), "InstantAI": (F, False), "InstantAO": (F, True),
}
IO_WHOLE_ARRAYS = NEW
# points per module for whole-array reads; our choice of a TM5-700 with its control box and end module
IO_SIZES = {"ControlBox": {"DI": 16, "DO": 16, "AI": 2, "AO": 2}, "EndModule": {"DI": 3, "DO": 4, "AI": 1, "AO": 0},
            "Safety": {"SI": 8, "SO": 8}}
IO_EXT_SIZES = {"DI": 16, "DO": 16, "AI": 0, "AO": 0}


def overloads(name: str, version: str) -> list[tuple[tuple[str, ...], str]] | None:
    """[(parameter types, return type)] of function ``name`` in ``version``; None when it does not exist."""
    entry = FUNCTIONS.get(name)
    if entry is None:
        return None
    found = [(params, ret) for params, ret, versions in entry[1] if version in versions]
    return found or None


def int_parameter_kinds() -> dict[tuple[str, int], set]:
    """(function, argument count) -> the set of its overloads' int parameters, each a tuple of
    (position, is int[]). One element per key: overloads of one arity agree on which parameters are int
    (tests/sim/test_tmscript_profiles.py checks it)."""
    kinds: dict[tuple[str, int], set] = {}
    for name, (_queued, entries) in FUNCTIONS.items():
        for params, _ret, _versions in entries:
            kinds.setdefault((name, len(params)), set()).add(
                tuple((i, p == IA) for i, p in enumerate(params) if p in (I, IA)))
    return kinds


# (function, argument count) -> ((position, is int[]), ...): the interpreter converts int arguments by arity
# alone, whichever overload the checker matched
INT_ARGUMENTS: dict[tuple[str, int], tuple[tuple[int, bool], ...]] = {
    key: min(kinds) for key, kinds in int_parameter_kinds().items() if any(kinds)}


def formats(name: str, version: str) -> tuple[str, ...] | None:
    table = FORMATS.get(name)
    return None if table is None else tuple(f for f, versions in table.items() if version in versions)


def queued(name: str) -> bool:
    entry = FUNCTIONS.get(name)
    return bool(entry and entry[0])


def io_size(module: str, attribute: str) -> int:
    base = attribute.replace("Instant", "")
    return IO_SIZES.get(module, IO_EXT_SIZES).get(base, 0)
