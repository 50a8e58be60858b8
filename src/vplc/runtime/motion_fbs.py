"""The single-axis motion instructions of W508 (declared in prelude/sysmac_motion.st) on virtual axes.

Output timing (W508 output timing tables, read in the Chinese edition's MC_Power and MC_Stop pages; details we
chose are in docs/toolchain/runtime_sysmac.md section 5):

* the rising edge of Execute starts the instruction: Busy TRUE in that call (Active too when the axis takes
  the command at once, i.e. always except a Buffered command waiting for the one before it); a parameter or
  state error sets Error and ErrorID in that call instead;
* the motion runs in the motion processing after the program (``motion.MotionController.cycle``), so Done,
  InVelocity and CommandAborted appear at the earliest in the next call;
* Done and CommandAborted stay TRUE while Execute is TRUE and are cleared in the call that sees Execute FALSE;
  if Execute was already FALSE when they came, they are TRUE for that one call;
* an instruction error is an error of the axis (ErrorStop): Error stays TRUE until MC_Reset has cleared it;
  an instruction started while the axis has an error ends in CommandAborted.

What vplc does not model is refused as a major fault naming the instruction and the value (the blending buffer
modes), never run with another meaning.
"""
from __future__ import annotations

import math
from typing import Any

from . import motion as M
from .faults import RuntimeFaultError

_BLENDING = {2: "_mcBlendingLow", 3: "_mcBlendingPrevious", 4: "_mcBlendingNext", 5: "_mcBlendingHigh"}


def _axis(fb: Any) -> M.Axis | None:
    """The virtual axis behind fb.Axis, or None after recording why (Error 16#5401 follows)."""
    ctl = getattr(fb.i__rt, "motion", None)
    axis = ctl.axis_of(fb.Axis) if ctl is not None else None
    if axis is None:
        why = "no axis configuration was given (vplc run/test --axes FILE, load_plc(axes=...))" if ctl is None \
            else "it is not one of the axes of the axis configuration"
        fb.i__rt.instruction_error(f"{type(fb).__name__}: the Axis passed is not a virtual axis: {why}; "
                                   f"ErrorID 16#{M.ERR_AXIS_UNUSED:04X}")
    return axis


REFUSED = -1        # begin(): the instruction ends in CommandAborted (not an ErrorID)


def _state_error(axis: M.Axis, stop: bool = False) -> int:
    """The PLCopen state diagram as W508 applies it (output timing of MC_Home, MC_SetPosition, MC_Stop: an
    instruction started while the axis has an error, or while MC_Stop runs, ends in CommandAborted; MC_Power: a
    motion instruction on a disabled axis is an error). Another MC_Stop (``stop``) may start while one runs."""
    if axis.state == M.ERRORSTOP or (axis.state == M.STOPPING and not stop):
        return REFUSED
    if axis.state == M.DISABLED:
        return M.ERR_DISABLED
    return 0


def _now(fb: Any) -> float:
    return fb.i__rt.now_ns / 1e9


class _ExecuteFB:
    """Execute / Done / Busy / CommandAborted / Error handshake shared by the instructions with Execute."""

    DONE_OUT = "Done"

    def __init__(self, rt: Any, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Axis: Any = None
        self.Execute = False
        self.Busy = self.CommandAborted = self.Error = False
        setattr(self, self.DONE_OUT, False)
        self.ErrorID = 0
        self.i__prev = False
        self.i__cmd: M.Command | None = None
        self.i__final = False
        self.i__eaxis: M.Axis | None = None     # the axis whose error this instance's Error reports
        self.i__eserial = 0

    def i__run(self) -> None:
        ex = self.Execute
        if self.i__final and not ex:
            self._clear()
        eaxis = self.i__eaxis
        if eaxis is not None and eaxis.error_serial != self.i__eserial:
            self.Error, self.ErrorID, self.i__eaxis = False, 0, None    # W508: FALSE once the error is reset
        if ex and not self.i__prev:
            self._clear()
            self.Error, self.ErrorID, self.i__eaxis = False, 0, None
            self.i__cmd = None
            axis = _axis(self)
            if axis is None:
                self._fail(M.ERR_AXIS_UNUSED)
            else:
                code = self.begin(axis)
                if code == REFUSED:
                    self.CommandAborted = True
                    self._end()
                elif code:
                    axis.instruction_error(code, _now(self))
                    self._fail(code)
                    self.i__eaxis, self.i__eserial = axis, axis.error_serial
        elif self.i__cmd is not None:
            self._poll(self.i__cmd)
        self.i__prev = ex

    def _clear(self) -> None:
        """Done and CommandAborted end with Execute (one call if Execute was already FALSE); so does an Error
        that is not an error of the axis (an Axis that is not a virtual axis)."""
        setattr(self, self.DONE_OUT, False)
        self.CommandAborted = False
        if self.i__eaxis is None:
            self.Error, self.ErrorID = False, 0
        self.i__final = False

    def _fail(self, code: int) -> None:
        self.Busy = False
        self._set_active(False)
        self.Error, self.ErrorID, self.i__final = True, code, True
        self.i__cmd = None

    def _set_active(self, value: bool) -> None:
        pass

    def _poll(self, cmd: M.Command) -> None:
        st = cmd.status
        if st == M.DONE:
            setattr(self, self.DONE_OUT, True)
            self._end()
        elif st == M.ABORTED:
            self.CommandAborted = True
            self._end()
        elif st == M.ACTIVE:
            self._set_active(True)

    def _end(self) -> None:
        self.Busy = False
        self._set_active(False)
        self.i__cmd, self.i__final = None, True

    def _issue(self, cmd: M.Command) -> None:
        self.i__cmd = cmd
        self.Busy = True

    def begin(self, axis: M.Axis) -> int:
        raise NotImplementedError


class _MoveFB(_ExecuteFB):
    """Instructions with Active and BufferMode: MoveAbsolute, MoveRelative, MoveVelocity, Halt, Stop."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Active = False
        self.Velocity = self.Acceleration = self.Deceleration = self.Jerk = 0.0
        self.BufferMode = 0

    def _set_active(self, value: bool) -> None:
        self.Active = value

    def _ramps(self, need_velocity: bool, velocity_zero_ok: bool = False) -> int:
        """W508 input ranges: Velocity positive (MC_MoveVelocity: or 0), Acceleration, Deceleration and Jerk
        positive or 0."""
        v, a, d, j = self.Velocity, self.Acceleration, self.Deceleration, self.Jerk
        if need_velocity and not (math.isfinite(v) and (v > 0 or (velocity_zero_ok and v == 0))):
            return M.ERR_VELOCITY
        if not (math.isfinite(a) and a >= 0):
            return M.ERR_ACCELERATION
        if not (math.isfinite(d) and d >= 0):
            return M.ERR_DECELERATION
        if not (math.isfinite(j) and j >= 0):
            return M.ERR_JERK
        return self._buffer_mode()

    def _buffer_mode(self) -> int:
        bm = self.BufferMode
        if bm in _BLENDING:
            raise RuntimeFaultError(f"{type(self).__name__}: BufferMode {_BLENDING[bm]} is not modelled by vplc "
                                    "(only _mcAborting and _mcBuffered)")
        return 0 if bm in (0, 1) else M.ERR_BUFFER_MODE

    def _give(self, axis: M.Axis, cmd: M.Command) -> int:
        """Hand cmd to the axis: at once (Aborting, or Buffered on an axis at rest) or after the running one."""
        act = axis.active
        if self.BufferMode == 1 and act is not None and act.status == M.ACTIVE and act.fb is not self \
                and not act.in_velocity:
            if axis.queued is not None:
                return M.ERR_BUFFER_FULL
            axis.queued = cmd
            self._issue(cmd)
            return 0
        queued = axis.queued
        if queued is not None:                  # PLCopen Part 1 _mcAborting: the buffer is cleared
            if queued.fb is not self:
                axis.end_command(queued, M.ABORTED)
            axis.queued = None
        axis.start(cmd, _now(self))
        self._issue(cmd)
        self.Active = True
        return 0


class MC_MoveAbsolute(_MoveFB):
    """W508 MC_MoveAbsolute. Linear count mode: Direction is checked (0..4) and otherwise not used."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Position = 0.0
        self.Direction = 0

    def target(self, axis: M.Axis) -> tuple[float, float | None]:
        """(target, None), or (0.0, distance) for a motion whose target is counted from where it starts."""
        return self.Position, None

    def begin(self, axis: M.Axis) -> int:
        code = _state_error(axis) or self._ramps(True)
        if code:
            return code
        if not 0 <= self.Direction <= 4:
            return M.ERR_DIRECTION
        x, later = self.target(axis)
        if later is not None:                   # counted when the motion starts (MC_MoveRelative, Buffered)
            if not math.isfinite(later):
                return M.ERR_POSITION
        elif not math.isfinite(x) or not axis.in_limits(x):
            return M.ERR_POSITION
        cfg = axis.cfg
        cmd = M.Command("position", self, x, self.Velocity, axis.ramp(self.Acceleration, cfg.max_acceleration),
                        axis.ramp(self.Deceleration, cfg.max_deceleration), axis.jerk(self.Jerk))
        cmd.distance = later
        return self._give(axis, cmd)


class MC_MoveRelative(MC_MoveAbsolute):
    """W508 MC_MoveRelative: the target is Distance from the command position when the motion starts (from the
    target of the command before it when Buffered; after a buffered-upon MC_MoveVelocity or MC_Halt, which
    have no target, from where the axis is when this motion starts: PLCopen Part 1, "relative to the set
    position at the time of the execution")."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Distance = 0.0

    def target(self, axis: M.Axis) -> tuple[float, float | None]:
        base = axis.pos
        act = axis.active
        if self.BufferMode == 1 and act is not None and act.status == M.ACTIVE:
            if act.kind == "position":
                return act.target + self.Distance, None
            if act.fb is not self and not act.in_velocity:
                return 0.0, self.Distance       # waits for a motion without a target: counted when it starts
        if axis.profile is not None:
            base = axis.profile.at(_now(self))[0]
        return base + self.Distance, None


class MC_MoveVelocity(_MoveFB):
    """W508 MC_MoveVelocity: Direction _mcPositiveDirection (default), _mcNegativeDirection or
    _mcCurrentDirection; BufferMode _mcAborting or _mcBuffered (its valid range); Continuous is reserved."""

    def _buffer_mode(self) -> int:
        return 0 if self.BufferMode in (0, 1) else M.ERR_BUFFER_MODE

    DONE_OUT = "InVelocity"

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Direction = 0
        self.Continuous = False

    def begin(self, axis: M.Axis) -> int:
        code = _state_error(axis) or self._ramps(True, velocity_zero_ok=True)
        if code:
            return code
        d = self.Direction
        if d == 0:
            sign = 1.0
        elif d == 2:
            sign = -1.0
        elif d == 3:
            sign = (1.0 if axis.vel > 0 else -1.0) if axis.vel else axis.last_dir
        else:
            return M.ERR_DIRECTION
        cfg = axis.cfg
        cmd = M.Command("velocity", self, 0.0, self.Velocity, axis.ramp(self.Acceleration, cfg.max_acceleration),
                        axis.ramp(self.Deceleration, cfg.max_deceleration), axis.jerk(self.Jerk), sign)
        return self._give(axis, cmd)

    def _poll(self, cmd: M.Command) -> None:
        if cmd.status == M.ACTIVE:
            self.Active = True
            self.InVelocity = cmd.in_velocity
        elif cmd.status == M.ABORTED or cmd.status == M.DONE:
            self.InVelocity = False
            self.CommandAborted = True
            self._end()

    def _clear(self) -> None:
        super()._clear()
        self.InVelocity = False


class MC_Halt(_MoveFB):
    """W508 MC_Halt: decelerates to a stop (Discrete); another instruction may abort it."""

    def begin(self, axis: M.Axis) -> int:
        code = _state_error(axis) or self._ramps(False)
        if code:
            return code
        cmd = M.Command("halt", self, dec=axis.ramp(self.Deceleration, axis.cfg.max_deceleration),
                        jerk=axis.jerk(self.Jerk))
        return self._give(axis, cmd)


class MC_Stop(_MoveFB):
    """W508 MC_Stop: aborts every command, decelerates to a stop and holds the axis in Stopping while Execute
    is TRUE; the axis goes to Standstill when MC_Stop is Done and called with Execute FALSE."""

    def _buffer_mode(self) -> int:
        return 0                    # reserved for MC_Stop: the stop always aborts

    def begin(self, axis: M.Axis) -> int:
        code = _state_error(axis, stop=True) or self._ramps(False)
        if code:
            return code
        cmd = M.Command("stop", self, dec=axis.ramp(self.Deceleration, axis.cfg.max_deceleration),
                        jerk=axis.jerk(self.Jerk))
        axis.abort_all()
        if axis.stop_cmd is not None and axis.stop_cmd.fb is not self:
            axis.end_command(axis.stop_cmd, M.ABORTED)
        axis.stop_cmd, axis.stop_execute = cmd, True
        axis.start(cmd, _now(self))
        self._issue(cmd)
        self.Active = True
        self.i__stop = cmd
        return 0

    def i__run(self) -> None:
        super().i__run()
        stop = self.i__stop
        if stop is None:
            return
        ctl = getattr(self.i__rt, "motion", None)
        axis = ctl.axis_of(self.Axis) if ctl is not None else None
        if axis is None or axis.stop_cmd is not stop:
            self.i__stop = None
            return
        axis.stop_execute = self.Execute
        if not self.Execute and stop.status == M.DONE:
            axis.release_stop()
            self.i__stop = None

    i__stop: M.Command | None = None        # the stop this instance gave, until the axis leaves Stopping


class MC_Home(_ExecuteFB):
    """W508 MC_Home with the zero position preset homing method: home = the configured home_position."""

    def begin(self, axis: M.Axis) -> int:
        code = _state_error(axis)
        if code or axis.state != M.STANDSTILL:
            return code or M.ERR_MOVING
        cmd = M.Command("home", self, axis.cfg.home_position)
        axis.instant.append(cmd)
        axis.set_state(M.HOMING)
        self._issue(cmd)
        return 0


class MC_SetPosition(_ExecuteFB):
    """W508 MC_SetPosition: the command and actual position become Position (the virtual servo has no following
    error, so both ReferenceType values give the same result; _mcLatestCommand, outside the instruction's valid
    range, is an error); home becomes defined. Relative and ExecutionMode are reserved."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Position = 0.0
        self.ReferenceType = 0
        self.Relative = False
        self.ExecutionMode = 0

    def begin(self, axis: M.Axis) -> int:
        if axis.state in (M.ERRORSTOP, M.STOPPING):
            return REFUSED
        if axis.state not in (M.STANDSTILL, M.DISABLED):
            return M.ERR_MOVING
        if self.ReferenceType not in (0, 1):    # W508 (zh) MC_SetPosition: valid range _mcCommand, _mcFeedback
            return M.ERR_REFERENCE_TYPE
        x = self.Position
        lo, hi = axis.cfg.limit_negative, axis.cfg.limit_positive
        if not math.isfinite(x) or (lo is not None and hi is not None and not lo <= x <= hi):
            return M.ERR_POSITION
        cmd = M.Command("setpos", self, x)
        axis.instant.append(cmd)
        self._issue(cmd)
        return 0


class MC_Reset(_ExecuteFB):
    """W508 MC_Reset: clears the axis error; Busy until the axis has stopped, then Done. Failure stays FALSE
    (a virtual axis has no error cause that outlasts the reset)."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Failure = False
        self.i__axis: M.Axis | None = None

    def begin(self, axis: M.Axis) -> int:
        self._issue(M.Command("reset", self))
        self.i__axis = axis
        self._try()
        return 0

    def _poll(self, cmd: M.Command) -> None:
        self._try()

    def _try(self) -> None:
        axis = self.i__axis
        if axis is not None and axis.reset():
            self.Done = True
            self._end()


class _EnableFB:
    def __init__(self, rt: Any, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Axis: Any = None
        self.Enable = False
        self.Busy = self.Error = False
        self.ErrorID = 0


class MC_Power(_EnableFB):
    """W508 MC_Power: servo ON while Enable is TRUE; Status TRUE once it is ON (after the motion processing of
    the period); Busy follows Enable."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Status = False

    def i__run(self) -> None:
        en = self.Enable
        ctl = getattr(self.i__rt, "motion", None)
        axis = ctl.axis_of(self.Axis) if ctl is not None else None
        if axis is None:
            if en and not self.Error:
                _axis(self)
                self.Error, self.ErrorID = True, M.ERR_AXIS_UNUSED
            elif not en:
                self.Error, self.ErrorID = False, 0
            self.Status = self.Busy = False
            return
        axis.power_request = en
        self.Busy = en
        self.Status = en and axis.powered


class MC_ReadAxisError(_EnableFB):
    """W508 MC_ReadAxisError: AxisErrorID is the axis' minor fault code while Enable is TRUE."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.Valid = False
        self.AxisErrorID = 0

    def i__run(self) -> None:
        if not self.Enable:
            self.Valid = self.Busy = self.Error = False
            self.ErrorID = self.AxisErrorID = 0
            return
        ctl = getattr(self.i__rt, "motion", None)
        axis = ctl.axis_of(self.Axis) if ctl is not None else None
        if axis is None:
            if not self.Error:
                _axis(self)
            self.Valid, self.Busy, self.Error, self.ErrorID = False, False, True, M.ERR_AXIS_UNUSED
            return
        self.Valid = self.Busy = True
        self.AxisErrorID = axis.error_code


class MC_SetOverride(_EnableFB):
    """W508 MC_SetOverride: while Enable is TRUE the target velocity of the running instruction is VelFactor %
    of what it asks (at most the axis maximum); VelFactor above 500 counts as 500, below 0.01 (negative included)
    as 0.01, and only 0 as 0 — which holds the axis without ending its motion. Enabled goes FALSE one period after
    Enable. AccFactor and JerkFactor are reserved."""

    def __init__(self, rt: Any, path: str) -> None:
        super().__init__(rt, path)
        self.VelFactor = self.AccFactor = self.JerkFactor = 100.0
        self.Enabled = False

    i__on = False           # the override is applied (Enabled follows it one call later when Enable drops)

    def i__run(self) -> None:
        ctl = getattr(self.i__rt, "motion", None)
        axis = ctl.axis_of(self.Axis) if ctl is not None else None
        if not self.Enable:
            self.Enabled = self.i__on
            if self.i__on and axis is not None:
                axis.set_override(1.0, _now(self))
            self.i__on = self.Busy = self.Error = False
            self.ErrorID = 0
            return
        if axis is None:
            if not self.Error:
                _axis(self)
            self.Enabled, self.Busy, self.Error, self.ErrorID = False, False, True, M.ERR_AXIS_UNUSED
            return
        f = self.VelFactor
        if math.isnan(f):
            self.Enabled, self.Busy, self.Error, self.ErrorID = False, False, True, M.ERR_OVERRIDE
            self.i__on = False
            return
        if f != 0.0:
            f = min(max(f, 0.01), M.MAX_OVERRIDE * 100)
        self.Error, self.ErrorID = False, 0
        axis.set_override(f / 100.0, _now(self))
        self.Enabled = self.Busy = self.i__on = True


NATIVE_FBS = {c.__name__: c for c in (MC_Power, MC_Home, MC_MoveAbsolute, MC_MoveRelative, MC_MoveVelocity,
                                      MC_Stop, MC_Halt, MC_Reset, MC_ReadAxisError, MC_SetPosition,
                                      MC_SetOverride)}
