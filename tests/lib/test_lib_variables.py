"""CBT_ReadVariable and CBT_WriteVariable (issue 26 item 7) on the virtual PLC against the simulator's Ethernet
Slave over loopback: the project's global variables (TMscript 2.24 §17.2 "Global Variable") read in mode 11
(§17.4.5, binary value) and written in mode 2 (§17.4.3, 'Name=Value'), typed - BOOL, INT, FLOAT, STRING and arrays
of them - with the robot's status codes (§17.4.1) as their own ErrorIDs, parameter errors before anything is sent,
and no Listen-node traffic."""
import math

import pytest
from rig import Rig

from tmsim.protocol import svr_table as table

SPECS = ['g_count:int=5', 'g_ratio:float=0.5', 'g_ok:bool=true', 'g_name:string="Cell 1"',
         'g_pos:float[6]={1,2,3,0.1,0.2,0.3}', 'g_ss:string[3]={"Hi","TM","Robot"}', 'g_flags:bool[3]={1,0,1}',
         'g_counts:int[4]={-1,0,1,2147483647}', 'g_limit:int:ro=100', 'g_mode:int:auto=0', 'g_empty:string']


@pytest.fixture
def var():
    r = Rig(program="Main_Var.st", svr_port=0, svr_options={"variables": [table.parse_variable(s) for s in SPECS]})
    assert r.until(lambda: r.read("Cobot.Status.SlaveLink"), 1)
    yield r
    r.close()


def variable(rig, path, name, kind, count=1, **values):
    rig.write(f"{path}.Name", name)
    rig.write(f"{path}.DataType", kind)
    rig.write(f"{path}.Count", count)
    for member, items in values.items():
        for k, value in enumerate(items, start=1):
            rig.write(f"{path}.{member}[{k}]", value)


def run(rig, fb, execute, seconds=3):
    rig.write(execute, True)
    assert rig.until(lambda: rig.read(f"{fb}.Done") or rig.read(f"{fb}.Error"), seconds)
    done, error_id = rig.read(f"{fb}.Done"), rig.read(f"{fb}.ErrorID")
    rig.write(execute, False)
    rig.scans(2)
    return done, error_id


def svr_events(rig, kind):
    return [e for e in rig.robot.events if e["kind"] == kind]


@pytest.mark.parametrize("name,kind,count,member,expected", [
    ("g_count", "VarInt", 1, "IntValue", [5]),
    ("g_ratio", "VarFloat", 1, "FloatValue", [0.5]),
    ("g_ok", "VarBool", 1, "BoolValue", [True]),
    ("g_name", "VarString", 1, "StringValue", ["Cell 1"]),
    ("g_empty", "VarString", 1, "StringValue", [""]),
    ("g_pos", "VarFloat", 6, "FloatValue", [1, 2, 3, 0.1, 0.2, 0.3]),
    ("g_ss", "VarString", 3, "StringValue", ["Hi", "TM", "Robot"]),
    ("g_flags", "VarBool", 3, "BoolValue", [True, False, True]),
    ("g_counts", "VarInt", 4, "IntValue", [-1, 0, 1, 2147483647]),
    ("g_limit", "VarInt", 1, "IntValue", [100]),                       # read only: reading is allowed
])
def test_read_gives_the_value_of_its_type(var, name, kind, count, member, expected):
    var.write(f"RdVar.{member}[1]", {"VarString": "x", "VarBool": False, "VarFloat": 7.0}.get(kind, 7))
    variable(var, "RdVar", name, kind, count)
    var.write("RdExec", True)
    var.scans(1)
    assert var.read("rd.Busy") and not var.read("rd.Done")
    assert var.until(lambda: var.read("rd.Done") or var.read("rd.Error"), 1)
    assert var.read("rd.Done"), var.read("rd.ErrorDescrip")
    got = [var.read(f"RdVar.{member}[{k}]") for k in range(1, count + 1)]
    assert got == pytest.approx(expected, rel=1e-6) if kind == "VarFloat" else got == expected
    (read,) = svr_events(var, "svr_read")
    assert read["mode"] == 11 and read["items"] == [name]                # binary request read, §17.4.5
    assert var.scripts_in() == []                                         # nothing on the Listen node
    var.scans(20)
    assert var.read("rd.Done")                                           # R3: stays while Execute is TRUE
    var.write("RdExec", False)
    var.scans(1)
    assert not var.read("rd.Done") and not var.read("rd.Busy")


@pytest.mark.parametrize("name,kind,count,member,values,expected,text", [
    ("g_count", "VarInt", 1, "IntValue", [-7], -7, "g_count=-7"),
    ("g_ratio", "VarFloat", 1, "FloatValue", [-0.125], -0.125, "g_ratio=-0.125"),
    ("g_ok", "VarBool", 1, "BoolValue", [False], 0, "g_ok=false"),
    ("g_name", "VarString", 1, "StringValue", ["Cell 2; part 4"], "Cell 2; part 4", 'g_name="Cell 2; part 4"'),
    ("g_pos", "VarFloat", 6, "FloatValue", [417.5, -122.345, 360, 180, 0, 90],
     [417.5, -122.345, 360, 180, 0, 90], "g_pos={417.5,-122.345,360,180,0,90}"),
    ("g_ss", "VarString", 3, "StringValue", ["a", "", "c,d"], ["a", "", "c,d"], 'g_ss={"a","","c,d"}'),
    ("g_flags", "VarBool", 3, "BoolValue", [False, True, False], [0, 1, 0], "g_flags={false,true,false}"),
])
def test_write_changes_the_robots_variable(var, name, kind, count, member, values, expected, text):
    variable(var, "WrVar", name, kind, count, **{member: values})
    var.write("WrExec", True)
    var.scans(1)                                       # the edge: the text goes out in this scan
    assert var.read("Cobot.SvrCmd") == text and var.read("Cobot.SvrCmdState") == "SvrCmdSent"
    done, error_id = run(var, "wr", "WrExec")
    assert done, hex(error_id)
    got = var.robot.svr.variables[name]
    assert got == pytest.approx(expected, rel=1e-6) if kind == "VarFloat" else got == expected
    writes = svr_events(var, "svr_write")
    assert len(writes) == 1 and writes[0]["mode"] == 2                   # string mode, §17.4.3
    assert var.scripts_in() == []


def test_a_written_value_reads_back(var):
    variable(var, "WrVar", "g_counts", "VarInt", 4, IntValue=[10, -20, 30, -2147483648])
    assert run(var, "wr", "WrExec") == (True, 0)
    variable(var, "RdVar", "g_counts", "VarInt", 4)
    assert run(var, "rd", "RdExec") == (True, 0)
    assert [var.read(f"RdVar.IntValue[{k}]") for k in range(1, 5)] == [10, -20, 30, -2147483648]


def test_a_variable_that_does_not_exist_is_16_4040(var):
    variable(var, "RdVar", "g_missing", "VarInt")
    assert run(var, "rd", "RdExec") == (False, 0x4040)
    variable(var, "WrVar", "g_missing", "VarInt", IntValue=[1])
    assert run(var, "wr", "WrExec") == (False, 0x4040)
    assert var.read("wr.ErrorDescrip") == ""                             # cleared one scan after Execute fell


@pytest.mark.parametrize("name,kind,count", [
    ("g_pos", "VarFloat", 5), ("g_pos", "VarBool", 6), ("g_count", "VarBool", 1), ("g_ok", "VarInt", 1),
    ("g_ss", "VarString", 2), ("g_ss", "VarString", 4), ("g_name", "VarString", 2),
])
def test_a_read_of_another_type_or_size_is_16_4045_and_leaves_the_value(var, name, kind, count):
    var.write("RdVar.IntValue[1]", 99)
    var.write("RdVar.BoolValue[1]", False)
    variable(var, "RdVar", name, kind, count)
    assert run(var, "rd", "RdExec") == (False, 0x4045)
    assert var.read("RdVar.IntValue[1]") == 99 and var.read("RdVar.StringValue[1]") == ""


def test_a_text_longer_than_80_bytes_is_16_4045(var):
    var.robot.svr.variables["g_name"] = "x" * 81
    variable(var, "RdVar", "g_name", "VarString")
    assert run(var, "rd", "RdExec") == (False, 0x4045)
    var.robot.svr.variables["g_name"] = "y" * 80
    assert run(var, "rd", "RdExec") == (True, 0) and var.read("RdVar.StringValue[1]") == "y" * 80


def test_the_robots_refusals_of_a_write_are_their_own_error_ids(var):
    variable(var, "WrVar", "g_limit", "VarInt", IntValue=[1])
    assert run(var, "wr", "WrExec") == (False, 0x4042)                 # 05 ReadOnly
    var.robot.svr_source.set_auto_mode(False)
    variable(var, "WrVar", "g_mode", "VarInt", IntValue=[1])
    assert run(var, "wr", "WrExec") == (False, 0x4043)                 # 06 ModeError
    var.robot.svr_source.set_auto_mode(True)
    assert run(var, "wr", "WrExec") == (True, 0)
    variable(var, "WrVar", "g_count", "VarFloat", FloatValue=[1.5])
    assert run(var, "wr", "WrExec") == (False, 0x4044)                 # 07 ValueError: 1.5 to an int
    variable(var, "WrVar", "g_pos", "VarFloat", 3, FloatValue=[1, 2, 3])
    assert run(var, "wr", "WrExec") == (False, 0x4044)                 # 07: three values to a float[6]
    var.robot.svr.configure(write_permission=False)
    variable(var, "WrVar", "g_count", "VarInt", IntValue=[1])
    assert run(var, "wr", "WrExec") == (False, 0x4041)                 # 02 WritePermission
    variable(var, "RdVar", "g_count", "VarInt")
    assert run(var, "rd", "RdExec") == (True, 0)                       # reading needs no write permission
    var.robot.svr.configure(write_permission=True)
    var.robot.svr.inject("refuse_writes", status=3)                    # 03 InvalidData
    assert run(var, "wr", "WrExec") == (False, 0x4046)
    assert var.robot.svr.variables["g_count"] == 5 and var.robot.svr.variables["g_mode"] == 1


@pytest.mark.parametrize("fb,execute,path,values,error_id", [
    ("rd", "RdExec", "RdVar", dict(Name=""), 0x1050),
    ("rd", "RdExec", "RdVar", dict(Name="g count"), 0x1050),
    ("wr", "WrExec", "WrVar", dict(Name="1count"), 0x1050),
    ("wr", "WrExec", "WrVar", dict(Name="g_a=1"), 0x1050),
    ("rd", "RdExec", "RdVar", dict(Name="g-count"), 0x1050),
    ("rd", "RdExec", "RdVar", dict(Name="g_zähler"), 0x1050),
    ("rd", "RdExec", "RdVar", dict(Count=0), 0x1052),
    ("wr", "WrExec", "WrVar", dict(Count=17), 0x1052),
    ("wr", "WrExec", "WrVar", dict(DataType="VarFloat", **{"FloatValue[1]": math.nan}), 0x1053),
    ("wr", "WrExec", "WrVar", dict(DataType="VarFloat", **{"FloatValue[1]": 1.0e6 + 1}), 0x1053),
    ("wr", "WrExec", "WrVar", dict(DataType="VarFloat", Count=2, **{"FloatValue[2]": -math.inf}), 0x1053),
    ("wr", "WrExec", "WrVar", dict(DataType="VarString", **{"StringValue[1]": 'say "hi"'}), 0x1054),
    ("wr", "WrExec", "WrVar", dict(DataType="VarString", **{"StringValue[1]": "two\r\nlines"}), 0x1054),
    ("wr", "WrExec", "WrVar", dict(DataType="VarString", Count=5, **{f"StringValue[{k}]": "z" * 80
                                                                      for k in range(1, 6)}), 0x1055),
])
def test_parameter_errors_are_raised_before_anything_is_sent(var, fb, execute, path, values, error_id):
    variable(var, path, "g_count", "VarInt")
    for member, value in values.items():
        var.write(f"{path}.{member}", value)
    var.write(execute, True)
    var.scans(1)                                                        # the scan of the rising edge
    assert var.read(f"{fb}.Error") and var.read(f"{fb}.ErrorID") == error_id
    var.scans(5)
    assert svr_events(var, "svr_read") == [] and svr_events(var, "svr_write") == []


def test_the_largest_write_that_fits_is_sent(var):
    """Four texts of 80 characters: 'g_ss={...}' is 343 characters, within the 400 of a request."""
    var.robot.svr.declare(table.variable_item("g_long", "string", 4))
    variable(var, "WrVar", "g_long", "VarString", 4, StringValue=["z" * 80] * 4)
    assert run(var, "wr", "WrExec") == (True, 0)
    assert var.robot.svr.variables["g_long"] == ["z" * 80] * 4


def test_an_undefined_data_type_is_16_1051(var):
    variable(var, "RdVar", "g_count", "VarInt")
    var.write("RdVar.DataType", 9, raw=True)
    assert run(var, "rd", "RdExec") == (False, 0x1051)


def test_without_the_ethernet_slave_it_is_16_2010():
    r = Rig(program="Main_Var.st")
    try:
        variable(r, "RdVar", "g_count", "VarInt")
        assert run(r, "rd", "RdExec") == (False, 0x2010)
        variable(r, "WrVar", "g_count", "VarInt")
        assert run(r, "wr", "WrExec") == (False, 0x2010)
    finally:
        r.close()


def test_a_silent_ethernet_slave_is_16_2021_before_and_16_3007_after_sending(var):
    variable(var, "WrVar", "g_count", "VarInt", IntValue=[1])
    var.robot.svr.inject("stall")                                       # requests dropped unanswered
    var.write("WrExec", True)
    assert var.until(lambda: var.read("wr.Error"), 3)
    assert var.read("wr.ErrorID") == 0x3007
    var.write("WrExec", False)
    assert var.until(lambda: not var.read("Cobot.Status.SlaveLink"), 2)
    variable(var, "RdVar", "g_count", "VarInt")
    assert run(var, "rd", "RdExec") == (False, 0x2021)


def test_an_answer_that_is_not_the_variable_asked_for_is_16_3008(var):
    var.robot.svr.inject("answer_other_item", item="g_count", instead="g_ratio")
    variable(var, "RdVar", "g_count", "VarInt")
    assert run(var, "rd", "RdExec") == (False, 0x3008)


def test_reader_writer_and_override_share_the_channel(var):
    """One Ethernet Slave request at a time per connection: three FBs started in one scan each get their answer."""
    variable(var, "RdVar", "g_pos", "VarFloat", 6)
    variable(var, "WrVar", "g_count", "VarInt", IntValue=[42])
    for execute in ("RdExec", "WrExec", "OvrExec"):
        var.write(execute, True)
    assert var.until(lambda: all(var.read(f"{fb}.Done") or var.read(f"{fb}.Error") for fb in ("rd", "wr", "ovr")), 5)
    assert var.read("rd.Done") and var.read("wr.Done") and var.read("ovr.Done"), \
        (var.read("rd.ErrorID"), var.read("wr.ErrorID"), var.read("ovr.ErrorID"))
    assert var.read("RdVar.FloatValue[3]") == pytest.approx(3.0) and var.robot.svr.variables["g_count"] == 42


def range_rows():
    import importlib.util
    import sys

    from rig import ROOT
    spec = importlib.util.spec_from_file_location("make_types", ROOT / "docs" / "library" / "make_types.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_types"] = module
    spec.loader.exec_module(module)
    return [r for r in module.read_ranges() if r.struct in ("CBT_ReadVariable", "CBT_WriteVariable")], module


ROWS, MT = range_rows()
FB = {"CBT_ReadVariable": ("rd", "RdExec", "RdVar"), "CBT_WriteVariable": ("wr", "WrExec", "WrVar")}


@pytest.fixture(scope="module")
def offline():
    r = Rig(program="Main_Var.st", connect=False)
    yield r
    r.close()


def outcome(rig, row, value):
    """ErrorID with the row's member at ``value`` and everything else valid: 16#2010 (no Ethernet Slave configured,
    checked after the parameters) when the value passes."""
    fb, execute, path = FB[row.struct]
    variable(rig, path, "g_count", "VarFloat" if "FloatValue" in row.member else "VarInt")
    member = row.member.removeprefix("Variable.")
    rig.write(f"{path}.{member}" + ("[1]" if member == "FloatValue" else ""), value)
    rig.write(execute, True)
    rig.scans(1)
    error_id = rig.read(f"{fb}.ErrorID")
    rig.write(execute, False)
    rig.scans(2)
    return error_id


@pytest.mark.parametrize("row", ROWS, ids=lambda r: f"{r.struct}.{r.member}:{r.line}")
def test_range_row_of_the_one_range_table_matches_the_st_check(offline, row):
    code = int(row.error[3:], 16)
    if row.allowed is not None:
        enum = next(t for t in MT.read_types() if t.name == "eCBT_VarType")
        assert [v.name for v in enum.members] == row.allowed
        for value in row.allowed:
            assert outcome(offline, row, value) == 0x2010, value
        return
    assert outcome(offline, row, row.low) == 0x2010 and outcome(offline, row, row.high) == 0x2010
    step = 1 if isinstance(row.low, int) else 0.125
    assert outcome(offline, row, row.low - step) == code and outcome(offline, row, row.high + step) == code
