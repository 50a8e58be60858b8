"""Virtual servo axes: the PLCopen axis state machine as Omron's NJ/NX motion control implements it (W507 axis
states, W508 single-axis instructions) and trapezoidal profiles evaluated in closed form.

A :class:`MotionController` owns the axes of one PLC. The motion instructions (``motion_fbs``) hand it
commands; :meth:`MotionController.cycle` runs after the programs of the primary task in every one of its
periods, as the motion control processing of an NJ/NX primary periodic task does, advances each axis to the
scan time and writes ``_MC_AX[n]``. Positions are never integrated: every motion is a :class:`Profile` of
constant-acceleration segments from its start, so the command position at time t is the closed-form value.
The servo is ideal (``Act`` = ``Cmd``).
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from .motion_config import UNITS, AxisConfig
from .motion_profile import Profile, plan_position, plan_velocity

# ---- ErrorIDs and axis error codes (docs/toolchain/runtime_sysmac.md section 5.3) ---------------------------
# Omron's own values (W508 appendix, W503 error tables) were not found in any public source we could read (the
# searches are listed in section 5.3): every value below is our choice. Its first hex digit follows Omron's
# classification of error codes (W503 NJ-series Troubleshooting Manual, 1-3-1 "Relationship between Event Codes
# and Error Codes"): 5 = user software error ("an input value to an instruction that is out of range"), 6 =
# observation error ("a position outside of the motion range"). The names say what was refused.
ERR_AXIS_UNUSED = 0x5401       # the axis is not a configured virtual axis
ERR_DISABLED = 0x5402          # motion command while the servo is OFF (Disabled)
ERR_MOVING = 0x5405            # MC_Home / MC_SetPosition while the axis moves
ERR_VELOCITY = 0x5410          # Velocity out of range
ERR_ACCELERATION = 0x5411      # Acceleration negative
ERR_DECELERATION = 0x5412      # Deceleration negative
ERR_JERK = 0x5413              # Jerk negative
ERR_DIRECTION = 0x5414         # Direction not allowed for the instruction
ERR_BUFFER_MODE = 0x5415       # BufferMode out of range
ERR_POSITION = 0x5416          # target (or SetPosition value) outside the software limits, or not finite
ERR_OVERRIDE = 0x5417          # VelFactor is not a number (NaN)
ERR_BUFFER_FULL = 0x5418       # a second buffered command while one is already waiting
ERR_REFERENCE_TYPE = 0x5419    # MC_SetPosition ReferenceType outside its valid range (W508: _mcCommand, _mcFeedback)
AXIS_SW_LIMIT_POS = 0x6440     # axis minor fault: positive software limit reached (MFaultLvl.Code)
AXIS_SW_LIMIT_NEG = 0x6441     # axis minor fault: negative software limit reached

# axis states (W507 axis status, exactly one is TRUE)
DISABLED, STANDSTILL, DISCRETE, CONTINUOUS, HOMING, STOPPING, ERRORSTOP = (
    "Disabled", "Standstill", "Discrete", "Continuous", "Homing", "Stopping", "ErrorStop")

# command status seen by the instruction that gave it
WAITING, ACTIVE, DONE, ABORTED = "waiting", "active", "done", "aborted"

MAX_OVERRIDE = 5.0             # MC_SetOverride VelFactor 0 .. 500 %


class Command:
    """One execution of a motion instruction on an axis."""

    __slots__ = ("kind", "fb", "status", "in_velocity", "target", "velocity", "acc", "dec", "jerk", "direction",
                 "distance")

    def __init__(self, kind: str, fb: Any, target: float = 0.0, velocity: float = 0.0, acc: float = 0.0,
                 dec: float = 0.0, jerk: float = 0.0, direction: float = 1.0) -> None:
        self.kind, self.fb, self.status, self.in_velocity = kind, fb, WAITING, False
        self.target, self.velocity, self.acc, self.dec, self.direction = target, velocity, acc, dec, direction
        self.jerk = jerk
        self.distance: float | None = None      # a relative move whose target is counted when it starts


class Axis:
    """One virtual servo axis and the _sAXIS_REF value the program sees."""

    def __init__(self, cfg: AxisConfig, ref: Any) -> None:
        self.cfg, self.ref = cfg, ref
        self.state = DISABLED
        self.pos = self.vel = self.acc = 0.0
        self.jerk_now = 0.0                     # jerk of the profile segment at the last evaluation
        self.homed = cfg.homed
        self.powered = False
        self.power_request = False
        self.override = 1.0
        self.profile: Profile | None = None
        self.active: Command | None = None      # the command the profile belongs to
        self.queued: Command | None = None      # a buffered command waiting for the active one
        self.stop_cmd: Command | None = None    # MC_Stop holding the axis in Stopping
        self.stop_execute = False               # that MC_Stop's Execute at its last call
        self.error_code = 0
        self.error_serial = 0                   # counts the resets: an instruction's Error lasts until the next
        self.limit_stop = False                 # decelerating onto a software limit
        self.instant: list[Command] = []        # MC_Home / MC_SetPosition for this period
        self.last_dir = 1.0
        ref.Cfg.AxNo = cfg.number
        ref.Cfg.AxEnable = 2                    # _mcUsedAxis
        ref.Cfg.AxType = 2                      # _mcVirServo
        ref.Scale.Units = UNITS[cfg.units]
        ref.Scale.Num, ref.Scale.Den = 1, 1.0
        ref.Scale.MaxPos = cfg.limit_positive if cfg.limit_positive is not None else 0.0
        ref.Scale.MinPos = cfg.limit_negative if cfg.limit_negative is not None else 0.0
        ref.DrvStatus.Ready = ref.DrvStatus.MainPower = True
        ref.Details.Homed = self.homed
        self.set_state(DISABLED)
        self._write()

    # ---- what the program sees -------------------------------------------------------------------
    def set_state(self, state: str) -> None:
        """Enter the PLCopen axis state ``state``: its Status flag, Ready and Details.Idle as the program reads them."""
        st = self.ref.Status
        setattr(st, self.state, False)
        self.state = state
        setattr(st, state, True)
        st.Ready = state == STANDSTILL
        self.ref.Details.Idle = state in (STANDSTILL, DISABLED) or (state in (STOPPING, ERRORSTOP)
                                                                   and self.profile is None)

    def _write(self) -> None:
        ref = self.ref
        cmd, act = ref.Cmd, ref.Act
        cmd.Pos = act.Pos = self.pos
        cmd.Vel = act.Vel = self.vel
        # W507 6-28, Cmd.AccDec and Cmd.Jerk: AccDec is plus while the axis accelerates (its speed grows, from
        # rest too) and minus while it decelerates, whatever the direction of travel; Jerk is plus while the
        # magnitude of AccDec grows and minus while it falls; both 0 when the instruction's rate is 0.
        # (0.0 - x rather than -x: no -0.0 in the axis variable.)
        a, v, j = self.acc, self.vel, self.jerk_now
        cmd.AccDec = a if v > 0.0 else 0.0 - a if v < 0.0 else abs(a)
        cmd.Jerk = j if a > 0.0 else 0.0 - j if a < 0.0 else abs(j)
        ref.Details.InHome = self.homed and self.pos == self.cfg.home_position and self.vel == 0.0

    # ---- limits ------------------------------------------------------------------------------------
    def limits_active(self) -> bool:
        return self.homed and self.cfg.limit_positive is not None

    def in_limits(self, x: float) -> bool:
        lo, hi = self.cfg.limit_negative, self.cfg.limit_positive
        return not self.homed or lo is None or hi is None or lo <= x <= hi

    def vmax_of(self, velocity: float) -> tuple[float, bool]:
        """Target velocity × override, at most the axis maximum (W508 MC_SetOverride); True when the maximum
        limited it (Details.VelLimit)."""
        v = velocity * self.override
        return (self.cfg.max_velocity, True) if v > self.cfg.max_velocity else (v, False)

    def jerk(self, value: float) -> float:
        """Jerk actually used: 0 is a trapezoid (W508: Jerk positive or 0); with `max_jerk` configured, values
        above it run at it (our choice, like the acceleration)."""
        top = self.cfg.max_jerk
        return top if top and value > top else value

    def ramp(self, value: float, maximum: float) -> float:
        """Acceleration or deceleration actually used: 0 (no limit in W508) and values above the axis maximum
        run at the axis maximum (our choice: the axis parameter 'Acceleration/Deceleration Over' is not
        modelled)."""
        return maximum if value <= 0.0 or value > maximum else value

    # ---- commands -----------------------------------------------------------------------------------
    def end_command(self, cmd: Command | None, status: str) -> None:
        """End ``cmd`` with ``status`` (done, aborted ...) if it is still waiting or running; None is no command."""
        if cmd is not None and cmd.status in (WAITING, ACTIVE):
            cmd.status = status

    def abort_all(self) -> None:
        self.end_command(self.active, ABORTED)
        self.end_command(self.queued, ABORTED)
        self.active = self.queued = None

    def start(self, cmd: Command, t: float, at_end: bool = False) -> None:
        """Make ``cmd`` the axis' motion from time t on: Aborting (from where the running motion is at t, in
        closed form), or a buffered command whose turn came (``at_end``: from where the one before it ended)."""
        if self.profile is not None and not at_end:
            self.pos, self.vel, self.acc, _ = self.profile.at(t)
        if self.active is not cmd:
            self.end_command(self.active, ABORTED)
        if self.stop_cmd is not None and cmd.kind != "stop":
            self.stop_cmd = None
        self.active, cmd.status = cmd, ACTIVE
        self.limit_stop = False
        k = cmd.kind
        vlim = self.cfg.max_velocity
        if k == "velocity":
            self.last_dir = cmd.direction
            vt, limited = self.vmax_of(cmd.velocity)
            self.ref.Details.VelLimit = limited
            self.profile = Profile(t, self.pos, self.vel, plan_velocity(self.vel, cmd.direction * vt, cmd.acc,
                                                                        cmd.dec, cmd.jerk, self.acc, vlim))
            self.set_state(CONTINUOUS)
        elif k == "position":
            if cmd.distance is not None:        # PLCopen MC_MoveRelative: from where the motion starts
                cmd.target, cmd.distance = self.pos + cmd.distance, None
            self.plan_to(cmd, t)
            self.set_state(DISCRETE)
        elif k in ("halt", "stop"):
            self.profile = Profile(t, self.pos, self.vel, plan_velocity(self.vel, 0.0, cmd.dec, cmd.dec, cmd.jerk,
                                                                        self.acc, vlim))
            self.set_state(DISCRETE if k == "halt" else STOPPING)

    def plan_to(self, cmd: Command, t: float) -> None:
        vmax, limited = self.vmax_of(cmd.velocity)
        self.ref.Details.VelLimit = limited
        if vmax <= 0.0:                         # 0 % override: decelerate and hold, still in motion
            self.profile = Profile(t, self.pos, self.vel, plan_velocity(self.vel, 0.0, cmd.acc, cmd.dec, cmd.jerk,
                                                                        self.acc, self.cfg.max_velocity))
            self.profile.hold = True
        else:
            self.profile = Profile(t, self.pos, self.vel, plan_position(self.pos, self.vel, cmd.target, vmax,
                                                                          cmd.acc, cmd.dec, cmd.jerk, self.acc,
                                                                          self.cfg.max_velocity),
                                   cmd.target)
        if self.vel == 0.0 and cmd.target != self.pos:
            self.last_dir = 1.0 if cmd.target > self.pos else -1.0

    def set_override(self, factor: float, t: float) -> None:
        if factor == self.override:
            return
        self.override = factor
        cmd = self.active
        if cmd is not None and cmd.kind in ("position", "velocity") and self.state in (DISCRETE, CONTINUOUS):
            self.start(cmd, t)

    # ---- the motion control processing of one period -----------------------------------------------
    def advance(self, t: float) -> None:
        """Evaluate the motion at time t; a buffered command starts exactly when the one before it ends
        (Done, or InVelocity after a velocity command), so the command position stays continuous."""
        prof = self.profile
        while prof is not None:
            x, v, a, finished = prof.at(t)
            jerk = prof.jerk
            if self.limits_active():
                guarded = self._guard_limits(prof, x, v, a, finished, t)
                if guarded[0] is not prof:      # the software-limit stop is a trapezoid
                    jerk = 0.0
                prof, x, v, a, finished = guarded
            self.pos, self.vel, self.acc, self.jerk_now = x, v, a, jerk
            cmd = self.active
            if not finished or prof.hold:
                break
            if cmd is not None and cmd.kind == "velocity":
                cmd.in_velocity = True
                if self.queued is None:
                    break
            if self.queued is not None:
                self.pos, self.vel = prof.x_end, prof.v_end
                self.end_command(cmd, DONE)
                nxt, self.queued, self.active = self.queued, None, None
                self.start(nxt, prof.t_end, at_end=True)
                prof = self.profile
                continue
            self.profile = None
            self.vel = self.acc = self.jerk_now = 0.0
            self._end_of_motion()
            break
        self._write()

    def _end_of_motion(self) -> None:
        cmd = self.active
        if self.state == ERRORSTOP:
            self.limit_stop = False
            self.set_state(ERRORSTOP)
            return
        if cmd is not None and cmd.kind == "stop":
            cmd.status = DONE
            if not self.stop_execute:
                self.release_stop()
            else:
                self.set_state(STOPPING)
            return
        self.end_command(cmd, DONE)
        self.active = None
        self.set_state(STANDSTILL)

    def release_stop(self) -> None:
        """MC_Stop is done and its Execute is FALSE: the axis leaves Stopping (W507 state chart)."""
        self.stop_cmd = None
        if self.active is not None and self.active.kind == "stop":
            self.active = None
        if self.state == STOPPING and self.profile is None:
            self.set_state(STANDSTILL)

    def run_instant(self) -> None:
        """MC_Home (zero position preset) and MC_SetPosition given in this period."""
        for cmd in self.instant:
            if cmd.status != WAITING:
                continue
            self.define_position(cmd.target, True)
            cmd.status = DONE
            if self.state == HOMING:
                self.set_state(STANDSTILL)
        self.instant.clear()

    def _guard_limits(self, prof: Profile, x: float, v: float, a: float, finished: bool,
                      t: float) -> tuple[Profile, float, float, float, bool]:
        """Software limits on the command position (W507): a motion that would pass a limit decelerates with
        the axis' maximum deceleration so that it stops on the limit, and the axis goes to ErrorStop with a
        minor fault; a position already past a limit is held on it. Returns the profile the axis now follows
        with (position, velocity, acceleration, finished) at t."""
        lo, hi = self.cfg.limit_negative, self.cfg.limit_positive
        if self.limit_stop or lo is None or hi is None:
            return prof, x, v, a, finished
        if x > hi or x < lo:
            x = hi if x > hi else lo
            self._limit_fault(x, t)
            prof = self.profile = Profile(t, x, 0.0, [])
            return prof, x, 0.0, 0.0, True
        if v != 0.0:
            edge = hi if v > 0 else lo
            room = abs(edge - x)
            brake = v * v / (2 * self.cfg.max_deceleration)
            if room <= brake:
                self._limit_fault(edge, t)
                dec = v * v / (2 * room) if room > 0 else 0.0
                segs = [(abs(v) / dec, math.copysign(dec, -v), 0.0)] if dec > 0 else []
                prof = self.profile = Profile(t, x, v if dec > 0 else 0.0, segs, edge)
                self.limit_stop = True
                if dec > 0:
                    return prof, x, v, -math.copysign(dec, v), False
                return prof, edge, 0.0, 0.0, True
        return prof, x, v, a, finished

    def _limit_fault(self, edge: float, t: float) -> None:
        self.error(AXIS_SW_LIMIT_POS if edge == self.cfg.limit_positive else AXIS_SW_LIMIT_NEG)

    def error(self, code: int) -> None:
        """An axis minor fault: the commands are aborted, the axis goes to ErrorStop (W507 state chart)."""
        self.abort_all()
        self.end_command(self.stop_cmd, ABORTED)
        self.stop_cmd = None
        if not self.error_code:
            self.error_code = code
            self.ref.MFaultLvl.Active, self.ref.MFaultLvl.Code = True, code
        self.set_state(ERRORSTOP)

    def instruction_error(self, code: int, t: float) -> None:
        """An instruction refused on this axis: on an NJ/NX it is an error of the axis (the instruction's Error
        stays TRUE until the error is reset, the running instructions end in CommandAborted: W508, output
        timing of MC_Power and MC_Stop). A moving axis decelerates to a stop with its maximum deceleration
        (our choice of the stop method)."""
        if self.profile is not None:
            self.pos, self.vel, self.acc, _ = self.profile.at(t)
        self.error(code)
        self.limit_stop = False
        if self.vel:
            dec = self.cfg.max_deceleration
            self.profile = Profile(t, self.pos, self.vel, plan_velocity(self.vel, 0.0, dec, dec))
        elif self.profile is not None:
            self.profile = Profile(t, self.pos, 0.0, [])

    def power(self, on: bool) -> None:
        """Servo ON / OFF (applied in the motion processing after the program, so MC_Power's Status follows
        one period later). Servo OFF stops the axis at once and aborts its commands."""
        if on == self.powered:
            return
        self.powered = self.ref.DrvStatus.ServoOn = on
        if not on:
            self.abort_all()
            self.end_command(self.stop_cmd, ABORTED)
            self.stop_cmd = None
            self.profile = None
            self.vel = self.acc = self.jerk_now = 0.0
            self._write()
            if self.state != ERRORSTOP:
                self.set_state(DISABLED)
        elif self.state == DISABLED:
            self.set_state(STANDSTILL)

    def reset(self) -> bool:
        """MC_Reset: clear the axis error once the axis has stopped. False while it still decelerates."""
        if self.state != ERRORSTOP:
            return True
        if self.profile is not None:
            return False
        self.error_code = 0
        self.error_serial += 1
        self.ref.MFaultLvl.Active, self.ref.MFaultLvl.Code = False, 0
        self.set_state(STANDSTILL if self.powered else DISABLED)
        return True

    def define_position(self, x: float, homed: bool = True) -> None:
        """Zero position preset (MC_Home) and MC_SetPosition: the command position becomes x; home is defined."""
        self.pos = x
        self.homed = homed
        self.ref.Details.Homed = homed
        self._write()


class MotionController:
    """The axes of one PLC and the motion processing that runs in its primary task."""

    def __init__(self, rt: Any, configs: Iterable[AxisConfig], globals_obj: Any) -> None:
        self.rt = rt
        table = getattr(globals_obj, "_MC_AX", None)
        if table is None:
            raise ValueError("the prelude's _MC_AX is not loaded")
        self.axes: list[Axis] = []
        self.by_ref: dict[int, Axis] = {}
        for cfg in configs:
            ref = table[cfg.number]
            if cfg.name is not None:             # a global _sAXIS_REF of that name is the same axis
                alias = self._global(globals_obj, cfg.name)
                if alias is None:
                    raise ValueError(f"axis {cfg.number}: the program declares no global variable "
                                     f"`{cfg.name}` of type _sAXIS_REF")
                setattr(globals_obj, alias, ref)
            axis = Axis(cfg, ref)
            self.axes.append(axis)
            self.by_ref[id(ref)] = axis
        n = len(self.axes)
        self.i__path = f"motion control of {n} ax{'is' if n == 1 else 'es'}"     # how `vplc run` lists it

    @staticmethod
    def _global(globals_obj: Any, name: str) -> str | None:
        info = getattr(type(globals_obj), "i__vars", {})
        entry = info.get(name.upper())
        if entry is None or getattr(entry[1], "name", "").upper() != "_SAXIS_REF":
            return None
        return entry[0]

    def axis_of(self, ref: Any) -> Axis | None:
        return self.by_ref.get(id(ref))

    def cycle(self) -> None:
        """The motion control processing of one primary-task period: every axis to the scan time."""
        t = self.rt.now_ns / 1e9
        for axis in self.axes:
            if axis.power_request != axis.powered:
                axis.power(axis.power_request)
            if axis.instant:
                axis.run_instant()
            if axis.profile is not None:
                axis.advance(t)
