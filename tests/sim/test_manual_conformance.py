"""The TMscript 2.24 manual's printed Listen-node and Ethernet Slave examples, sent byte for byte over loopback
(chapter 15 Listen Node, chapter 17 Ethernet Slave): what a client built to the manual sends, and the exact
bytes it must get back."""
import pytest
from sim_harness import Harness

from tmsim.protocol import codec
from tmsim.protocol import svr_table as table


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


# TMscript 2.24 §15.8, the five worked examples of the priority commands: script 1 (and 2) wait in QueueTag(n,1)
# behind a motion, then a priority command arrives. Exact bytes of the manual, in the order it prints them.
P1 = (b'$TMSCT,86,1,float[] targetP1= {0,0,90,0,90,0}\r\nPTP("JPP",targetP1,10,200,0,false)\r\n'
      b'QueueTag(1,1),*60\r\n')
P2 = (b'$TMSCT,86,2,float[] targetP2= {90,0,0,90,0,0}\r\nPTP("JPP",targetP2,10,200,0,false)\r\n'
      b'QueueTag(2,1),*60\r\n')


def waiting(h, *packets):
    """The manual's packets sent while the arm is on its way elsewhere (from the home pose, the manual's
    targetP1 would be reached at once): script 1 then waits in its QueueTag(1,1)."""
    peer = h.connect()
    assert exchange(h, peer, codec.encode("TMSCT", '0,PTP("JPP",{90,0,0,90,0,0},10,200,0,false)')) == \
        b"$TMSCT,4,0,OK,*5D\r\n"
    peer.frames.clear()
    for packet in packets:
        peer.send(packet)
    h.run(0.2)
    assert peer.frames == []                   # "QueueTag(1,1) waits"
    return peer


def test_manual_15_8_example_1_script_exit_0_answers_the_waiting_script_first_and_leaves_via_fail(h):
    peer = waiting(h, P1)
    assert exchange(h, peer, b"$TMSCT,15,2,ScriptExit(0),*55\r\n", 2) == \
        b"$TMSCT,4,1,OK,*5C\r\n$TMSCT,4,2,OK,*5F\r\n"
    state = h.robot.state()
    assert state["node_state"] != "in_node" and state["exit_path"] == "Fail"


def test_manual_15_8_example_2_stop_0_answers_the_released_script_before_itself(h):
    # before: the priority command's OK went first ($TMSCT,4,2,OK then $TMSCT,4,1,OK), against the manual
    peer = waiting(h, P1)
    assert exchange(h, peer, b"$TMSCT,23,2,StopAndClearBuffer(0),*55\r\n", 2) == \
        b"$TMSCT,4,1,OK,*5C\r\n$TMSCT,4,2,OK,*5F\r\n"
    h.run(0.5)
    assert len(peer.frames) == 2               # "It does not send out TMSTA tag number" for the cleared tag
    assert h.robot.state()["node_state"] == "in_node"


def test_manual_15_8_example_3_stop_0_cannot_end_a_wait_on_tag_0_so_script_1_answers_after_60_s(h):
    peer = waiting(h, b'$TMSCT,145,1,float[] targetP1= {0,0,90,0,90,0}\r\nPTP("JPP",targetP1,10,200,0,false)\r\n'
                      b'QueueTag(1,0)\r\nWaitQueueTag(0,60000)\r\nPTP("JPP",targetP1,40,200,0,false),*64\r\n')
    assert exchange(h, peer, b"$TMSCT,23,2,StopAndClearBuffer(0),*55\r\n") == b"$TMSCT,4,2,OK,*5F\r\n"
    h.run(59.0, dt=0.5)
    assert len(peer.frames) == 1
    assert h.until(lambda: len(peer.frames) == 2, timeout=2.0)
    assert peer.frames[1].raw == b"$TMSCT,4,1,OK,*5C\r\n"


def test_manual_15_8_example_4_stop_1_ends_script_1_and_runs_script_2(h):
    peer = waiting(h, P1, P2)
    assert exchange(h, peer, b"$TMSCT,23,3,StopAndClearBuffer(1),*55\r\n", 2) == \
        b"$TMSCT,4,1,OK,*5C\r\n$TMSCT,4,3,OK,*5E\r\n"
    assert h.until(lambda: len(peer.frames) == 4, timeout=30.0)
    # the manual prints script 2's OK before the tag 2 push; its layout there is garbled, and the simulator
    # keeps the push first (docs/simulator.md, choices): both frames are the manual's bytes
    assert sorted(f.raw for f in peer.frames[2:]) == [b"$TMSCT,4,2,OK,*5F\r\n", b"$TMSTA,10,01,02,true,*67\r\n"]


def test_manual_15_8_example_5_stop_2_ends_script_1_and_discards_script_2_without_a_reply(h):
    peer = waiting(h, P1, P2)
    assert exchange(h, peer, b"$TMSCT,23,3,StopAndClearBuffer(2),*56\r\n", 2) == \
        b"$TMSCT,4,1,OK,*5C\r\n$TMSCT,4,3,OK,*5E\r\n"
    h.run(30.0, dt=0.1)
    assert len(peer.frames) == 2 and h.robot.state()["queue_length"] == 0


# TMscript 2.24 §17.4.2-17.4.4: the global variable g_ss is a `string[]` (no size); the manual's T2 writes two texts
# over its three and is answered 00 OK. Before, every declared array had a fixed size and T2 got 07 ValueError.
@pytest.fixture
def svr():
    harness = Harness(svr_port=0, svr_options={"period": 0, "variables": [
        table.parse_variable('g_ss:string[]={"Hi","TM","Robot"}'), table.parse_variable("g_arr:int[]={1,2}"),
        table.parse_variable("g_pos:float[6]")]})
    yield harness
    harness.close()


def test_manual_17_4_2_binary_write_of_a_string_array_with_another_length_is_ok(svr):
    peer = svr.connect_svr()
    request = bytes.fromhex("24544D5356522C" "32352C" "54322C312C" "0400675F7373" "0C0048656C6C6F0000576F726C64"
                            "2C2A30320D0A")
    assert exchange(svr, peer, request) == b"$TMSVR,10,T2,0,00,OK,*1D\r\n"
    assert svr.robot.svr.variables["g_ss"] == ["Hello", "World"]
    assert exchange(svr, peer, codec.encode("TMSVR", "R1,12,g_ss")) == \
        codec.encode("TMSVR", 'R1,12,g_ss={"Hello","World"}')


def test_manual_17_4_4_json_write_of_the_string_array_is_ok(svr):
    peer = svr.connect_svr()
    assert exchange(svr, peer, b'$TMSVR,113,T9,3,[{"Item":"Ctrl_DO0","Value":1},{"Item":"Ctrl_DO1","Value":0},'
                               b'{"Item":"g_ss","Value":["Hello","TM","Robot"]}],*7C\r\n') == \
        b"$TMSVR,10,T9,0,00,OK,*16\r\n"
    assert svr.robot.svr.variables["g_ss"] == ["Hello", "TM", "Robot"]


def test_an_unsized_array_takes_any_number_of_elements_a_sized_one_keeps_its_size(svr):
    peer = svr.connect_svr()
    assert exchange(svr, peer, codec.encode("TMSVR", "W1,2,g_arr={1,2,3}")) == codec.encode("TMSVR", "W1,0,00,OK")
    packed = b"\x04\x00" + (7).to_bytes(4, "little")
    assert exchange(svr, peer, codec.encode("TMSVR", b"W2,1,\x05\x00g_arr" + packed)) == \
        codec.encode("TMSVR", "W2,0,00,OK")
    assert svr.robot.svr.variables["g_arr"] == [7]
    reply = exchange(svr, peer, codec.encode("TMSVR", b"R1,11,\x05\x00g_arr"))
    assert reply == codec.encode("TMSVR", b"R1,11,\x05\x00g_arr" + packed)
    for bad in ("W3,2,g_arr={}", "W3,2,g_arr=5", "W3,2,g_pos={1,2,3}"):
        name = bad.split(",")[2].split("=")[0]
        assert exchange(svr, peer, codec.encode("TMSVR", bad)) == codec.encode("TMSVR", f"W3,0,07,ValueError;{name}")
    odd = b"W4,1,\x05\x00g_arr\x03\x00\x01\x02\x03"                # 3 bytes: no whole int
    assert exchange(svr, peer, codec.encode("TMSVR", odd)) == codec.encode("TMSVR", "W4,0,07,ValueError;g_arr")
    assert svr.robot.svr.variables["g_arr"] == [7]


@pytest.mark.parametrize("spec, words", [("g_x:int[]={}", "1..1024"), ("g_x:bool[]={1,2}", "outside 0..1"),
                                         ("g_x:thing[]", "type 'thing'")])
def test_an_unsized_array_declaration_names_what_is_wrong(spec, words):
    with pytest.raises(ValueError, match=words):
        table.parse_variable(spec)


# The manual's ambiguous or misprinted points, as docs/simulator.md "Choices" answers them.
def test_manual_15_5_f1_example_with_its_misprinted_checksum_is_a_checksum_error(h):
    # §15.5 prints `$TMSCT,25,1,ChangeBase("RobotBase"),*0D` as its F1 example; the checksum of those bytes is
    # *08 (the 15.7 example above), and the frame is checked before its content: CPERR 02
    assert codec.encode("TMSCT", '1,ChangeBase("RobotBase")').endswith(b",*08\r\n")
    peer = h.connect()
    assert exchange(h, peer, b'$TMSCT,25,1,ChangeBase("RobotBase"),*0D\r\n') == b"$CPERR,2,02,*4A\r\n"


@pytest.mark.parametrize("data", ["90", "95,x", "99"])
def test_manual_15_4_tmsta_90_to_99_from_a_client_is_a_data_error(h, data):
    # §15.4: sub-commands 90-99 go from the robot to the client only ("Receive: None")
    peer = h.connect()
    assert exchange(h, peer, codec.encode("TMSTA", data)) == b"$CPERR,2,04,*4C\r\n"


def test_manual_17_4_a_tmsvr_packet_without_a_mode_is_a_data_error(svr):
    peer = svr.connect_svr()
    assert exchange(svr, peer, codec.encode("TMSVR", "S6")) == b"$CPERR,2,04,*4C\r\n"


def test_manual_17_4_3_and_17_4_6_examples_with_their_misprinted_length(svr):
    # The printed checksums are those of the right lengths (27 and 26, not 15 and 28)
    write = codec.encode("TMSVR", "T2,2,Ctrl_DO0=0\r\nCtrl_DO1=1")
    read = codec.encode("TMSVR", "Q2,12,Robot_Link\r\nTCP_Mass")
    assert (write, read) == (b"$TMSVR,27,T2,2,Ctrl_DO0=0\r\nCtrl_DO1=1,*34\r\n",
                             b"$TMSVR,26,Q2,12,Robot_Link\r\nTCP_Mass,*0E\r\n")
    peer = svr.connect_svr()
    # as printed (length 15), the length field does not end at the data's end: CPERR 01 (§15.5's rule)
    assert exchange(svr, peer, b"$TMSVR,15,T2,2,Ctrl_DO0=0\r\nCtrl_DO1=1,*34\r\n") == b"$CPERR,2,01,*49\r\n"
    # with the right length, the manual's replies (§17.4.6 prints Robot_Link=0: its robot is not connected)
    assert exchange(svr, peer, write) == b"$TMSVR,10,T2,0,00,OK,*1D\r\n"
    assert exchange(svr, peer, read) == codec.encode("TMSVR", "Q2,12,Robot_Link=1\r\nTCP_Mass=0")
    assert codec.encode("TMSVR", "Q2,12,Robot_Link=0\r\nTCP_Mass=0").endswith(b",*09\r\n")    # the printed reply
