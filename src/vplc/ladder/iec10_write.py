"""Write a ladder body in the shape Omron's schemas define (IEC61131_10_Ed1_0_Spc1_0.xsd with the Sysmac
extension; docs/toolchain/export.md, "Ladder bodies")::

    MainBody
      BodyContent xsi:type="smcext:LdSection" name="Section0" evaluationOrder="1"   (a program)
      BodyContent xsi:type="LD"                                                     (a function block, a function)
        Rung evaluationOrder="1" [label]
          CommonObject xsi:type="Comment" / Content xsi:type="SimpleText"      (the rung comment)
          LdObject xsi:type="LeftPowerRail" / ConnectionPointOut connectionPointOutId
          LdObject xsi:type="Contact" operand [negated] [edge] / ConnectionPointIn/Connection, ConnectionPointOut
          FbdObject xsi:type="Block" typeName [instanceName] / InOutVariables, InputVariables, OutputVariables
          FbdObject xsi:type="DataSource" | "DataSink" identifier
          FbdObject xsi:type="Jump" targetNetworkLabel
          LdObject xsi:type="Coil" operand [negated] [edge] [latch]
          LdObject xsi:type="RightPowerRail" / ConnectionPointIn*

Connection point ids are numbered from 1 in each rung, in element order. A block output nothing reads gets
no ConnectionPointOut (Sysmac Studio imports an unreferenced pin output as an empty rung). The schema has no
Return object: a return is written as a jump to a last, empty rung labelled for it, which ends the body
the same way.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from .model import Element, LadderBody, Rung

KIND_TAG = {"left_rail": ("LdObject", "LeftPowerRail"), "right_rail": ("LdObject", "RightPowerRail"),
            "contact": ("LdObject", "Contact"), "coil": ("LdObject", "Coil"), "block": ("FbdObject", "Block"),
            "in_var": ("FbdObject", "DataSource"), "out_var": ("FbdObject", "DataSink"),
            "inout_var": ("FbdObject", "DataSink"), "jump": ("FbdObject", "Jump"), "return": ("FbdObject", "Jump"),
            "inline_st": ("LdObject", "smcext:InlineST")}
# Sysmac's pin names of MOVE (EN, In -> ENO, Out: field notes of engineers who imported generated files);
# ST names are case-insensitive, so vplc reads them as IN / OUT.
PIN_SPELLING = {"MOVE": {"IN": "In", "OUT": "Out"}}
RETURN_LABEL = "Return_End"


def _sub(parent: ET.Element, tag: str, attrs: dict | None = None, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag, attrs or {})
    if text is not None:
        el.text = text
    return el


def ld_body(main_body: ET.Element, ladder: LadderBody, *, section: bool = True) -> None:
    """``section``: Sysmac's ``smcext:LdSection`` (programs); otherwise the base schema's ``LD`` body, which
    Sysmac uses for function blocks and functions."""
    attrs = ({"xsi:type": "smcext:LdSection", "name": "Section0", "evaluationOrder": "1"} if section
             else {"xsi:type": "LD"})
    body = _sub(main_body, "BodyContent", attrs)
    end_label = _return_label(ladder)
    for n, rung in enumerate(ladder.rungs, start=1):
        _rung(body, rung, n, end_label)
    if end_label:
        _sub(body, "Rung", {"evaluationOrder": str(len(ladder.rungs) + 1), "label": end_label})


def _return_label(ladder: LadderBody) -> str | None:
    if not any(e.kind == "return" for r in ladder.rungs for e in r.elements):
        return None
    taken = {r.label.upper() for r in ladder.rungs if r.label}
    label, n = RETURN_LABEL, 1
    while label.upper() in taken:
        n += 1
        label = f"{RETURN_LABEL}{n}"
    return label


def _rung(section: ET.Element, rung: Rung, number: int, end_label: str | None) -> None:
    attrs = {"evaluationOrder": str(number)}
    if rung.label:
        attrs["label"] = rung.label
    r = _sub(section, "Rung", attrs)
    if rung.comment:
        _sub(_sub(r, "CommonObject", {"xsi:type": "Comment"}), "Content", {"xsi:type": "SimpleText"}, rung.comment)
    resolve_pins(rung)
    read = {(c.ref, c.pin) for e in rung.elements for pin in [*e.inputs, *e.inouts] for c in pin.conns}
    ids: dict[tuple[str, str | None], str] = {}
    for e in rung.elements:                              # number every output point first
        for pin in _out_pins(e):
            if e.kind != "block" or (e.id, pin) in read:
                ids[(e.id, pin)] = str(len(ids) + 1)
    for e in rung.elements:
        _element(r, e, ids, end_label)


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
        return [*(p.name for p in e.inouts), *(p.name for p in e.outputs)]
    if e.kind in ("left_rail", "contact", "coil", "in_var", "inout_var", "inline_st"):
        return [None]
    return []


def _point_in(parent: ET.Element, conns, ids) -> None:
    """``conns`` are resolved: a wire from a block names its pin (:func:`resolve_pins`)."""
    pt = _sub(parent, "ConnectionPointIn")
    for c in conns:
        _sub(pt, "Connection", {"refConnectionPointOutId": ids[(c.ref, c.pin)]})


def _element(r: ET.Element, e: Element, ids, end_label: str | None) -> None:
    tag, kind = KIND_TAG[e.kind]
    attrs = {"xsi:type": kind}
    if e.kind in ("contact", "coil"):
        attrs["operand"] = e.var
        if e.negated:
            attrs["negated"] = "true"
        if e.edge != "none":
            attrs["edge"] = e.edge
        if e.storage != "none":
            attrs["latch"] = e.storage                   # the schema's Coil/@latch: none | set | reset
    elif e.kind in ("in_var", "out_var", "inout_var"):
        attrs["identifier"] = e.var
    elif e.kind == "jump":
        attrs["targetNetworkLabel"] = e.var
    elif e.kind == "return":
        attrs["targetNetworkLabel"] = end_label or ""           # a RETURN always has the end label
    elif e.kind == "block":
        attrs["typeName"] = e.type_name
        if e.instance:
            attrs["instanceName"] = e.instance
    el = _sub(r, tag, attrs)
    if e.kind == "block":
        _block_pins(el, e, ids)
        return
    if e.kind == "inline_st":            # Omron's extension: its children are in the smcext namespace (schema)
        pt = _sub(el, "smcext:ConnectionPointIn")
        for c in e.inputs[0].conns if e.inputs else ():
            _sub(pt, "Connection", {"refConnectionPointOutId": ids[(c.ref, c.pin)]})
        if (e.id, None) in ids:
            _sub(el, "smcext:ConnectionPointOut", {"connectionPointOutId": ids[(e.id, None)]})
        _sub(_sub(el, "smcext:ST"), "ST", text=e.var)
        return
    if e.kind == "right_rail":
        for pin in e.inputs:
            for c in pin.conns:
                if (c.ref, c.pin) in ids:              # a rail shared by several rungs: this rung's wires only
                    _point_in(el, [c], ids)
        return
    if e.kind != "left_rail" and e.kind != "in_var" and e.inputs:
        _point_in(el, e.inputs[0].conns, ids)
    if (e.id, None) in ids and e.kind in ("left_rail", "contact", "coil", "in_var"):
        _sub(el, "ConnectionPointOut", {"connectionPointOutId": ids[(e.id, None)]})


def _block_pins(el: ET.Element, e: Element, ids) -> None:
    """The schema's order: InOutVariables, InputVariables, OutputVariables."""
    spelling = PIN_SPELLING.get(e.type_name.upper(), {})
    name = lambda p: spelling.get(p.name.upper(), p.name)       # noqa: E731
    if e.inouts:
        group = _sub(el, "InOutVariables")
        for p in e.inouts:
            v = _sub(group, "InOutVariable", {"parameterName": name(p)})
            _point_in(v, p.conns, ids)
            if (e.id, p.name) in ids:
                _sub(v, "ConnectionPointOut", {"connectionPointOutId": ids[(e.id, p.name)]})
    if e.inputs:
        group = _sub(el, "InputVariables")
        for p in e.inputs:
            a = {"parameterName": name(p)}
            if p.negated:
                a["negated"] = "true"
            if p.edge != "none":
                a["edge"] = p.edge
            _point_in(_sub(group, "InputVariable", a), p.conns, ids)
    if e.outputs:
        group = _sub(el, "OutputVariables")
        for p in e.outputs:
            a = {"parameterName": name(p)}
            if p.negated:
                a["negated"] = "true"
            v = _sub(group, "OutputVariable", a)
            if (e.id, p.name) in ids:
                _sub(v, "ConnectionPointOut", {"connectionPointOutId": ids[(e.id, p.name)]})
