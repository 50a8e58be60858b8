"""SVG timing diagram in the style of PLCopen Execute/Busy/Done/Error charts: one row per signal.

BOOL is a square wave whose high pulses stay at least ``MIN_PULSE`` pixels wide, however long the trace (a
pulse that had to be widened also gets a marker above it); REAL/LREAL are analog curves scaled to their range
in the window, with the range written at the left; other values are a bus with the value written where it
fits (bit strings BYTE .. LWORD in 16# notation, as the controller shows them), and changes too dense to draw
one by one become a hatched band. ``window`` (FROM, TO) in ns draws only
that part of the run."""
from __future__ import annotations

from xml.sax.saxutils import escape

from ..frontend import types as T

ROW, LABEL_W, WIDTH, HIGH = 34, 220, 900, 18
ANALOG_ROW = 56                # REAL rows are taller: the curve needs height to be read
RIGHT = 30                     # room for the last time label, centred on the end of the plot
MIN_PULSE = 2.0                # px: narrowest BOOL pulse drawn
MIN_BUS = 4.0                  # px: narrower bus segments are drawn as one hatched band
BLUE = "#1a5fb4"


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    return str(v)


def time_label(t_ns: float, step_ns: float) -> str:
    """Axis label of a PLC time: unit chosen by the grid step (µs, ms or s), as few decimals as the step needs."""
    unit, scale = ("s", 1e9) if step_ns >= 1e9 else ("ms", 1e6) if step_ns >= 1e6 else ("µs", 1e3)
    step = step_ns / scale
    whole = step >= 10 or (step >= 1 and abs(step - round(step)) < 1e-9)
    decimals = 0 if whole else 1 if step >= 1 else 2 if step >= 0.1 else 3
    value = t_ns / scale
    return f"{0.0 if abs(value) < 0.5 * 10 ** -decimals else value:.{decimals}f} {unit}"


def nice_step(span_ns: float, most: int = 8) -> float:
    """Grid step of 1, 2 or 5 times a power of ten giving at most ``most`` intervals over the span."""
    step = 1.0
    while span_ns / step > most:
        for factor in (2, 2.5, 2):            # 1 -> 2 -> 5 -> 10
            step *= factor
            if span_ns / step <= most:
                break
    return step


def clip(changes, t0: int, t1: int) -> list[tuple[int, object]]:
    """The changes inside [t0, t1], starting with the value in effect at t0 (none if it had no value yet)."""
    out, before = [], None
    for t, v in changes:
        if t <= t0:
            before = (t0, v)
        elif t <= t1:
            out.append((t, v))
    return ([before] if before is not None else []) + out


def _bool_row(ch, x, t1, hi, base) -> list[str]:
    segs = list(zip(ch, ch[1:] + [(t1, None)], strict=False))
    pts, marks = [], []
    cursor = None
    for (t, v), (t2, _) in segs:
        xa, xb = x(t), x(t2)
        if cursor is not None and xa < cursor:
            xa = cursor                         # a widened pulse before this one moved the edge
        if v and xb - xa < MIN_PULSE:
            if xb - xa < MIN_PULSE / 2:
                marks.append(xa)
            xb = xa + MIN_PULSE
        xb = max(xb, xa)
        cursor = xb
        y = hi if v else base
        pts += [f"{xa:.1f},{y}", f"{xb:.1f},{y}"]
    out = [f'<polyline points="{" ".join(pts)}" fill="none" stroke="{BLUE}" stroke-width="2"/>'] if pts else []
    out += [f'<path d="M{m - 3:.1f},{hi - 7} h6 l-3,4 z" fill="#c01c28"/>' for m in marks]
    return out


def _analog_row(ch, x, t1, top, bottom) -> list[str]:
    vals = [float(v) for _, v in ch]
    lo, hi = min(vals), max(vals)
    if hi - lo < 1e-12:
        lo, hi = lo - 1, hi + 1
    y = lambda v: bottom - (float(v) - lo) * (bottom - top) / (hi - lo)  # noqa: E731
    cols: dict[int, list[float]] = {}           # one pixel column keeps first, min, max, last
    order: list[int] = []
    for (t, v), (t2, _) in zip(ch, ch[1:] + [(t1, None)], strict=False):
        for px in {int(x(t)), int(x(t2))}:
            if px not in cols:
                cols[px] = []
                order.append(px)
            cols[px].append(y(v))
    pts = []
    for px in sorted(order):
        ys = cols[px]
        pts += [f"{px},{ys[0]:.1f}", f"{px},{min(ys):.1f}", f"{px},{max(ys):.1f}", f"{px},{ys[-1]:.1f}"]
    return [f'<text x="{LABEL_W - 6}" y="{top + 9}" font-size="9" text-anchor="end" fill="#555">{_fmt(hi)}</text>',
            f'<text x="{LABEL_W - 6}" y="{bottom}" font-size="9" text-anchor="end" fill="#555">{_fmt(lo)}</text>',
            f'<polyline points="{" ".join(pts)}" fill="none" stroke="{BLUE}" stroke-width="1.5"/>']


def _bus_row(ch, x, t1, hi, base, fmt=_fmt) -> list[str]:
    out = []
    mid = (hi + base) / 2
    segs = [(x(t), x(t2), v) for (t, v), (t2, _) in zip(ch, ch[1:] + [(t1, None)], strict=False)]
    i = 0
    while i < len(segs):
        x1, x2, v = segs[i]
        if x2 - x1 < MIN_BUS:                    # a run of dense changes: one hatched band
            j = i
            while j + 1 < len(segs) and segs[j + 1][1] - segs[j + 1][0] < MIN_BUS:
                j += 1
            end = max(segs[j][1], x1 + 1)
            out.append(f'<rect x="{x1:.1f}" y="{hi}" width="{end - x1:.1f}" height="{base - hi}" '
                       f'fill="url(#dense)" stroke="{BLUE}" stroke-width="0.5"/>')
            i = j + 1
            continue
        out.append(f'<polygon points="{x1 + 3:.1f},{hi} {x2:.1f},{hi} {x2:.1f},{base} {x1 + 3:.1f},{base} '
                   f'{x1:.1f},{mid}" fill="#eef" stroke="{BLUE}"/>')
        text = fmt(v)
        if x2 - x1 > 6 * len(text) + 8:
            out.append(f'<text x="{x1 + 6:.1f}" y="{base - 4}" font-size="10">{escape(text)}</text>')
        i += 1
    return out


def render_svg(rec, window: tuple[int, int] | None = None) -> str:
    first = min((ch[0][0] for ch in rec.changes if ch), default=0)
    t0, t1 = (first, rec.end_ns) if window is None else (window[0], min(window[1], rec.end_ns))
    if t1 <= t0:
        t1 = t0 + 1
    span = t1 - t0
    x = lambda t: LABEL_W + (t - t0) * (WIDTH - LABEL_W - RIGHT) / span   # noqa: E731
    heights = [ANALOG_ROW if kind == "real" else ROW for kind, _ in rec.kinds]
    h = sum(heights) + 40
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{h}" font-family="sans-serif" '
           f'font-size="12">',
           '<defs><pattern id="dense" width="4" height="4" patternUnits="userSpaceOnUse">'
           f'<path d="M0,4 L4,0" stroke="{BLUE}" stroke-width="0.8"/></pattern></defs>',
           f'<rect width="{WIDTH}" height="{h}" fill="white"/>']
    top = 10
    labels = getattr(rec, "labels", None) or rec.paths
    for i, (p, (kind, bits)) in enumerate(zip(labels, rec.kinds, strict=False)):
        rh = heights[i]
        base, hi = top + rh - 8, top + rh - 8 - (HIGH if kind != "real" else rh - 14)
        label_y = base - 4 if kind != "real" else (hi + base) / 2 + 4
        out.append(f'<text x="6" y="{label_y:.0f}">{escape(p)}</text>')
        out.append(f'<line x1="{LABEL_W}" y1="{base + 4}" x2="{WIDTH - RIGHT}" y2="{base + 4}" stroke="#ddd"/>')
        ch = clip(rec.changes[i], t0, t1)
        if ch:
            if kind == "bool":
                out += _bool_row(ch, x, t1, hi, base)
            elif kind == "real":
                out += _analog_row(ch, x, t1, hi, base)
            elif kind == "bits":                  # BYTE .. LWORD in the controller's notation: 16#4006
                out += _bus_row(ch, x, t1, hi, base, lambda v, n=bits: T.bits_literal(v, n))
            else:
                out += _bus_row(ch, x, t1, hi, base)
        top += rh
    axis = top + 14
    step = nice_step(span)
    k = -(-t0 // step)                          # first grid line at or after the start of the window
    while k * step <= t1:
        t = k * step
        out.insert(3, f'<line x1="{x(t):.1f}" y1="10" x2="{x(t):.1f}" y2="{top}" stroke="#eee"/>')
        out.append(f'<text x="{x(t):.1f}" y="{axis}" font-size="10" text-anchor="middle">'
                   f'{escape(time_label(t, step))}</text>')
        k += 1
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_svg(rec, filename: str, window: tuple[int, int] | None = None) -> None:
    with open(filename, "w", encoding="utf-8") as f:
        f.write(render_svg(rec, window))
