"""Every IEC 61131-10 file `vplc export` writes in the test suite validates against Omron's own schemas, the
two XSDs Sysmac Studio checks an import against (IEC61131_10_Ed1_0_Spc1_0.xsd and its Sysmac extension
IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd): the library, the examples (the ladder Commands_Example.xml
round-tripped, the pick-and-place program, the palletizer), every ladder fixture, and synthetic sources
with the constructs the library does not use. The schemas are Omron's files and are not in the repository:
they are looked up in ``$SYSMAC_XSD_DIR`` or ``<repo>/../shared/sysmac_xml/``; without them the tests are
skipped and say so. lxml is a test-only dependency."""
from __future__ import annotations

import os
import pathlib

import pytest

from tests.vplc.export.conftest import LIB, ROOT, run
from tests.vplc.ladder.ld_xml import block, coil, contact, document, invar, outvar, rail, right

etree = pytest.importorskip("lxml.etree", reason="lxml is a test dependency: run `make test-deps`")
SMC_XSD = "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
BASE_XSD = "IEC61131_10_Ed1_0_Spc1_0.xsd"


def _schema_dir() -> pathlib.Path:
    env = os.environ.get("SYSMAC_XSD_DIR")
    return pathlib.Path(env) if env else ROOT.parent / "shared" / "sysmac_xml"


@pytest.fixture(scope="module")
def schema():
    folder = _schema_dir()
    if not (folder / SMC_XSD).exists() or not (folder / BASE_XSD).exists():
        pytest.skip(f"Omron's IEC 61131-10 schemas ({SMC_XSD}, {BASE_XSD}) are not in {folder}; set SYSMAC_XSD_DIR "
                    "to the folder that holds them (Sysmac Studio: Sample\\IEC 61131-10 XML\\Controller)")
    return etree.XMLSchema(etree.parse(str(folder / SMC_XSD)))    # imports the base schema from the same folder


def errors(schema, path: pathlib.Path) -> list[str]:
    schema.validate(etree.parse(str(path)))
    return [f"{path.name}:{e.line}: {e.message}" for e in schema.error_log]


def export(capsys, out: pathlib.Path, *paths) -> pathlib.Path:
    code, _, err = run(capsys, "export", *map(str, paths), "--format", "iec61131-10", "-o", str(out))
    assert code == 0, err
    return out


@pytest.mark.slow
@pytest.mark.parametrize("paths", [[LIB], [LIB, ROOT / "examples"], [LIB, ROOT / "examples" / "palletizer"]],
                         ids=["library", "library+examples", "library+palletizer"])
def test_library_and_examples_validate(schema, tmp_path, capsys, paths):
    out = export(capsys, tmp_path / "out.xml", *paths)
    assert errors(schema, out) == []
    assert errors(schema, export(capsys, tmp_path / "flat.xml", *paths, "--flat")) == []


def test_device_info_names_the_controller_and_validates(schema, tmp_path, capsys):
    out = export(capsys, tmp_path / "dev.xml", LIB, "--device", "NJ501-1500@1.40")
    assert errors(schema, out) == []
    assert '<smcext:DeviceInfo modelName="NJ501-1500" version="1.40" />' in out.read_text(encoding="utf-8")
    code, _, err = run(capsys, "export", str(LIB), "--device", "@1.40", "-o", str(tmp_path / "x.xml"))
    assert code == 2 and "--device `@1.40`: give MODEL or MODEL@VERSION" in err


def test_the_shipped_ladder_example_validates(schema):
    assert errors(schema, ROOT / "examples" / "Commands_Example.xml") == []


def _ladder_fixtures(tmp_path):
    """(name, PLCopen source) of every ladder fixture of tests/vplc/ladder that exports to IEC 61131-10."""
    from tests.vplc.ladder.ld_xml import ALL_BODY, ALL_KINDS
    out = []
    for kind in ("program", "functionBlock"):
        path = tmp_path / f"all_{kind}.xml"
        path.write_text(document(ALL_KINDS, ALL_BODY, name="Main" if kind == "program" else "AllKinds",
                                 pou_type=kind), encoding="utf-8")
        out.append((f"every element kind as a {kind}", path))
    st = tmp_path / "Bump.st"                            # test_ld_semantics: an in-out pin, an output read on
    st.write_text("FUNCTION_BLOCK Bump\nVAR_IN_OUT Value : INT; END_VAR\nVAR_INPUT Go : BOOL; END_VAR\n"
                  "VAR_OUTPUT Big : BOOL; Small : BOOL; END_VAR\nIF Go THEN Value := Value + 1; END_IF;\n"
                  "Big := Value > 2;\nSmall := NOT Big;\nEND_FUNCTION_BLOCK\n", encoding="utf-8")
    body = [rail(1), contact(2, "Go", 1), invar(3, "N", y=20),
            block(4, "Bump", {"Go": 2}, ["Big", "Small"], instance="B", inouts={"Value": 3}),
            contact(5, "Ok", (4, "Big")), coil(6, "Q", 5), right(7, 6),
            invar(10, "N", y=100), block(11, "MOVE", {"EN": 1, "IN": 10}, ["ENO", "OUT"], y=100),
            outvar(12, "M", (11, "OUT"), y=100)]
    path = tmp_path / "inout.xml"
    path.write_text(document({"Go": "BOOL", "N": "INT", "M": "INT", "Ok": "BOOL", "Q": "BOOL", "B": "Bump"}, body),
                    encoding="utf-8")
    out.append(("in-out pin, unread output, MOVE", [path, st]))
    return out


def test_every_ladder_fixture_validates_and_has_sysmac_shape(schema, tmp_path, capsys):
    for name, src in _ladder_fixtures(tmp_path):
        out = export(capsys, tmp_path / "out.xml", *(src if isinstance(src, list) else [src]))
        assert errors(schema, out) == [], name
    text = export(capsys, tmp_path / "fb.xml", tmp_path / "all_functionBlock.xml").read_text(encoding="utf-8")
    assert '<BodyContent xsi:type="LD">' in text and "smcext:LdSection" not in text, "Sysmac's LD body in an FB"
    for shape in ('latch="set"', 'latch="reset"', 'targetNetworkLabel="After"', 'edge="rising"', 'negated="true"'):
        assert shape in text, shape
    assert "storage=" not in text and 'xsi:type="Return"' not in text
    text = export(capsys, tmp_path / "io.xml", tmp_path / "inout.xml", tmp_path / "Bump.st").read_text("utf-8")
    assert '<InputVariable parameterName="In">' in text and '<OutputVariable parameterName="Out">' in text
    assert '<OutputVariable parameterName="Small" />' in text, "an output nothing reads has no ConnectionPointOut"
    assert text.index("<InOutVariables>") < text.index("<InputVariables>") < text.index("<OutputVariables>")


SYNTHETIC = {
    "DemoLib/types.st": "TYPE\n    eMode : (Off, Slow := 5, Fast);\nEND_TYPE\n",
    "DemoLib/Scale.st": "FUNCTION Scale : REAL\nVAR_INPUT CONSTANT\n    Factor : REAL := 2.0;\nEND_VAR\n"
                        "VAR_INPUT\n    X : REAL;\nEND_VAR\nScale := X * Factor;\nEND_FUNCTION\n",
    "DemoLib/Now.st": "FUNCTION Now : INT\nNow := 7;\nEND_FUNCTION\n",
    "DemoLib/Keep.st": "FUNCTION_BLOCK Keep\nVAR_INPUT\n    Go : BOOL;\nEND_VAR\nVAR_INPUT RETAIN\n    Count : DINT;\n"
                       "END_VAR\nVAR_IN_OUT\n    Buf : ARRAY[*] OF BYTE;\nEND_VAR\n"
                       "VAR_OUTPUT\n    Last : DINT;\nEND_VAR\n"
                       "IF Go THEN Last := Count; END_IF;\nEND_FUNCTION_BLOCK\n",
    "Main.st": "PROGRAM Main\nVAR_EXTERNAL\n    gRun : BOOL;\n    gSpeed : REAL;\nEND_VAR\n"
               "VAR\n    K : DemoLib\\Keep;\n    B : ARRAY[0..3] OF BYTE;\n    M : DemoLib\\eMode;\n"
               "    Y : REAL;\nEND_VAR\nK(Go := gRun, Count := 3, Buf := B);\nY := DemoLib\\Scale(X := gSpeed);\n"
               "gSpeed := gSpeed + DemoLib\\Now();\nEND_PROGRAM\n",
    "globals.st": "VAR_GLOBAL\n    gRun : BOOL;\n    gSpeed : REAL := 3.0;\nEND_VAR\nVAR_GLOBAL CONSTANT\n"
                  "    gMax : INT := 9;\nEND_VAR\n",
}


def test_constructs_the_library_does_not_use_validate_and_load_back(schema, tmp_path, capsys):
    for rel, text in SYNTHETIC.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text, encoding="utf-8")
    out = export(capsys, tmp_path / "demo.xml", tmp_path / "DemoLib", tmp_path / "Main.st", tmp_path / "globals.st")
    assert errors(schema, out) == []
    text = out.read_text(encoding="utf-8")
    assert 'smcext:ParameterSetVariableAdditionalProperties constant="true"' in text
    assert '<InputVars retain="true">' in text and "<VariableLength>true</VariableLength>" in text
    assert "<BaseType>DINT</BaseType>" in text
    code, _, err = run(capsys, "check", str(out))
    assert code == 0 and "warning" not in err, err
