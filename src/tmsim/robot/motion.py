"""Motion planning for the robot model: targets, paths and durations (all derived from the parameters).

Duration of one motion (trapezoidal speed profile):

    ta  = accel_ms / 1000                         time to reach the cruise speed
    T(d, v) = d / v + ta          if d >= v * ta   (the arm reaches cruise speed)
            = 2 * sqrt(d * ta / v) otherwise       (triangular profile)

* PTP / joint moves: every joint i moves d_i degrees with v_i = JOINT_SPEED[i] * speed% / 100;
  all joints are synchronised, so T = max_i T(d_i, v_i).
* Line / PLine / Circle: d = path length in mm with v = TCP_SPEED * speed% / 100 (formats "?P?")
  or v = min(speed mm/s, TCP_SPEED) (formats "?A?"); the orientation change runs at
  ROT_SPEED scaled the same way; T = max of both.
* Blending (blend > 0) overlaps the deceleration with the next motion:
  T -= b * min(ta, T/2), b = blend% / 100, or for radius formats b = min(1, radius / (d / 2)).
* Precise positioning (last argument false) adds SETTLE_S of fine settling at the end.
* PVTPoint (between PVTEnter and PVTExit): the duration is given; every coordinate follows the cubic
  Hermite curve from the current position and velocity to the point's position and velocity
  (joint mode: the six joints, deg and deg/s; Cartesian mode: X, Y, Z, RX, RY, RZ in the current base,
  mm and deg per s, converted to joints by inverse kinematics along the way). A curve whose joint speed
  exceeds JOINT_SPEED (joint mode: the curve's velocity at 51 instants; Cartesian mode: joint steps between
  12 inverse-kinematics samples, so a plan costs ~2 ms, not ~10), or whose target is outside the joint
  limits or out of reach, fails like any other motion.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

from tmsim.robot import kinematics as kin

JOINT_SPEED = (180.0, 180.0, 180.0, 225.0, 225.0, 225.0)   # deg/s, TM5-700 data sheet
TCP_SPEED = 1100.0                                           # mm/s
ROT_SPEED = 225.0                                            # deg/s for the TCP orientation
SETTLE_S = 0.15                                              # precise positioning settling time


class MotionError(Exception):
    """A motion that cannot be executed (bad value, unreachable target, joint limit)."""


def trapezoid_time(distance: float, speed: float, ta: float) -> float:
    if distance <= 0:
        return 0.0
    if ta <= 0 or distance >= speed * ta:
        return distance / speed + max(ta, 0.0)
    return 2.0 * math.sqrt(distance * ta / speed)


def trapezoid_fraction(t: float, total: float, ta: float) -> float:
    """Fraction of the path covered at time t of a symmetric trapezoidal profile of length total."""
    if total <= 0 or t >= total:
        return 1.0
    if t <= 0:
        return 0.0
    ta = min(ta, total / 2.0)
    if ta <= 0:
        return t / total
    vmax = 1.0 / (total - ta)              # normalised cruise speed (area under profile = 1)
    if t < ta:
        return 0.5 * vmax * t * t / ta
    if t <= total - ta:
        return vmax * (t - ta / 2.0)
    rest = total - t
    return 1.0 - 0.5 * vmax * rest * rest / ta


class MotionRequest(NamedTuple):
    """One queued motion as written in the script (values already evaluated).

    A tuple of plain values: a long motion FIFO costs ~250 bytes per motion and nothing at garbage
    collection (the collector stops tracking tuples that hold no containers)."""
    function: str             # PTP, Line, Circle, PLine, Move_PTP, Move_Line, Move_PLine
    fmt: str
    target: tuple             # 6 values (or 12 for Circle: via point then end point)
    speed: float
    accel_ms: float
    blend: float
    precise: bool
    config: tuple | None = None
    arc_angle: float = 0.0
    line: str = ""
    duration: float = 0.0     # PVTPoint only: the given duration in s (target = 6 positions + 6 velocities)


@dataclass
class Plan:
    """A motion ready to run: start/end joints, a path function and its duration."""
    request: MotionRequest
    start_joints: list
    end_joints: list
    duration: float            # motion time without settling/blending adjustments
    ta: float
    total: float               # time until the next FIFO item starts
    cartesian: Callable[[float], list] | None = None   # s -> TCP matrix in robot coordinates; None: joint motion
    end_pose: list = field(default_factory=list)
    tool: Sequence[Sequence[float]] | None = None
    start_pose: list = field(default_factory=list)

    def joints_at(self, t: float, reference: Sequence[float] | None = None) -> list[float]:
        s = trapezoid_fraction(t, self.duration, self.ta)
        if s >= 1.0:
            return list(self.end_joints)
        if self.cartesian is None:
            return [a + (b - a) * s for a, b in zip(self.start_joints, self.end_joints, strict=False)]
        try:
            return kin.inverse_kinematics(self.cartesian(s), self.tool, reference=reference or self.start_joints)
        except kin.KinematicsError:
            return [a + (b - a) * s for a, b in zip(self.start_joints, self.end_joints, strict=False)]


def hermite(p0: Sequence[float], v0: Sequence[float], p1: Sequence[float], v1: Sequence[float], T: float,
            t: float) -> tuple[list[float], list[float]]:
    """Position and velocity at time t of the cubic Hermite curve p0,v0 (t=0) -> p1,v1 (t=T), per coordinate."""
    s = min(max(t / T, 0.0), 1.0)
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2
    d00, d10, d01, d11 = 6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, -6 * s2 + 6 * s, 3 * s2 - 2 * s
    pos = [h00 * a + h10 * T * va + h01 * b + h11 * T * vb for a, va, b, vb in zip(p0, v0, p1, v1, strict=False)]
    vel = [(d00 * a + d01 * b) / T + d10 * va + d11 * vb for a, va, b, vb in zip(p0, v0, p1, v1, strict=False)]
    return pos, vel


@dataclass
class PvtPlan(Plan):
    """One PVTPoint: a Hermite curve in joint space (coords = joints) or in the base frame (coords = pose)."""
    p0: tuple = ()
    v0: tuple = ()
    p1: tuple = ()
    v1: tuple = ()
    # Cartesian mode: (pose, reference joints) -> joints
    to_joints: Callable[[list, Sequence[float]], list] | None = None

    def joints_at(self, t: float, reference: Sequence[float] | None = None) -> list[float]:
        if t >= self.duration:
            return list(self.end_joints)
        pos, _vel = hermite(self.p0, self.v0, self.p1, self.v1, self.duration, t)
        if self.to_joints is None:
            return pos
        try:
            return self.to_joints(pos, reference or self.start_joints)
        except kin.KinematicsError:
            return list(reference or self.start_joints)


def _rot(m):
    return [row[:3] for row in m[:3]]


def _slerp_matrix(m0, m1, s):
    """Interpolate position linearly and orientation along the shortest rotation."""
    r0, r1 = _rot(m0), _rot(m1)
    rel = [[sum(r0[k][i] * r1[k][j] for k in range(3)) for j in range(3)] for i in range(3)]   # r0^T r1
    angle = math.acos(max(-1.0, min(1.0, (rel[0][0] + rel[1][1] + rel[2][2] - 1) / 2)))
    if angle < 1e-9:
        rs = r0
    else:
        axis = [rel[2][1] - rel[1][2], rel[0][2] - rel[2][0], rel[1][0] - rel[0][1]]
        n = math.sqrt(sum(a * a for a in axis))
        if n < 1e-9:                       # 180 degrees: axis from the diagonal
            axis = [math.sqrt(max(0.0, (rel[i][i] + 1) / 2)) for i in range(3)]
            n = math.sqrt(sum(a * a for a in axis)) or 1.0
        x, y, z = (a / n for a in axis)
        a = angle * s
        c, sn, v = math.cos(a), math.sin(a), 1 - math.cos(a)
        rr = [[c + x * x * v, x * y * v - z * sn, x * z * v + y * sn],
              [y * x * v + z * sn, c + y * y * v, y * z * v - x * sn],
              [z * x * v - y * sn, z * y * v + x * sn, c + z * z * v]]
        rs = [[sum(r0[i][k] * rr[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    p = [m0[i][3] + (m1[i][3] - m0[i][3]) * s for i in range(3)]
    return [rs[0] + [p[0]], rs[1] + [p[1]], rs[2] + [p[2]], [0.0, 0.0, 0.0, 1.0]]


def rotation_angle(m0: Sequence[Sequence[float]], m1: Sequence[Sequence[float]]) -> float:
    r0, r1 = _rot(m0), _rot(m1)
    trace = sum(sum(r0[k][i] * r1[k][i] for k in range(3)) for i in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))


def _check_common(req):
    if not all(math.isfinite(v) for v in (*req.target, req.speed, req.accel_ms, req.blend)):
        raise MotionError(f"{req.function}: a value is not a finite number")
    if req.speed == -1:         # TMscript 2.24 §13.8-13.12: speed -1 = acceleration table, S-series models only
        raise MotionError(f"{req.function} speed -1 selects the acceleration table, which only TM S-series "
                          f"robots have (this is a TM5-700)")
    if req.fmt[1:2] == "P" or req.function.startswith(("PTP", "Move_PTP")):
        if not 0 < req.speed <= 100:
            raise MotionError(f"{req.function} speed {req.speed:g} % is outside 1..100 %")
    elif req.speed <= 0:
        raise MotionError(f"{req.function} speed {req.speed:g} mm/s must be positive")
    if req.accel_ms < 0:
        raise MotionError(f"{req.function} acceleration time {req.accel_ms:g} ms is negative")
    if req.blend < 0 or (req.fmt[2:3] == "P" and req.blend > 100):
        raise MotionError(f"{req.function} blending {req.blend:g} is outside its range")


class Planner:
    """Turns MotionRequests into Plans for a given robot state (base, tool, joints)."""

    def __init__(self, base: Sequence[Sequence[float]], tool: Sequence[Sequence[float]]):
        self.base = base          # base frame matrix in robot coordinates
        self.tool = tool          # TCP matrix in flange coordinates
        self.base_inverse = kin.inverse(base)

    def tcp_in_base(self, joints: Sequence[float]) -> list[list[float]]:
        return kin.matmul(self.base_inverse, kin.forward(joints, self.tool))

    def flange_target(self, pose_in_base: Sequence[float]) -> list[list[float]]:
        """TCP pose in the current base -> TCP matrix in robot coordinates."""
        return kin.matmul(self.base, kin.pose_to_matrix(pose_in_base))

    def plan(self, req: MotionRequest, joints: list) -> Plan:
        start_tcp = kin.forward(joints, self.tool)
        plan = self._plan(req, joints, start_tcp)
        plan.start_pose = kin.matrix_to_pose(kin.matmul(self.base_inverse, start_tcp))
        return plan

    def _plan(self, req: MotionRequest, joints: list, start_tcp) -> Plan:
        _check_common(req)
        relative = req.function.startswith("Move_")
        frame = req.fmt[0]
        if req.function == "Circle":
            return self._plan_circle(req, joints, start_tcp)
        if frame == "J":
            end_joints = [a + b for a, b in zip(joints, req.target, strict=False)] if relative else list(req.target)
            if not kin.within_limits(end_joints):
                raise MotionError(f"{req.function} target joints exceed the joint limits")
            end_tcp = kin.forward(end_joints, self.tool)
        else:
            if relative and frame == "T":
                end_tcp = kin.matmul(start_tcp, kin.pose_to_matrix(req.target))
            elif relative:
                cur = kin.matmul(kin.inverse(self.base), start_tcp)
                delta = kin.pose_to_matrix([0, 0, 0] + list(req.target[3:]))
                moved = kin.matmul(delta, [r[:3] + [0.0] for r in cur[:3]] + [[0.0, 0.0, 0.0, 1.0]])
                for i in range(3):
                    moved[i][3] = cur[i][3] + req.target[i]
                end_tcp = kin.matmul(self.base, moved)
            else:
                end_tcp = self.flange_target(req.target)
            try:
                end_joints = kin.inverse_kinematics(end_tcp, self.tool, reference=joints, config=req.config)
            except kin.KinematicsError as exc:
                raise MotionError(f"{req.function}: {exc}") from None
        ta = req.accel_ms / 1000.0
        joint_move = req.function in ("PTP", "Move_PTP")
        if joint_move:
            duration = max(trapezoid_time(abs(b - a), JOINT_SPEED[i] * req.speed / 100.0, ta)
                           for i, (a, b) in enumerate(zip(joints, end_joints, strict=False)))
            distance = math.dist([start_tcp[i][3] for i in range(3)], [end_tcp[i][3] for i in range(3)])
            path = None
        else:
            distance = math.dist([start_tcp[i][3] for i in range(3)], [end_tcp[i][3] for i in range(3)])
            duration = self._linear_time(req, distance, rotation_angle(start_tcp, end_tcp), ta)
            path = None if frame == "J" else (lambda s, a=start_tcp, b=end_tcp: _slerp_matrix(a, b, s))
        return self._finish(req, joints, end_joints, duration, ta, distance, path)

    def plan_pvt(self, req: MotionRequest, joints: list, mode: int, velocity: Sequence[float]) -> PvtPlan:
        """One PVTPoint from the current joints and velocity (joint mode 0, Cartesian mode 1)."""
        T = req.duration
        if not 0 < T <= 3600:
            raise MotionError(f"PVTPoint duration {T:g} s is outside 0..3600 s")
        if not all(math.isfinite(v) for v in req.target):
            raise MotionError("PVTPoint: a position or velocity is not a finite number")
        p1, v1 = tuple(req.target[:6]), tuple(req.target[6:12])
        start_tcp = kin.forward(joints, self.tool)
        start_pose = kin.matrix_to_pose(kin.matmul(self.base_inverse, start_tcp))
        if mode == 0:
            p0, to_joints = tuple(joints), None
            end_joints = list(p1)
            if not kin.within_limits(end_joints):
                raise MotionError("PVTPoint target joints exceed the joint limits")
        else:
            p0 = tuple(start_pose)
            p1 = tuple(a + _unwrap(b - a) if i >= 3 else b for i, (a, b) in enumerate(zip(p0, p1, strict=False)))

            def to_joints(pose, reference, planner=self):
                return kin.inverse_kinematics(planner.flange_target(pose), planner.tool, reference=reference)
            try:
                end_joints = to_joints(list(p1), joints)
            except kin.KinematicsError as exc:
                raise MotionError(f"PVTPoint: {exc}") from None
        plan = PvtPlan(req, list(joints), list(end_joints), T, 0.0, T, None,
                       kin.matrix_to_pose(self.tcp_in_base(end_joints)), self.tool, start_pose,
                       p0=p0, v0=tuple(velocity), p1=p1, v1=v1, to_joints=to_joints)
        if mode == 0:                       # joint mode: the curve's own velocity, exactly, at 51 instants
            samples = [hermite(p0, plan.v0, p1, v1, T, T * k / 50)[1] for k in range(51)]
            peaks = [max(abs(v[i]) for v in samples) for i in range(6)]
        else:                               # Cartesian mode: joints by inverse kinematics at 12 instants
            peaks, previous, dt = [0.0] * 6, list(joints), T / 12
            for k in range(1, 13):
                current = plan.joints_at(dt * k, previous)
                peaks = [max(peak, abs(b - a) / dt) for peak, a, b in zip(peaks, previous, current, strict=False)]
                previous = current
        for i, peak in enumerate(peaks):
            if peak > JOINT_SPEED[i] * 1.001:
                raise MotionError(f"PVTPoint: joint {i + 1} would move at {peak:.4g} deg/s, "
                                  f"above its limit of {JOINT_SPEED[i]:g} deg/s")
        return plan

    def _linear_time(self, req, distance, angle, ta):
        if req.fmt[1] == "P":
            v, w = TCP_SPEED * req.speed / 100.0, ROT_SPEED * req.speed / 100.0
        else:
            v = min(req.speed, TCP_SPEED)
            w = ROT_SPEED * v / TCP_SPEED
        return max(trapezoid_time(distance, v, ta), trapezoid_time(angle, w, ta))

    def _finish(self, req, joints, end_joints, duration, ta, distance, path):
        total = duration
        if req.blend > 0 and duration > 0:
            b = req.blend / 100.0 if req.fmt[2:3] != "R" else min(1.0, req.blend / max(distance / 2.0, 1e-9))
            total -= b * min(ta, duration / 2.0)
        if req.precise:
            total += SETTLE_S
        tool_pose = kin.matrix_to_pose(self.tcp_in_base(end_joints))
        return Plan(req, list(joints), list(end_joints), duration, ta, total, path, tool_pose, self.tool)

    def _plan_circle(self, req, joints, start_tcp):
        via = self.flange_target(req.target[:6])
        end = self.flange_target(req.target[6:12])
        p0 = [start_tcp[i][3] for i in range(3)]
        p1 = [via[i][3] for i in range(3)]
        p2 = [end[i][3] for i in range(3)]
        centre, radius, normal = _circle(p0, p1, p2)
        if centre is None:
            raise MotionError("Circle: start, via and end points are on one line")
        u = [(p0[i] - centre[i]) / radius for i in range(3)]
        w = _cross(normal, u)
        ang_via = _angle_on(p1, centre, u, w)
        ang_end = _angle_on(p2, centre, u, w)
        if ang_via > ang_end:             # going the other way round keeps the via point on the arc
            normal = [-n for n in normal]
            w = _cross(normal, u)
            ang_end = _angle_on(p2, centre, u, w)
        sweep = math.radians(req.arc_angle) if req.arc_angle else ang_end
        keep = bool(req.arc_angle)

        def tcp(s, c=centre, r=radius, u=u, w=w, a=start_tcp, b=end):
            th = sweep * s
            m = a if keep else _slerp_matrix(a, b, s)
            m = [row[:] for row in m]
            for i in range(3):
                m[i][3] = c[i] + r * (math.cos(th) * u[i] + math.sin(th) * w[i])
            return m

        end_tcp = tcp(1.0)
        try:
            end_joints = kin.inverse_kinematics(end_tcp, self.tool, reference=joints)
        except kin.KinematicsError as exc:
            raise MotionError(f"Circle: {exc}") from None
        ta = req.accel_ms / 1000.0
        distance = abs(sweep) * radius
        duration = self._linear_time(req, distance, 0.0 if keep else rotation_angle(start_tcp, end), ta)
        return self._finish(req, joints, end_joints, duration, ta, distance, tcp)


def _unwrap(delta):
    """An angle difference brought into -180..180 deg (orientation targets take the short way)."""
    return (delta + 180.0) % 360.0 - 180.0


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _angle_on(p, c, u, w):
    v = [p[i] - c[i] for i in range(3)]
    a = math.atan2(sum(v[i] * w[i] for i in range(3)), sum(v[i] * u[i] for i in range(3)))
    return a if a >= 0 else a + 2 * math.pi


def _circle(p0, p1, p2):
    """Centre, radius and unit normal of the circle through three points (None when collinear)."""
    a = [p1[i] - p0[i] for i in range(3)]
    b = [p2[i] - p0[i] for i in range(3)]
    n = _cross(a, b)
    nn = sum(x * x for x in n)
    if nn < 1e-6:
        return None, 0.0, None
    aa, bb = sum(x * x for x in a), sum(x * x for x in b)
    t1 = _cross(n, a)
    t2 = _cross(b, n)
    centre = [p0[i] + (bb * t1[i] + aa * t2[i]) / (2 * nn) for i in range(3)]
    radius = math.dist(centre, p0)
    norm = math.sqrt(nn)
    return centre, radius, [x / norm for x in n]
