"""Read an IEC 61131-10 Ed.1 XML project as Sysmac Studio writes it (Omron's schemas
``IEC61131_10_Ed1_0_Spc1_0.xsd`` + ``IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd``) and as vplc exports it.

``Types/GlobalNamespace`` holds data types and POUs, optionally inside ``NamespaceDecl``; a POU body is
``MainBody/BodyContent`` of ``xsi:type="ST"`` (text), ``smcext:LdSection`` or ``LD`` (rungs). A rung lists
``LdObject`` (LeftPowerRail, Contact, Coil, RightPowerRail), ``FbdObject`` (Block, DataSource, DataSink,
Jump) and ``CommonObject`` comments; wires are ``ConnectionPointIn/Connection refConnectionPointOutId``
pointing at a ``ConnectionPointOut connectionPointOutId`` of the same rung. Global variables are read from
``Instances/Configuration/Resource/GlobalVars``.

Every element and attribute of the schemas that changes what a program does is read with its meaning or
refused with an error naming it (docs/toolchain/export.md, "Reading"): nothing is read with another
meaning. Spellings written by earlier vplc exports that the schemas refuse (``InOutVars``, ``Coil storage``,
``Jump label``, ``FbdObject Label / Return``, an enumeration's ``BaseType/TypeName``, an empty open-array
``DimensionSpec``, ``constant`` on a parameter list) are still read, each with a warning naming the rule.
"""
from __future__ import annotations

import threading
import xml.etree.ElementTree as ET

from ..frontend import ast as A
from ..frontend.diagnostics import DiagnosticBag
from ..frontend.parser import parse
from ..frontend.source import SourceFile
from .decls import FormatError, PouText, SectionText, TypeText, VarText, XmlUnit, join_inouts
from .model import EDGES, STORAGES, Conn, Element, LadderBody, Pin, Rung
from .xmlsafe import XSI_TYPE, text_of, xsi_type

POUS = {"Program": "PROGRAM", "FunctionBlock": "FUNCTION_BLOCK", "Function": "FUNCTION"}
PARAMS = {"InputVars": "VAR_INPUT", "OutputVars": "VAR_OUTPUT", "InOutVars": "VAR_IN_OUT", "InoutVars": "VAR_IN_OUT"}
# Elements of the Sysmac extension (namespace https://www.ia.omron.com/Smc) that may stand in an AddData/Data,
# and what reading them means. Anything else in an Omron Data block is refused by name.
SMC_IGNORED = {"DeviceInfo", "PouInfo", "GlobalVariableAdditionalProperties", "VariableComment",
               "EnumeratorsComment", "MultiComment", "FunctionResultComment", "ConnectionPointInOrder",
               "ConnectionPointOutOrder", "SmcSize"}   # identification, comments, network publish, drawing
SMC_READ = {"ParameterSetVariableAdditionalProperties", "StructTypeSpecAdditionalProperties"}
ELEMENTARY = {"BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD",
              "LWORD", "REAL", "LREAL", "TIME", "DATE", "TIME_OF_DAY", "TOD", "DATE_AND_TIME", "DT", "STRING"}
LISTS = {"ExternalVars": "VAR_EXTERNAL", "Vars": "VAR", "TempVars": "VAR_TEMP"}
LD_OBJECTS = {"LeftPowerRail": "left_rail", "RightPowerRail": "right_rail", "Contact": "contact", "Coil": "coil"}
FBD_OBJECTS = {"Block": "block", "DataSource": "in_var", "DataSink": "out_var", "Jump": "jump", "Label": "label",
               "Return": "return"}
KNOWN = ", ".join([*LD_OBJECTS, *FBD_OBJECTS])


_state = threading.local()          # the warnings of the file being read (one reader per thread)


def _old(where: str, message: str) -> None:
    """A spelling of an earlier vplc export that Omron's schemas refuse: read with its meaning, and said."""
    warnings = getattr(_state, "warnings", None)
    if warnings is not None:
        warnings.append((where, message))


def read(root: ET.Element, warnings: list | None = None) -> list[XmlUnit]:
    """The units of the file; ``warnings`` receives (where, message) for each old-export spelling read."""
    _state.warnings = [] if warnings is None else warnings
    try:
        return _read(root)
    finally:
        _state.warnings = []


def _read(root: ET.Element) -> list[XmlUnit]:
    gns = root.find("Types/GlobalNamespace")
    units: dict[str | None, XmlUnit] = {None: XmlUnit(None)}
    header = root.find("ContentHeader")
    if header is not None:
        _add_data(header, "ContentHeader")
    if gns is not None:
        _no_using(gns)
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
            inner = item.get("name") or None
            if ns is not None and ns.count("\\") >= 31:
                raise FormatError(f"namespace {ns}", "namespaces nested deeper than 32 levels")
            if ns is not None and inner is not None:
                inner = f"{ns}\\{inner}"      # a nested namespace (Sysmac: Namespace1\Namespace1): its full name
            _namespace(item, inner, units)
        elif item.tag in ("DataTypeDecl", "UserDefinedTypeDecl"):
            unit.types.append(_data_type(item))
        elif item.tag in POUS:
            using = [(u.text or "").strip() for u in item.iterfind("UsingDirective") if (u.text or "").strip()]
            if len(using) > 1 or (using and ns is not None):
                raise FormatError(item.get("name", ""), "UsingDirective " + ", ".join(using) + ": vplc resolves "
                                  "the names of a POU in one namespace only; qualify the names instead")
            target = units.setdefault(using[0], XmlUnit(using[0])) if using else unit
            target.pous.append(_pou(item))


def _no_using(gns: ET.Element) -> None:
    """A UsingDirective changes how names resolve; vplc reads the one of a POU (see _namespace) and refuses
    it anywhere else (namespace, variable list, body, variable) rather than resolve names another way."""
    for el in gns.iter():
        if el.tag in POUS:
            continue
        for c in el:
            if c.tag == "UsingDirective" and (c.text or "").strip():
                name = el.get("name")
                raise FormatError(f"{el.tag}{' ' + name if name else ''}", f"UsingDirective {(c.text or '').strip()} "
                                  "is read on a POU only; vplc does not model it here: qualify the names instead")


def _add_data(el: ET.Element, where: str) -> dict[str, ET.Element]:
    """The Sysmac-extension elements in ``el``'s AddData, by name. A Data block of another vendor is skipped
    (the schema's handleUnknown="discard"); an element of Omron's block that vplc does not know is refused."""
    found: dict[str, ET.Element] = {}
    for data in el.iterfind("AddData/Data"):
        omron = "omron" in (data.get("name") or "").lower()
        for child in data:
            if child.tag in SMC_READ or child.tag in SMC_IGNORED:
                found[child.tag] = child
            elif omron:
                raise FormatError(where, f"unknown Sysmac extension element <smcext:{child.tag}> in AddData; vplc "
                                  "reads " + ", ".join(sorted(SMC_READ | SMC_IGNORED)))
    return found


def _smc_type(el: ET.Element) -> str:
    """``xsi:type`` with its prefix as written (``smcext:LdSection``)."""
    return el.get(XSI_TYPE, "")


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
    # dimensionNumber (xsd:unsignedInt, required) says which dimension a DimensionSpec is: read in that order,
    # not in the document's, so ARRAY[1..2, 1..5] never comes back as ARRAY[1..5, 1..2]
    numbered = [(_count(ds, "dimensionNumber", n, where), ds) for n, ds in enumerate(spec.iterfind("DimensionSpec"), 1)]
    for _number, ds in sorted(numbered, key=lambda p: p[0]):
        r = ds.find("IndexRange")
        if r is None and ds.find("VariableLength") is None:
            _old(where, "an open array dimension is an empty DimensionSpec; the schema needs IndexRange or "
                        "VariableLength (read as ARRAY[*])")
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
    edge = v.get("edgeDetection", "none")
    if edge not in ("", "none"):
        raise FormatError(f"{where}:variable {name}", f'edgeDetection="{edge}" (an input that is TRUE only on the '
                          "edge of its value) is not modelled by vplc; pass the edge from the caller "
                          "(R_TRIG / F_TRIG, or an edge contact)")
    _add_data(v, f"{where}:variable {name}")
    addr = v.find("Address")
    return VarText(name, type_text(v.find("Type"), f"{where}:variable {name}"), value_text(v.find("InitialValue")),
                   _doc(v), addr.get("address") if addr is not None else None)


def _list(kind: str, lst: ET.Element, where: str) -> SectionText:
    # constant / retain are xsd:boolean: "1" is as true as "true" (IEC61131_10_Ed1_0_Spc1_0.xsd, VarList)
    return SectionText(kind, [_var(v, where) for v in lst.iterfind("Variable")],
                       constant=_flag(lst, "constant", where), retain=_flag(lst, "retain", where))


def _data_type(dt: ET.Element) -> TypeText:
    name = dt.get("name", "")
    where = f"data type {name}"
    spec = dt.find("UserDefinedTypeSpec")
    kind = xsi_type(spec) if spec is not None else ""
    offset = "NJ"
    if spec is not None:
        props = _add_data(spec, where).get("StructTypeSpecAdditionalProperties")
        offset = props.get("offsetType", "NJ") if props is not None else "NJ"
        # W501 6-43 (member offsets, offset type CJ or User): the memory layout of the structure's members. No
        # behaviour of vplc depends on it (a structure is refused wherever its memory image would be read: AT,
        # union members, ToAryByte); it is kept and written back by the export
        if offset not in ("NJ", "CJ", "User"):
            raise FormatError(where, f'StructTypeSpecAdditionalProperties offsetType="{offset}": the schema allows '
                              "NJ, CJ and User")
    _add_data(dt, where)
    if spec is None:
        raise FormatError(where, "data type specification `?` is not supported")
    if kind == "StructTypeSpec":
        # overlap="true": Sysmac's union, the members sharing one memory image (W501 6-3-6)
        word = "UNION" if _flag(spec, "overlap", where) else "STRUCT"
        fields = "".join(f"    {_line(m_var)}{_trailing(m_var.comment)}\n"
                         for m_var in (_var(m, where) for m in spec.iterfind("Member")))
        text = f"{word}\n{fields}END_{word}"
    elif kind == "EnumTypeWithNamedValueSpec":
        values = ", ".join(f"{e.get('name')} := {e.get('value')}" for e in spec.iterfind("Enumerator"))
        text = f"({values})" + _enum_base(spec.find("BaseType"), where)
    elif kind == "EnumTypeSpec":
        text = "(" + ", ".join(e.get("name", "") for e in spec.iterfind("Enumerator")) + ")"
    elif kind == "ArrayTypeSpec":
        text = _array(spec, where)
    else:
        raise FormatError(where, f"data type specification `{kind or '?'}` is not supported")
    return TypeText(name, text, value_text(dt.find("InitialValue")), _doc(dt), offset)


def _enum_base(base: ET.Element | None, where: str) -> str:
    """The schema's BaseType is the elementary type name as text (ElementaryType: DINT)."""
    if base is None:
        _old(where, "an enumeration without BaseType; the schema requires it (read with vplc's default base "
                    "type, as the earlier export meant)")
        return ""
    if len(base):
        _old(where, "the enumeration's BaseType holds a TypeName element; the schema wants the type name as "
                    "text (<BaseType>DINT</BaseType>)")
        return f" {type_text(base, where)}"
    name = (base.text or "").strip()
    if name.upper() not in ELEMENTARY:
        raise FormatError(where, f"enumeration base type `{name}` is not an elementary type")
    return f" {name}"


def _trailing(comment: str) -> str:
    """A member's Documentation as the comment at the end of its line, where the export reads it back from."""
    return f" (* {comment.replace('(*', '( *').replace('*)', '* )')} *)" if comment else ""


def _line(v: VarText) -> str:
    at = f" AT {v.at}" if v.at else ""
    init = f" := {v.init}" if v.init is not None else ""
    return f"{v.name}{at} : {v.type}{init};"


# ---- POUs ----------------------------------------------------------------------------------------

def _pou(el: ET.Element) -> PouText:
    name = el.get("name", "")
    out = PouText(POUS[el.tag], name, comment=_doc(el))
    _add_data(el, name)
    rt = el.find("ResultType")
    if rt is not None:
        out.return_type = type_text(rt, f"{name}:result")
    params: list[tuple[int, str, ET.Element, ET.Element, bool]] = []
    for holder in [*el.iterfind("Parameters"), *el.iterfind("ParameterSet")]:
        for lst in holder:
            if lst.tag not in PARAMS:
                continue
            if lst.tag == "InOutVars":
                _old(name, "<InOutVars> is spelt InoutVars in the schema")
            if _flag(lst, "constant", name):
                _old(name, f"<{lst.tag} constant=\"true\">: the schema marks a constant parameter per variable "
                           "(smcext:ParameterSetVariableAdditionalProperties constant=\"true\")")
            for v in lst.iterfind("Variable"):
                props = _add_data(v, f"{name}:variable {v.get('name', '')}").get(
                    "ParameterSetVariableAdditionalProperties")
                constant = _flag(lst, "constant", name) or (
                    props is not None and _flag(props, "constant", f"{name}:variable {v.get('name', '')}"))
                order = _count(v, "orderWithinParamSet", len(params), f"{name}:variable {v.get('name', '')}")
                params.append((order, PARAMS[lst.tag], lst, v, constant))
    params.sort(key=lambda p: p[0])
    if out.kind == "FUNCTION":                           # Sysmac's EN / ENO are vplc's implicit EN / ENO
        params = [p for p in params if not _en_eno(p[1], p[3])]
    holder_of = None
    for _order, kind, lst, v, constant in params:        # declaration order; one section per source section
        if not out.sections or holder_of is not lst or out.sections[-1].constant != constant:
            out.sections.append(SectionText(kind, constant=constant, retain=_flag(lst, "retain", name)))
            holder_of = lst
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
    elif kinds <= {"LdSection", "LD"}:
        contents.sort(key=lambda c: _count(c, "evaluationOrder", 0, f"{name}:body {c.get('name', '')}".rstrip()))
        rungs = []
        for section in contents:
            rungs += _rungs(section, name)
        out.ladder = LadderBody(name, rungs)
    else:
        raise FormatError(name, f"body type {', '.join(sorted(kinds))} is not supported; the virtual PLC runs ST "
                                "and LD (LD, smcext:LdSection)")
    return out


def _en_eno(kind: str, v: ET.Element) -> bool:
    """A function's ``EN`` input or ``ENO`` output of type BOOL."""
    want = {"VAR_INPUT": "EN", "VAR_OUTPUT": "ENO"}.get(kind)
    return want is not None and v.get("name", "").upper() == want and \
        (v.findtext("Type/TypeName") or "").strip().upper() == "BOOL"


def _count(el: ET.Element, attr: str, default: int, where: str) -> int:
    """An ordering attribute (orderWithinParamSet, evaluationOrder: xsd:integer); anything else is refused."""
    text = (el.get(attr) or "").strip()
    if not text:
        return default
    try:
        return int(text)
    except ValueError:
        raise FormatError(where, f'{attr}="{text[:40]}" is not an integer') from None


def _rungs(section: ET.Element, pou: str) -> list[Rung]:
    items = list(section.iterfind("Rung"))
    items.sort(key=lambda r: _count(r, "evaluationOrder", 0, f"{pou}:rung"))
    return [_rung(r, pou, n) for n, r in enumerate(items, start=1)]


def _point_ins(el: ET.Element, outs: dict) -> list[Conn]:
    return [outs.get(c.get("refConnectionPointOutId", ""), Conn("?" + c.get("refConnectionPointOutId", "")))
            for pt in el.iterfind("ConnectionPointIn") for c in pt.iterfind("Connection")]


def _inline_st(obj: ET.Element, where: str) -> str:
    """The statements of Sysmac's smcext:InlineST (ST inside a rung, run while the rung gives it power). They
    must be statements only, whole: they are checked alone before they join the POU's generated text, so a
    fragment cannot close the POU around it or leave a block open."""
    st = obj.find("ST")
    if st is None:
        raise FormatError(where, "smcext:InlineST without its ST element")
    text = text_of(st)
    diags = DiagnosticBag()
    unit = parse(SourceFile(where, f"PROGRAM InlineST\n{text}\nEND_PROGRAM\n"), diags)
    errors = [d for d in diags.items if d.severity == "error"]
    items = unit.items
    if errors or len(items) != 1 or not isinstance(items[0], A.Pou) or items[0].sections:
        why = errors[0].message if errors else "it must hold statements only (no declarations, no POUs)"
        raise FormatError(where, f"smcext:InlineST: {why}")
    return text


def _rung(r: ET.Element, pou: str, number: int) -> Rung:
    rung = Rung([], label=r.get("label", "") or "")
    objects = []
    outs: dict[str, Conn] = {}
    for index, obj in enumerate(r, start=1):
        kind = xsi_type(obj)
        if obj.tag == "CommonObject" and kind == "Comment":
            rung.comment = f"{rung.comment}\n{text_of(obj.find('Content'))}".strip()
            continue
        place = f"{pou}:rung {number}:element {index}"
        inline = obj.tag == "LdObject" and _smc_type(obj) == "smcext:InlineST"
        table = LD_OBJECTS if obj.tag == "LdObject" else FBD_OBJECTS if obj.tag == "FbdObject" else {}
        if inline:
            table = {kind: "inline_st"}
        if kind not in table:
            if obj.tag in ("AddData", "Documentation"):
                continue
            raise FormatError(place, f"unknown element <{obj.tag} xsi:type=\"{_smc_type(obj) or kind}\"> in a rung; "
                                     f"a rung has {KNOWN}")
        if kind in ("Label", "Return"):
            _old(place, f"<FbdObject xsi:type=\"{kind}\"> is not in the schema (a label is the Rung's label "
                        "attribute; a return is a jump to the last rung)")
        if kind == "DataSink" and not obj.get("identifier", "") and obj.find("ConnectionPointOut") is None:
            continue                                     # Sysmac's empty sink: an output written nowhere
        eid = obj.get("globalId") or f"r{number}e{index}"
        ekind = table[kind]
        if ekind == "out_var" and obj.find("ConnectionPointOut") is not None:
            _old(place, "a DataSink with a ConnectionPointOut is not in the schema (read as a variable written "
                        "and read on)")
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
            where = f"{pou}:rung {number}:{e.kind} {e.var}"
            e.negated = _flag(obj, "negated", where, ("true", "1", "negated"))
            e.edge = _choice(obj, "edge", EDGES, where)
            if e.kind == "coil":
                e.storage = _latch(obj, where)
        elif e.kind in ("in_var", "out_var", "inout_var"):
            e.var = obj.get("identifier", "")
            e.negated = _flag(obj, "negated", where)
        elif e.kind == "jump":
            e.var = obj.get("targetNetworkLabel", "")
            if not e.var and obj.get("label"):
                _old(where, "a Jump names its target in targetNetworkLabel, not label")
                e.var = obj.get("label", "")
            if not e.var:
                raise FormatError(where, "a Jump without targetNetworkLabel: name the label of the rung to jump to")
        elif e.kind == "label":
            e.var = obj.get("label", "")
        elif e.kind == "inline_st":
            e.var = _inline_st(obj, f"{pou}:rung {number}:inline ST")
        elif e.kind == "block":
            e.type_name = obj.get("typeName", "")
            e.instance = obj.get("instanceName", "") or ""
            where = f"{pou}:rung {number}:block {e.type_name}"
            for v in obj.iterfind("InputVariables/InputVariable"):
                e.inputs.append(Pin(v.get("parameterName", ""), _point_ins(v, outs),
                                    _flag(v, "negated", where), _choice(v, "edge", EDGES, where)))
            for v in obj.iterfind("InOutVariables/InOutVariable"):
                if _flag(v, "negated", where):
                    raise FormatError(where, f"in-out `{v.get('parameterName', '')}` is negated; an in-out passes the "
                                      "variable itself and cannot be negated")
                e.inouts.append(Pin(v.get("parameterName", ""), _point_ins(v, outs)))
            for v in obj.iterfind("OutputVariables/OutputVariable"):
                e.outputs.append(Pin(v.get("parameterName", ""), negated=_flag(v, "negated", where)))
            join_inouts(e, where)
        if e.kind != "block" and e.kind not in ("left_rail", "in_var", "label"):
            e.inputs = [Pin("", _point_ins(obj, outs))]
        if e.kind == "label":
            rung.label = rung.label or e.var
            continue
        rung.elements.append(e)
    return rung


def _flag(el: ET.Element, name: str, where: str, true=("true", "1")) -> bool:
    """An xsd:boolean attribute (``true``/``1``, ``false``/``0``); anything else is refused."""
    value = el.get(name, "false")
    if value in true:
        return True
    if value in ("false", "0", ""):
        return False
    raise FormatError(where, f'{name}="{value}" is not a boolean (true, false, 1, 0)')


def _latch(coil: ET.Element, where: str) -> str:
    """A set / reset coil: the schema's ``latch``; ``storage`` is the spelling of earlier vplc exports."""
    latch = _choice(coil, "latch", STORAGES, where)
    storage = _choice(coil, "storage", STORAGES, where)
    if storage != "none":
        _old(where, f'Coil storage="{storage}": the schema spells it latch="{storage}"')
        if latch not in ("none", storage):
            raise FormatError(where, f'latch="{latch}" and storage="{storage}" contradict each other')
        return storage
    return latch


def _choice(el: ET.Element, name: str, allowed, where: str) -> str:
    value = el.get(name, "none") or "none"
    if value not in allowed:
        raise FormatError(where, f"{name}=\"{value}\" is not one of {', '.join(allowed)}")
    return value
