"""Contract A queries for tools that judge or sample a variable: ``Plc.type_of`` (the declared type) and
``Plc.lasting_slot`` (where a directly declared variable's value lives), with the errors ``read`` gives."""
import pytest
from rt_helpers import plc_of

from vplc.api import PathError, T

SOURCE = """
TYPE eMode : (Off, Auto); stP : STRUCT X : REAL; Name : STRING[8]; END_STRUCT; END_TYPE
VAR_GLOBAL
    Count : INT;
    Pos : stP;
END_VAR
PROGRAM Main
VAR_EXTERNAL Count : INT; END_VAR
VAR s : STRING[50]; p : stP; a : ARRAY[1..3] OF INT; m : eMode; w : WORD; END_VAR
Count := Count + 1; a[2] := Count; w := 16#12;
END_PROGRAM
"""


@pytest.fixture
def plc(tmp_path):
    with plc_of(tmp_path, SOURCE) as p:
        yield p


def test_type_of_gives_the_declared_type_the_var_type_text_names(plc):
    cases = {"Main.s": T.StringType, "Main.p": T.StructType, "Main.a": T.ArrayType, "Main.m": T.EnumType}
    for path, kind in cases.items():
        assert isinstance(T.base_of(plc.type_of(path)), kind), path
    element = T.base_of(plc.type_of("Main.a[2]"))
    assert isinstance(element, T.ElementaryType) and element.name == "INT"
    word = T.base_of(plc.type_of("Main.w"))
    assert isinstance(word, T.ElementaryType) and (word.name, word.bits) == ("WORD", 16)
    assert T.base_of(plc.type_of("Main.p.Name")).name == plc.var_type("Main.p.Name") == "STRING[8]"
    assert T.base_of(plc.type_of("Main.Count")) is T.base_of(plc.type_of("Count"))    # the external is the global


@pytest.mark.parametrize("path, message", [
    ("Main.nope", "is not a variable of Main"),
    ("Main.a[7]", "Main.a\\[7\\]"),
    ("Main.w.x", "has no members"),
    ("Main", "names a program instance"),
    ("", "empty variable path"),
])
def test_type_of_and_lasting_slot_refuse_a_bad_path_as_read_does(plc, path, message):
    with pytest.raises(PathError, match=message):
        plc.read(path)
    with pytest.raises(PathError, match=message):
        plc.type_of(path)
    with pytest.raises(PathError, match=message):
        plc.lasting_slot(path)


def test_lasting_slot_holds_a_directly_declared_variable_for_the_controllers_life(plc):
    slot = plc.lasting_slot("Main.w")
    assert slot is not None and T.base_of(slot.type).name == "WORD"
    plc.scan(0)
    assert slot.container[slot.key] == plc.read("Main.w") == 0x12
    ext, glob = plc.lasting_slot("Main.Count"), plc.lasting_slot("Count")
    assert ext is not None and glob is not None
    assert ext.container is glob.container and ext.key == glob.key        # a VAR_EXTERNAL lands in the globals
    plc.scan(1_000_000)
    assert ext.container[ext.key] == plc.read("Count") == 2


def test_lasting_slot_is_none_for_members_and_elements(plc):
    assert plc.lasting_slot("Main.p.X") is None
    assert plc.lasting_slot("Main.a[2]") is None
    assert plc.lasting_slot("Pos.X") is None
    assert plc.lasting_slot("Main.p") is not None          # the structure itself is declared in Main
