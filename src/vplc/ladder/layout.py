"""Place the elements of each rung on a grid, the way Sysmac Studio lays out a rung: power flows left to
right, coils line up at the right rail, a block's pins are one row apart, and variables wired to a block
pin are written next to the pin instead of taking a cell. The drawing (:mod:`vplc.ladder.svg`), the HMI's
Program page and the PLCopen writer (positions) all use this one layout.
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

from .model import Element, LadderBody, Rung

CELL_W = {"contact": 96, "coil": 86, "block": 200, "in_var": 130, "out_var": 130, "inout_var": 130,
          "jump": 110, "return": 100}
ROW_H = 44
PIN_LABEL_W = 136          # room for a variable name left of a block input / right of a block output
LEFT_RAIL = 18             # x of the left power rail; the right one stands at RungLayout.width + RAIL_GAP or further
RAIL_GAP = 10
CHAR_W = 8.0               # width of one character of a 12 px name in DejaVu Sans, with a margin: mixed-case
SMALL = 11 / 12            # identifiers measure 7.6 px in Chromium; pin names and values are drawn at 11 px,
BOLD = 1.1                 # the block type in bold
PAD = 6                    # clearance between a name and a rail, a box or another name


@dataclass
class Placed:
    element: Element
    col: int
    row: int
    rows: int = 1
    x: float = 0.0
    y: float = 0.0          # top of the element's first row, relative to the rung
    w: float = 0.0
    label_x: float = 0.0    # centre of the name drawn above a contact or coil


@dataclass
class RungLayout:
    rung: Rung
    number: int
    placed: dict[str, Placed] = field(default_factory=dict)
    pin_labels: dict[tuple[str, str], str] = field(default_factory=dict)     # (block id, pin) -> variable text
    attached: set[str] = field(default_factory=set)                          # variables drawn as pin labels
    height: float = ROW_H
    width: float = 0.0


def text_width(text: str, scale: float = 1.0) -> float:
    """Estimated width of ``text`` as the drawing writes it (12 px; ``scale`` SMALL or BOLD for the others)."""
    return len(text) * CHAR_W * scale


def cell_width(e: Element) -> float:
    """Width of an element's own cell: the symbol, or a box wide enough for its texts."""
    w = CELL_W.get(e.kind, 100)
    if e.kind == "block":
        ins, outs = pin_rows(e)
        pins = max((text_width(a, SMALL) for a in ins), default=0) + max((text_width(b, SMALL) for b in outs),
                                                                          default=0)
        return max(w, text_width(e.type_name.split("\\")[-1], BOLD) + 16, text_width(e.instance) + 16, pins + 24)
    if e.kind in ("in_var", "out_var", "inout_var", "jump"):
        return max(w, text_width(e.var if e.kind != "jump" else ">> " + e.var) + 24)
    return w


def pin_rows(e: Element) -> tuple[list[str], list[str]]:
    """Input and output pin names of a block, top to bottom (in-outs on both sides, first)."""
    ins = [p.name for p in e.inouts] + [p.name for p in e.inputs]
    outs = [p.name for p in e.inouts] + [p.name for p in e.outputs]
    return ins, outs


def layout_rung(rung: Rung, number: int) -> RungLayout:
    lay = RungLayout(rung, number)
    by_id = {e.id: e for e in rung.elements}
    blocks = {e.id: e for e in rung.elements if e.kind == "block"}
    readers: dict[str, int] = {}
    for e in rung.elements:
        for pin in [*e.inputs, *e.inouts]:
            for c in pin.conns:
                readers[c.ref] = readers.get(c.ref, 0) + 1
    for b in blocks.values():                          # variables written next to the pins
        for pin in [*b.inputs, *b.inouts]:
            if len(pin.conns) == 1:
                src = by_id.get(pin.conns[0].ref)
                if src is not None and src.kind == "in_var" and readers.get(src.id, 0) == 1:
                    lay.pin_labels[(b.id, pin.name)] = src.var
                    lay.attached.add(src.id)
    for e in rung.elements:
        if e.kind == "out_var" and len(e.inputs[0].conns) == 1:
            c = e.inputs[0].conns[0]
            if c.ref in blocks and c.pin:
                lay.pin_labels[(c.ref, "out:" + c.pin)] = e.var
                lay.attached.add(e.id)
    body = [e for e in rung.elements if e.kind not in ("left_rail", "right_rail") and e.id not in lay.attached]
    col: dict[str, int] = {}
    ids = {e.id for e in body}

    def column(e: Element, depth: int = 0) -> int:
        if e.id in col:
            return col[e.id]
        col[e.id] = 0                                  # guards against loops (reported by the translation)
        srcs = [c.ref for pin in [*e.inputs, *e.inouts] for c in pin.conns if c.ref in ids]
        col[e.id] = 1 + max((column(by_id[s], depth + 1) for s in srcs), default=-1)
        return col[e.id]

    for e in body:
        column(e)
    last = max((col[e.id] for e in body if e.kind != "coil"), default=-1) + 1
    for e in body:
        if e.kind in ("coil", "jump", "return") and not readers.get(e.id):
            col[e.id] = max(last, col[e.id])
    desired: dict[str, int] = {}                       # a chain feeding block pin k starts on the pin's row
    for e in sorted(body, key=lambda e: -col[e.id]):
        if e.kind == "block":
            names = pin_rows(e)[0]
            for pin in [*e.inouts, *e.inputs]:
                for c in pin.conns:
                    if c.ref in ids and pin.name in names:
                        desired[c.ref] = max(desired.get(c.ref, 0), desired.get(e.id, 0) + names.index(pin.name))
        elif e.id in desired:
            for pin in e.inputs:
                for c in pin.conns:
                    if c.ref in ids:
                        desired[c.ref] = max(desired.get(c.ref, 0), desired[e.id])
    taken: set[tuple[int, int]] = set()
    for e in sorted(body, key=lambda e: col[e.id]):
        rows = max(len(pin_rows(e)[0]), len(pin_rows(e)[1]), 1) if e.kind == "block" else 1
        want = 0
        names = pin_rows(e)[0] if e.kind == "block" else []
        first = next(((pin, c) for pin in [*e.inouts, *e.inputs] for c in pin.conns if c.ref in lay.placed), None)
        if first is not None:                          # line up with the wire that feeds the first connected pin
            pin, c = first
            feeder = lay.placed[c.ref]
            outs = pin_rows(feeder.element)[1] if feeder.element.kind == "block" else []
            offset = outs.index(c.pin) if c.pin in outs else 0
            want = max(0, feeder.row + offset - (names.index(pin.name) if pin.name in names else 0))
        row = max(want, desired.get(e.id, 0))
        while any((col[e.id], r) in taken for r in range(row, row + rows)):
            row += 1
        # a block keeps the row under it free in its column: its box reaches below its last pin, and the next
        # element's name (or the next block's instance name) would touch it there (two MOVEs stacked)
        for r in range(row, row + rows + (1 if e.kind == "block" else 0)):
            taken.add((col[e.id], r))
        lay.placed[e.id] = Placed(e, col[e.id], row, rows)
    ncols = max((p.col for p in lay.placed.values()), default=-1) + 1
    widths = [0.0] * ncols
    for p in lay.placed.values():
        p.w = cell_width(p.element)
        widths[p.col] = max(widths[p.col], p.w + (PIN_LABEL_W * 2 if p.element.kind == "block" else 0))
    xs = [44.0]
    for w in widths:
        xs.append(xs[-1] + w)
    for p in lay.placed.values():
        p.x = xs[p.col] + (PIN_LABEL_W if p.element.kind == "block" else 0)
        p.y = p.row * ROW_H
    lay.width = xs[-1] + 10
    lay.height = (max((p.row + p.rows for p in lay.placed.values()), default=1)) * ROW_H
    _fit_names(lay)
    return lay


def _fit_names(lay: RungLayout) -> None:
    """Give every name room between the rails, column by column. The name above a contact or coil is centred on
    it; near the right rail it moves left (a coil's long name over the wire from the block before it), and where
    the row leaves too little room the symbol itself moves right, under its name. The variables written next to
    block pins keep to their row. Whatever moves right takes the columns after it and the right rail along.

    Linear in the rung's size (a rung of 10,000 contacts took 16 s when every element looked at every other): a
    move always takes the current column or the next along with every column after it, so the columns already
    passed never move again (their right edges are kept per row), and the columns not reached yet all move by the
    same amount (``ahead``, added when the column is reached); the first element after a column in a row is the
    nearest one to its right, since x grows with the column."""
    placed = sorted(lay.placed.values(), key=lambda p: (p.col, p.row))
    ahead = 0.0                                   # moved since the start: columns not reached yet
    current: list[Placed] = []                    # the elements of the column being fitted
    boxes_right: dict[int, float] = {}            # per row: right edge + PAD of the blocks in passed columns
    names_right: dict[int, float] = {}            # per row: end + PAD of the contact and coil names passed
    later_cols: dict[int, list[int]] = {}         # per row: columns of the blocks covering it, ascending
    later_x: dict[int, list[float]] = {}          # ... and their x before any move
    any_cols: dict[int, list[int]] = {}           # per row: columns of every element covering it, ascending
    any_x: dict[int, list[float]] = {}
    by_col: dict[int, list[Placed]] = {}
    for q in placed:
        by_col.setdefault(q.col, []).append(q)
        for r in range(q.row, q.row + q.rows):
            any_cols.setdefault(r, []).append(q.col)
            any_x.setdefault(r, []).append(q.x)
            if q.element.kind == "block":
                later_cols.setdefault(r, []).append(q.col)
                later_x.setdefault(r, []).append(q.x)

    def shift(col: int, dx: float) -> None:       # col is the current column or the next one
        nonlocal ahead
        if col == current[0].col:
            for q in current:
                q.x += dx
                q.label_x += dx
        ahead += dx
        lay.width += dx

    def first_after(cols: dict, xs: dict, row: int, col: int) -> float | None:
        """x now of the first element covering ``row`` in a column after ``col``."""
        cs = cols.get(row)
        if not cs:
            return None
        i = bisect.bisect_right(cs, col)
        return xs[row][i] + ahead if i < len(cs) else None

    def leave_column() -> None:
        for q in current:
            if q.element.kind == "block":
                for r in range(q.row, q.row + q.rows):
                    boxes_right[r] = max(boxes_right.get(r, -math.inf), q.x + q.w + PAD)
            elif q.element.kind in ("contact", "coil"):
                names_right[q.row] = max(names_right.get(q.row, -math.inf),
                                         q.label_x + text_width(q.element.var) / 2 + PAD)
        current.clear()

    for p in placed:
        if not current or current[0].col != p.col:
            leave_column()
            same = by_col[p.col]
            for q in same:
                q.x += ahead
                q.label_x += ahead
            current.extend(same)
        e = p.element
        if e.kind in ("contact", "coil"):
            tw = text_width(e.var)
            lo = max(LEFT_RAIL + PAD, boxes_right.get(p.row, -math.inf), names_right.get(p.row, -math.inf))
            if p.x + p.w / 2 < lo + tw / 2:          # the symbol moves right, to stay under its name
                shift(p.col, lo + tw / 2 - p.x - p.w / 2)
            nxt = first_after(later_cols, later_x, p.row, p.col)
            hi = min(lay.width + RAIL_GAP - PAD, nxt - PAD if nxt is not None else math.inf)
            if hi - lo < tw:
                shift(p.col + 1, tw - (hi - lo))
                hi = lo + tw
            p.label_x = max(min(p.x + p.w / 2, hi - tw / 2), lo + tw / 2)
        elif e.kind == "block":
            ins, outs = pin_rows(e)
            for i, name in enumerate(ins):
                label = lay.pin_labels.get((e.id, name))
                if label is not None:
                    lo = max(LEFT_RAIL + PAD, boxes_right.get(p.row + i, -math.inf))
                    room = p.x - 18 - lo
                    if room < text_width(label):
                        shift(p.col, text_width(label) - room)
            for i, name in enumerate(outs):
                label = lay.pin_labels.get((e.id, "out:" + name))
                if label is not None:
                    nxt = first_after(any_cols, any_x, p.row + i, p.col)
                    hi = min(lay.width + RAIL_GAP - PAD, nxt - PAD if nxt is not None else math.inf)
                    need = p.x + p.w + 18 + text_width(label) - hi
                    if need > 0:
                        shift(p.col + 1, need)


def layout(body: LadderBody) -> list[RungLayout]:
    """Every rung of the body; the coils that end a rung stand in one column at the right rail in every rung, as
    Sysmac Studio draws them (each rung on its own would put them right after its widest column)."""
    lays = [layout_rung(r, n) for n, r in enumerate(body.rungs, start=1)]
    right = max((lay.width for lay in lays), default=0.0)
    for lay in lays:
        read = {c.ref for e in lay.rung.elements if e.kind != "right_rail" for pin in [*e.inputs, *e.inouts]
                for c in pin.conns}
        for p in lay.placed.values():
            if p.element.kind == "coil" and p.element.id not in read:
                dx = right - 10 - (p.x + p.w)
                p.x += dx                             # its name follows while it stays inside the rails
                p.label_x = max(p.label_x, min(p.label_x + dx, right + RAIL_GAP - PAD - text_width(p.element.var) / 2))
        lay.width = right
    return lays
