"""Kinematic model of the TM5-700 (standard Denavit-Hartenberg, mm and degrees).

| joint | alpha | a     | d      | theta offset | limit      |
|-------|-------|-------|--------|--------------|------------|
| 1     | -90   | 0     | 145.1  | 0            | +-270      |
| 2     | 0     | 329.0 | 0      | -90          | +-180      |
| 3     | 0     | 311.5 | 0      | 0            | +-155      |
| 4     | 90    | 0     | -122.3 | 90           | +-180      |
| 5     | 90    | 0     | 106.0  | 0            | +-180      |
| 6     | 0     | 0     | 114.4  | 0            | +-270      |

Link lengths are the published TM5-700 dimensions; they place joints (0,0,90,0,90,0) at flange
X 417.5, Y -122.3. Poses are (X, Y, Z, Rx, Ry, Rz) with R = Rz * Ry * Rx (fixed X-Y-Z angles), the
convention TMflow displays. Inverse kinematics is closed-form (joints 2, 3, 4 are parallel, as on
UR-type arms: up to 8 solutions, each verified with the forward model), with a numerical fallback
(Newton / damped least squares from several seeds) for the singular wrist-straight case. Solutions
are classified into the 8 arm configurations:

* shoulder RIGHTY (0) / LEFTY (1): wrist centre in front of / behind joint 1's vertical plane
  (x of the wrist centre in the frame turned by joint 1 >= 0 -> RIGHTY)
* elbow ABOVE (2) / BELOW (3): joint 3 >= 0 -> ABOVE (mirrored when LEFTY)
* wrist NOFLIP (4) / FLIP (5): joint 5 >= 0 -> NOFLIP
"""
from __future__ import annotations

import math
import operator
from collections.abc import Sequence

ALPHA = (-90.0, 0.0, 0.0, 90.0, 90.0, 0.0)
A = (0.0, 329.0, 311.5, 0.0, 0.0, 0.0)
D = (145.1, 0.0, 0.0, -122.3, 106.0, 114.4)
OFFSET = (0.0, -90.0, 0.0, 90.0, 0.0, 0.0)
LIMITS = (270.0, 180.0, 155.0, 180.0, 180.0, 270.0)
REACH_TOLERANCE_MM = 0.001
MAX_REACH_MM = A[1] + A[2] + abs(D[3]) + D[4] + 1.0   # shoulder to joint-6 axis, fully stretched
_SIN_ALPHA = tuple(math.sin(math.radians(a)) for a in ALPHA)
_COS_ALPHA = tuple(math.cos(math.radians(a)) for a in ALPHA)

Matrix = list  # 4x4 as a list of 4 rows


class KinematicsError(Exception):
    """Target out of reach or beyond the joint limits."""


def matmul(m: Sequence[Sequence[float]], n: Sequence[Sequence[float]]) -> list[list[float]]:
    """4x4 product, unrolled (the planner's hot spot); same operation order as the textbook loop."""
    (a0, a1, a2, a3), (b0, b1, b2, b3), (c0, c1, c2, c3), (d0, d1, d2, d3) = n
    return [[r0 * a0 + r1 * b0 + r2 * c0 + r3 * d0, r0 * a1 + r1 * b1 + r2 * c1 + r3 * d1,
             r0 * a2 + r1 * b2 + r2 * c2 + r3 * d2, r0 * a3 + r1 * b3 + r2 * c3 + r3 * d3]
            for r0, r1, r2, r3 in m]


def inverse(m: Sequence[Sequence[float]]) -> list[list[float]]:
    r = [[m[j][i] for j in range(3)] for i in range(3)]
    t = [-(r[i][0] * m[0][3] + r[i][1] * m[1][3] + r[i][2] * m[2][3]) for i in range(3)]
    return [r[0] + [t[0]], r[1] + [t[1]], r[2] + [t[2]], [0.0, 0.0, 0.0, 1.0]]


def pose_to_matrix(pose: Sequence[float]) -> list[list[float]]:
    x, y, z, rx, ry, rz = pose
    a, b, c = math.radians(rx), math.radians(ry), math.radians(rz)
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return [[cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa, x],
            [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa, y],
            [-sb, cb * sa, cb * ca, z],
            [0.0, 0.0, 0.0, 1.0]]


def matrix_to_pose(m: Sequence[Sequence[float]]) -> list[float]:
    sb = -m[2][0]
    cb = math.hypot(m[0][0], m[1][0])
    ry = math.atan2(sb, cb)
    if cb > 1e-9:
        rx = math.atan2(m[2][1], m[2][2])
        rz = math.atan2(m[1][0], m[0][0])
    else:                                  # gimbal lock: put everything on Rz
        rx = 0.0
        rz = math.atan2(-m[0][1], m[1][1])
    return [m[0][3], m[1][3], m[2][3], math.degrees(rx), math.degrees(ry), math.degrees(rz)]


def link_frames(joints: Sequence[float]) -> list[list[list[float]]]:
    """Base-to-link transforms T0 (identity) .. T6 (flange) of ``joints`` (degrees), 4x4 matrices in mm: where
    each joint of the arm is (a view draws the arm from them). Each step is T(i-1) * DH(i), unrolled."""
    rows: Sequence[tuple[float, float, float, float]] = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0),
                                                         (0.0, 0.0, 1.0, 0.0))
    frames = [[list(r) for r in rows] + [[0.0, 0.0, 0.0, 1.0]]]
    for i in range(6):
        th = math.radians(joints[i] + OFFSET[i])
        ct, st, ca, sa, a, d = math.cos(th), math.sin(th), _COS_ALPHA[i], _SIN_ALPHA[i], A[i], D[i]
        rows = tuple((r0 * ct + r1 * st,
                      -r0 * st * ca + r1 * ct * ca + r2 * sa,
                      r0 * st * sa - r1 * ct * sa + r2 * ca,
                      (r0 * ct + r1 * st) * a + r2 * d + r3) for r0, r1, r2, r3 in rows)
        frames.append([list(r) for r in rows] + [[0.0, 0.0, 0.0, 1.0]])
    return frames


def forward(joints: Sequence[float], tool: Sequence[Sequence[float]] | None = None) -> list[list[float]]:
    """Flange (or TCP when ``tool`` matrix given) pose matrix in the robot base frame.

    The loop of ``link_frames`` without keeping the intermediate frames (same arithmetic)."""
    rows: Sequence[tuple[float, float, float, float]] = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0),
                                                         (0.0, 0.0, 1.0, 0.0))
    for i in range(6):
        th = math.radians(joints[i] + OFFSET[i])
        ct, st, ca, sa, a, d = math.cos(th), math.sin(th), _COS_ALPHA[i], _SIN_ALPHA[i], A[i], D[i]
        rows = [(r0 * ct + r1 * st,
                 -r0 * st * ca + r1 * ct * ca + r2 * sa,
                 r0 * st * sa - r1 * ct * sa + r2 * ca,
                 (r0 * ct + r1 * st) * a + r2 * d + r3) for r0, r1, r2, r3 in rows]
    m = [list(r) for r in rows] + [[0.0, 0.0, 0.0, 1.0]]
    return matmul(m, tool) if tool is not None else m


def _jacobian(frames):
    """Geometric Jacobian (rows: vx, vy, vz in mm/rad, then 300 * wx, wy, wz) of the flange."""
    pe = [frames[6][i][3] for i in range(3)]
    cols = []
    for j in range(6):
        f = frames[j]
        z = [f[0][2], f[1][2], f[2][2]]
        r = [pe[i] - f[i][3] for i in range(3)]
        cols.append([z[1] * r[2] - z[2] * r[1], z[2] * r[0] - z[0] * r[2], z[0] * r[1] - z[1] * r[0],
                     300.0 * z[0], 300.0 * z[1], 300.0 * z[2]])
    return [[cols[j][i] for j in range(6)] for i in range(6)]


def _error(current, target):
    """6-vector: position error (mm) and orientation error (rad, axis*angle, base frame)."""
    e = [target[i][3] - current[i][3] for i in range(3)]
    # rotation error R_t * R_c^T as a small axis-angle vector
    r = [[sum(target[i][k] * current[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    angle = math.acos(max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2)))
    axis = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    s = math.sin(angle)
    scale = angle / (2 * s) if s > 1e-9 else 0.5
    if angle > 3.0 and s < 1e-3:          # near 180 degrees: use the diagonal
        axis = [math.sqrt(max(0.0, (r[i][i] + 1) / 2)) * math.pi for i in range(3)]
        scale = 1.0
    return e + [a * scale for a in axis]


def _gauss(m, n):
    """Solve the augmented n x (n+1) system ``m`` in place by Gauss-Jordan with partial pivoting."""
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(m[r][col]))
        m[col], m[pivot] = m[pivot], m[col]
        head = m[col]
        if abs(head[col]) < 1e-9:
            return None
        for r in range(n):
            if r != col:
                row = m[r]
                f = row[col] / head[col]
                if f:
                    for c in range(col, n + 1):
                        row[c] -= f * head[c]
    return [m[i][n] / m[i][i] for i in range(n)]


def _solve(jac, err, damping):
    """Newton step J dq = e; near a singularity damped least squares dq = J^T (J J^T + l^2 I)^-1 e."""
    step = _gauss([row[:] + [e] for row, e in zip(jac, err, strict=False)], 6)
    if step is not None and max(abs(v) for v in step) < 1.0:
        return step
    m = [[sum(map(operator.mul, jac[i], jac[j])) + (damping if i == j else 0.0) for j in range(6)] + [err[i]]
         for i in range(6)]
    y = _gauss(m, 6)
    if y is None:
        return None
    return [sum(jac[k][j] * y[k] for k in range(6)) for j in range(6)]


def _ik_from(seed, target, iterations=60):
    q = list(seed)
    for _ in range(iterations):
        frames = link_frames(q)
        err = _error(frames[6], target)
        if math.sqrt(sum(e * e for e in err[:3])) < REACH_TOLERANCE_MM and max(abs(e) for e in err[3:]) < 1e-6:
            return q
        werr = err[:3] + [e * 300.0 for e in err[3:]]
        step = _solve(_jacobian(frames), werr, 1e-3)
        if step is None:
            return None
        norm = math.sqrt(sum(v * v for v in step))
        if norm > 0.5:
            step = [v * 0.5 / norm for v in step]
        q = [q[i] + math.degrees(step[i]) for i in range(6)]
    err = _error(forward(q), target)
    if math.sqrt(sum(e * e for e in err[:3])) < REACH_TOLERANCE_MM and max(abs(e) for e in err[3:]) < 1e-5:
        return q
    return None


def _analytic(target):
    """Closed-form candidates for the flange pose ``target`` (up to 8; joints 2, 3, 4 are parallel).

    theta1 from the joint-5 origin having a fixed offset d4 along the parallel axes, theta5 from the
    angle between the tool axis and that common axis, theta6 from the common axis seen in the
    flange frame, then a planar 2R problem for joints 2 and 3. Every candidate is checked with
    ``forward`` by the caller; singular cases (wrist straight) fall back to the numerical solver.
    """
    z6 = [target[0][2], target[1][2], target[2][2]]
    p5 = [target[i][3] - D[5] * z6[i] for i in range(3)]
    r = math.hypot(p5[0], p5[1])
    if r < abs(D[3]) + 1e-9:
        return []
    phi = math.atan2(p5[1], p5[0])
    base = math.asin(max(-1.0, min(1.0, D[3] / r)))
    out = []
    for t1 in (phi - base, phi - (math.pi - base)):
        c1, s1 = math.cos(t1), math.sin(t1)
        inv_a1 = [[c1, s1, 0.0, 0.0], [0.0, 0.0, -1.0, D[0]], [-s1, c1, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
        z1 = [-s1, c1, 0.0]
        c5 = -(z1[0] * z6[0] + z1[1] * z6[1])
        if abs(c5) > 1.0 - 1e-9:
            continue
        z1_6 = [sum(target[k][j] * z1[k] for k in range(3)) for j in range(3)]   # R^T z1
        m1t = matmul(inv_a1, target)
        for t5 in (math.acos(c5), -math.acos(c5)):
            s5 = math.sin(t5)
            t6 = math.atan2(-z1_6[1] / s5, z1_6[0] / s5)
            # frame 4 in frame 1: inverse(A1) * target * inverse(A5 * A6)
            a5a6 = _chain(4, [math.degrees(t5), math.degrees(t6)])
            m14 = matmul(m1t, inverse(a5a6))
            x, y = m14[0][3], m14[1][3]
            c3 = (x * x + y * y - A[1] ** 2 - A[2] ** 2) / (2 * A[1] * A[2])
            if abs(c3) > 1.0:
                continue
            for t3 in (math.acos(c3), -math.acos(c3)):
                t2p = math.atan2(y, x) - math.atan2(A[2] * math.sin(t3), A[1] + A[2] * math.cos(t3))
                t234 = math.atan2(m14[1][0], m14[0][0])
                t4p = t234 - t2p - t3
                out.append([math.degrees(t1), math.degrees(t2p) - OFFSET[1], math.degrees(t3),
                            math.degrees(t4p) - OFFSET[3], math.degrees(t5), math.degrees(t6)])
    return out


def _chain(first, angles):
    """Product of the DH transforms of joints first+1 .. first+len(angles) (0-based ``first``)."""
    m = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    for i, q in zip(range(first, first + len(angles)), angles, strict=False):
        th = math.radians(q + OFFSET[i])
        ct, st, ca, sa = math.cos(th), math.sin(th), _COS_ALPHA[i], _SIN_ALPHA[i]
        m = matmul(m, [[ct, -st * ca, st * sa, A[i] * ct], [st, ct * ca, -ct * sa, A[i] * st],
                       [0.0, sa, ca, D[i]], [0.0, 0.0, 0.0, 1.0]])
    return m


def _wrap(q, reference):
    """Bring each angle to the 360-degree equivalent closest to the reference."""
    return [a - 360.0 * round((a - r) / 360.0) for a, r in zip(q, reference, strict=False)]


def configuration(joints: Sequence[float]) -> tuple[int, int, int]:
    """Arm configuration (shoulder, elbow, wrist) as (0|1, 2|3, 4|5)."""
    m = forward(joints)
    wx = m[0][3] - D[5] * m[0][2]
    wy = m[1][3] - D[5] * m[1][2]
    t1 = math.radians(joints[0])
    forward_x = wx * math.cos(t1) + wy * math.sin(t1)
    shoulder = 0 if forward_x >= 0 else 1
    elbow_up = joints[2] >= 0
    elbow = 2 if elbow_up == (shoulder == 0) else 3
    wrist = 4 if math.sin(math.radians(joints[4])) >= 0 else 5
    return shoulder, elbow, wrist


def _best_turn(q, reference):
    """The 360-degree variant of each joint nearest to the reference that respects the limits."""
    out = []
    for a, ref, lim in zip(q, reference, LIMITS, strict=False):
        v = a + 360.0 * round((ref - a) / 360.0)
        if v > lim + 1e-6:
            v -= 360.0
        elif v < -lim - 1e-6:
            v += 360.0
        if abs(v) > lim + 1e-6:
            return None
        out.append(v)
    return out


def _matches(q, target):
    err = _error(forward(q), target)
    return math.sqrt(sum(e * e for e in err[:3])) < REACH_TOLERANCE_MM and max(abs(e) for e in err[3:]) < 1e-6


def within_limits(joints: Sequence[float]) -> bool:
    return all(abs(q) <= lim + 1e-6 for q, lim in zip(joints, LIMITS, strict=False))


def inverse_kinematics(target: Sequence[Sequence[float]], tool: Sequence[Sequence[float]] | None = None,
                       reference: Sequence[float] = (0.0, 0.0, 90.0, 0.0, 90.0, 0.0),
                       config: Sequence[int] | None = None) -> list[float]:
    """Joint angles reaching the pose matrix ``target``; raises KinematicsError.

    Without ``config`` the solution nearest to ``reference`` is kept (the arm keeps its
    configuration, as for Line motions); with ``config`` = (shoulder, elbow, wrist) only that
    configuration is accepted.
    """
    if tool is not None:
        target, tool = matmul(target, inverse(tool)), None
    px, py = target[0][3], target[1][3]
    wx = [target[i][3] - D[5] * target[i][2] for i in range(3)]
    if math.hypot(wx[0], wx[1], wx[2] - D[0]) > MAX_REACH_MM:
        raise KinematicsError("target pose is out of reach")
    heading = math.degrees(math.atan2(py, px)) if abs(px) + abs(py) > 1e-6 else reference[0]
    candidates = [q for q in (_best_turn(q, reference) for q in _analytic(target)) if q is not None]
    candidates.sort(key=lambda q: sum((a - b) ** 2 for a, b in zip(q, reference, strict=False)))
    for q in candidates:
        if (config is None or configuration(q) == tuple(config)) and _matches(q, target):
            return q
    seeds = [list(reference)]
    for base in (heading + 15.0, heading + 195.0):
        for elbow in (90.0, -90.0):
            for wrist in (90.0, -90.0):
                seeds.append([base, -20.0 if elbow > 0 else 20.0, elbow, 0.0, wrist, 0.0])
    found = []
    for index, seed in enumerate(seeds):
        q = _ik_from(seed, target)
        if q is None:
            continue
        q = _wrap(q, reference if index == 0 else [0.0] * 6)
        if not within_limits(q):
            q = _wrap(q, [0.0] * 6)
            if not within_limits(q):
                continue
        if config is None or configuration(q) == tuple(config):
            found.append(q)
            if index == 0 and config is None:
                break
    if not found:
        if config is not None:
            raise KinematicsError("target pose cannot be reached in the requested arm configuration "
                                  "or within the joint limits")
        raise KinematicsError("target pose is out of reach or beyond the joint limits")
    return min(found, key=lambda q: sum((a - b) ** 2 for a, b in zip(q, reference, strict=False)))
