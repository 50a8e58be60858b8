"""A program's (or function block's) VAR_EXTERNAL is the global it names (W501, external variables): its path
reads and writes that global through the API, the CLI and traces (issue 27, defect D1 of a new user's cell)."""
import pytest
from rt_helpers import plc_of

from vplc.api import PathError

SOURCE = """
TYPE stPos : STRUCT X : INT; Flags : WORD; END_STRUCT; END_TYPE
VAR_GLOBAL
    Count : INT;
    Pos : stPos;
    Table : ARRAY[0..3] OF INT;
    Word0 AT %W10 : WORD;
END_VAR
FUNCTION_BLOCK Bump
VAR_EXTERNAL Count : INT; END_VAR
Count := Count + 1;
END_FUNCTION_BLOCK
PROGRAM Main
VAR_EXTERNAL Count : INT; Pos : stPos; Table : ARRAY[0..3] OF INT; Word0 : WORD; END_VAR
VAR b : Bump; END_VAR
VAR_TEMP tmp : INT; END_VAR
tmp := 2;
b();
Pos.X := Count * tmp; Table[2] := Count; Word0 := 16#12;
END_PROGRAM
"""


@pytest.fixture
def plc(tmp_path):
    with plc_of(tmp_path, SOURCE) as p:
        yield p


def test_an_external_path_reads_the_global_before_and_after_scans(plc):
    assert plc.read("Main.Count") == 0                 # before the first scan too: a KeyError before
    plc.scan(0)
    plc.scan(1_000_000)
    assert plc.read("Main.Count") == plc.read("Count") == 2
    assert plc.read("Main.b.Count") == 2               # a function block's external variable
    assert plc.read("Main.Pos.X") == 4 and plc.read("Main.Pos") == {"X": 4, "Flags": 0}
    assert plc.read("Main.Table[2]") == 2
    assert plc.read("Main.Word0") == plc.read("Word0") == 0x12     # a global AT a memory area
    assert plc.var_type("Main.Count") == "INT"


def test_an_external_path_writes_the_global(plc):
    plc.write("Main.Count", 40)                        # silently ignored before: the global stayed 0
    assert plc.read("Count") == 40
    plc.scan(0)
    assert plc.read("Count") == 41 and plc.read("Main.Count") == 41
    plc.write("Main.b.Count", 7)
    plc.write("Main.Pos.Flags", 5)
    assert plc.read("Count") == 7 and plc.read("Pos.Flags") == 5


def test_a_written_external_keeps_its_type_check(plc):
    with pytest.raises(PathError, match=r"outside the range -32768\.\.32767 of Main\.Count \(INT\)"):
        plc.write("Main.Count", 99999)
    assert plc.read("Count") == 0


def test_an_ordinary_global_still_reads_beside_a_memory_area_global(plc):
    plc.scan(0)
    assert plc.read("Count") == 1 and plc.read("Table[2]") == 1


def test_an_unknown_member_is_a_path_error_naming_the_path(plc):
    with pytest.raises(PathError, match=r"`Nope` is not a variable of Main \(in 'Main.Nope'\)"):
        plc.read("Main.Nope")
    with pytest.raises(PathError, match="Main.Nope"):
        plc.write("Main.Nope", 1)
