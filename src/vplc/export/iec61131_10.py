"""IEC 61131-10 Ed.1 XML writer (the exchange format of Sysmac Studio's Tools > IEC 61131-10 XML > Import).

Layout of the file (element order as in Omron's published sample; docs/toolchain/export.md lists what
is not verified against Sysmac Studio)::

    Project (xmlns = www.iec.ch/public/TC65SC65BWG7TF10)
      FileHeader companyName productName productVersion
      ContentHeader name creationDateTime
      Types
        GlobalNamespace
          NamespaceDecl name="CBT_Commands_Lib"           (omitted with flat=True)
            DataTypeDecl name                              (dependency order)
              Documentation? UserDefinedTypeSpec xsi:type="StructTypeSpec" | "EnumTypeWithNamedValueSpec" |
                                                 "ArrayTypeSpec"   InitialValue?
            Function | FunctionBlock | Program name        (call-dependency order)
              Documentation? ResultType? Parameters(InputVars OutputVars InOutVars)? ExternalVars?
              Vars* TempVars? MainBody/BodyContent xsi:type="ST"/ST
      Instances
        Configuration/Resource/GlobalVars                  (only when the sources declare VAR_GLOBAL)

Every variable is ``Variable name [orderWithinParamSet]`` with the children Documentation, Type,
InitialValue, Address in that order. The ST body is the source text unchanged. Output is deterministic:
no wall-clock time, attributes in a fixed order, items in dependency order.
"""
from __future__ import annotations

import os
import time
import xml.etree.ElementTree as ET

from .. import __version__
from ..frontend import ast as A
from ..ladder.iec10_write import ld_body
from .model import ExportError, ExportSet, PouItem, TypeItem, enum_values, expr_text, type_text

IEC_NS = "www.iec.ch/public/TC65SC65BWG7TF10"
XSI_NS = "http://www.w3.org/2001/XMLSchema-instance"
SMC_NS = "https://www.ia.omron.com/Smc"
SMC_SCHEMA = "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
SCHEMA_VERSION = "1"
COMPANY = "CBT_Commands_Lib project"
PRODUCT = "vplc (open IEC 61131-3 ST toolchain)"
POU_ELEMENT = {"FUNCTION": "Function", "FUNCTION_BLOCK": "FunctionBlock", "PROGRAM": "Program"}
PARAM_ELEMENT = {"VAR_INPUT": "InputVars", "VAR_OUTPUT": "OutputVars", "VAR_IN_OUT": "InOutVars"}


def creation_time() -> str:
    """``SOURCE_DATE_EPOCH`` (reproducible-builds convention) as ISO 8601, else a fixed date.

    The file must not change when the sources do not, so the wall clock is never used.
    """
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "")
    seconds = int(epoch) if epoch.isdigit() else 0
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(seconds))


def _sub(parent: ET.Element, tag: str, attrs: dict | None = None, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag, attrs or {})
    if text is not None:
        el.text = text
    return el


def _doc(parent: ET.Element, text: str) -> None:
    if text:
        _sub(parent, "Documentation", {"xsi:type": "SimpleText"}, text=text)


# ---- types ---------------------------------------------------------------------------------------

def _bound(e: A.Expr) -> str:
    return str(e.value) if isinstance(e, A.Literal) and e.kind == "int" else expr_text(e)


def _array_spec(el: ET.Element, ref: A.ArrayTypeRef) -> None:
    """Children of an ArrayTypeSpec: BaseType, then one DimensionSpec per dimension."""
    _type_into(_sub(el, "BaseType"), ref.element)
    for n, dim in enumerate(ref.dims, start=1):
        ds = _sub(el, "DimensionSpec", {"dimensionNumber": str(n)})
        if dim.lo is not None:                      # ARRAY[*]: a DimensionSpec without IndexRange
            _sub(ds, "IndexRange", {"lower": _bound(dim.lo), "upper": _bound(dim.hi)})


def _type_into(el: ET.Element, ref: A.TypeRef) -> None:
    """Write a type reference into ``el`` (a Type, BaseType or ResultType element)."""
    if isinstance(ref, A.ArrayTypeRef):
        _array_spec(_sub(el, "InstantlyDefinedType", {"xsi:type": "ArrayTypeSpec"}), ref)
    else:                                           # elementary, user-defined, STRING[n]: by name
        _sub(el, "TypeName", text=type_text(ref))


def _value_into(el: ET.Element, e: A.Expr) -> None:
    """An initial value: SimpleValue, ArrayValue (Value repetitionValue) or StructValue (Value member)."""
    if isinstance(e, A.ArrayInit):
        av = _sub(el, "ArrayValue")
        for item in e.items:
            attrs = {"repetitionValue": expr_text(item.repeat)} if item.repeat is not None else {}
            v = _sub(av, "Value", attrs)
            if item.value is not None:
                _value_into(v, item.value)
    elif isinstance(e, A.StructInit):
        sv = _sub(el, "StructValue")
        for f in e.fields:
            _value_into(_sub(sv, "Value", {"member": f.name}), f.value)
    else:
        _sub(el, "SimpleValue", {"value": expr_text(e)})


def _variable(parent: ET.Element, tag: str, d: A.VarDecl, comment: str, order: int | None = None) -> None:
    attrs = {"name": d.name}
    if order is not None:
        attrs["orderWithinParamSet"] = str(order)
    v = _sub(parent, tag, attrs)
    _doc(v, comment)
    _type_into(_sub(v, "Type"), d.type)
    if d.init is not None:
        _value_into(_sub(v, "InitialValue"), d.init)
    if d.at:
        _sub(v, "Address", {"address": d.at})


def _data_type(parent: ET.Element, item: TypeItem, project) -> None:
    decl = item.decl
    el = _sub(parent, "DataTypeDecl", {"name": decl.name})
    _doc(el, item.comment)
    spec = decl.spec
    if isinstance(spec, A.StructTypeRef):
        ts = _sub(el, "UserDefinedTypeSpec", {"xsi:type": "StructTypeSpec"})
        for f in spec.fields:
            _variable(ts, "Member", f, item.member_comments.get(id(f), ""))
    elif isinstance(spec, A.EnumTypeRef):
        ts = _sub(el, "UserDefinedTypeSpec", {"xsi:type": "EnumTypeWithNamedValueSpec"})
        values = enum_values(project, item)
        for v in spec.values:
            _sub(ts, "Enumerator", {"name": v.name, "value": str(values[v.name.upper()])})
        if spec.base is not None:
            _type_into(_sub(ts, "BaseType"), spec.base)
    elif isinstance(spec, A.ArrayTypeRef):
        _array_spec(_sub(el, "UserDefinedTypeSpec", {"xsi:type": "ArrayTypeSpec"}), spec)
    else:
        raise ExportError(f"{item.path}: data type `{decl.name}` ({type_text(spec)}) is an alias or subrange "
                          "type; the IEC 61131-10 export writes structures, enumerations and arrays only")
    if decl.init is not None:
        _value_into(_sub(el, "InitialValue"), decl.init)


# ---- POUs ----------------------------------------------------------------------------------------

def _pou(parent: ET.Element, item: PouItem) -> None:
    pou = item.pou
    el = _sub(parent, POU_ELEMENT[pou.kind], {"name": pou.name})
    _doc(el, item.comment)
    comment = item.var_comments
    if pou.kind == "FUNCTION":
        if pou.return_type is None:
            raise ExportError(f"{item.path}: FUNCTION `{pou.name}` has no result type")
        _type_into(_sub(el, "ResultType"), pou.return_type)
    params = [(s, d) for s in pou.sections if s.kind in PARAM_ELEMENT for d in s.vars]
    if params:
        ps = _sub(el, "Parameters")
        order = {id(d): i for i, (_s, d) in enumerate(params)}    # one counter, declaration order
        for kind in ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT"):
            group = [(s, d) for s, d in params if s.kind == kind]
            if group:
                g = _sub(ps, PARAM_ELEMENT[kind], _qualifiers(group[0][0]))
                for _s, d in group:
                    _variable(g, "Variable", d, comment.get(id(d), ""), order[id(d)])
    _var_lists(el, item, "VAR_EXTERNAL", "ExternalVars", {})
    if pou.kind == "FUNCTION":                      # a function's VAR are temporaries
        _var_lists(el, item, ("VAR", "VAR_TEMP"), "TempVars", {})
    else:
        _var_lists(el, item, ("VAR", "VAR_STAT"), "Vars", {"accessSpecifier": "private"})
        _var_lists(el, item, "VAR_TEMP", "TempVars", {})
    ladder = getattr(pou, "ladder", None)
    if ladder is not None:                          # a ladder POU keeps its rungs (Sysmac's LdSection)
        ld_body(_sub(el, "MainBody"), ladder)
        return
    bc = _sub(_sub(el, "MainBody"), "BodyContent", {"xsi:type": "ST"})
    _sub(bc, "ST", text=item.body)


def _qualifiers(section: A.VarSection) -> dict:
    attrs = {}
    if section.constant:
        attrs["constant"] = "true"
    if section.retain:
        attrs["retain"] = "true"
    return attrs


def _var_lists(el: ET.Element, item: PouItem, kinds, tag: str, base_attrs: dict) -> None:
    """One list element per source section of ``kinds`` (sections differ in CONSTANT / RETAIN)."""
    kinds = (kinds,) if isinstance(kinds, str) else kinds
    ladder = getattr(item.pou, "ladder", None)
    helpers = {h.upper() for h in (ladder.helpers if ladder is not None else [])}   # the translation's own
    for section in item.pou.sections:
        decls = [d for d in section.vars if d.name.upper() not in helpers]
        if section.kind in kinds and decls:
            lst = _sub(el, tag, {**base_attrs, **_qualifiers(section)})
            for d in decls:
                _variable(lst, "Variable", d, item.var_comments.get(id(d), ""))


# ---- document ------------------------------------------------------------------------------------

def build(export: ExportSet, project, *, flat: bool = False) -> ET.Element:
    """The ``Project`` element of the export."""
    root = ET.Element("Project", {
        "xmlns": IEC_NS,
        "xmlns:xsi": XSI_NS,
        "xmlns:smcext": SMC_NS,
        "xsi:schemaLocation": f"{SMC_NS} {SMC_SCHEMA}",
        "schemaVersion": SCHEMA_VERSION,
    })
    _sub(root, "FileHeader", {"companyName": COMPANY, "productName": PRODUCT, "productVersion": __version__})
    _sub(root, "ContentHeader", {"name": export.name, "creationDateTime": creation_time()})
    gns = _sub(_sub(root, "Types"), "GlobalNamespace")
    containers: dict[str | None, ET.Element] = {None: gns}
    if not flat:
        for ns in export.namespaces:
            containers[ns] = _sub(gns, "NamespaceDecl", {"name": ns})
    for t in export.types:
        _data_type(containers[None if flat else t.namespace], t, project)
    for p in export.pous:
        _pou(containers[None if flat else p.namespace], p)
    instances = _sub(root, "Instances")
    if export.globals:
        _globals(instances, export)
    return root


def _globals(instances: ET.Element, export: ExportSet) -> None:
    res = _sub(_sub(instances, "Configuration", {"name": export.name}), "Resource",
               {"name": "Resource", "resourceTypeName": ""})
    for g in export.globals:
        for section in g.gvl.sections:
            lst = _sub(res, "GlobalVars", _qualifiers(section))
            for d in section.vars:
                _variable(lst, "Variable", d, g.var_comments.get(id(d), ""))


def to_bytes(root: ET.Element) -> bytes:
    """Serialised document: UTF-8, two-space indentation, LF line ends, trailing newline."""
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    return ('<?xml version="1.0" encoding="utf-8"?>\n' + body + "\n").encode("utf-8")


def render(export: ExportSet, project, *, flat: bool = False) -> bytes:
    return to_bytes(build(export, project, flat=flat))
