"""Write a ladder body in Sysmac Studio's IEC 61131-10 shape (docs/toolchain/export.md, "Ladder bodies"):

    MainBody
      BodyContent xsi:type="smcext:LdSection" name="Section0" evaluationOrder="1"
        Rung evaluationOrder="1" [label]
          CommonObject xsi:type="Comment" / Content xsi:type="SimpleText"      (the rung comment)
          LdObject xsi:type="LeftPowerRail" / ConnectionPointOut connectionPointOutId
          LdObject xsi:type="Contact" operand [negated] [edge] / ConnectionPointIn/Connection, ConnectionPointOut
          FbdObject xsi:type="Block" typeName [instanceName] / InputVariables, InOutVariables, OutputVariables
          FbdObject xsi:type="DataSource" | "DataSink" identifier
          LdObject xsi:type="Coil" operand [negated] [storage] [edge]
          LdObject xsi:type="RightPowerRail" / ConnectionPointIn*

Connection point ids are numbered from 1 in each rung, in element order. Every rung gets its own rails.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from .model import Element, LadderBody, Rung

KIND_TAG = {"left_rail": ("LdObject", "LeftPowerRail"), "right_rail": ("LdObject", "RightPowerRail"),
            "contact": ("LdObject", "Contact"), "coil": ("LdObject", "Coil"), "block": ("FbdObject", "Block"),
            "in_var": ("FbdObject", "DataSource"), "out_var": ("FbdObject", "DataSink"),
            "inout_var": ("FbdObject", "DataSink"), "jump": ("FbdObject", "Jump"), "return": ("FbdObject", "Return")}


def _sub(parent: ET.Element, tag: str, attrs: dict | None = None, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag, attrs or {})
    if text is not None:
        el.text = text
    return el


def ld_body(main_body: ET.Element, ladder: LadderBody) -> None:
    section = _sub(main_body, "BodyContent", {"xsi:type": "smcext:LdSection", "name": "Section0",
                                              "evaluationOrder": "1"})
    for n, rung in enumerate(ladder.rungs, start=1):
        _rung(section, rung, n)


def _rung(section: ET.Element, rung: Rung, number: int) -> None:
    attrs = {"evaluationOrder": str(number)}
    if rung.label:
        attrs["label"] = rung.label
    r = _sub(section, "Rung", attrs)
    if rung.comment:
        _sub(_sub(r, "CommonObject", {"xsi:type": "Comment"}), "Content", {"xsi:type": "SimpleText"}, rung.comment)
    resolve_pins(rung)
    ids: dict[tuple[str, str | None], str] = {}
    for e in rung.elements:                              # number every output point first
        for pin in _out_pins(e):
            ids[(e.id, pin)] = str(len(ids) + 1)
    for e in rung.elements:
        _element(r, e, ids)


def resolve_pins(rung: Rung) -> None:
    """Name the pin of every wire that starts at a block without naming one (PLCopen: the first output
    that is not ENO)."""
    blocks = {e.id: e for e in rung.elements if e.kind == "block"}
    for e in rung.elements:
        for pin in [*e.inputs, *e.inouts]:
            for c in pin.conns:
                if c.pin is None and c.ref in blocks:
                    c.pin = next((p.name for p in blocks[c.ref].outputs if p.name.upper() != "ENO"), None)


def _out_pins(e: Element) -> list[str | None]:
    if e.kind == "block":
        return [p.name for p in e.inouts] + [p.name for p in e.outputs]
    if e.kind in ("left_rail", "contact", "coil", "in_var", "inout_var"):
        return [None]
    return []


def _point_in(parent: ET.Element, conns, ids, rung_el: Element) -> None:
    """``conns`` are resolved: a wire from a block names its pin (:func:`resolve_pins`)."""
    pt = _sub(parent, "ConnectionPointIn")
    for c in conns:
        _sub(pt, "Connection", {"refConnectionPointOutId": ids[(c.ref, c.pin)]})


def _element(r: ET.Element, e: Element, ids) -> None:
    tag, kind = KIND_TAG[e.kind]
    attrs = {"xsi:type": kind}
    if e.kind in ("contact", "coil"):
        attrs["operand"] = e.var
        if e.negated:
            attrs["negated"] = "true"
        if e.edge != "none":
            attrs["edge"] = e.edge
        if e.storage != "none":
            attrs["storage"] = e.storage
    elif e.kind in ("in_var", "out_var", "inout_var"):
        attrs["identifier"] = e.var
        if e.negated:
            attrs["negated"] = "true"
    elif e.kind == "jump":
        attrs["label"] = e.var
    elif e.kind == "block":
        attrs["typeName"] = e.type_name
        if e.instance:
            attrs["instanceName"] = e.instance
    el = _sub(r, tag, attrs)
    if e.kind == "block":
        if e.inputs:
            group = _sub(el, "InputVariables")
            for p in e.inputs:
                a = {"parameterName": p.name}
                if p.negated:
                    a["negated"] = "true"
                if p.edge != "none":
                    a["edge"] = p.edge
                _point_in(_sub(group, "InputVariable", a), p.conns, ids, e)
        if e.inouts:
            group = _sub(el, "InOutVariables")
            for p in e.inouts:
                v = _sub(group, "InOutVariable", {"parameterName": p.name})
                _point_in(v, p.conns, ids, e)
                _sub(v, "ConnectionPointOut", {"connectionPointOutId": ids[(e.id, p.name)]})
        if e.outputs:
            group = _sub(el, "OutputVariables")
            for p in e.outputs:
                a = {"parameterName": p.name}
                if p.negated:
                    a["negated"] = "true"
                _sub(_sub(group, "OutputVariable", a), "ConnectionPointOut",
                     {"connectionPointOutId": ids[(e.id, p.name)]})
        return
    if e.kind == "right_rail":
        for pin in e.inputs:
            for c in pin.conns:
                if (c.ref, c.pin) in ids:              # a rail shared by several rungs: this rung's wires only
                    _point_in(el, [c], ids, e)
        return
    if e.kind != "left_rail" and e.kind != "in_var" and e.inputs:
        _point_in(el, e.inputs[0].conns, ids, e)
    if (e.id, None) in ids:
        _sub(el, "ConnectionPointOut", {"connectionPointOutId": ids[(e.id, None)]})
