"""Read a PLCopen XML TC6 v2.01 project (as CODESYS, Beremiz/OpenPLC and many IDEs write it).

Read: ``types/dataTypes`` (structures, enumerations, arrays, aliases, subranges), ``types/pous`` (program,
function block, function; their interface lists; ST and LD bodies) and the global variable lists of
``instances/configurations``. A body in FBD, SFC or IL is refused with a clear message.

An ``<LD>`` body is a flat list of elements with positions; there is no rung element in TC6. Rungs are
the groups of elements joined by connections (the power rails do not join groups), ordered top to bottom
by their topmost element; a comment belongs to the rung below it, a label to the rung it stands in or
the one below it.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from ..frontend import codes
from .decls import FormatError, PouText, SectionText, TypeText, VarText, XmlUnit, join_inouts
from .model import EDGES, STORAGES, Conn, Element, LadderBody, Pin, Rung
from .xmlsafe import text_of

POU_KINDS = {"program": "PROGRAM", "functionBlock": "FUNCTION_BLOCK", "function": "FUNCTION"}
VAR_LISTS = {"inputVars": "VAR_INPUT", "outputVars": "VAR_OUTPUT", "inOutVars": "VAR_IN_OUT",
             "externalVars": "VAR_EXTERNAL", "localVars": "VAR", "tempVars": "VAR_TEMP"}
SIMPLE = {"contact": "contact", "coil": "coil", "inVariable": "in_var", "outVariable": "out_var",
          "inOutVariable": "inout_var", "jump": "jump", "label": "label", "return": "return",
          "leftPowerRail": "left_rail", "rightPowerRail": "right_rail", "block": "block"}
LD_ELEMENTS = ", ".join(sorted(SIMPLE)) + ", comment"


NAMESPACE_DATA = "https://github.com/cbt-commands-lib/vplc/namespace"     # vplc export (vplc.export.plcopen)


def read(root: ET.Element) -> list[XmlUnit]:
    units: dict[str | None, XmlUnit] = {None: XmlUnit(None)}
    types = root.find("types")
    if types is None:
        raise FormatError("", "the PLCopen project has no <types> element")
    for dt in types.iterfind("dataTypes/dataType"):
        ns = _namespace(dt)
        units.setdefault(ns, XmlUnit(ns)).types.append(_data_type(dt))
    for pou in types.iterfind("pous/pou"):
        ns = _namespace(pou)
        units.setdefault(ns, XmlUnit(ns)).pous.append(_pou(pou))
    for holder in root.iterfind("instances/configurations/configuration"):
        for gl in [*holder.iterfind("globalVars"), *holder.iterfind("resource/globalVars")]:
            units[None].globals.append(_var_list("VAR_GLOBAL", gl, f"configuration {holder.get('name', '')}"))
    return [u for u in units.values() if u.types or u.pous or u.globals]


def _namespace(el: ET.Element) -> str | None:
    for data in el.iterfind("addData/data"):
        if data.get("name") == NAMESPACE_DATA:
            ns = data.find("namespace")
            return ns.get("name") if ns is not None else None
    return None


# ---- types and values ----------------------------------------------------------------------------

def type_text(t: ET.Element | None, where: str) -> str:
    """The ST spelling of a ``<type>`` / ``<baseType>`` / ``<returnType>`` element."""
    kids = list(t) if t is not None else []
    if not kids:
        raise FormatError(where, "a type is missing (empty <type> element)")
    c = kids[0]
    tag = c.tag
    if tag in ("string", "wstring"):
        word = "STRING" if tag == "string" else "WSTRING"
        return f"{word}[{c.get('length')}]" if c.get("length") else word
    if tag == "derived":
        return c.get("name", "")
    if tag == "array":
        dims = ", ".join(f"{d.get('lower')}..{d.get('upper')}" for d in c.iterfind("dimension"))
        return f"ARRAY[{dims}] OF {type_text(c.find('baseType'), where)}"
    if tag == "enum":
        values = ", ".join(v.get("name", "") + (f" := {v.get('value')}" if v.get("value") else "")
                           for v in c.iterfind("values/value"))
        base = c.find("baseType")
        return f"({values})" + (f" {type_text(base, where)}" if base is not None else "")
    if tag == "struct":
        fields = "".join(f"    {_var_line(v)}\n" for v in _variables(c, where))
        return f"STRUCT\n{fields}END_STRUCT"
    if tag in ("subrangeSigned", "subrangeUnsigned"):
        r = c.find("range")
        if r is None:
            raise FormatError(where, f"<{tag}> without <range>")
        return f"{type_text(c.find('baseType'), where)}({r.get('lower')}..{r.get('upper')})"
    if tag == "pointer":
        raise FormatError(where, "POINTER types are not supported; pass the variable as an in-out instead")
    return tag


def value_text(v: ET.Element | None) -> str | None:
    """The ST text of an ``<initialValue>`` (simple, array or structure value)."""
    if v is None or not len(v):
        return None
    c = v[0]
    if c.tag == "simpleValue":
        return c.get("value")
    if c.tag == "arrayValue":
        items = []
        for item in c.iterfind("value"):
            text = value_text(item) or ""
            rep = item.get("repetitionValue", "1")
            items.append(text if rep == "1" else f"{rep}({text})")
        return "[" + ", ".join(items) + "]"
    if c.tag == "structValue":
        return "(" + ", ".join(f"{m.get('member')} := {value_text(m)}" for m in c.iterfind("value")) + ")"
    return None


def _variables(lst: ET.Element, where: str) -> list[VarText]:
    out = []
    for v in lst.iterfind("variable"):
        name = v.get("name", "")
        out.append(VarText(name, type_text(v.find("type"), f"{where}:variable {name}"),
                           value_text(v.find("initialValue")), text_of(v.find("documentation")),
                           v.get("address")))
    return out


def _var_line(v: VarText) -> str:
    at = f" AT {v.at}" if v.at else ""
    init = f" := {v.init}" if v.init is not None else ""
    return f"{v.name}{at} : {v.type}{init};"


def _var_list(kind: str, lst: ET.Element, where: str) -> SectionText:
    return SectionText(kind, _variables(lst, where), constant=lst.get("constant") in ("true", "1"),
                       retain=lst.get("retain") in ("true", "1"))


def _data_type(dt: ET.Element) -> TypeText:
    name = dt.get("name", "")
    return TypeText(name, type_text(dt.find("baseType"), f"data type {name}"), value_text(dt.find("initialValue")),
                    text_of(dt.find("documentation")))


# ---- POUs ----------------------------------------------------------------------------------------

def _pou(pou: ET.Element) -> PouText:
    name = pou.get("name", "")
    kind = POU_KINDS.get(pou.get("pouType", ""))
    if kind is None:
        raise FormatError(name, f"pouType `{pou.get('pouType')}` is not program, functionBlock or function")
    out = PouText(kind, name, comment=text_of(pou.find("documentation")))
    iface = pou.find("interface")
    if iface is not None:
        for lst in iface:
            if lst.tag == "returnType":
                out.return_type = type_text(lst, f"{name}:result")
            elif lst.tag in VAR_LISTS:
                out.sections.append(_var_list(VAR_LISTS[lst.tag], lst, name))
            elif lst.tag not in ("addData", "documentation"):
                raise FormatError(name, f"variable list <{lst.tag}> is not allowed in a POU")
    body = pou.find("body")
    lang = body[0] if body is not None and len(body) else None
    if lang is None:
        raise FormatError(name, "the POU has no body")
    if lang.tag == "ST":
        out.st_body = text_of(lang)
    elif lang.tag == "LD":
        out.ladder = read_ld(lang, name)
    else:
        raise FormatError(name, f"{lang.tag} bodies are not supported; the virtual PLC runs ST and LD")
    return out


def _conns(point: ET.Element | None) -> list[Conn]:
    if point is None:
        return []
    return [Conn(c.get("refLocalId", ""), c.get("formalParameter") or None) for c in point.iterfind("connection")]


def _flag(el: ET.Element, name: str) -> bool:
    return el.get(name, "false") in ("true", "1")


def _choice(el: ET.Element, name: str, allowed, where: str) -> str:
    value = el.get(name, "none")
    if value not in allowed:
        raise FormatError(where, f"{name}=\"{value}\" is not one of {', '.join(allowed)}")
    return value


def _element(el: ET.Element, pou: str) -> Element:
    kind = SIMPLE[el.tag]
    lid = el.get("localId", "")
    p = el.find("position")
    pos = (float(p.get("x", 0)), float(p.get("y", 0))) if p is not None else None
    e = Element(lid, kind, pos=pos)
    where = f"{pou}:element {lid}"
    if kind in ("contact", "coil"):
        e.var = (el.findtext("variable") or "").strip()
        e.negated = _flag(el, "negated")
        e.edge = _choice(el, "edge", EDGES, where)
        e.storage = _choice(el, "storage", STORAGES, where)
        e.inputs = [Pin("", _conns(el.find("connectionPointIn")))]
    elif kind in ("in_var", "out_var", "inout_var"):
        e.var = (el.findtext("expression") or "").strip()
        e.negated = _flag(el, "negated") or _flag(el, "negatedIn")
        if kind != "in_var":
            e.inputs = [Pin("", _conns(el.find("connectionPointIn")))]
    elif kind in ("jump", "label"):
        e.var = el.get("label", "")
        if kind == "jump":
            e.inputs = [Pin("", _conns(el.find("connectionPointIn")))]
    elif kind == "return":
        e.inputs = [Pin("", _conns(el.find("connectionPointIn")))]
    elif kind == "right_rail":
        e.inputs = [Pin("", _conns(pt)) for pt in el.iterfind("connectionPointIn")]
    elif kind == "block":
        e.type_name = el.get("typeName", "")
        e.instance = el.get("instanceName", "") or ""
        for v in el.iterfind("inputVariables/variable"):
            e.inputs.append(Pin(v.get("formalParameter", ""), _conns(v.find("connectionPointIn")),
                                _flag(v, "negated"), _choice(v, "edge", EDGES, where)))
        for v in el.iterfind("inOutVariables/variable"):
            e.inouts.append(Pin(v.get("formalParameter", ""), _conns(v.find("connectionPointIn"))))
        for v in el.iterfind("outputVariables/variable"):
            e.outputs.append(Pin(v.get("formalParameter", ""), negated=_flag(v, "negated")))
        join_inouts(e, where)
    return e


def read_ld(ld: ET.Element, pou: str) -> LadderBody:
    elements: list[Element] = []
    seen: set[str] = set()
    comments: list[tuple[float, str]] = []
    for el in ld:
        if el.tag == "comment":
            p = el.find("position")
            comments.append((float(p.get("y", 0)) if p is not None else 0.0, text_of(el.find("content"))))
        elif el.tag in SIMPLE:
            e = _element(el, pou)
            if e.id in seen:
                raise FormatError(f"{pou}:element {e.id}", f"localId {e.id} is used by two elements; every "
                                  "element needs its own id for the wires to be unambiguous",
                                  codes.LADDER_MISSING_CONNECTION)
            seen.add(e.id)
            elements.append(e)
        elif el.tag not in ("addData", "documentation"):
            raise FormatError(f"{pou}:element {el.get('localId', '?')}",
                              f"unknown element <{el.tag}> in a ladder body; a ladder has {LD_ELEMENTS}")
    return LadderBody(pou, group_rungs(elements, comments))


def group_rungs(elements: list[Element], comments: list[tuple[float, str]]) -> list[Rung]:
    """Split a flat element list into rungs: connected groups, the rails not joining them."""
    by_id = {e.id: e for e in elements}
    parent = {e.id: e.id for e in elements}

    def find(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    rails = {e.id for e in elements if e.kind in ("left_rail", "right_rail")}
    for e in elements:
        if e.kind in ("left_rail", "right_rail"):
            continue
        for pin in [*e.inputs, *e.inouts]:
            for c in pin.conns:
                if c.ref in by_id and c.ref not in rails:
                    parent[find(c.ref)] = find(e.id)
    groups: dict[str, list[Element]] = {}
    order = {e.id: i for i, e in enumerate(elements)}
    for e in elements:
        if e.id not in rails:
            groups.setdefault(find(e.id), []).append(e)
    rail_of_ref: dict[str, set[str]] = {}          # element id -> right rails its output reaches
    for e in elements:
        if e.kind == "right_rail":
            for pin in e.inputs:
                for c in pin.conns:
                    rail_of_ref.setdefault(c.ref, set()).add(e.id)

    def top(members: list[Element]) -> tuple:
        ys = [m.pos[1] for m in members if m.pos is not None]
        return (min(ys) if ys else 0.0, min(order[m.id] for m in members))

    ordered = sorted(groups.values(), key=top)
    rungs: list[Rung] = []
    pending_label = ""
    for members in ordered:
        if len(members) == 1 and members[0].kind == "label":
            pending_label = members[0].var
            continue
        used = set()
        for m in members:
            used |= rail_of_ref.get(m.id, set())
            used |= {c.ref for pin in [*m.inputs, *m.inouts] for c in pin.conns if c.ref in rails}
        rung_elements = [by_id[r] for r in sorted(used, key=lambda r: order[r])] + \
            sorted(members, key=lambda m: order[m.id])
        rungs.append(Rung(rung_elements, label=pending_label))
        pending_label = ""
    if pending_label:
        rungs.append(Rung([], label=pending_label))
    for y, text in comments:
        target = next((r for r in rungs if top_y(r) >= y), rungs[-1] if rungs else None)
        if target is not None:
            target.comment = f"{target.comment}\n{text}".strip()
    return rungs


def top_y(rung: Rung) -> float:
    ys = [e.pos[1] for e in rung.elements if e.pos is not None and e.kind not in ("left_rail", "right_rail")]
    return min(ys) if ys else 0.0
