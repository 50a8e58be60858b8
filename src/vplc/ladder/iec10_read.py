"""Read an IEC 61131-10 Ed.1 XML project: our own export (:mod:`vplc.export.iec61131_10`) and the
ladder shape Sysmac Studio exchanges (docs/toolchain/export.md, section "Ladder bodies").

``Types/GlobalNamespace`` holds data types and POUs, optionally inside ``NamespaceDecl``; a POU body is
``MainBody/BodyContent`` of ``xsi:type="ST"`` (text) or ``smcext:LdSection`` (rungs). A rung lists
``LdObject`` (LeftPowerRail, Contact, Coil, RightPowerRail), ``FbdObject`` (Block, DataSource, DataSink,
Jump, Label, Return) and ``CommonObject`` comments; wires are ``ConnectionPointIn/Connection
refConnectionPointOutId`` pointing at a ``ConnectionPointOut connectionPointOutId`` of the same rung.
Global variables are read from ``Instances/Configuration/Resource/GlobalVars``.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from .decls import FormatError, PouText, SectionText, TypeText, VarText, XmlUnit
from .model import EDGES, STORAGES, Conn, Element, LadderBody, Pin, Rung
from .xmlsafe import text_of, xsi_type

POUS = {"Program": "PROGRAM", "FunctionBlock": "FUNCTION_BLOCK", "Function": "FUNCTION"}
PARAMS = {"InputVars": "VAR_INPUT", "OutputVars": "VAR_OUTPUT", "InOutVars": "VAR_IN_OUT", "InoutVars": "VAR_IN_OUT"}
LISTS = {"ExternalVars": "VAR_EXTERNAL", "Vars": "VAR", "TempVars": "VAR_TEMP"}
LD_OBJECTS = {"LeftPowerRail": "left_rail", "RightPowerRail": "right_rail", "Contact": "contact", "Coil": "coil"}
FBD_OBJECTS = {"Block": "block", "DataSource": "in_var", "DataSink": "out_var", "Jump": "jump", "Label": "label",
               "Return": "return"}
KNOWN = ", ".join([*LD_OBJECTS, *FBD_OBJECTS])


def read(root: ET.Element) -> list[XmlUnit]:
    gns = root.find("Types/GlobalNamespace")
    units: dict[str | None, XmlUnit] = {None: XmlUnit(None)}
    if gns is not None:
        _namespace(gns, None, units)
    for gl in root.iterfind("Instances/Configuration/Resource/GlobalVars"):
        units[None].globals.append(_list("VAR_GLOBAL", gl, "global variables"))
    for gl in root.iterfind("Instances/Configuration/GlobalVars"):
        units[None].globals.append(_list("VAR_GLOBAL", gl, "global variables"))
    return [u for u in units.values() if u.types or u.pous or u.globals]


def _namespace(container: ET.Element, ns: str | None, units: dict) -> None:
    unit = units.setdefault(ns, XmlUnit(ns))
    for item in container:
        if item.tag == "NamespaceDecl":
            _namespace(item, item.get("name") or None, units)
        elif item.tag in ("DataTypeDecl", "UserDefinedTypeDecl"):
            unit.types.append(_data_type(item))
        elif item.tag in POUS:
            unit.pous.append(_pou(item))


# ---- types and values ----------------------------------------------------------------------------

def type_text(t: ET.Element | None, where: str) -> str:
    if t is None:
        raise FormatError(where, "a type is missing")
    name = t.find("TypeName")
    if name is not None:
        return (name.text or "").strip()
    inst = t.find("InstantlyDefinedType")
    if inst is not None and xsi_type(inst) == "ArrayTypeSpec":
        return _array(inst, where)
    raise FormatError(where, "a type is neither a TypeName nor an ArrayTypeSpec")


def _array(spec: ET.Element, where: str) -> str:
    dims = []
    for ds in spec.iterfind("DimensionSpec"):
        r = ds.find("IndexRange")
        dims.append(f"{r.get('lower')}..{r.get('upper')}" if r is not None else "*")
    return f"ARRAY[{', '.join(dims)}] OF {type_text(spec.find('BaseType'), where)}"


def value_text(v: ET.Element | None) -> str | None:
    if v is None or not len(v):
        return None
    c = v[0]
    if c.tag == "SimpleValue":
        return c.get("value")
    if c.tag == "ArrayValue":
        items = []
        for item in c.iterfind("Value"):
            text = value_text(item) or ""
            rep = item.get("repetitionValue")
            items.append(f"{rep}({text})" if rep else text)
        return "[" + ", ".join(items) + "]"
    if c.tag == "StructValue":
        return "(" + ", ".join(f"{m.get('member')} := {value_text(m)}" for m in c.iterfind("Value")) + ")"
    return None


def _doc(el: ET.Element) -> str:
    return text_of(el.find("Documentation"))


def _var(v: ET.Element, where: str) -> VarText:
    name = v.get("name", "")
    addr = v.find("Address")
    return VarText(name, type_text(v.find("Type"), f"{where}:variable {name}"), value_text(v.find("InitialValue")),
                   _doc(v), addr.get("address") if addr is not None else None)


def _list(kind: str, lst: ET.Element, where: str) -> SectionText:
    return SectionText(kind, [_var(v, where) for v in lst.iterfind("Variable")],
                       constant=lst.get("constant") == "true", retain=lst.get("retain") == "true")


def _data_type(dt: ET.Element) -> TypeText:
    name = dt.get("name", "")
    where = f"data type {name}"
    spec = dt.find("UserDefinedTypeSpec")
    kind = xsi_type(spec) if spec is not None else ""
    if kind == "StructTypeSpec":
        fields = "".join(f"    {_line(_var(m, where))}\n" for m in spec.iterfind("Member"))
        text = f"STRUCT\n{fields}END_STRUCT"
    elif kind == "EnumTypeWithNamedValueSpec":
        values = ", ".join(f"{e.get('name')} := {e.get('value')}" for e in spec.iterfind("Enumerator"))
        base = spec.find("BaseType")
        text = f"({values})" + (f" {type_text(base, where)}" if base is not None else "")
    elif kind == "EnumTypeSpec":
        text = "(" + ", ".join(e.get("name", "") for e in spec.iterfind("Enumerator")) + ")"
    elif kind == "ArrayTypeSpec":
        text = _array(spec, where)
    else:
        raise FormatError(where, f"data type specification `{kind or '?'}` is not supported")
    return TypeText(name, text, value_text(dt.find("InitialValue")), _doc(dt))


def _line(v: VarText) -> str:
    at = f" AT {v.at}" if v.at else ""
    init = f" := {v.init}" if v.init is not None else ""
    return f"{v.name}{at} : {v.type}{init};"


# ---- POUs ----------------------------------------------------------------------------------------

def _pou(el: ET.Element) -> PouText:
    name = el.get("name", "")
    out = PouText(POUS[el.tag], name, comment=_doc(el))
    rt = el.find("ResultType")
    if rt is not None:
        out.return_type = type_text(rt, f"{name}:result")
    params = []
    for holder in [*el.iterfind("Parameters"), *el.iterfind("ParameterSet")]:
        for lst in holder:
            if lst.tag in PARAMS:
                for v in lst.iterfind("Variable"):
                    params.append((int(v.get("orderWithinParamSet", len(params))), PARAMS[lst.tag], lst, v))
    params.sort(key=lambda p: p[0])
    for _order, kind, lst, v in params:                  # declaration order, one section per run of a kind
        if not out.sections or out.sections[-1].kind != kind:
            out.sections.append(SectionText(kind, constant=lst.get("constant") == "true",
                                            retain=lst.get("retain") == "true"))
        out.sections[-1].vars.append(_var(v, name))
    for lst in el:
        if lst.tag in LISTS:
            kind = "VAR_TEMP" if lst.tag == "Vars" and out.kind == "FUNCTION" else LISTS[lst.tag]
            out.sections.append(_list(kind, lst, name))
    contents = el.findall("MainBody/BodyContent")
    if not contents:
        raise FormatError(name, "the POU has no MainBody/BodyContent")
    kinds = {xsi_type(c) for c in contents}
    if kinds == {"ST"}:
        out.st_body = "\n".join((c.findtext("ST") or "") for c in contents)
    elif kinds == {"LdSection"}:
        contents.sort(key=lambda c: int(c.get("evaluationOrder", "0") or 0))
        rungs = []
        for section in contents:
            rungs += _rungs(section, name)
        out.ladder = LadderBody(name, rungs)
    else:
        raise FormatError(name, f"body type {', '.join(sorted(kinds))} is not supported; the virtual PLC runs ST "
                                "and LD (smcext:LdSection)")
    return out


def _rungs(section: ET.Element, pou: str) -> list[Rung]:
    items = list(section.iterfind("Rung"))
    items.sort(key=lambda r: int(r.get("evaluationOrder", "0") or 0))
    return [_rung(r, pou, n) for n, r in enumerate(items, start=1)]


def _point_ins(el: ET.Element, outs: dict) -> list[Conn]:
    return [outs.get(c.get("refConnectionPointOutId", ""), Conn("?" + c.get("refConnectionPointOutId", "")))
            for pt in el.iterfind("ConnectionPointIn") for c in pt.iterfind("Connection")]


def _rung(r: ET.Element, pou: str, number: int) -> Rung:
    rung = Rung([], label=r.get("label", "") or "")
    objects = []
    outs: dict[str, Conn] = {}
    for index, obj in enumerate(r, start=1):
        kind = xsi_type(obj)
        if obj.tag == "CommonObject" and kind == "Comment":
            rung.comment = f"{rung.comment}\n{text_of(obj.find('Content'))}".strip()
            continue
        table = LD_OBJECTS if obj.tag == "LdObject" else FBD_OBJECTS if obj.tag == "FbdObject" else {}
        if kind not in table:
            if obj.tag in ("AddData", "Documentation"):
                continue
            raise FormatError(f"{pou}:rung {number}:element {index}",
                              f"unknown element <{obj.tag} xsi:type=\"{kind}\"> in a rung; a rung has {KNOWN}")
        eid = obj.get("globalId") or f"r{number}e{index}"
        ekind = table[kind]
        if ekind == "out_var" and obj.find("ConnectionPointOut") is not None:
            ekind = "inout_var"                          # a DataSink that is also read further on
        objects.append((obj, Element(eid, ekind)))
        for pt in obj.iterfind("ConnectionPointOut"):
            outs[pt.get("connectionPointOutId", "")] = Conn(eid)
        for group in ("OutputVariables/OutputVariable", "InOutVariables/InOutVariable"):
            for v in obj.iterfind(group):
                for pt in v.iterfind("ConnectionPointOut"):
                    outs[pt.get("connectionPointOutId", "")] = Conn(eid, v.get("parameterName"))
    for obj, e in objects:
        where = f"{pou}:rung {number}:{e.kind}"
        if e.kind in ("contact", "coil"):
            e.var = obj.get("operand", "")
            e.negated = obj.get("negated", "false") in ("true", "negated")
            e.edge = _choice(obj, "edge", EDGES, where)
            e.storage = _choice(obj, "storage", STORAGES, where)
        elif e.kind in ("in_var", "out_var", "inout_var"):
            e.var = obj.get("identifier", "")
            e.negated = obj.get("negated", "false") == "true"
        elif e.kind in ("jump", "label"):
            e.var = obj.get("label", "")
        elif e.kind == "block":
            e.type_name = obj.get("typeName", "")
            e.instance = obj.get("instanceName", "") or ""
            for v in obj.iterfind("InputVariables/InputVariable"):
                e.inputs.append(Pin(v.get("parameterName", ""), _point_ins(v, outs),
                                    v.get("negated", "false") == "true", _choice(v, "edge", EDGES, where)))
            for v in obj.iterfind("InOutVariables/InOutVariable"):
                e.inouts.append(Pin(v.get("parameterName", ""), _point_ins(v, outs)))
            for v in obj.iterfind("OutputVariables/OutputVariable"):
                e.outputs.append(Pin(v.get("parameterName", ""), negated=v.get("negated", "false") == "true"))
        if e.kind != "block" and e.kind not in ("left_rail", "in_var", "label"):
            e.inputs = [Pin("", _point_ins(obj, outs))]
        if e.kind == "label":
            rung.label = rung.label or e.var
            continue
        rung.elements.append(e)
    return rung


def _choice(el: ET.Element, name: str, allowed, where: str) -> str:
    value = el.get(name, "none") or "none"
    if value not in allowed:
        raise FormatError(where, f"{name}=\"{value}\" is not one of {', '.join(allowed)}")
    return value
