"""The TMscript 2.24 manual's printed Listen-node and Ethernet Slave examples, sent byte for byte over loopback
(chapter 15 Listen Node, chapter 17 Ethernet Slave): what a client built to the manual sends, and the exact
bytes it must get back."""
import pytest
from sim_harness import Harness


@pytest.fixture
def h():
    harness = Harness()
    yield harness
    harness.close()


def exchange(h, peer, frame, count=1):
    """Send the manual's bytes and return the raw bytes of the next ``count`` frames."""
    start = len(peer.frames)
    peer.send(frame)
    assert h.until(lambda: len(peer.frames) >= start + count), f"no reply to {frame!r}"
    return b"".join(f.raw for f in peer.frames[start:])


def test_manual_15_3_three_line_script_selects_the_robot_end_flange_tool(h):
    # §15.3 Receive item 3: ChangeTCP("RobotEndFlange") is the manual's own example; before, the simulator
    # knew only "NOTOOL", took it for an unknown tool, stopped the project and closed the connection.
    peer = h.connect()
    reply = exchange(h, peer, b'$TMSCT,72,2,ChangeBase("RobotBase")\r\nChangeTCP("RobotEndFlange")\r\n'
                              b'ChangeLoad(10.1),*5A\r\n')
    assert reply == b"$TMSCT,4,2,OK,*5F\r\n"
    h.run(0.1)
    state = h.robot.state()
    assert not peer.closed and state["node_state"] == "in_node" and state["project_running"]
    assert state["tool"]["name"] == "RobotEndFlange" and state["load"] == 10.1


def test_manual_15_7_script_exit_example_leaves_the_node_and_skips_the_rest(h):
    peer = h.connect()
    reply = exchange(h, peer, b'$TMSCT,86,2,ChangeBase("RobotBase")\r\nChangeTCP("RobotEndFlange")\r\n'
                              b'ScriptExit()\r\nChangeLoad(10.1),*58\r\n')
    assert reply == b"$TMSCT,4,2,OK,*5F\r\n"
    assert h.until(lambda: h.robot.state()["node_state"] != "in_node")
    state = h.robot.state()
    assert state["tool"]["name"] == "RobotEndFlange" and state["project_running"]
    assert state["load"] == 0.0                # "ChangeLoad will not be executed"
    assert exchange(h, peer, b'$TMSCT,25,1,ChangeBase("RobotBase"),*08\r\n') == b"$CPERR,2,F1,*3F\r\n"
