"""Global variables of the robot's project in the Ethernet Slave (TMscript 2.24 §17.2 "Global Variable": external
devices read / write them by name; §17.4: like user-defined items they must be in the communication file, so
the simulator knows only the variables declared to it). Reads in modes 11/12/13, writes in modes 1/2/3, the
§17.4.1 status codes for a variable that does not exist, a read-only one, an auto-only one in manual mode and a
value of the wrong type or size; the manual's byte dump of the string array g_ss; the --svr-var option."""
import pytest
from sim_harness import Harness

from tmsim.cli import build_parser, check_args, check_variables
from tmsim.protocol import codec
from tmsim.protocol import svr_table as table
from tmsim.protocol.svr_session import SvrConfigError, SvrSession

SPECS = ['g_count:int=5', 'g_ratio:float=0.5', 'g_ok:bool=true', 'g_name:string="Cell 1"',
         'g_pos:float[6]={1,2,3,0.1,0.2,0.3}', 'g_ss:string[3]={"Hi","TM","Robot"}', 'g_limit:int:ro=100',
         'g_mode:int:auto=0']


@pytest.fixture
def h():
    harness = Harness(svr_port=0, svr_options={"period": 0, "variables": [table.parse_variable(s) for s in SPECS]})
    yield harness
    harness.close()


def ask(h, peer, data):
    start = len(peer.frames)
    peer.send(codec.encode("TMSVR", data))
    assert h.until(lambda: len(peer.frames) > start, timeout=2), "the Ethernet Slave did not answer"
    return peer.frames[start].data


def test_declared_variables_are_read_in_string_mode_17_4_6(h):
    peer = h.connect_svr()
    assert ask(h, peer, "Q1,12,g_count\r\ng_ratio\r\ng_ok\r\ng_name\r\ng_pos\r\ng_ss") == (
        b'Q1,12,g_count=5\r\ng_ratio=0.5\r\ng_ok=true\r\ng_name="Cell 1"\r\ng_pos={1,2,3,0.1,0.2,0.3}\r\n'
        b'g_ss={"Hi","TM","Robot"}')


def test_a_string_array_is_read_in_binary_mode_as_the_manual_dumps_it_17_4_2(h):
    peer = h.connect_svr()
    reply = ask(h, peer, b"Q2,11," + bytes.fromhex("0400") + b"g_ss")
    # "04 00 67 5F 73 73 0D 00 48 69 00 00 54 4D 00 00 52 6F 62 6F 74  // g_ss={"Hi","TM","Robot"}"
    assert reply == b"Q2,11," + bytes.fromhex("0400675F73730D0048690000544D0000526F626F74")
    reply = ask(h, peer, b"Q3,11," + bytes.fromhex("0700") + b"g_count" + bytes.fromhex("0700") + b"g_ratio")
    assert reply == (b"Q3,11," + bytes.fromhex("0700") + b"g_count" + bytes.fromhex("0400") + (5).to_bytes(4, "little")
                     + bytes.fromhex("0700") + b"g_ratio" + bytes.fromhex("0400") + bytes.fromhex("0000003F"))


def test_writes_in_string_binary_and_json_mode_change_the_value(h):
    peer = h.connect_svr()
    assert ask(h, peer, 'W1,2,g_count=-7\r\ng_name="Cell 2"\r\ng_pos={0,0,1,0,0,0}') == b"W1,0,00,OK"
    assert ask(h, peer, b"W2,1," + bytes.fromhex("0400") + b"g_ok" + bytes.fromhex("0100") + b"\x00") == b"W2,0,00,OK"
    assert ask(h, peer, 'W3,3,[{"Item":"g_ss","Value":["a","b","c"]}]') == b"W3,0,00,OK"
    assert h.robot.svr.variables["g_count"] == -7 and h.robot.svr.variables["g_name"] == "Cell 2"
    assert ask(h, peer, "Q4,12,g_ok\r\ng_pos\r\ng_ss") == \
        b'Q4,12,g_ok=false\r\ng_pos={0,0,1,0,0,0}\r\ng_ss={"a","b","c"}'


def test_status_codes_for_variables_17_4_1(h):
    peer = h.connect_svr()
    assert ask(h, peer, "S1,12,g_missing") == b"S1,0,04,NotExist;g_missing"
    assert ask(h, peer, "S2,2,g_missing=1") == b"S2,0,04,NotExist;g_missing"
    assert ask(h, peer, "S3,2,g_limit=5") == b"S3,0,05,ReadOnly;g_limit"
    h.robot.svr_source.set_auto_mode(False)
    assert ask(h, peer, "S4,2,g_mode=1") == b"S4,0,06,ModeError;g_mode"
    h.robot.svr_source.set_auto_mode(True)
    assert ask(h, peer, "S5,2,g_mode=1") == b"S5,0,00,OK"
    # "Values to write mismatches with the configured type or the size" (the manual's adata={1,2,3} for int[4])
    for content in ("g_count=1.5", 'g_count="x"', "g_pos={1,2,3}", "g_ok=2", 'g_name=abc', "g_count={1,2}"):
        assert ask(h, peer, "S6,2," + content) == f"S6,0,07,ValueError;{content.split('=')[0]}".encode(), content
    assert h.robot.svr.variables["g_count"] == 5                      # nothing of a refused write is performed
    h.robot.svr.configure(write_permission=False)
    assert ask(h, peer, "S7,2,g_count=1") == b"S7,0,02,WritePermission"
    assert ask(h, peer, "S8,12,g_count") == b"S8,12,g_count=5"       # reading needs no write permission


def test_a_variable_may_be_streamed_in_the_data_table(h):
    h.robot.svr.configure(items=["g_count", "Project_Speed"], mode=2, period=0.1)
    peer = h.connect_svr()
    assert h.until(lambda: peer.frames, timeout=1)
    assert peer.frames[0].data.endswith(b",2,Robot_Link=1\r\ng_count=5\r\nProject_Speed=100")


def test_fault_answer_other_item_answers_a_read_with_another_item_until_cleared(h):
    """A robot that answers another item than the one asked for (the library's 16#3008): the other item's name and
    value stand in the answer; clear_faults() ends it; what names no item is refused with the parameter named."""
    peer = h.connect_svr()
    h.srv.svr.inject(h.robot, "answer_other_item", item="g_count", instead="g_ratio")
    assert ask(h, peer, "Q1,12,g_count\r\ng_ok") == b"Q1,12,g_ratio=0.5\r\ng_ok=true"
    h.srv.svr.clear_faults(h.robot)
    assert ask(h, peer, "Q2,12,g_count\r\ng_ok") == b"Q2,12,g_count=5\r\ng_ok=true"
    for params, words in [({"item": "g_none", "instead": "g_ratio"}, "'item' of fault 'answer_other_item'"),
                          ({"item": "g_count"}, "'instead' of fault 'answer_other_item'"),
                          ({"item": "g_count", "instead": ["g_ratio"]}, "'instead' of fault"),
                          ({"item": "g_count", "instead": "g_ratio", "count": 1}, "has no parameter count")]:
        with pytest.raises(ValueError, match=words):
            h.srv.svr.inject(h.robot, "answer_other_item", **params)


def test_fault_answer_other_item_also_stands_in_the_data_table(h):
    h.robot.svr.configure(items=["g_count", "Project_Speed"], mode=2, period=0.1)
    h.srv.svr.inject(h.robot, "answer_other_item", item="g_count", instead="g_ratio")
    peer = h.connect_svr()
    assert h.until(lambda: peer.frames, timeout=1)
    assert peer.frames[0].data.endswith(b",2,Robot_Link=1\r\ng_ratio=0.5\r\nProject_Speed=100")


@pytest.mark.parametrize("spec,message", [
    ("g_x", "expected NAME:TYPE[:ACCESS][=VALUE]"),
    ("g x:int", "1..64 letters, digits or '_'"),
    ("g_x:long", "type 'long' is not one of bool, byte, int, float, string"),
    ("g_x:int[0]", "array size must be 1..1024"),
    ("g_x:int[many]", "array size 'many' is not a number"),
    ("g_x:int=1.5", "value '1.5' is not a int"),
    ("g_x:int[2]={1,2,3}", "needs 2 values"),
    ("Ctrl_DO0:int", "is a predefined item of the data table"),
    ("g_x:int:rx", "access 'rx' is not one of rw, auto, ro"),
])
def test_a_bad_declaration_is_refused_with_what_is_wrong(spec, message):
    args = build_parser().parse_args(["--svr-var", spec])
    problems, variables = check_variables(args)
    assert variables == [] and len(problems) == 1 and message in problems[0], problems


def test_the_option_declares_the_variables_and_lets_the_data_table_stream_them():
    args = build_parser().parse_args(["--svr-var", "g_a:int=1", "--svr-var", "g_b:float[2]", "--svr-items", "g_a"])
    problems, variables = check_variables(args)
    assert problems == [] and [(i.name, i.type, i.size, v) for i, v in variables] == \
        [("g_a", "int", 1, 1), ("g_b", "float", 2, [0.0, 0.0])]
    assert check_args(args)[0] == []
    twice = build_parser().parse_args(["--svr-var", "g_a:int", "--svr-var", "g_a:float"])
    assert "declared twice" in check_variables(twice)[0][0]


def test_declare_checks_the_value():
    session = SvrSession(source=None, period=0)
    with pytest.raises(SvrConfigError, match="global variable g_x: g_x value 300 is outside 0..255"):
        session.declare(table.variable_item("g_x", "byte"), 300)
    with pytest.raises(SvrConfigError, match="not a global variable"):
        session.declare(table.ITEMS["Ctrl_DO0"])
