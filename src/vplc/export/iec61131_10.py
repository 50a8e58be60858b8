"""IEC 61131-10 Ed.1 XML writer (the exchange format of Sysmac Studio's Tools > IEC 61131-10 XML > Import).

Every file validates against Omron's two schemas (``IEC61131_10_Ed1_0_Spc1_0.xsd`` and its Sysmac extension
``IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd``, tests/vplc/export/test_export_sysmac_xsd.py); element and
attribute names below are the schemas' own. Layout::

    Project (xmlns = www.iec.ch/public/TC65SC65BWG7TF10)
      FileHeader companyName productName productVersion
      ContentHeader name creationDateTime / AddDataInfo/Info (the Sysmac extension is declared)
      Types
        GlobalNamespace
          NamespaceDecl name="CBT_Commands_Lib"           (omitted with flat=True)
            DataTypeDecl name                              (dependency order)
              Documentation? UserDefinedTypeSpec xsi:type="StructTypeSpec" | "EnumTypeWithNamedValueSpec" |
                                                 "ArrayTypeSpec"
            Function | FunctionBlock name                  (call-dependency order)
              Documentation? ResultType? Parameters(InoutVars | InputVars | OutputVars, one per ST section)
              ExternalVars* Vars* | TempVars* MainBody/BodyContent xsi:type="ST"/ST | "LD"/Rung*
          Program name                                     (the schema allows programs in GlobalNamespace only)
            Documentation? AddData(smcext:PouInfo) ExternalVars* Vars* MainBody/BodyContent "ST" | "smcext:LdSection"
      Instances
        Configuration/Resource/GlobalVars                  (only when the sources declare VAR_GLOBAL)

Every variable is ``Variable name [orderWithinParamSet]`` with the children Documentation, AddData, Type,
InitialValue, Address in that order. The ST body is the source text unchanged. Output is deterministic:
no wall-clock time, attributes in a fixed order, items in dependency order.
"""
from __future__ import annotations

import os
import re
import time
import xml.etree.ElementTree as ET

from .. import __version__
from ..frontend import ast as A
from ..ladder.iec10_write import ld_body
from ..project import Project
from .model import ExportError, ExportSet, PouItem, TypeItem, enum_values, expr_text, type_text

IEC_NS = "www.iec.ch/public/TC65SC65BWG7TF10"
XSI_NS = "http://www.w3.org/2001/XMLSchema-instance"
SMC_NS = "https://www.ia.omron.com/Smc"
SMC_SCHEMA = "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
# The name under which Sysmac-generated files declare (AddDataInfo/Info) and use (AddData/Data) the Omron
# extension, and its vendor: as in the public generator meyn-git/meyncraft, whose files Sysmac Studio imports.
SMC_DATA_NAME = f"{SMC_NS} {SMC_SCHEMA}"
SCHEMA_VERSION = "1"
COMPANY = "CBT_Commands_Lib project"
PRODUCT = "vplc (open IEC 61131-3 ST toolchain)"
POU_ELEMENT = {"FUNCTION": "Function", "FUNCTION_BLOCK": "FunctionBlock", "PROGRAM": "Program"}
# ParameterSet of the base schema: the in-out list is spelt ``InoutVars``.
PARAM_ELEMENT = {"VAR_INPUT": "InputVars", "VAR_OUTPUT": "OutputVars", "VAR_IN_OUT": "InoutVars"}
# EnumTypeWithNamedValueSpec/BaseType is the simple type ElementaryType, whose only value is DINT: a Sysmac
# enumeration is always DINT-sized (values outside DINT are refused).
ENUM_BASE = "DINT"
DINT_RANGE = (-2**31, 2**31 - 1)


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


def _add_data(parent: ET.Element, tag: str, attrs: dict) -> None:
    """``AddData/Data`` holding one element of the Omron extension (``smcext:`` prefix)."""
    data = _sub(_sub(parent, "AddData"), "Data", {"name": SMC_DATA_NAME, "handleUnknown": "discard"})
    _sub(data, f"smcext:{tag}", attrs)


# ---- types ---------------------------------------------------------------------------------------

def _bound(e: A.Expr) -> str:
    return str(e.value) if isinstance(e, A.Literal) and e.kind == "int" else expr_text(e)


def _array_spec(el: ET.Element, ref: A.ArrayTypeRef) -> None:
    """Children of an ArrayTypeSpec: BaseType, then one DimensionSpec per dimension."""
    _type_into(_sub(el, "BaseType"), ref.element)
    for n, dim in enumerate(ref.dims, start=1):
        ds = _sub(el, "DimensionSpec", {"dimensionNumber": str(n)})
        if dim.lo is None or dim.hi is None:        # ARRAY[*]: the schema's VariableLength (fixed "true")
            _sub(ds, "VariableLength", text="true")
        else:
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


def _variable(parent: ET.Element, tag: str, d: A.VarDecl, comment: str, order: int | None = None, *,
              constant: bool = False, plain: bool = False) -> None:
    """One Variable (or Member). ``constant``: a CONSTANT parameter, which the schema marks per variable
    (``smcext:ParameterSetVariableAdditionalProperties constant="true"``; ParameterSet lists have no
    ``constant`` attribute). ``plain``: an ExternalVars entry (VariableDeclPlain: no InitialValue, no Address)."""
    attrs = {"name": d.name}
    if order is not None:
        attrs["orderWithinParamSet"] = str(order)
    v = _sub(parent, tag, attrs)
    _doc(v, comment)
    if constant:
        _add_data(v, "ParameterSetVariableAdditionalProperties", {"constant": "true"})
    _type_into(_sub(v, "Type"), d.type)
    if plain:
        return
    if d.init is not None:
        _value_into(_sub(v, "InitialValue"), d.init)
    if d.at:
        _sub(v, "Address", {"address": d.at})


def _data_type(parent: ET.Element, item: TypeItem, project: Project) -> None:
    decl = item.decl
    if decl.init is not None:
        raise ExportError(f"{item.path}: data type `{decl.name}` has an initial value of its own; IEC 61131-10 "
                          "(UserDefinedTypeDecl) and Sysmac Studio's data types have none: give the initial "
                          "value to the variables or members of that type")
    el = _sub(parent, "DataTypeDecl", {"name": decl.name})
    _doc(el, item.comment)
    spec = decl.spec
    if isinstance(spec, A.StructTypeRef):
        ts = _sub(el, "UserDefinedTypeSpec", {"xsi:type": "StructTypeSpec", **({"overlap": "true"} if spec.union
                                                                               else {})})
        for f in spec.fields:
            _variable(ts, "Member", f, item.member_comments.get(id(f), ""))
        offset_type = getattr(decl, "offset_type", None)      # kept from the file it was read from (ladder/load)
        if offset_type in ("CJ", "User"):
            _add_data(ts, "StructTypeSpecAdditionalProperties", {"offsetType": offset_type})
    elif isinstance(spec, A.EnumTypeRef):
        ts = _sub(el, "UserDefinedTypeSpec", {"xsi:type": "EnumTypeWithNamedValueSpec"})
        values = enum_values(project, item)
        for v in spec.values:
            value = values[v.name.upper()]
            if not DINT_RANGE[0] <= value <= DINT_RANGE[1]:
                raise ExportError(f"{item.path}: enumeration `{decl.name}`: value {v.name} = {value} is outside "
                                  "DINT; Sysmac enumerations are DINT")
            _sub(ts, "Enumerator", {"name": v.name, "value": str(value)})
        _sub(ts, "BaseType", text=ENUM_BASE)
    elif isinstance(spec, A.ArrayTypeRef):
        _array_spec(_sub(el, "UserDefinedTypeSpec", {"xsi:type": "ArrayTypeSpec"}), spec)
    else:
        raise ExportError(f"{item.path}: data type `{decl.name}` ({type_text(spec)}) is an alias or subrange "
                          "type; the IEC 61131-10 export writes structures, enumerations and arrays only")


# ---- POUs ----------------------------------------------------------------------------------------

def _refuse(item: PouItem, what: str) -> None:
    raise ExportError(f"{item.path}: {item.kind} `{item.name}`: {what}")


def _pou(parent: ET.Element, item: PouItem, external: list, using: str | None = None) -> None:
    """``using``: the namespace of a program written outside it (its names resolve there: UsingDirective)."""
    pou = item.pou
    el = _sub(parent, POU_ELEMENT[pou.kind], {"name": pou.name})
    _doc(el, item.comment)
    if pou.kind == "PROGRAM":                       # Sysmac writes PouInfo for each program
        _add_data(el, "PouInfo", {"version": __version__, "creationDateTime": creation_time(),
                                  "modificationDateTime": creation_time()})
    if using:
        _sub(el, "UsingDirective", text=using)
    comment = item.var_comments
    if pou.kind == "FUNCTION":
        if pou.return_type is None:
            raise ExportError(f"{item.path}: FUNCTION `{pou.name}` has no result type")
        _type_into(_sub(el, "ResultType"), pou.return_type)
    _parameters(el, item)
    ladder = getattr(pou, "ladder", None)
    helpers = {h.upper() for h in (ladder.helpers if ladder is not None else [])}   # the translation's own
    _external_vars(el, item, external)
    for section in pou.sections:
        decls = [d for d in section.vars if d.name.upper() not in helpers]
        if not decls or section.kind in PARAM_ELEMENT or section.kind == "VAR_EXTERNAL":
            continue
        if pou.kind == "FUNCTION":                  # a function's VAR are temporaries
            tag, attrs = "TempVars", {}
        elif section.kind == "VAR_TEMP":            # FunctionBlock and Program have no TempVars in the schema
            _refuse(item, "VAR_TEMP has no counterpart in Sysmac Studio's function blocks and programs "
                          "(the schema has TempVars for functions only); declare the variables in VAR")
        else:
            tag, attrs = "Vars", {"accessSpecifier": "private"}
        lst = _sub(el, tag, {**attrs, **_qualifiers(section)})
        for d in decls:
            _variable(lst, "Variable", d, comment.get(id(d), ""))
    if ladder is not None:                          # a ladder POU keeps its rungs
        _check_ladder(item, ladder)
        ld_body(_sub(el, "MainBody"), ladder, section=pou.kind == "PROGRAM")
        return
    bc = _sub(_sub(el, "MainBody"), "BodyContent", {"xsi:type": "ST"})
    _sub(bc, "ST", text=item.body)


def _check_ladder(item: PouItem, ladder) -> None:
    """Ladder elements the schema cannot express are refused, never written with another meaning: a
    DataSource / DataSink has no ``negated`` and a DataSink no output (PLCopen's inOutVariable)."""
    for n, rung in enumerate(ladder.rungs, start=1):
        for e in rung.elements:
            where = f"rung {n}: {e.describe()}"
            if e.kind == "inout_var":
                _refuse(item, f"{where} is written and read on in the rung (PLCopen inOutVariable); IEC 61131-10's "
                              "DataSink has no output: use a coil (BOOL) or a second rung that reads the variable")
            if e.kind in ("in_var", "out_var") and e.negated:
                _refuse(item, f"{where} is negated; IEC 61131-10's DataSource / DataSink have no negation: "
                              "negate the pin of the block instead")


def _parameters(el: ET.Element, item: PouItem) -> None:
    """``Parameters``: one list per source section, so each keeps its own RETAIN (the schema's ``retain``
    on InputVars / OutputVars) and CONSTANT (per variable); ``orderWithinParamSet`` is one counter in
    declaration order. Functions always have it (the schema requires it) and start with ``EN``, the BOOL
    input every Sysmac function has (issue 24 field notes, docs/toolchain/export.md); vplc reads it as the
    implicit EN. Programs have none in the schema."""
    pou = item.pou
    sections = [s for s in pou.sections if s.kind in PARAM_ELEMENT and s.vars]
    if pou.kind == "PROGRAM":
        if sections:
            _refuse(item, f"{sections[0].kind} in a program has no counterpart in Sysmac Studio (the schema's "
                          "Program has no Parameters); use a function block or global variables")
        return
    ps = _sub(el, "Parameters")
    order = 0
    if pou.kind == "FUNCTION":
        own = next((d.name for s in sections for d in s.vars if d.name.upper() in ("EN", "ENO")), None)
        if own:
            _refuse(item, f"declares its own `{own}`; EN and ENO are the implicit input and output of every "
                          "Sysmac function: rename the parameter")
        en = _sub(_sub(ps, "InputVars"), "Variable", {"name": "EN", "orderWithinParamSet": "0"})
        _sub(_sub(en, "Type"), "TypeName", text="BOOL")
        _sub(_sub(en, "InitialValue"), "SimpleValue", {"value": "TRUE"})
        order = 1
    for s in sections:
        attrs = {}
        if s.retain:
            if s.kind == "VAR_IN_OUT":
                _refuse(item, "VAR_IN_OUT RETAIN: an in-out refers to the caller's variable and cannot be "
                              "retained (the schema's InoutVars has no retain)")
            attrs["retain"] = "true"
        if s.constant and s.kind == "VAR_OUTPUT":
            _refuse(item, "VAR_OUTPUT CONSTANT: an output cannot be constant")
        g = _sub(ps, PARAM_ELEMENT[s.kind], attrs)
        for d in s.vars:
            _variable(g, "Variable", d, item.var_comments.get(id(d), ""), order, constant=s.constant)
            order += 1


def _external_vars(el: ET.Element, item: PouItem, external: list) -> None:
    """Declared VAR_EXTERNAL sections, then one list for the globals the body uses without declaring them:
    Sysmac Studio needs every global a program uses among its external variables (field notes of
    engineers who imported generated files; meyncraft writes them the same way)."""
    for section in item.pou.sections:
        if section.kind == "VAR_EXTERNAL" and section.vars:
            lst = _sub(el, "ExternalVars", {"constant": "true"} if section.constant else {})
            for d in section.vars:
                _variable(lst, "Variable", d, item.var_comments.get(id(d), ""), plain=True)
    for constant in (True, False):
        group = [d for d, c in external if c == constant]
        if group:
            lst = _sub(el, "ExternalVars", {"constant": "true"} if constant else {})
            for d in group:
                _variable(lst, "Variable", d, "", plain=True)


def system_globals(project: Project) -> frozenset[int]:
    """Identities of the system-defined variables' declarations (the prelude's global lists: P_On, _CurrentTime,
    _MC_AX, ...). A POU uses them without an external variable (W501, system-defined variables; vplc's ST1009
    exempts them too), so the export never writes them into ExternalVars: Sysmac Studio declares them itself."""
    return frozenset(id(d) for unit in project.units if getattr(unit, "in_prelude", False)
                     for item in unit.items if isinstance(item, A.GlobalVarList)
                     for s in item.sections for d in s.vars)


def used_globals(item: PouItem, system: frozenset[int] = frozenset()) -> list:
    """(declaration, constant) of every user global the POU's body names without a VAR_EXTERNAL, first use first;
    ``system``: the declarations of the system-defined variables (:func:`system_globals`), which are left out."""
    declared = {d.name.upper() for s in item.pou.sections for d in s.vars}
    seen: dict[str, tuple] = {}
    for node in (n for stmt in item.pou.body for n in A.walk(stmt)):
        sym = getattr(node, "sym", None) if isinstance(node, A.Name) else None
        if sym is None or getattr(sym, "section", None) != "VAR_GLOBAL" or sym.decl is None:
            continue
        key = sym.name.upper()
        if key not in declared and key not in seen and id(sym.decl) not in system:
            seen[key] = (sym.decl, bool(sym.constant))
    return list(seen.values())


def _qualifiers(section: A.VarSection) -> dict:
    attrs = {}
    if section.constant:
        attrs["constant"] = "true"
    if section.retain:
        attrs["retain"] = "true"
    return attrs


# ---- document ------------------------------------------------------------------------------------

def _namespace_decl(containers: dict, ns: str) -> ET.Element:
    """The NamespaceDecl of ``ns``, nested as Sysmac nests namespaces (`A\\B` is a NamespaceDecl B inside A)."""
    if ns in containers:
        return containers[ns]
    outer, _, name = ns.rpartition("\\")
    parent = _namespace_decl(containers, outer) if outer else containers[None]
    containers[ns] = _sub(parent, "NamespaceDecl", {"name": name})
    return containers[ns]


def build(export: ExportSet, project: Project, *, flat: bool = False,
          device: tuple[str, str] | None = None) -> ET.Element:
    """The ``Project`` element of the export; ``device`` (model, version) names the controller."""
    root = ET.Element("Project", {
        "xmlns": IEC_NS,
        "xmlns:xsi": XSI_NS,
        "xmlns:smcext": SMC_NS,
        "xsi:schemaLocation": f"{SMC_NS} {SMC_SCHEMA}",
        "schemaVersion": SCHEMA_VERSION,
    })
    _sub(root, "FileHeader", {"companyName": COMPANY, "productName": PRODUCT, "productVersion": __version__})
    ch = _sub(root, "ContentHeader", {"name": export.name, "creationDateTime": creation_time()})
    _sub(_sub(ch, "AddDataInfo"), "Info", {"name": SMC_DATA_NAME, "vendor": SMC_NS})
    if device is not None:
        model, version = device
        _add_data(ch, "DeviceInfo", {"modelName": model, **({"version": version} if version else {})})
    gns = _sub(_sub(root, "Types"), "GlobalNamespace")
    containers: dict[str | None, ET.Element] = {None: gns}
    if not flat:
        for ns in export.namespaces:
            _namespace_decl(containers, ns)
    for t in export.types:
        _data_type(containers[None if flat else t.namespace], t, project)
    system = system_globals(project)
    for p in export.pous:                           # NamespaceDecl holds no Program in the schema
        where = None if flat or p.kind == "PROGRAM" else p.namespace
        using = p.namespace if not flat and where != p.namespace else None
        _pou(containers[where], p, used_globals(p, system), using=using)
    instances = _sub(root, "Instances")
    if export.globals:
        _globals(instances, export)
    if flat:
        _flatten_names(root, export)
    return root


# ST text outside comments and string literals: a qualified name (``ns\Name``, ``ns\Inner\eMode``), or a comment or
# string, which is kept as it is.
_QUALIFIED = re.compile(r"""(?P<keep>\(\*.*?\*\)|/\*.*?\*/|//[^\n]*|'(?:\$.|[^'$])*'|"(?:\$.|[^"$])*")"""
                        r"|(?P<name>[A-Za-z_]\w*(?:\\[A-Za-z_]\w*)+)", re.S)


def _flatten_names(root: ET.Element, export: ExportSet) -> None:
    """With ``--flat`` every object is written in the global namespace, so every reference to one must lose its
    namespace too: type names, initial values (``ns\\eMode#Idle``), ladder block types and the ST bodies. Only
    the namespaces of the exported objects are removed (a name of another namespace is left to the checker);
    comments and string literals are not touched. Two objects that would get the same name are refused."""
    # each exported namespace and every namespace enclosing it (rsplit with 0 splits is the namespace itself)
    spaces = {ns.upper().rsplit("\\", i)[0] for ns in export.namespaces for i in range(ns.count("\\") + 1)}
    seen: dict[str, str] = {}
    for item in export.items:
        full = f"{item.namespace}\\{item.name}" if item.namespace else item.name
        other = seen.setdefault(item.name.upper(), full)
        if other != full:
            raise ExportError(f"--flat: `{other}` and `{full}` would both be named `{item.name}` in the global "
                              "namespace; export without --flat, or rename one")

    def strip(text: str) -> str:
        def one(m: re.Match) -> str:
            name = m.group("name")
            if name is None:
                return m.group("keep")
            prefix, _, last = name.rpartition("\\")
            return last if prefix.upper() in spaces else name
        return _QUALIFIED.sub(one, text) if "\\" in text else text

    for el in root.iter():
        if el.tag == "Documentation":
            continue
        if el.text:
            el.text = strip(el.text)
        for key, value in el.attrib.items():
            if "\\" in value:
                el.set(key, strip(value))


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


def render(export: ExportSet, project: Project, *, flat: bool = False, device: tuple[str, str] | None = None) -> bytes:
    return to_bytes(build(export, project, flat=flat, device=device))
