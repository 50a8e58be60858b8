"""Draw a ladder POU as SVG: rails, contacts, coils, blocks with pin names, variable names above the
elements, the rung comment and number. ``vplc draw`` writes it to a file; the HMI's Program page shows
the same drawing and colours it live: every drawn element and wire carries ``data-id`` (the element, or
``element:pin`` for a wire leaving a block pin) and every value text ``data-var`` (docs/toolchain/ladder.md).
"""
from __future__ import annotations

from xml.sax.saxutils import escape, quoteattr

from .layout import CHAR_W, LEFT_RAIL, ROW_H, RungLayout, layout, pin_rows, text_width
from .model import LadderBody

COMMENT_H = 26
GAP = 14
MID = 40                       # y of the power line in an element's first row (room for the names above)
STYLE = """
.ld text{font-family:'DejaVu Sans',Arial,sans-serif;font-size:12px;fill:#1d2733}
.ld .rail{stroke:#1d2733;stroke-width:4}
.ld .wire,.ld .sym{stroke:#1d2733;stroke-width:2;fill:none}
.ld .box{stroke:#1d2733;stroke-width:2;fill:#fff}
.ld .on.wire,.ld .on .sym,.ld .on.sym{stroke:#0a9d3f;stroke-width:3}
.ld .on .box{stroke:#0a9d3f;fill:#e9f8ee}
.ld .cmt{fill:#4b6b2a;font-style:italic}
.ld .num{fill:#6b7785;font-size:11px}
.ld .type{font-weight:bold}
.ld .pin{font-size:11px;fill:#44505c}
.ld .val{font-size:11px;fill:#0b5cad;font-weight:bold}
.ld .band{fill:#f4f6f8}
"""


def _t(x, y, text, cls="", anchor="start", var: str | None = None) -> str:
    extra = f' data-var={quoteattr(var)}' if var is not None else ""
    c = f' class="{cls}"' if cls else ""
    return f'<text x="{x:.0f}" y="{y:.0f}"{c} text-anchor="{anchor}"{extra}>{escape(text)}</text>'


def _line(x1, y1, x2, y2, cls="wire", did: str | None = None) -> str:
    d = f' data-id={quoteattr(did)}' if did else ""
    return f'<path class="{cls}"{d} d="M{x1:.0f} {y1:.0f}H{x2:.0f}V{y2:.0f}"/>' if y1 == y2 else \
        f'<path class="{cls}"{d} d="M{x1:.0f} {y1:.0f}H{(x1 + x2) / 2:.0f}V{y2:.0f}H{x2:.0f}"/>'


def render_rungs(body: LadderBody, width: float | None = None) -> tuple[str, float, float]:
    """The SVG content of every rung, stacked; returns (markup, width, height)."""
    lays = layout(body)
    w = max([width or 0.0] + [lay.width + 24 for lay in lays])
    parts = []
    y = 8.0
    for lay in lays:
        parts.append(_rung(lay, y, w))
        y += COMMENT_H + lay.height + GAP + 12
    return "".join(parts), w, y


def _rung(lay: RungLayout, top: float, width: float) -> str:
    out = [f'<g class="rung" data-rung="{lay.number}" transform="translate(0 {top:.0f})">']
    h = COMMENT_H + lay.height + 12
    if lay.number % 2 == 0:
        out.append(f'<rect class="band" x="0" y="-4" width="{width:.0f}" height="{h:.0f}"/>')
    out.append(_t(4, 15, str(lay.number), "num"))
    x: float = 40
    if lay.rung.label:                                 # a jump target, written first as Sysmac shows labels
        out.append(_t(x, 15, lay.rung.label + ":", "type"))
        x += 12 + text_width(lay.rung.label, 1.1)
    if lay.rung.comment:
        room = int((width - x - 20) / CHAR_W)         # characters that fit before the right edge
        text = lay.rung.comment.splitlines()[0]
        out.append(_t(x, 15, text if len(text) <= room else text[:room - 1].rstrip() + "…", "cmt"))
    oy = COMMENT_H
    left, right = LEFT_RAIL, width - 14
    out.append(f'<path class="rail" d="M{left} {oy} V{oy + lay.height + 8:.0f}"/>')
    out.append(f'<path class="rail" d="M{right:.0f} {oy} V{oy + lay.height + 8:.0f}"/>')
    by_id = {e.id: e for e in lay.rung.elements}

    def out_point(ref: str, pin: str | None) -> tuple[float, float] | None:
        src = by_id.get(ref)
        if src is None:
            return None
        if src.kind == "left_rail":
            return None
        p = lay.placed.get(ref)
        if p is None:
            return None
        if src.kind == "block":
            names = pin_rows(src)[1]
            i = names.index(pin) if pin in names else 0
            return p.x + p.w, oy + p.y + MID + i * ROW_H
        return p.x + p.w, oy + p.y + MID

    for p in lay.placed.values():
        e = p.element
        x, y = p.x, oy + p.y
        ins = [(pin, 0) for pin in [*e.inputs]] if e.kind != "block" else []
        if e.kind == "block":
            names = pin_rows(e)[0]
            ins = [(pin, names.index(pin.name)) for pin in [*e.inouts, *e.inputs] if pin.name in names]
        for pin, i in ins:                               # wires into this element
            ty = y + MID + i * ROW_H
            for c in pin.conns:
                if c.ref in lay.attached:
                    continue
                src = by_id.get(c.ref)
                start = (left, ty) if src is not None and src.kind == "left_rail" else out_point(c.ref, c.pin)
                if start is None:
                    continue
                did = c.ref if src is None or src.kind != "block" else f"{c.ref}:{c.pin}"
                out.append(_line(start[0], start[1], x, ty, "wire", did))
        out.append(_element(p, y, lay))
    read = {c.ref for e in lay.rung.elements if e.kind != "right_rail" for pin in [*e.inputs, *e.inouts]
            for c in pin.conns}
    for p in lay.placed.values():                      # a coil's right side always reaches the right rail
        if p.element.kind == "coil" and p.element.id not in read:
            pt = out_point(p.element.id, None)
            if pt is not None:                         # a placed coil always has its point
                out.append(_line(pt[0], pt[1], right, pt[1], "wire", p.element.id))
    out.append("</g>")
    return "".join(out)


def _element(p, y: float, lay: RungLayout) -> str:
    e = p.element
    x, w = p.x, p.w
    cy = y + MID
    g = [f'<g class="el {e.kind}" data-id={quoteattr(e.id)}>']
    if e.kind in ("contact", "coil"):
        cx = x + w / 2
        g.append(_line(x, cy, cx - 10, cy, "sym"))
        g.append(_line(cx + 10, cy, x + w, cy, "sym"))
        if e.kind == "contact":
            g.append(f'<path class="sym" d="M{cx - 10:.0f} {cy - 12:.0f}V{cy + 12:.0f}'
                     f'M{cx + 10:.0f} {cy - 12:.0f}V{cy + 12:.0f}"/>')
            if e.negated:
                g.append(f'<path class="sym" d="M{cx - 12:.0f} {cy + 12:.0f}L{cx + 12:.0f} {cy - 12:.0f}"/>')
        else:
            g.append(f'<path class="sym" d="M{cx - 6:.0f} {cy - 12:.0f}'
                     f'Q{cx - 14:.0f} {cy:.0f} {cx - 6:.0f} {cy + 12:.0f}'
                     f'M{cx + 6:.0f} {cy - 12:.0f}Q{cx + 14:.0f} {cy:.0f} {cx + 6:.0f} {cy + 12:.0f}"/>')
            if e.negated:
                g.append(f'<path class="sym" d="M{cx - 6:.0f} {cy + 10:.0f}L{cx + 6:.0f} {cy - 10:.0f}"/>')
        mark = {"rising": "P", "falling": "N"}.get(e.edge, "") or {"set": "S", "reset": "R"}.get(e.storage, "")
        if mark:
            g.append(_t(cx, cy + 4, mark, "pin", "middle"))
        g.append(_t(p.label_x, cy - 18, e.var, "", "middle"))      # placed by layout._fit_names
        if e.kind == "contact":                        # a coil's value is its colour
            g.append(_t(cx, cy + 26, "", "val", "middle", var=e.var))
    elif e.kind == "block":
        ins, outs = pin_rows(e)
        h = p.rows * ROW_H - 12
        g.append(f'<rect class="box" x="{x:.0f}" y="{y + MID - 30:.0f}" width="{w:.0f}" height="{h + 16:.0f}" rx="3"/>')
        g.append(_t(x + w / 2, y + MID - 34, e.instance or "", "", "middle"))
        g.append(_t(x + w / 2, y + MID - 16, e.type_name.split("\\")[-1], "type", "middle"))
        for i, name in enumerate(ins):
            py = y + MID + i * ROW_H
            g.append(_t(x + 6, py + 4, name, "pin"))
            label = lay.pin_labels.get((e.id, name))
            if label is not None:
                g.append(_line(x - 14, py, x, py, "sym"))
                g.append(_t(x - 18, py + 4, label, "", "end"))
                g.append(_t(x - 18, py + 18, "", "val", "end", var=label))
        for i, name in enumerate(outs):
            py = y + MID + i * ROW_H
            g.append(_t(x + w - 6, py + 4, name, "pin", "end"))
            label = lay.pin_labels.get((e.id, "out:" + name))
            if label is not None:
                g.append(_line(x + w, py, x + w + 14, py, "sym"))
                g.append(_t(x + w + 18, py + 4, label, "", "start"))
                g.append(_t(x + w + 18, py + 18, "", "val", "start", var=label))
    else:
        text = {"jump": f">> {e.var}", "return": "RETURN", "inline_st": "ST"}.get(e.kind, e.var)
        g.append(f'<rect class="box" x="{x + 4:.0f}" y="{cy - 12:.0f}" width="{w - 8:.0f}" height="24" rx="10"/>')
        g.append(_t(x + w / 2, cy + 4, text, "", "middle"))
        if e.kind in ("in_var", "out_var", "inout_var"):
            g.append(_t(x + w / 2, cy + 26, "", "val", "middle", var=e.var))
    g.append("</g>")
    return "".join(g)


def svg_document(body: LadderBody) -> str:
    content, w, h = render_rungs(body)
    return (f'<svg xmlns="http://www.w3.org/2000/svg" class="ld" width="{w:.0f}" height="{h:.0f}" '
            f'viewBox="0 0 {w:.0f} {h:.0f}"><style>{STYLE}</style>'
            f'<rect x="0" y="0" width="{w:.0f}" height="{h:.0f}" fill="#fff"/>{content}</svg>\n')
