"""Omron system control instructions for user-defined errors and controller errors (W502 System Control
Instructions, declared in prelude/sysmac_control.st): SetAlarm, ResetAlarm, GetAlarm and the Get/Reset
instructions of the PLC, Motion Control and EtherCAT Master Function Modules.

The virtual controller keeps a table of the user-defined errors that exist (:func:`user_alarms`, read by tests and
tools through ``plc.engine``). Controller errors are what vplc models: the errors of the virtual axes (motion
runtime) for the Motion Control Function Module; vplc models no PLC Function Module event and no EtherCAT, so
those report no error, truthfully. docs/toolchain/runtime_sysmac.md section 2c lists the choices.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

LEVEL_MINOR_FAULT = 3       # event levels: 1 major fault, 2 partial fault, 3 minor fault, 4 observation (chosen)
USER_LEVEL = 1              # vplc has no user-defined event table: every user-defined error is of level 1 (chosen)
MAX_USER_ALARMS = 1024      # a bound on the table (a program raising new codes in a loop stays bounded)
ERR_TOO_MANY = 0x0400       # more user-defined errors than the table holds


@dataclass
class UserAlarm:
    """One user-defined error that exists: its code, attached information and when it was created."""
    code: int
    level: int
    info1: int
    info2: int
    time_ns: int


def user_alarms(rt: Any) -> dict[int, UserAlarm]:
    """The user-defined errors of controller ``rt`` that exist, by code, oldest first."""
    table: dict[int, UserAlarm] = rt.__dict__.setdefault("user_alarms", {})
    return table


class _InstantFB:
    """Execute / Done / Busy / Error handshake of an instruction that completes in the call of its rising edge:
    Done (or Error) TRUE from that call while Execute stays TRUE, cleared by the call that sees Execute FALSE."""

    def __init__(self, rt: Any, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Execute = False
        self.Done = self.Busy = self.Error = False
        self.ErrorID = 0
        self.i__last = False

    def i__run(self) -> None:
        ex = self.Execute
        if ex and not self.i__last:
            err = self.execute()
            self.Done, self.Error, self.ErrorID = not err, bool(err), err
        elif not ex:
            self.Done = self.Error = False
            self.ErrorID = 0
        self.i__last = ex

    def execute(self) -> int:
        """Carry the instruction out; its ErrorID, 0 when it succeeded."""
        raise NotImplementedError


class SetAlarm(_InstantFB):
    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Code = self.Info1 = self.Info2 = 0

    def execute(self) -> int:
        table = user_alarms(self.i__rt)
        if self.Code not in table and len(table) >= MAX_USER_ALARMS:
            self.i__rt.instruction_error(f"SetAlarm: {MAX_USER_ALARMS} user-defined errors exist already; "
                                         f"ErrorID 16#{ERR_TOO_MANY:04X}")
            return ERR_TOO_MANY
        if self.Code not in table:           # an error that exists already keeps its first occurrence
            table[self.Code] = UserAlarm(self.Code, USER_LEVEL, self.Info1, self.Info2, self.i__rt.now_ns)
        return 0


class ResetAlarm(_InstantFB):
    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Code = 0

    def execute(self) -> int:
        user_alarms(self.i__rt).pop(self.Code, None)
        return 0


class ResetPLCError(_InstantFB):
    def execute(self) -> int:
        return 0                              # no PLC Function Module error is modelled: nothing to reset


class _ResetWithFailure(_InstantFB):
    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Failure = False

    def i__run(self) -> None:
        super().i__run()
        if not self.Execute:
            self.Failure = False


class ResetMCError(_ResetWithFailure):
    """Resets the error of every virtual axis that has stopped (MC_Reset's rule); Failure TRUE when an axis still
    decelerates and keeps its error."""

    def execute(self) -> int:
        ctl = getattr(self.i__rt, "motion", None)
        results = [axis.reset() for axis in ctl.axes] if ctl is not None else []
        self.Failure = not all(results)
        return 0


class ResetECError(_ResetWithFailure):
    def execute(self) -> int:
        self.Failure = False                  # no EtherCAT is modelled: nothing to reset
        return 0


def _report(level_ref: Any, code_ref: Any, level: int, code: int) -> bool:
    container, key = level_ref
    container[key] = level
    container, key = code_ref
    container[key] = code
    return level != 0


def GetAlarm(rt: Any, Level: Any, Code: Any) -> bool:
    table = user_alarms(rt)
    if not table:
        return _report(Level, Code, 0, 0)
    first = min(table.values(), key=lambda a: (a.level, a.time_ns))
    return _report(Level, Code, first.level, first.code)


def GetPLCError(rt: Any, Level: Any, Code: Any) -> bool:
    return _report(Level, Code, 0, 0)


def GetMCError(rt: Any, Level: Any, Code: Any) -> bool:
    ctl = getattr(rt, "motion", None)
    codes = [axis.error_code for axis in ctl.axes if axis.error_code] if ctl is not None else []
    return _report(Level, Code, LEVEL_MINOR_FAULT if codes else 0, codes[0] if codes else 0)


def GetECError(rt: Any, Level: Any, Code: Any) -> bool:
    return _report(Level, Code, 0, 0)


NATIVE_FBS = {c.__name__: c for c in (SetAlarm, ResetAlarm, ResetPLCError, ResetMCError, ResetECError)}
FUNCTIONS = {f.__name__: f for f in (GetAlarm, GetPLCError, GetMCError, GetECError)}
