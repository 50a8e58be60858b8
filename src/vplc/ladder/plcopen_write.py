"""Write a ladder body as a PLCopen XML TC6 v2.01 ``<LD>`` element (element order as the official schema
``tc6_xml_v201.xsd`` requires). Positions come from :mod:`vplc.ladder.layout`, rungs stacked top to bottom;
every rung gets its own power rails and a comment element above it; a rung's label is a ``label`` element
above the rung. Local ids are numbered from 1 in document order.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from .iec10_write import resolve_pins
from .layout import ROW_H, layout_rung
from .model import Element, LadderBody, WriteError

XHTML_NS = "http://www.w3.org/1999/xhtml"
RUNG_GAP = 60


def _sub(parent: ET.Element, tag: str, attrs: dict | None = None, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag, attrs or {})
    if text is not None:
        el.text = text
    return el


def _pos(parent: ET.Element, x: float, y: float, tag: str = "position") -> None:
    _sub(parent, tag, {"x": f"{x:.0f}", "y": f"{y:.0f}"})


def formatted(parent: ET.Element, tag: str, text: str) -> None:
    """A formattedText element: one XHTML paragraph."""
    _sub(_sub(parent, tag), "xhtml:p", text=text)


def ld_body(body: ET.Element, ladder: LadderBody) -> None:
    ld = _sub(body, "LD")
    next_id = [0]

    def new_id() -> str:
        next_id[0] += 1
        return str(next_id[0])

    top = 0.0
    for number, rung in enumerate(ladder.rungs, start=1):
        resolve_pins(rung)
        lay = layout_rung(rung, number)
        if rung.label:
            label = _sub(ld, "label", {"localId": new_id(), "label": rung.label})
            _pos(label, 0, top)
            top += 20
        if rung.comment:
            c = _sub(ld, "comment", {"localId": new_id(), "height": "20", "width": "600"})
            _pos(c, 30, top)
            formatted(c, "content", rung.comment)
            top += 30
        ids: dict[str, str] = {}
        for e in rung.elements:
            ids[e.id] = new_id()
        height = lay.height + 20

        def where(e: Element, lay=lay, top: float = top, rung=rung) -> tuple[float, float]:
            p = lay.placed.get(e.id)
            if p is not None:
                return p.x, top + p.y
            for other in rung.elements:                  # a variable written next to a block pin
                for pin in [*other.inputs, *other.inouts]:
                    if any(c.ref == e.id for c in pin.conns) and other.id in lay.placed:
                        q = lay.placed[other.id]
                        return q.x - 130, top + q.y
                if e.kind == "out_var" and e.inputs and e.inputs[0].conns:
                    src = lay.placed.get(e.inputs[0].conns[0].ref)
                    if src is not None:
                        return src.x + src.w + 14, top + src.y
            return 0.0, top

        for e in rung.elements:
            _element(ld, e, ids, where(e), height, lay.width)
        top += height + RUNG_GAP


def _conns(parent: ET.Element, conns, ids) -> None:
    pt = _sub(parent, "connectionPointIn")
    for c in conns:
        if c.ref not in ids:
            continue
        attrs = {"refLocalId": ids[c.ref]}
        if c.pin:
            attrs["formalParameter"] = c.pin
        _sub(pt, "connection", attrs)


def _flags(attrs: dict, e: Element) -> dict:
    if e.negated:
        attrs["negated"] = "true"
    if e.edge != "none":
        attrs["edge"] = e.edge
    if e.storage != "none":
        attrs["storage"] = e.storage
    return attrs


def _element(ld: ET.Element, e: Element, ids, xy, height: float, width: float) -> None:
    x, y = xy
    lid = ids[e.id]
    if e.kind == "inline_st":
        raise WriteError("a rung holds Sysmac inline ST (smcext:InlineST), which PLCopen TC6 cannot express; "
                         "export with --format iec61131-10")
    if e.kind == "left_rail":
        el = _sub(ld, "leftPowerRail", {"localId": lid, "height": f"{height:.0f}", "width": "3"})
        _pos(el, 10, y)
        _sub(el, "connectionPointOut", {"formalParameter": ""})
    elif e.kind == "right_rail":
        el = _sub(ld, "rightPowerRail", {"localId": lid, "height": f"{height:.0f}", "width": "3"})
        _pos(el, width, y)
        for pin in e.inputs:
            for c in pin.conns:
                if c.ref in ids:
                    _conns(el, [c], ids)
    elif e.kind in ("contact", "coil"):
        el = _sub(ld, e.kind, _flags({"localId": lid, "height": "20", "width": "21"}, e))
        _pos(el, x, y)
        _conns(el, e.inputs[0].conns, ids)
        _sub(el, "connectionPointOut")
        _sub(el, "variable", text=e.var)
    elif e.kind in ("in_var", "out_var", "inout_var"):
        tag = {"in_var": "inVariable", "out_var": "outVariable", "inout_var": "inOutVariable"}[e.kind]
        attrs = {"localId": lid, "height": "20", "width": "120"}
        if e.negated:
            attrs["negatedIn" if e.kind == "inout_var" else "negated"] = "true"
        el = _sub(ld, tag, attrs)
        _pos(el, x, y)
        if e.kind != "in_var":
            _conns(el, e.inputs[0].conns if e.inputs else [], ids)
        if e.kind != "out_var":
            _sub(el, "connectionPointOut")
        _sub(el, "expression", text=e.var)
    elif e.kind in ("jump", "return"):
        attrs = {"localId": lid, "height": "20", "width": "80"}
        if e.kind == "jump":
            attrs["label"] = e.var
        el = _sub(ld, e.kind, attrs)
        _pos(el, x, y)
        _conns(el, e.inputs[0].conns if e.inputs else [], ids)
    elif e.kind == "block":
        rows = max(len(e.inputs) + len(e.inouts), len(e.outputs) + len(e.inouts), 1)
        attrs = {"localId": lid, "width": "200", "height": f"{rows * ROW_H:.0f}", "typeName": e.type_name}
        if e.instance:
            attrs["instanceName"] = e.instance
        el = _sub(ld, "block", attrs)
        _pos(el, x, y)
        ins = _sub(el, "inputVariables")
        for p in e.inputs:
            a = {"formalParameter": p.name}
            if p.negated:
                a["negated"] = "true"
            if p.edge != "none":
                a["edge"] = p.edge
            _conns(_sub(ins, "variable", a), p.conns, ids)
        ios = _sub(el, "inOutVariables")
        for p in e.inouts:
            v = _sub(ios, "variable", {"formalParameter": p.name})
            _conns(v, p.conns, ids)
            _sub(v, "connectionPointOut")
        outs = _sub(el, "outputVariables")
        for p in e.outputs:
            a = {"formalParameter": p.name}
            if p.negated:
                a["negated"] = "true"
            _sub(_sub(outs, "variable", a), "connectionPointOut")
