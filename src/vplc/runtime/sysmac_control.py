"""Omron control instructions (W502 Control Instructions, declared in prelude/sysmac_control.st): PIDAT and
TimeProportionalOut as native function blocks.

What W502 says and what we chose where its page was not readable is listed in docs/toolchain/runtime_sysmac.md
(section 2b). What vplc does not model (PIDAT autotuning, TimeProportionalOut's minimum pulse width and delay) stops
the controller with a fault naming it, never runs with another meaning.
"""
from __future__ import annotations

import math
from typing import Any

from .faults import RuntimeFaultError

ERR_RANGE = 0x0400          # input value out of range (Omron's common instruction ErrorID, as the socket instructions)
_NS = 1_000_000_000


def _task_period_ns(rt: Any) -> int:
    """The period of the task executing the call (the sampling period W502 derives from the task)."""
    task = getattr(rt, "current_task", None)
    return task.period_ns if task is not None else rt.period_ns


def _deref(ref: Any, default: Any) -> Any:
    """The value behind a scalar VAR_IN_OUT reference (container, key), or ``default`` when none is connected."""
    if ref is None:
        return default
    container, key = ref
    return container[key]


class PIDAT:
    """PID control of W502 PIDAT without autotuning.

    Two-degree-of-freedom PID in position form, in % of the range RngLowLmt .. RngUpLmt::

        e  = SP% - PV%                  (reverse operation; direct operation DirOpr: PV% - SP%)
        Kp = 100 / ProportionalBand
        P  = Kp * (Alpha * SP% - PV%)   (signs as for e; Alpha weighs the set point in the P action)
        I  = I + Kp * e * dt / IntegrationTime      (IntegrationTime 0: I = ManResetVal, no integral action)
        D  = -Kp * DerivativeTime * d(PV%)/dt       (on PV only: a set point step gives no derivative kick)
        MV = limit(P + I + D, MVLowLmt, MVUpLmt)

    With Alpha 1 it is the textbook PID on e; with Alpha < 1 the integral carries the rest of the set point, so
    the weighting only shapes the response to a set point change. The integral stops growing while MV is at a limit
    in the direction of e (anti-windup). Manual mode and MV tracking preset the integral so that the return to
    automatic is bumpless. The sampling period is InitSetParams.SampTime, or the task period when it is T#0s.
    """

    def __init__(self, rt: Any, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Run = self.ManCtl = self.StartAT = False
        self.PV = self.SP = self.ManMV = 0.0
        self.OprSetParams = rt.new_struct("_sOPR_SET_PARAMS")
        self.InitSetParams = rt.new_struct("_sINIT_SET_PARAMS")
        self.ProportionalBand: Any = None
        self.IntegrationTime: Any = None
        self.DerivativeTime: Any = None
        self.ATDone = self.ATBusy = self.Error = False
        self.ErrorID = 0
        self.MV = 0.0
        self.i__running = False
        self.i__integral = 0.0
        self.i__bumpless = True
        self.i__last_pv = 0.0
        self.i__last_t = 0
        self.i__init = (0, 0.0, 100.0, False)       # SampTime, RngLowLmt, RngUpLmt, DirOpr as read at Run TRUE

    def _fail(self, why: str) -> None:
        self.Error, self.ErrorID = True, ERR_RANGE
        self.MV = float(self.OprSetParams.ErrorMV)
        self.i__rt.instruction_error(f"PIDAT: {why}; Error TRUE, ErrorID 16#{ERR_RANGE:04X}, MV := ErrorMV")

    def i__run(self) -> None:
        rt, opr = self.i__rt, self.OprSetParams
        if not self.Run:
            self.i__running = False
            self.Error, self.ErrorID = False, 0
            self.MV = float(opr.StopMV)
            return
        if self.StartAT and not self.ManCtl:
            raise RuntimeFaultError("PIDAT: autotuning (StartAT TRUE) is not modelled by vplc; run it with "
                                    "StartAT FALSE and the PID constants set (docs/toolchain/runtime_sysmac.md)")
        now = rt.now_ns
        if not self.i__running:            # W502: the initial settings are read when Run changes to TRUE
            init = self.InitSetParams
            self.i__init = (int(init.SampTime), float(init.RngLowLmt), float(init.RngUpLmt), bool(init.DirOpr))
            self.i__running = True
            self.i__last_t = now
            self.i__last_pv = self._percent(self.PV)
            self.i__integral, self.i__bumpless = float(self.MV), True
        samp, low, high, _direct = self.i__init
        pb = float(_deref(self.ProportionalBand, 0.0))
        ti = int(_deref(self.IntegrationTime, 0))
        td = int(_deref(self.DerivativeTime, 0))
        lo, hi = float(opr.MVLowLmt), float(opr.MVUpLmt)
        checks = ((high <= low, f"RngUpLmt {high} is not greater than RngLowLmt {low}"),
                  (lo > hi, f"MVLowLmt {lo} is greater than MVUpLmt {hi}"),
                  (not pb > 0.0 or math.isinf(pb), f"ProportionalBand {pb} is not a positive number"),
                  (ti < 0 or td < 0 or samp < 0, "a negative time (IntegrationTime, DerivativeTime or SampTime)"),
                  (not all(map(math.isfinite, (self.PV, self.SP, lo, hi))), "PV, SP or an MV limit is not a number"))
        for bad, why in checks:
            if bad:
                self._fail(why)
                return
        self.Error, self.ErrorID = False, 0
        pv = self._percent(self.PV)
        if self.ManCtl or opr.MVTrackSw:
            mv = float(self.ManMV if self.ManCtl else opr.MVTrackVal)
            self.MV = min(max(mv, lo), hi)
            self.i__integral, self.i__bumpless = self.MV, True      # bumpless return to automatic
            self.i__last_pv, self.i__last_t = pv, now
            return
        period = samp if samp > 0 else _task_period_ns(rt)
        dt_ns = now - self.i__last_t
        if dt_ns < period and dt_ns != 0:
            return                                      # between two samples MV holds
        dt = max(dt_ns, period) / _NS
        self.MV = self._compute(pv, self._percent(self.SP), pb, ti / _NS, td / _NS, dt, lo, hi)
        self.i__last_pv, self.i__last_t = pv, now

    def _percent(self, x: float) -> float:
        _samp, low, high, _direct = self.i__init
        return (float(x) - low) / (high - low) * 100.0 if high > low else 0.0

    def _compute(self, pv: float, sp: float, pb: float, ti: float, td: float, dt: float, lo: float,
                 hi: float) -> float:
        opr = self.OprSetParams
        sign = -1.0 if self.i__init[3] else 1.0         # direct operation: MV rises with PV
        kp = 100.0 / pb
        e = sign * (sp - pv)
        p = kp * sign * (float(opr.Alpha) * sp - pv)
        d = -kp * td * sign * (pv - self.i__last_pv) / dt if td > 0 else 0.0
        if ti <= 0:
            return min(max(float(opr.ManResetVal) + kp * e + d, lo), hi)
        if self.i__bumpless:                            # from Run, manual or tracking: MV continues from there
            self.i__integral -= p
            self.i__bumpless = False
        step = kp * e * dt / ti
        unclamped = self.i__integral + step + p + d
        if not ((unclamped > hi and step > 0) or (unclamped < lo and step < 0)):
            self.i__integral += step
        return min(max(self.i__integral + p + d, lo), hi)


class TimeProportionalOut:
    """W560 2-728 (NY-series, the same instruction as W502's): while Enable is TRUE, DOut is TRUE for AIn % of each
    control period CtlPrd, from the start of the period; Enable FALSE resets the output (DOut and Error FALSE).
    CtlPrd, MinPlsWidth and Delay are read when Enable changes to TRUE. The resolution of DOut is task period ÷
    CtlPrd × 100 %: AIn is truncated to it (W560 2-728: 1 ms task, CtlPrd 1 s → 0.1 %). AIn is read at the start
    of each control period (chosen) and limited to 0 .. 100 % (chosen)."""

    def __init__(self, rt: Any, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Enable = False
        self.AIn = self.MinPlsWidth = self.Delay = 0.0
        self.CtlPrd = 0
        self.DOut = self.Error = False
        self.i__enabled = False
        self.i__t0 = 0
        self.i__period = 0
        self.i__start = -1                      # start of the current control period
        self.i__on_ns = 0

    def i__run(self) -> None:
        if not self.Enable:
            self.i__enabled = False
            self.DOut = self.Error = False
            return
        rt = self.i__rt
        now = rt.now_ns
        if not self.i__enabled:
            self.i__enabled = True
            for name in ("MinPlsWidth", "Delay"):
                value = float(getattr(self, name))
                if value != 0.0:
                    raise RuntimeFaultError(f"TimeProportionalOut: {name} {value:g} is not modelled by vplc (only 0 "
                                            "runs; docs/toolchain/runtime_sysmac.md)")
            self.i__period = int(self.CtlPrd)
            self.i__t0, self.i__start = now, -1
            task = _task_period_ns(rt)
            self.Error = self.i__period < task or self.i__period <= 0
            if self.Error:
                rt.instruction_error(f"TimeProportionalOut: CtlPrd {self.i__period / 1e9:g} s is shorter than the "
                                     f"task period {task / 1e9:g} s; Error TRUE")
        if self.Error:
            self.DOut = False
            return
        period = self.i__period
        start = now - (now - self.i__t0) % period
        if start != self.i__start:
            self.i__start = start
            task = _task_period_ns(rt)
            ain = float(self.AIn)
            share = min(max(ain, 0.0), 100.0) if math.isfinite(ain) else 0.0
            ticks = int(share * period / (100.0 * task) + 1e-9)     # truncated to the resolution of DOut
            self.i__on_ns = ticks * task
        self.DOut = now - start < self.i__on_ns


NATIVE_FBS = {c.__name__: c for c in (PIDAT, TimeProportionalOut)}
