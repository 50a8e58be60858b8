"""IEC 61131-10 XML export of the real library: structure, completeness, interfaces, bodies, order."""
from __future__ import annotations

import xml.etree.ElementTree as ET

from tests.vplc.export.conftest import LIB, NS, XSI_TYPE, local, q
from vplc.frontend import ast as A
from vplc.frontend import printer
from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.parser import parse
from vplc.frontend.source import SourceFile

PARAM_TAG = {"in": "InputVars", "out": "OutputVars", "inout": "InoutVars"}
POU_TAG = {"FUNCTION": "Function", "FUNCTION_BLOCK": "FunctionBlock", "PROGRAM": "Program"}
# Element order rules of Omron's schemas (IEC61131_10_Ed1_0_Spc1_0.xsd; test_export_sysmac_xsd.py validates).
PROJECT_ORDER = ["FileHeader", "ContentHeader", "Types", "Instances"]
VARIABLE_ORDER = ["Documentation", "AddData", "Type", "InitialValue", "Address"]
DATATYPE_ORDER = ["Documentation", "UserDefinedTypeSpec"]
POU_ORDER = ["Documentation", "AddData", "UsingDirective", "ResultType", "Parameters", "ExternalVars", "Vars",
             "TempVars", "MainBody"]
PARAM_LISTS = {"InputVars", "OutputVars", "InoutVars"}


def _user_decls(proj):
    types, pous = {}, {}
    for unit in proj.units:
        if getattr(unit, "in_prelude", False):
            continue
        for item in unit.items:
            if isinstance(item, A.TypeBlock):
                for d in item.decls:
                    types[d.name] = d
            elif isinstance(item, A.Pou):
                pous[item.name] = item
    return types, pous


def _container(root):
    return root.find(f"{q('Types')}/{q('GlobalNamespace')}/{q('NamespaceDecl')}")


def _assert_order(children, rule, where):
    idx = [rule.index(local(c)) for c in children]
    assert all(local(c) in rule for c in children), f"{where}: unexpected child in {[local(c) for c in children]}"
    assert idx == sorted(idx), f"{where}: children out of order: {[local(c) for c in children]}"


def _type_text(type_el) -> str:
    """A Type/BaseType/ResultType element back to ST type text (for comparison with the printer)."""
    name = type_el.find(q("TypeName"))
    if name is not None:
        return name.text
    spec = type_el.find(q("InstantlyDefinedType"))
    assert spec.get(XSI_TYPE) == "ArrayTypeSpec"
    dims = []
    for ds in spec.findall(q("DimensionSpec")):
        r = ds.find(q("IndexRange"))
        dims.append("*" if r is None else f"{r.get('lower')}..{r.get('upper')}")
    return f"ARRAY[{', '.join(dims)}] OF {_type_text(spec.find(q('BaseType')))}"


def test_root_is_an_iec_61131_10_project_with_file_header_and_namespace(lib_root):
    assert lib_root.tag == q("Project")
    _assert_order(list(lib_root), PROJECT_ORDER, "Project")
    assert [local(c) for c in lib_root] == PROJECT_ORDER
    fh = lib_root.find(q("FileHeader"))
    assert fh.get("productName").startswith("vplc") and fh.get("companyName") and fh.get("productVersion")
    ch = lib_root.find(q("ContentHeader"))
    assert ch.get("name") == "CBT_Commands_Lib" and ch.get("creationDateTime")
    gns = lib_root.find(f"{q('Types')}/{q('GlobalNamespace')}")
    assert [(local(c), c.get("name")) for c in gns] == [("NamespaceDecl", "CBT_Commands_Lib")]


def test_every_library_type_is_exported_with_its_members_in_order(lib_root, lib_project):
    types, _ = _user_decls(lib_project)
    decls = {el.get("name"): el for el in _container(lib_root).findall(q("DataTypeDecl"))}
    assert set(decls) == set(types) and len(types) >= 25
    for name, decl in types.items():
        el = decls[name]
        _assert_order(list(el), DATATYPE_ORDER, name)
        spec = el.find(q("UserDefinedTypeSpec"))
        if isinstance(decl.spec, A.StructTypeRef):
            assert spec.get(XSI_TYPE) == "StructTypeSpec"
            members = spec.findall(q("Member"))
            assert [m.get("name") for m in members] == [f.name for f in decl.spec.fields]
            for m, f in zip(members, decl.spec.fields, strict=False):
                _assert_order(list(m), VARIABLE_ORDER, f"{name}.{f.name}")
                assert _type_text(m.find(q("Type"))) == printer.type_ref(f.type)
                init = m.find(f"{q('InitialValue')}/{q('SimpleValue')}")
                assert (init.get("value") if init is not None else None) == \
                    (printer.expr(f.init) if f.init is not None else None)
        else:
            assert isinstance(decl.spec, A.EnumTypeRef), f"{name}: the library has structures and enums only"
            assert spec.get(XSI_TYPE) == "EnumTypeWithNamedValueSpec"
            values = lib_project.lookup_type(name, "CBT_Commands_Lib").values
            assert [(e.get("name"), int(e.get("value"))) for e in spec.findall(q("Enumerator"))] == \
                list(values.items())


def test_struct_initial_values_arrays_and_strings_are_written(lib_root):
    conn = _container(lib_root).find(f"{q('DataTypeDecl')}[@name='stCBT_Connection']")
    timeout = conn.find(f".//{q('Member')}[@name='ReplyTimeout']")
    assert timeout.find(f"{q('InitialValue')}/{q('SimpleValue')}").get("value") == "T#5s"
    req = conn.find(f".//{q('Member')}[@name='Req']/{q('Type')}/{q('InstantlyDefinedType')}")
    assert req.get(XSI_TYPE) == "ArrayTypeSpec"
    assert [local(c) for c in req] == ["BaseType", "DimensionSpec"]
    assert req.find(f"{q('BaseType')}/{q('TypeName')}").text == "stCBT_Request"
    ds = req.find(q("DimensionSpec"))
    assert ds.get("dimensionNumber") == "1"
    assert ds.find(q("IndexRange")).attrib == {"lower": "1", "upper": "16"}
    stop = _container(lib_root).find(f"{q('FunctionBlock')}[@name='CBT_Stop']")
    descr = stop.find(f".//{q('Variable')}[@name='ErrorDescrip']/{q('Type')}/{q('TypeName')}")
    assert descr.text == "STRING[80]"


def test_every_pou_is_exported_with_its_interface_in_declaration_order(lib_root, lib_project):
    _, pous = _user_decls(lib_project)
    found = {el.get("name"): el for el in _container(lib_root) if local(el) in POU_TAG.values()}
    assert set(found) == set(pous) and len(pous) >= 20
    for name, pou in pous.items():
        el = found[name]
        assert local(el) == POU_TAG[pou.kind]
        _assert_order(list(el), POU_ORDER, name)
        pt = pou.sym
        params = el.find(q("Parameters"))
        got = []
        assert (params is not None) == (pou.kind != "PROGRAM"), f"{name}: Parameters (functions and FBs only)"
        if params is not None:
            assert {local(c) for c in params} <= PARAM_LISTS
            for group in params:
                for v in group.findall(q("Variable")):
                    got.append((int(v.get("orderWithinParamSet")), v.get("name"), local(group),
                                _type_text(v.find(q("Type")))))
        got.sort()
        assert [g[0] for g in got] == list(range(len(got)))
        if pou.kind == "FUNCTION":                   # every Sysmac function starts with EN
            assert got[0][1:] == ("EN", "InputVars", "BOOL")
            got = got[1:]
        assert [(n, g, t) for _i, n, g, t in got] == \
            [(p.name, PARAM_TAG[p.direction], printer.type_ref(p.decl.type)) for p in pt.params]
        locals_tag = "TempVars" if pou.kind == "FUNCTION" else "Vars"
        want_locals = [d.name for s in pou.sections if s.kind in ("VAR", "VAR_TEMP") for d in s.vars]
        got_locals = [v.get("name") for lst in el.findall(q(locals_tag)) for v in lst.findall(q("Variable"))]
        assert got_locals == want_locals
        for lst in el.findall(q("Vars")):
            assert lst.get("accessSpecifier") == "private"
        for v in el.iter(q("Variable")):
            _assert_order(list(v), VARIABLE_ORDER, f"{name}.{v.get('name')}")
        if pou.kind == "FUNCTION":
            assert _type_text(el.find(q("ResultType"))) == printer.type_ref(pou.return_type)


def test_each_body_is_the_source_text_and_reparses_to_the_same_ast(lib_root, lib_project):
    _, pous = _user_decls(lib_project)
    with_comments = 0
    for el in _container(lib_root):
        if local(el) not in POU_TAG.values():
            continue
        body = el.find(f"{q('MainBody')}/{q('BodyContent')}")
        assert body.get(XSI_TYPE) == "ST" and [local(c) for c in body] == ["ST"]
        st = body.find(q("ST")).text
        pou = pous[el.get("name")]
        source = pou.span.file.text.replace("\r\n", "\n")
        assert st in source, f"{pou.name}: body is not the source text"
        with_comments += "(*" in st
        diags = DiagnosticBag()
        unit = parse(SourceFile("roundtrip.st", f"PROGRAM RoundTrip\n{st}\nEND_PROGRAM\n"), diags)
        assert not diags.items, [d.render() for d in diags.items]
        assert unit.items[0].body == pou.body, f"{pou.name}: re-parsed body differs"
    assert with_comments >= 5


def test_types_come_after_the_types_they_use_and_pous_after_their_callees(lib_root, lib_project):
    children = list(_container(lib_root))
    position = {c.get("name").upper(): i for i, c in enumerate(children)}
    first_pou = min(i for i, c in enumerate(children) if local(c) != "DataTypeDecl")
    assert all(local(c) == "DataTypeDecl" for c in children[:first_pou])
    for i, c in enumerate(children):
        for tn in c.iter(q("TypeName")):
            used = position.get((tn.text or "").upper())
            if used is not None:
                assert used < i, f"{c.get('name')} uses {tn.text}, which comes later"
    _, pous = _user_decls(lib_project)
    for pou in pous.values():
        for node in (n for s in pou.body for n in A.walk(s)):
            callee = getattr(getattr(node, "binding", None), "pou", None)
            if isinstance(node, A.Call) and callee is not None and callee.name.upper() in position:
                assert position[callee.name.upper()] < position[pou.name.upper()], \
                    f"{pou.name} calls {callee.name}, which comes later"


def test_export_is_deterministic_and_independent_of_path_order(lib_xml, tmp_path, capsys):
    from tests.vplc.export.conftest import run
    again = tmp_path / "again.xml"
    other = tmp_path / "other.xml"
    assert run(capsys, "export", str(LIB), "-o", str(again))[0] == 0
    assert run(capsys, "export", str(LIB / "types"), str(LIB), "-o", str(other))[0] == 0
    assert again.read_bytes() == lib_xml.read_bytes() == other.read_bytes()


def test_source_date_epoch_sets_the_creation_time(tmp_path, capsys, monkeypatch):
    from tests.vplc.export.conftest import run
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    out = tmp_path / "dated.xml"
    assert run(capsys, "export", str(LIB), "-o", str(out))[0] == 0
    ch = ET.parse(out).getroot().find(q("ContentHeader"))
    assert ch.get("creationDateTime") == "2023-11-14T22:13:20"


def test_flat_writes_every_object_in_the_global_namespace(lib_root, tmp_path, capsys):
    from tests.vplc.export.conftest import run
    out = tmp_path / "flat.xml"
    code, stdout, _ = run(capsys, "export", str(LIB), "--flat", "-o", str(out))
    assert code == 0 and "(flat)" in stdout
    gns = ET.parse(out).getroot().find(f"{q('Types')}/{q('GlobalNamespace')}")
    assert gns.find(q("NamespaceDecl")) is None
    flat = [(local(c), c.get("name")) for c in gns]
    nested = [(local(c), c.get("name")) for c in _container(lib_root)]
    assert flat == nested


def test_xml_text_is_utf8_with_declaration_and_default_namespace(lib_xml):
    data = lib_xml.read_bytes()
    assert data.startswith(b'<?xml version="1.0" encoding="utf-8"?>\n<Project xmlns="' + NS.encode() + b'"')
    assert data.endswith(b"</Project>\n") and b"\r" not in data


def test_synthetic_sources_cover_programs_constants_retain_at_and_globals(tmp_path, capsys):
    from tests.vplc.export.conftest import run
    lib = tmp_path / "DemoLib"
    lib.mkdir()
    (lib / "types.st").write_text(
        "TYPE\n    eMode : (Off, Slow := 5, Fast) INT;\n    aTable : ARRAY[0..2] OF INT;\n"
        "    stPoint : STRUCT\n        X : REAL := 1.5;\n        Tab : aTable := [1, 2(7)];\n    END_STRUCT;\n"
        "END_TYPE\n",
        encoding="utf-8")
    (lib / "Main.st").write_text(
        "PROGRAM Main\nVAR CONSTANT\n    Limit : INT := 10;\nEND_VAR\nVAR RETAIN\n    Count : DINT;   (* kept *)\n"
        "END_VAR\nVAR\n    Lamp AT %QX0.1 : BOOL;\n    P : stPoint := (X := 2.0);\nEND_VAR\n"
        "VAR_EXTERNAL\n    gSpeed : INT;\n"
        "END_VAR\n// count up\nCount := Count + 1;\nEND_PROGRAM\n", encoding="utf-8")
    (tmp_path / "globals.st").write_text("VAR_GLOBAL\n    gSpeed : INT := 3;\nEND_VAR\n", encoding="utf-8")
    out = tmp_path / "demo.xml"
    code, _, err = run(capsys, "export", str(lib), str(tmp_path / "globals.st"), "-o", str(out))
    assert code == 0, err
    root = ET.parse(out).getroot()
    ns = root.find(f"{q('Types')}/{q('GlobalNamespace')}/{q('NamespaceDecl')}[@name='DemoLib']")
    enum = ns.find(f"{q('DataTypeDecl')}[@name='eMode']/{q('UserDefinedTypeSpec')}")
    assert [(e.get("name"), e.get("value")) for e in enum.findall(q("Enumerator"))] == \
        [("Off", "0"), ("Slow", "5"), ("Fast", "6")]
    assert enum.find(q("BaseType")).text == "DINT", "the schema's ElementaryType: Sysmac enumerations are DINT"
    table = ns.find(f"{q('DataTypeDecl')}[@name='aTable']")
    assert table.find(q("UserDefinedTypeSpec")).get(XSI_TYPE) == "ArrayTypeSpec"
    tab = ns.find(f"{q('DataTypeDecl')}[@name='stPoint']//{q('Member')}[@name='Tab']")
    values = tab.findall(f"{q('InitialValue')}/{q('ArrayValue')}/{q('Value')}")
    assert [(v.get("repetitionValue"), v.find(q("SimpleValue")).get("value")) for v in values] == \
        [(None, "1"), ("2", "7")]
    names = [c.get("name") for c in ns]
    assert names.index("aTable") < names.index("stPoint")
    assert ns.find(q("Program")) is None, "the schema's NamespaceDecl holds no Program"
    prog = root.find(f"{q('Types')}/{q('GlobalNamespace')}/{q('Program')}[@name='Main']")
    assert [local(c) for c in prog] == ["AddData", "UsingDirective", "ExternalVars", "Vars", "Vars", "Vars", "MainBody"]
    assert prog.find(q("UsingDirective")).text == "DemoLib"
    const, retain, plain = prog.findall(q("Vars"))
    assert const.get("constant") == "true" and retain.get("retain") == "true"
    assert retain.find(f"{q('Variable')}/{q('Documentation')}").text == "kept"
    assert plain.find(f"{q('Variable')}[@name='Lamp']/{q('Address')}").get("address") == "%QX0.1"
    sv = plain.find(f"{q('Variable')}[@name='P']/{q('InitialValue')}/{q('StructValue')}/{q('Value')}")
    assert sv.get("member") == "X" and sv.find(q("SimpleValue")).get("value") == "2.0"
    assert prog.find(f"{q('MainBody')}/{q('BodyContent')}/{q('ST')}").text == "// count up\nCount := Count + 1;"
    gv = root.find(f"{q('Instances')}/{q('Configuration')}/{q('Resource')}/{q('GlobalVars')}/{q('Variable')}")
    assert gv.get("name") == "gSpeed"
    assert gv.find(f"{q('InitialValue')}/{q('SimpleValue')}").get("value") == "3"
