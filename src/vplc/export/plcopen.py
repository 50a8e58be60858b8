"""PLCopen XML TC6 v2.01 writer (``vplc export --format plcopen``): the exchange format of CODESYS,
Beremiz / OpenPLC and many other IDEs. Valid against the official schema ``tc6_xml_v201.xsd`` (checked by
tests/vplc/export/test_export_plcopen.py)::

    project (xmlns = http://www.plcopen.org/xml/tc6_0201)
      fileHeader  contentHeader/coordinateInfo (fbd, ld, sfc scaling 1)
      types
        dataTypes/dataType name     baseType (struct | enum | array | derived | elementary), initialValue
        pous/pou name pouType       interface (returnType, inputVars outputVars inOutVars externalVars
                                    localVars tempVars), body: ST (the text as written) or LD (ladders)
      instances/configurations/configuration/globalVars   (the VAR_GLOBAL lists)

TC6 has no namespaces: an object of a library namespace carries it in ``addData`` (``data name=`` the URI
below, ``<namespace name="CBT_Commands_Lib"/>``); IDEs that do not know it discard it (``handleUnknown``),
and :mod:`vplc.ladder.plcopen_read` puts the object back into its namespace. An open array ``ARRAY[*]``
(TC6 has no open dimension) is written as a ``derived`` type named ``ARRAY[*] OF BYTE``. A UNION (TC6 has
none) and a rung of Sysmac inline ST are refused by name, never written with another meaning.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from .. import __version__
from ..frontend import ast as A
from ..ladder.model import WriteError
from ..ladder.plcopen_write import XHTML_NS, formatted, ld_body
from ..project import Project
from .iec61131_10 import COMPANY, PRODUCT, creation_time, to_bytes
from .model import ExportError, ExportSet, PouItem, TypeItem, enum_values, expr_text, type_text

PLCOPEN_NS = "http://www.plcopen.org/xml/tc6_0201"
POU_TYPE = {"FUNCTION": "function", "FUNCTION_BLOCK": "functionBlock", "PROGRAM": "program"}
LISTS = (("VAR_INPUT", "inputVars"), ("VAR_OUTPUT", "outputVars"), ("VAR_IN_OUT", "inOutVars"),
         ("VAR_EXTERNAL", "externalVars"), ("VAR", "localVars"), ("VAR_STAT", "localVars"), ("VAR_TEMP", "tempVars"))
ELEMENTARY = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT",
              "ULINT", "REAL", "LREAL", "TIME", "DATE", "DT", "TOD"}
ALIASES = {"DATE_AND_TIME": "DT", "TIME_OF_DAY": "TOD"}
NAMESPACE_DATA = "https://github.com/cbt-commands-lib/vplc/namespace"


def _namespace(parent: ET.Element, namespace: str | None) -> None:
    if namespace:
        data = _sub(_sub(parent, "addData"), "data", {"name": NAMESPACE_DATA, "handleUnknown": "discard"})
        _sub(data, "namespace", {"name": namespace})


def _sub(parent: ET.Element, tag: str, attrs: dict | None = None, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, tag, attrs or {})
    if text is not None:
        el.text = text
    return el


def _type(parent: ET.Element, ref: A.TypeRef) -> None:
    """A ``dataType`` child: elementary element, string, array, enum, subrange or derived name."""
    if isinstance(ref, A.StringTypeRef):
        attrs = {"length": expr_text(ref.length)} if ref.length is not None else {}
        _sub(parent, "wstring" if ref.wide else "string", attrs)
    elif isinstance(ref, A.ArrayTypeRef):
        bounds = [(dim.lo, dim.hi) for dim in ref.dims if dim.lo is not None and dim.hi is not None]
        if len(bounds) < len(ref.dims):
            _sub(parent, "derived", {"name": type_text(ref)})     # ARRAY[*]: TC6 has no open dimension
        else:
            arr = _sub(parent, "array")
            for lo, hi in bounds:
                _sub(arr, "dimension", {"lower": expr_text(lo), "upper": expr_text(hi)})
            _type(_sub(arr, "baseType"), ref.element)
    elif isinstance(ref, A.EnumTypeRef):
        en = _sub(parent, "enum")
        values = _sub(en, "values")
        for v in ref.values:
            attrs = {"name": v.name}
            if v.value is not None:
                attrs["value"] = expr_text(v.value)
            _sub(values, "value", attrs)
        if ref.base is not None:
            _type(_sub(en, "baseType"), ref.base)
    elif isinstance(ref, A.SubrangeTypeRef):
        sub = _sub(parent, "subrangeSigned")
        _sub(sub, "range", {"lower": expr_text(ref.lo), "upper": expr_text(ref.hi)})
        _type(_sub(sub, "baseType"), ref.base)
    elif isinstance(ref, A.StructTypeRef):
        st = _sub(parent, "struct")
        for f in ref.fields:
            _variable(st, f, "")
    else:
        name = type_text(ref)
        upper = ALIASES.get(name.upper(), name.upper())
        if upper in ELEMENTARY:
            _sub(parent, upper)
        else:
            _sub(parent, "derived", {"name": name})


def _value(parent: ET.Element, e: A.Expr) -> None:
    if isinstance(e, A.ArrayInit):
        av = _sub(parent, "arrayValue")
        for item in e.items:
            attrs = {"repetitionValue": expr_text(item.repeat)} if item.repeat is not None else {}
            v = _sub(av, "value", attrs)
            if item.value is not None:
                _value(v, item.value)
            else:
                _sub(v, "simpleValue")
    elif isinstance(e, A.StructInit):
        sv = _sub(parent, "structValue")
        for f in e.fields:
            _value(_sub(sv, "value", {"member": f.name}), f.value)
    else:
        _sub(parent, "simpleValue", {"value": expr_text(e)})


def _variable(parent: ET.Element, d: A.VarDecl, comment: str) -> None:
    attrs = {"name": d.name}
    if d.at:
        attrs["address"] = d.at
    v = _sub(parent, "variable", attrs)
    _type(_sub(v, "type"), d.type)
    if d.init is not None:
        _value(_sub(v, "initialValue"), d.init)
    if comment:
        formatted(v, "documentation", comment)


def _list_attrs(section: A.VarSection) -> dict:
    attrs = {}
    if section.constant:
        attrs["constant"] = "true"
    if section.retain:
        attrs["retain"] = "true"
    return attrs


def _data_type(parent: ET.Element, item: TypeItem, project: Project) -> None:
    decl = item.decl
    spec = decl.spec
    if isinstance(spec, A.StructTypeRef) and spec.union:
        # TC6 has no union: a struct would give every member its own memory (W501 6-3-6: a union's members share
        # one), so another IDE, and vplc reading the file back, would run it with another meaning.
        raise ExportError(f"{item.path}: data type `{decl.name}` is a UNION, which PLCopen TC6 cannot express (a "
                          "struct would not share the members' memory); export it with --format iec61131-10 "
                          "(StructTypeSpec overlap=\"true\")")
    dt = _sub(parent, "dataType", {"name": decl.name})
    if isinstance(spec, A.EnumTypeRef):              # write the values the compiler counts, as the 61131-10 export
        values = enum_values(project, item)
        spec = A.EnumTypeRef([A.EnumValueDecl(v.name, A.Literal(kind="int", value=values[v.name.upper()],
                                                                 text=str(values[v.name.upper()])))
                              for v in spec.values], spec.base)
    _type(_sub(dt, "baseType"), spec)
    if decl.init is not None:
        _value(_sub(dt, "initialValue"), decl.init)
    _namespace(dt, item.namespace)
    if item.comment:
        formatted(dt, "documentation", item.comment)


def _pou(parent: ET.Element, item: PouItem) -> None:
    pou = item.pou
    el = _sub(parent, "pou", {"name": pou.name, "pouType": POU_TYPE[pou.kind]})
    iface = _sub(el, "interface")
    if pou.kind == "FUNCTION" and pou.return_type is not None:     # (the checker requires one)
        _type(_sub(iface, "returnType"), pou.return_type)
    ladder = getattr(pou, "ladder", None)
    helpers = {h.upper() for h in (ladder.helpers if ladder is not None else [])}
    for section in pou.sections:
        tag = dict(LISTS).get(section.kind)
        decls = [d for d in section.vars if d.name.upper() not in helpers]
        if tag is None or not decls:
            continue
        if pou.kind == "FUNCTION" and section.kind == "VAR":
            tag = "tempVars"
        lst = _sub(iface, tag, _list_attrs(section))
        for d in decls:
            _variable(lst, d, item.var_comments.get(id(d), ""))
    body = _sub(el, "body")
    if ladder is not None:
        ld_body(body, ladder)
    else:
        formatted(body, "ST", item.body)
    _namespace(el, item.namespace)
    if item.comment:
        formatted(el, "documentation", item.comment)


def build(export: ExportSet, project: Project) -> ET.Element:
    root = ET.Element("project", {"xmlns": PLCOPEN_NS, "xmlns:xhtml": XHTML_NS})
    stamp = creation_time()
    _sub(root, "fileHeader", {"companyName": COMPANY, "productName": PRODUCT, "productVersion": __version__,
                              "creationDateTime": stamp})
    ch = _sub(root, "contentHeader", {"name": export.name, "modificationDateTime": stamp})
    ci = _sub(ch, "coordinateInfo")
    for lang in ("fbd", "ld", "sfc"):
        _sub(_sub(ci, lang), "scaling", {"x": "1", "y": "1"})
    types = _sub(root, "types")
    data_types = _sub(types, "dataTypes")
    refused: list[str] = []              # every construct TC6 cannot express, reported together
    for t in export.types:
        try:
            _data_type(data_types, t, project)
        except ExportError as exc:
            refused.append(str(exc))
    pous = _sub(types, "pous")
    for p in export.pous:
        try:
            _pou(pous, p)
        except WriteError as exc:
            refused.append(f"{p.path}: {p.kind} `{p.name}`: {exc}")
    if refused:
        raise ExportError("\n".join(refused))
    configs = _sub(_sub(root, "instances"), "configurations")
    if export.globals:
        cfg = _sub(configs, "configuration", {"name": export.name})
        for g in export.globals:
            for section in g.gvl.sections:
                lst = _sub(cfg, "globalVars", _list_attrs(section))
                for d in section.vars:
                    _variable(lst, d, g.var_comments.get(id(d), ""))
    return root


def render(export: ExportSet, project: Project) -> bytes:
    return to_bytes(build(export, project))
