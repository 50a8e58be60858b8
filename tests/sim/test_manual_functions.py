"""The function table follows the TMscript 2.24 manual (Techman, Programming Language TMscript, SW 2.24):
§13.4 StopAndClearBuffer() has no parameter, §13.5 ChangeBase has the syntax (string, int), and §15.8
priority commands take a literal argument only - a packet with StopAndClearBuffer(var) is invalid
(ERROR;line) and nothing of it runs."""
import pytest
from session_rig import PTP_LONG, S, sct

from tmsim.protocol import codec
from tmsim.tmscript import functions as tmscript
from tmsim.tmscript.profiles import Profile


def reply(ident, status):
    return codec.encode("TMSCT", f"{ident},{status}").decode()


def test_change_base_with_a_name_and_an_index_is_valid_and_changes_the_base_by_name(node):
    """§13.5 syntax 1, the manual's own example: ChangeBase("RobotBase", 10) - for the name of a base the
    index has no meaning."""
    assert node.send(1, sct("1", 'ChangeBase("RobotBase", 10)')) == [reply("1", "OK")]
    node.advance(0.05)
    assert node.s.robot.state()["base"]["name"] == "RobotBase"
    assert [f["name"] for kind, f in node.events if kind == "setting" and f["what"] == "base"] == ["RobotBase"]


def test_change_base_with_an_index_is_a_2_24_function_tmflow_1_8_refuses_it():
    """TMflow 1.84 lists ChangeBase(string) only (shared/tm_protocol.md §7); syntax 1 came with 2.x."""
    old = S(profile=Profile(tmflow="1.8"))
    old.connect(1)
    assert old.send(1, sct("1", 'ChangeBase("RobotBase", 10)')) == [reply("1", "ERROR;1")]
    assert old.send(1, sct("2", 'ChangeBase("RobotBase")')) == [reply("2", "OK")]


def test_stop_and_clear_buffer_with_a_variable_is_an_invalid_packet_and_nothing_runs(node):
    """§15.8: '$TMSCT,42,1,int var_st=2\\r\\nStopAndClearBuffer(var_st)' is answered ERROR;2 - the priority
    command takes no variable - and the arm keeps moving."""
    node.send(1, sct("M", PTP_LONG))
    node.advance(0.5)
    assert node.s.robot.state()["moving"]
    frame = b"$TMSCT,42,1,int var_st=2\r\nStopAndClearBuffer(var_st),*3A\r\n"
    assert codec.encode("TMSCT", "1,int var_st=2\r\nStopAndClearBuffer(var_st)") == frame     # the manual's bytes
    assert node.send(1, frame) == ["$TMSCT,9,1,ERROR;2,*04\r\n"]                              # the manual's answer
    assert "var_st" not in node.s.variables
    assert node.s.robot.state()["moving"] and not any(kind == "stop" for kind, _ in node.events)


@pytest.mark.parametrize("line", ["StopAndClearBuffer(3)", "StopAndClearBuffer(1+1)", "StopAndClearBuffer(0.5)"])
def test_stop_and_clear_buffer_with_any_other_argument_is_invalid(node, line):
    """§13.4 defines StopAndClearBuffer() only; §15.8 the literal priority forms 0, 1 and 2."""
    assert node.send(1, sct("1", "QueueTag(1)\r\n" + line)) == [reply("1", "ERROR;2")]
    assert node.s.robot.queue_length == 0


def test_the_priority_and_the_statement_forms_of_stop_and_clear_buffer_still_work(node):
    """§13.4 StopAndClearBuffer() in script order; §15.8 StopAndClearBuffer(0) at once."""
    node.send(1, sct("M", PTP_LONG))
    assert node.send(1, sct("S", "StopAndClearBuffer()")) == [reply("S", "OK")]
    assert not node.s.robot.state()["moving"]
    node.send(1, sct("N", PTP_LONG))
    assert node.send(1, sct("P", "StopAndClearBuffer(0)")) == [reply("P", "OK")]
    assert not node.s.robot.state()["moving"]


def test_the_function_table_has_exactly_the_manual_overloads_of_both_functions():
    assert [params for params, _ret, _v in tmscript.FUNCTIONS["StopAndClearBuffer"][1]] == [()]      # §13.4
    assert sorted(params for params, _ret, _v in tmscript.FUNCTIONS["ChangeBase"][1]) == sorted(      # §13.5
        [("string", "int"), ("string",), ("float[]",), ("float",) * 6])
