"""A test program with one instance of every single-axis motion instruction on _MC_AX[0], run scan by scan on
virtual time (1 ms task) through vplc.api.load_plc. The program is compiled once per test session."""
from __future__ import annotations

import pathlib

from vplc.api import load_plc

PERIOD = 1_000_000          # ns
MAIN = """
PROGRAM Main
VAR
    pwr : MC_Power; home : MC_Home; abs1 : MC_MoveAbsolute; abs2 : MC_MoveAbsolute; rel : MC_MoveRelative;
    vel : MC_MoveVelocity; hlt : MC_Halt; stp : MC_Stop; rst : MC_Reset; err : MC_ReadAxisError;
    setp : MC_SetPosition; ovr : MC_SetOverride;
    power : BOOL := TRUE;
    doHome, doAbs1, doAbs2, doRel, doVel, doHalt, doStop, doReset, doSetPos, doOvr : BOOL;
    pos1 : LREAL := 100.0; pos2 : LREAL; dist : LREAL; v1 : LREAL := 50.0; v2 : LREAL := 50.0; vv : LREAL := 20.0;
    a1 : LREAL := 1000.0; d1 : LREAL := 500.0; jerk : LREAL; jerkV : LREAL; jerkS : LREAL;
    buf1 : _eMC_BUFFER_MODE; buf2 : _eMC_BUFFER_MODE; bufRel : _eMC_BUFFER_MODE;
    dir : _eMC_DIRECTION := _mcPositiveDirection; stopDec : LREAL := 1000.0; factor : LREAL := 100.0;
    setTo : LREAL;
END_VAR
pwr(Axis := _MC_AX[0], Enable := power);
home(Axis := _MC_AX[0], Execute := doHome);
abs1(Axis := _MC_AX[0], Execute := doAbs1, Position := pos1, Velocity := v1, Acceleration := a1,
     Deceleration := d1, Jerk := jerk, BufferMode := buf1);
abs2(Axis := _MC_AX[0], Execute := doAbs2, Position := pos2, Velocity := v2, Acceleration := a1,
     Deceleration := d1, BufferMode := buf2);
rel(Axis := _MC_AX[0], Execute := doRel, Distance := dist, Velocity := v1, Acceleration := a1,
    Deceleration := d1, BufferMode := bufRel);
vel(Axis := _MC_AX[0], Execute := doVel, Velocity := vv, Acceleration := a1, Deceleration := d1, Jerk := jerkV,
    Direction := dir);
hlt(Axis := _MC_AX[0], Execute := doHalt, Deceleration := d1);
stp(Axis := _MC_AX[0], Execute := doStop, Deceleration := stopDec, Jerk := jerkS);
rst(Axis := _MC_AX[0], Execute := doReset);
err(Axis := _MC_AX[0], Enable := TRUE);
setp(Axis := _MC_AX[0], Execute := doSetPos, Position := setTo);
ovr(Axis := _MC_AX[0], Enable := doOvr, VelFactor := factor);
END_PROGRAM
"""

AXES = """
[[axis]]
number = 0
units = "mm"
max_velocity = 200.0
max_acceleration = 2000.0
max_deceleration = 2000.0
"""

AXES_JERK = AXES + "max_jerk = 20000.0\n"

AXES_LIMITED = AXES + """software_limit_negative = -10.0
software_limit_positive = 150.0
homed = true
"""

_DIR = {}


def files(tmp_path_factory):
    if not _DIR:
        d = tmp_path_factory.mktemp("motion")
        (d / "Main.st").write_text(MAIN, encoding="utf-8")
        (d / "axes.toml").write_text(AXES, encoding="utf-8")
        (d / "axes_limited.toml").write_text(AXES_LIMITED, encoding="utf-8")
        (d / "axes_jerk.toml").write_text(AXES_JERK, encoding="utf-8")
        _DIR["d"] = d
    return _DIR["d"]


class Rig:
    """One PLC: ``set`` writes Main variables before the next scan, ``scan`` runs scans 1 ms apart (the first at
    0 ms), ``r`` reads a Main variable, ``ax`` a member of _MC_AX[0]."""

    def __init__(self, folder: pathlib.Path, axes: str = "axes.toml") -> None:
        self.plc = load_plc([str(folder / "Main.st")], task="Main@1ms", axes=str(folder / axes))
        self.k = 0                  # index of the next scan; its time is k ms

    def set(self, **values) -> None:
        for name, value in values.items():
            self.plc.write(f"Main.{name}", value)

    def scan(self, n: int = 1) -> None:
        for _ in range(n):
            self.plc.scan(self.k * PERIOD)
            self.k += 1

    @property
    def t(self) -> float:
        """Time of the last scan, in s."""
        return (self.k - 1) * PERIOD / 1e9

    def r(self, path: str):
        return self.plc.read(f"Main.{path}")

    def ax(self, member: str):
        return self.plc.read(f"_MC_AX[0].{member}")

    def outputs(self, fb: str, names=("Busy", "Active", "Done", "CommandAborted", "Error")) -> tuple:
        return tuple(self.r(f"{fb}.{n}") for n in names)

    def state(self) -> str:
        names = ("Disabled", "Standstill", "Discrete", "Continuous", "Homing", "Stopping", "ErrorStop")
        on = [n for n in names if self.ax(f"Status.{n}")]
        assert len(on) == 1, on
        return on[0]

    def powered(self) -> Rig:
        self.scan(2)
        assert self.r("pwr.Status") and self.state() == "Standstill"
        return self


def trapezoid(tau: float, dist: float, v: float, a: float, d: float) -> tuple[float, float]:
    """Closed-form position and velocity, tau s after the start of a positioning from rest over ``dist`` (> 0)
    with velocity v, acceleration a and deceleration d (a triangle when the distance is too short)."""
    vp = min(v, (dist / (1 / (2 * a) + 1 / (2 * d))) ** 0.5)
    ta, td = vp / a, vp / d
    tc = (dist - vp * vp / (2 * a) - vp * vp / (2 * d)) / vp
    total = ta + tc + td
    if tau <= 0:
        return 0.0, 0.0
    if tau < ta:
        return a * tau * tau / 2, a * tau
    if tau < ta + tc:
        return vp * vp / (2 * a) + vp * (tau - ta), vp
    if tau < total:
        rest = total - tau
        return dist - d * rest * rest / 2, d * rest
    return dist, 0.0


def duration(dist: float, v: float, a: float, d: float) -> float:
    vp = min(v, (dist / (1 / (2 * a) + 1 / (2 * d))) ** 0.5)
    return vp / a + vp / d + (dist - vp * vp / (2 * a) - vp * vp / (2 * d)) / vp


def s_curve(tau: float, dist: float, v: float, a: float, j: float) -> tuple[float, float]:
    """Closed-form position and velocity, tau s after the start of a jerk-limited positioning from rest over
    ``dist`` with velocity v, acceleration = deceleration a and jerk j, for a distance long enough to reach v
    (v >= a * a / j): jerk phase t1 = a / j, constant acceleration t2, jerk phase t1, cruise, and the mirror
    image to rest."""
    t1 = a / j
    t2 = v / a - t1
    ta = 2 * t1 + t2
    da = v * ta / 2
    tc = (dist - 2 * da) / v
    total = 2 * ta + tc

    def up(t):                     # distance and velocity after t s of the acceleration phase
        if t <= 0:
            return 0.0, 0.0
        if t < t1:
            return j * t ** 3 / 6, j * t * t / 2
        if t < t1 + t2:
            x1, v1 = j * t1 ** 3 / 6, j * t1 * t1 / 2
            r = t - t1
            return x1 + v1 * r + a * r * r / 2, v1 + a * r
        if t < ta:
            r = ta - t
            return da - (v * r - j * r ** 3 / 6), v - j * r * r / 2
        return da, v

    if tau < ta:
        return up(tau)
    if tau < ta + tc:
        return da + v * (tau - ta), v
    if tau < total:
        x, vel = up(total - tau)
        return dist - x, vel
    return dist, 0.0


def s_curve_duration(dist: float, v: float, a: float, j: float) -> float:
    ta = v / a + a / j
    return 2 * ta + (dist - v * ta) / v
