"""Motion profiles of the virtual servo axes, in closed form.

A :class:`Profile` is a list of segments of constant jerk starting from (t0, x0, v0, a0); the position at any time
is the cubic of its segment, never an integration over scans. Planners build the segments:

* jerk 0 — trapezoids: acceleration jumps to ``acc`` / ``dec`` and back (the W508 profile without Jerk);
* jerk J > 0 — S-curves: the acceleration changes at the rate J, never exceeds ``acc`` / ``dec``, and every
  velocity change starts and ends at acceleration 0 (a motion taken over while the acceleration is not 0 first
  brings it to 0 with J: our choice, W508's blending of jerk-limited motions was not readable).
"""
from __future__ import annotations

import math
from collections.abc import Iterable

Segment = tuple[float, float, float]        # (duration, acceleration at its start, jerk)
Part = tuple[float, float, float, float, float, float]  # (end time, start time, x, v, a, jerk) of one segment


class Profile:
    """Motion from (t0, x0, v0, a0) as segments (duration, acceleration at its start, jerk); after the last
    segment the axis keeps the final velocity (0 for a positioning, the target velocity for velocity control)."""

    __slots__ = ("parts", "i", "t_end", "x_end", "v_end", "hold", "jerk")

    def __init__(self, t0: float, x0: float, v0: float, segments: Iterable[Segment],
                 target: float | None = None) -> None:
        parts: list[Part] = []
        t, x, v = t0, x0, v0
        for d, a, j in segments:
            if d > 0.0:
                parts.append((t + d, t, x, v, a, j))
                x += (v + (a / 2 + j * d / 6) * d) * d
                v += (a + j * d / 2) * d
                t += d
        self.parts, self.i, self.t_end = parts, 0, t
        self.x_end, self.v_end = (target, 0.0) if target is not None else (x, v)
        self.hold = False           # True: a positioning held at velocity 0 by a 0 % override
        self.jerk = 0.0             # jerk of the segment the last at() fell in (0 after the last segment)

    def at(self, t: float) -> tuple[float, float, float, bool]:
        """(position, velocity, acceleration, finished) at time t (seconds)."""
        parts, i = self.parts, self.i
        while i < len(parts) and t >= parts[i][0]:
            i += 1
        self.i = i
        if i == len(parts):
            self.jerk = 0.0
            return self.x_end + self.v_end * (t - self.t_end), self.v_end, 0.0, True
        _, ts, x, v, a, j = parts[i]
        self.jerk = j
        tau = t - ts
        if j:
            return x + (v + (a / 2 + j * tau / 6) * tau) * tau, v + (a + j * tau / 2) * tau, a + j * tau, False
        return x + (v + a * tau / 2) * tau, v + a * tau, a, False


def advance(x: float, v: float, segs: Iterable[Segment]) -> tuple[float, float]:
    """Position and velocity at the end of ``segs`` started at (x, v)."""
    for d, a, j in segs:
        x += (v + (a / 2 + j * d / 6) * d) * d
        v += (a + j * d / 2) * d
    return x, v


def ramp(u0: float, u1: float, limit: float, jerk: float) -> list[Segment]:
    """Segments changing the velocity from u0 to u1 (acceleration 0 at both ends with a jerk): with jerk 0 a
    constant acceleration of magnitude ``limit``; with jerk J an S-curve whose acceleration reaches at most
    ``limit`` (a triangle of acceleration when the change is too small to reach it)."""
    dv = u1 - u0
    if dv == 0.0:
        return []
    s = 1.0 if dv > 0 else -1.0
    dv = abs(dv)
    if not jerk:
        return [(dv / limit, s * limit, 0.0)]
    if dv * jerk >= limit * limit:
        t1 = limit / jerk
        return [(t1, 0.0, s * jerk), (dv / limit - t1, s * limit, 0.0), (t1, s * limit, -s * jerk)]
    peak = math.sqrt(dv * jerk)
    t1 = peak / jerk
    return [(t1, 0.0, s * jerk), (t1, s * peak, -s * jerk)]


def ramp_distance(u0: float, u1: float, limit: float, jerk: float) -> float:
    """Distance covered by ``ramp(u0, u1, ...)`` (its mean velocity is (u0 + u1) / 2: the ramp is symmetric)."""
    return (u0 + u1) / 2 * sum(d for d, _, _ in ramp(u0, u1, limit, jerk))


def settle(a0: float, jerk: float, v0: float = 0.0, vlimit: float = math.inf) -> list[Segment]:
    """With a jerk, the segment that brings a running acceleration a0 to 0 before a new plan starts. While it
    settles the speed still grows by a0^2 / 2J: a steeper jerk keeps it within ``vlimit`` (the axis maximum; an
    acceleration that cannot settle in time drops to 0 at once)."""
    if not (jerk and a0):
        return []
    if a0 * v0 > 0:
        room = vlimit - abs(v0)
        if room <= 0:
            return []
        jerk = max(jerk, a0 * a0 / (2 * room))
    return [(abs(a0) / jerk, a0, -math.copysign(jerk, a0))]


def plan_velocity(v0: float, vt: float, acc: float, dec: float, jerk: float = 0.0, a0: float = 0.0,
                  vlimit: float = math.inf) -> list[Segment]:
    """Segments from velocity v0 (acceleration a0) to vt: speeding up with acc, slowing down with dec (through 0
    when the direction changes: first dec to 0, then acc)."""
    segs = settle(a0, jerk, v0, vlimit)
    if segs:
        _, v0 = advance(0.0, v0, segs)
    if v0 * vt < 0:
        return segs + ramp(v0, 0.0, dec, jerk) + ramp(0.0, vt, acc, jerk)
    return segs + ramp(v0, vt, acc if abs(vt) >= abs(v0) else dec, jerk)


def plan_position(x0: float, v0: float, xt: float, vmax: float, acc: float, dec: float, jerk: float = 0.0,
                  a0: float = 0.0, vlimit: float = math.inf) -> list[Segment]:
    """Segments that take the axis from (x0, v0, a0) to rest at xt: speed up with acc to at most vmax, cruise,
    slow down with dec (a lower peak velocity when the distance is short). Moving away from the target, or too
    fast to stop before it, the axis first stops and then comes back."""
    segs = settle(a0, jerk, v0, vlimit)
    if segs:
        x0, v0 = advance(x0, v0, segs)
    dist = xt - x0
    s = 1.0 if dist > 0 or (dist == 0 and v0 < 0) else -1.0
    d, u = abs(dist), v0 * s               # distance and velocity in the direction of the target
    if u < 0 or ramp_distance(u, 0.0, dec, jerk) > d * (1 + 1e-12) + 1e-12:
        stop = ramp(v0, 0.0, dec, jerk)    # moving away, or cannot stop in time: stop, then come back
        x1, _ = advance(x0, v0, stop)
        return segs + stop + plan_position(x1, 0.0, xt, vmax, acc, dec, jerk)
    if d <= 0.0 and u <= 0.0:
        return segs

    def needed(vp: float) -> float:        # distance of the ramps up (or down) to vp and down to 0
        return ramp_distance(u, vp, acc if vp >= u else dec, jerk) + ramp_distance(vp, 0.0, dec, jerk)

    vp = vmax
    if not jerk and u <= vmax:             # trapezoid: the peak velocity in closed form
        vp = min(vmax, math.sqrt((d + u * u / (2 * acc)) / (1 / (2 * acc) + 1 / (2 * dec))))
    elif needed(vmax) > d:
        if u > vmax:                       # slower than now and no room to cruise: stop, then the rest
            stop = ramp(u, 0.0, dec, jerk)
            x1, _ = advance(x0, v0, [(t, s * a, s * j) for t, a, j in stop])
            return segs + [(t, s * a, s * j) for t, a, j in stop] + plan_position(x1, 0.0, xt, vmax, acc, dec,
                                                                                     jerk)
        lo, hi = u, vmax                   # needed() grows with vp: bisect the peak velocity
        for _ in range(100):
            vp = (lo + hi) / 2
            if needed(vp) > d:
                hi = vp
            else:
                lo = vp
            if hi - lo <= 1e-15 * vmax:
                break
        vp = lo
    cruise = d - needed(vp)
    body = ramp(u, vp, acc if vp >= u else dec, jerk)
    if cruise > 0 and vp > 0:
        body.append((cruise / vp, 0.0, 0.0))
    body += ramp(vp, 0.0, dec, jerk)
    return segs + [(t, s * a, s * j) for t, a, j in body]
