"""Inputs of the simulated robot for the PLC's I/O reads (issue 26 item 1): RobotDataSource.set_input changes a
control-box or end-module input as a wired sensor would, the Ethernet Slave's reads and data table show it
(TMflow 2.24 Appendix D items Ctrl_DI?, End_DI?, Ctrl_AI?, End_AI?), and anything that is not an input, or a
value the input cannot hold, is refused with a message naming it and changes nothing. Project_Speed as the PLC's
override writes it (mode 2, multiples of 5 in 5..100) is in test_ethernet_slave.py."""
import pytest
from sim_harness import Harness
from svr_client import ask, values

from tmsim.net.server import SimServer


@pytest.fixture
def h():
    harness = Harness(svr_port=0, svr_options={"period": 0})
    yield harness
    harness.close()


def test_a_set_input_shows_in_the_next_read_and_is_logged(h):
    peer = h.connect_svr()
    source = h.robot.svr_source
    source.set_input("End_DI0", 1)
    source.set_input("Ctrl_DI15", True)
    source.set_input("Ctrl_AI1", -2.5)
    assert values(h, peer, ["End_DI0", "Ctrl_DI15", "Ctrl_AI1", "End_DI1"]) == \
        {"End_DI0": 1, "Ctrl_DI15": 1, "Ctrl_AI1": -2.5, "End_DI1": 0}
    source.set_input("End_DI0", 0)
    assert values(h, peer, ["End_DI0"]) == {"End_DI0": 0}
    logged = [(e["point"], e["value"]) for e in h.robot.events if e["kind"] == "io" and e.get("source") == "input"]
    assert logged == [("EndModule.DI[0]", 1), ("ControlBox.DI[15]", 1), ("ControlBox.AI[1]", -2.5),
                      ("EndModule.DI[0]", 0)]


def test_an_input_is_read_by_a_tmscript_read_of_the_same_point(h):
    """The same point as IO['EndModule'].DI[0] in a script: one value, whichever channel reads it."""
    h.robot.svr_source.set_input("End_DI0", 1)
    assert h.robot.session.robot.io["EndModule.DI[0]"] == 1


@pytest.mark.parametrize("name,value,words", [
    ("End_DO0", 1, "not an input"), ("Ctrl_AO0", 1.0, "not an input"), ("Project_Speed", 50, "not an input"),
    ("End_DI9", 1, "not an input"), ("Nope", 1, "not an input"),
    ("End_DI0", 2, "0 or 1"), ("End_DI0", 0.5, "0 or 1"), ("Ctrl_AI0", 10.5, "-10..10"),
    ("Ctrl_AI0", True, "-10..10"), ("Ctrl_AI0", "3", "-10..10")])
def test_anything_but_an_input_value_is_refused_and_changes_nothing(h, name, value, words):
    before = dict(h.robot.session.robot.io)
    with pytest.raises(ValueError, match=words) as err:
        h.robot.svr_source.set_input(name, value)
    assert repr(name) in str(err.value) or name in str(err.value)
    assert h.robot.session.robot.io == before


def test_an_output_written_by_the_ethernet_slave_reads_back_in_the_data_table_items(h):
    """The read-back of a gripper output: what a client wrote (mode 2) is what the item shows."""
    peer = h.connect_svr()
    assert ask(h, peer, "W1,2,End_DO0=1") == ("TMSVR", b"W1,0,00,OK")
    assert values(h, peer, ["End_DO0"]) == {"End_DO0": 1}


def test_the_control_channel_sets_an_input_and_names_what_it_refuses():
    """`set_input` on the control channel (docs/simulator.md, Control channel) is RobotDataSource.set_input: the
    next read shows the value; a wrong item, a wrong value or a missing field is answered ok: false by name."""
    from tmsim.net.control import request
    srv = SimServer(port=0, control_port=0, svr_port=0)
    srv.start_background()
    try:
        port = srv.control.port
        assert request(port, {"cmd": "set_input", "name": "End_DI0", "value": 1}) == {"ok": True, "result": None}
        assert request(port, {"cmd": "set_input", "name": "Ctrl_AI0", "value": 2.5})["ok"]
        assert request(port, {"cmd": "set_input", "name": "Ctrl_DI3", "value": True})["ok"]
        io = srv.robots[0].session.robot.io
        assert (io["EndModule.DI[0]"], io["ControlBox.AI[0]"], io["ControlBox.DI[3]"]) == (1, 2.5, 1)
        assert "not an input" in request(port, {"cmd": "set_input", "name": "End_DO0", "value": 1})["error"]
        assert "0 or 1" in request(port, {"cmd": "set_input", "name": "End_DI0", "value": 2})["error"]
        assert "'value' missing" in request(port, {"cmd": "set_input", "name": "End_DI0"})["error"]
        assert "'name' must be a text" in request(port, {"cmd": "set_input", "value": 1})["error"]
        assert io["EndModule.DI[0]"] == 1
    finally:
        srv.close()
    plain = SimServer(port=0, control_port=0)
    plain.start_background()
    try:
        assert "not running" in request(plain.control.port, {"cmd": "set_input", "name": "End_DI0",
                                                             "value": 1})["error"]
    finally:
        plain.close()
