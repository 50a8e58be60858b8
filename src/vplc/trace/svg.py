"""SVG timing diagram in the style of PLCopen Execute/Busy/Done/Error charts: one row per signal, BOOL as a
square wave, other values as a bus with the value written at each change."""
from __future__ import annotations

from xml.sax.saxutils import escape

ROW, LABEL_W, WIDTH, HIGH = 34, 220, 900, 18
RIGHT = 30                     # room for the last time label, centred on the end of the plot


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def time_label(t_ns: float, step_ns: float) -> str:
    """Axis label of a PLC time: unit chosen by the grid step (µs, ms or s), as few decimals as the step needs."""
    unit, scale = ("s", 1e9) if step_ns >= 1e9 else ("ms", 1e6) if step_ns >= 1e6 else ("µs", 1e3)
    step = step_ns / scale
    whole = step >= 10 or (step >= 1 and abs(step - round(step)) < 1e-9)
    decimals = 0 if whole else 1 if step >= 1 else 2 if step >= 0.1 else 3
    return f"{t_ns / scale:.{decimals}f} {unit}"


def write_svg(rec, filename: str) -> None:
    t0 = min((ch[0][0] for ch in rec.changes if ch), default=0)
    span = max(rec.end_ns - t0, 1)
    x = lambda t: LABEL_W + (t - t0) * (WIDTH - LABEL_W - RIGHT) / span   # noqa: E731
    h = ROW * len(rec.paths) + 40
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{h}" font-family="sans-serif" '
           f'font-size="12">', f'<rect width="{WIDTH}" height="{h}" fill="white"/>']
    for i, (p, (kind, _bits)) in enumerate(zip(rec.paths, rec.kinds)):
        top = 10 + i * ROW
        base, hi = top + ROW - 8, top + ROW - 8 - HIGH
        out.append(f'<text x="6" y="{base - 4}">{escape(p)}</text>')
        out.append(f'<line x1="{LABEL_W}" y1="{base + 4}" x2="{WIDTH - RIGHT}" y2="{base + 4}" stroke="#ddd"/>')
        ch = rec.changes[i] + [(rec.end_ns, None)]
        if kind == "bool":
            pts = []
            for (t, v), (t2, _) in zip(ch, ch[1:]):
                y = hi if v else base
                pts += [f"{x(t):.1f},{y}", f"{x(t2):.1f},{y}"]
            out.append(f'<polyline points="{" ".join(pts)}" fill="none" stroke="#1a5fb4" stroke-width="2"/>')
        else:
            for (t, v), (t2, _) in zip(ch, ch[1:]):
                x1, x2 = x(t), x(t2)
                out.append(f'<polygon points="{x1 + 3:.1f},{hi} {x2:.1f},{hi} {x2:.1f},{base} {x1 + 3:.1f},{base} '
                           f'{x1:.1f},{(hi + base) / 2}" fill="#eef" stroke="#1a5fb4"/>')
                if x2 - x1 > 25:
                    out.append(f'<text x="{x1 + 6:.1f}" y="{base - 4}" font-size="10">{escape(_fmt(v))}</text>')
    axis = 10 + ROW * len(rec.paths) + 14
    for k in range(6):
        t = t0 + span * k / 5
        out.append(f'<text x="{x(t):.1f}" y="{axis}" font-size="10" text-anchor="middle">'
                   f'{escape(time_label(t, span / 5))}</text>')
    out.append("</svg>")
    with open(filename, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")
