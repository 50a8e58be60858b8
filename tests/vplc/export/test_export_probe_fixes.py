"""Defects the wide export probe found (issue 24: every clean ST/XML program of the repository and the constructs
of the issue's list exported, validated against Omron's schemas and loaded back), each pinned with a minimal source
of our own. The probe itself runs permanently as tests/vplc/export/test_export_round_trip.py."""
from __future__ import annotations

import xml.etree.ElementTree as ET

from tests.vplc.export.conftest import ROOT, q, run
from vplc.api import load_plc

SYSTEM_VARIABLES = """PROGRAM Main
VAR_EXTERNAL
    gCount : INT;
END_VAR
VAR
    First : BOOL;
    Seen : UDINT;
END_VAR
First := P_First_Run;
IF P_On THEN
    Seen := Seen + 1;
END_IF;
gCount := gCount + 1;
END_PROGRAM
VAR_GLOBAL
    gCount : INT;
END_VAR
"""


def test_system_defined_variables_are_not_written_as_external_variables(tmp_path, capsys):
    # W501, system-defined variables: a POU reads P_On, P_First_Run, _MC_AX ... without an external variable
    # (vplc's ST1009 exempts them too); before, the export declared each in ExternalVars with the prelude's type
    src = tmp_path / "Main.st"
    src.write_text(SYSTEM_VARIABLES, encoding="utf-8")
    out = tmp_path / "main.xml"
    code, _, err = run(capsys, "export", str(src), "-o", str(out))
    assert code == 0, err
    program = ET.parse(out).getroot().find(f"{q('Types')}/{q('GlobalNamespace')}/{q('Program')}")
    externals = [v.get("name") for lst in program.findall(q("ExternalVars")) for v in lst.findall(q("Variable"))]
    assert externals == ["gCount"]
    code, _, err = run(capsys, "check", str(out))
    assert code == 0 and "warning" not in err, err
    plc = load_plc([str(out)])
    try:
        for n in range(3):
            plc.scan(n * plc.period_ns)
        assert (plc.read("Main.Seen"), plc.read("Main.First"), plc.read("Main.gCount")) == (3, False, 3)
    finally:
        plc.close()


def test_a_user_global_used_without_var_external_is_still_declared_iec_dialect(tmp_path, capsys):
    src = tmp_path / "Main.st"
    src.write_text(SYSTEM_VARIABLES.replace("VAR_EXTERNAL\n    gCount : INT;\nEND_VAR\n", ""), encoding="utf-8")
    out = tmp_path / "main.xml"
    code, _, err = run(capsys, "export", str(src), "--dialect", "iec", "-o", str(out))
    assert code == 0, err
    program = ET.parse(out).getroot().find(f"{q('Types')}/{q('GlobalNamespace')}/{q('Program')}")
    externals = [v.get("name") for lst in program.findall(q("ExternalVars")) for v in lst.findall(q("Variable"))]
    assert externals == ["gCount"]


UNION_SOURCE = """TYPE
    uWord : UNION
        W : WORD;
        B : ARRAY[0..1] OF BYTE;
    END_UNION;
END_TYPE
PROGRAM Main
VAR
    U : uWord;
END_VAR
U.W := WORD#16#1234;
END_PROGRAM
"""


def test_plcopen_export_refuses_a_union_by_name_instead_of_writing_a_struct(tmp_path, capsys):
    # W501 6-3-6: a union's members share one memory image; TC6 has no union, and a struct read back (by vplc or
    # another IDE) gives B its own memory: U.B stayed [0, 0] after U.W := 16#1234 where it is [16#34, 16#12]
    src = tmp_path / "Main.st"
    src.write_text(UNION_SOURCE, encoding="utf-8")
    out = tmp_path / "tc6.xml"
    code, _, err = run(capsys, "export", str(src), "--format", "plcopen", "-o", str(out))
    assert code == 1 and not out.exists()
    assert "data type `uWord` is a UNION, which PLCopen TC6 cannot express" in err and "Traceback" not in err
    code, _, err = run(capsys, "export", str(src), "--format", "iec61131-10", "-o", str(tmp_path / "smc.xml"))
    assert code == 0, err
    plc = load_plc([str(tmp_path / "smc.xml")])
    try:
        plc.scan(0)
        assert plc.read("Main.U.B") == [0x34, 0x12]
    finally:
        plc.close()


FLAT_SOURCE = """NAMESPACE nsCell
TYPE
    eMode : (Idle, Run := 5);
END_TYPE
NAMESPACE Io
TYPE
    stIn : STRUCT
        Mode : nsCell\\eMode := nsCell\\eMode#Run;
        Count : INT;
    END_STRUCT;
END_TYPE
FUNCTION_BLOCK Tally
VAR_IN_OUT
    Data : nsCell\\Io\\stIn;
END_VAR
Data.Count := Data.Count + 1;
END_FUNCTION_BLOCK
END_NAMESPACE
END_NAMESPACE
PROGRAM Main
VAR
    In : nsCell\\Io\\stIn;
    T : nsCell\\Io\\Tally;
    Note : STRING[20] := 'nsCell\\Io\\stIn';   (* a comment naming nsCell\\Io\\Tally stays *)
    Running : BOOL;
END_VAR
T(Data := In);   (* calls nsCell\\Io\\Tally *)
Running := In.Mode = nsCell\\eMode#Run;
END_PROGRAM
"""


def test_flat_export_drops_the_namespaces_from_every_reference(tmp_path, capsys):
    # --flat writes every object in the global namespace; before, types, initial values and bodies still named
    # nsCell\\Io\\stIn, so the file did not load (vplc: 'unknown data type'; lib + examples --flat: 111 errors)
    src = tmp_path / "Cell.st"
    src.write_text(FLAT_SOURCE, encoding="utf-8")
    out = tmp_path / "flat.xml"
    code, _, err = run(capsys, "export", str(src), "--flat", "-o", str(out))
    assert code == 0, err
    text = out.read_text(encoding="utf-8")
    assert "nsCell\\eMode#Run" not in text and "<TypeName>stIn</TypeName>" in text and "T(Data := In);" in text
    assert "<SimpleValue value=\"'nsCell\\Io\\stIn'\" />" in text, "a string literal is not a reference"
    assert "T(Data := In);   (* calls nsCell\\Io\\Tally *)" in text, "nor is a comment"
    assert "a comment naming nsCell\\Io\\Tally stays</Documentation>" in text
    code, _, err = run(capsys, "check", str(out))
    assert code == 0 and "error" not in err, err
    plc = load_plc([str(out)])
    try:
        for n in range(3):
            plc.scan(n * plc.period_ns)
        assert (plc.read("Main.In.Count"), plc.read("Main.Running"), plc.read("Main.Note")) == (3, True,
                                                                                                 "nsCell\\Io\\stIn")
    finally:
        plc.close()


def test_flat_export_refuses_two_objects_that_would_get_one_name(tmp_path, capsys):
    src = tmp_path / "Two.st"
    src.write_text("NAMESPACE nsA\nTYPE\n    stP : STRUCT X : INT; END_STRUCT;\nEND_TYPE\nEND_NAMESPACE\n"
                   "NAMESPACE nsB\nTYPE\n    stP : STRUCT Y : INT; END_STRUCT;\nEND_TYPE\nEND_NAMESPACE\n",
                   encoding="utf-8")
    code, _, err = run(capsys, "export", str(src), "--flat", "-o", str(tmp_path / "flat.xml"))
    assert code == 1 and "--flat: `nsA\\stP` and `nsB\\stP` would both be named `stP`" in err, err
    assert not (tmp_path / "flat.xml").exists()


DOCUMENTED_TYPES = """TYPE
    (* Mode of the cell. *)
    eMode : (Idle, Run);
    (* One station: where it is and what it does. *)
    stStation : STRUCT
        Pos : LREAL;      (* mm from the home switch *)
        Mode : eMode;     (* what the station does *)
    END_STRUCT;
END_TYPE
"""


def test_type_and_member_comments_survive_export_and_reading_back(tmp_path, capsys):
    # A comment inside a TYPE block, above a declaration, is that type's Documentation (before: only a comment
    # above TYPE was taken, for the first declaration); the reader writes a member's Documentation back as its line
    # comment (before: dropped, so exporting an export lost every member comment of the library's structures)
    src = tmp_path / "Types.st"
    src.write_text(DOCUMENTED_TYPES, encoding="utf-8")
    first, again = tmp_path / "first.xml", tmp_path / "again.xml"
    code, _, err = run(capsys, "export", str(src), "-o", str(first))
    assert code == 0, err
    root = ET.parse(first).getroot()
    docs = {d.get("name"): d.findtext(q("Documentation")) for d in root.iter(q("DataTypeDecl"))}
    assert docs == {"eMode": "Mode of the cell.", "stStation": "One station: where it is and what it does."}
    members = {m.get("name"): m.findtext(q("Documentation")) for m in root.iter(q("Member"))}
    assert members == {"Pos": "mm from the home switch", "Mode": "what the station does"}
    code, _, err = run(capsys, "export", str(first), "-o", str(again))
    assert code == 0, err
    assert again.read_bytes() == first.read_bytes()


def test_plcopen_export_names_every_construct_it_refuses_at_once(tmp_path, capsys):
    # the manual-style project has two unions and a ladder FB with inline ST: one run names all three (the union
    # refusal must not hide the inline ST one, which the project's own test looks for)
    project = ROOT / "tests" / "vplc" / "sysmac" / "manual_project"
    code, _, err = run(capsys, "export", str(project), "--format", "plcopen", "-o", str(tmp_path / "tc6.xml"))
    assert code == 1 and "Traceback" not in err
    assert "data type `uStatus` is a UNION" in err and "data type `uRealImage` is a UNION" in err
    assert "FUNCTION_BLOCK `StartStop`: a rung holds Sysmac inline ST (smcext:InlineST)" in err
