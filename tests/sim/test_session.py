"""Listen-node session (sans-I/O): replies, node transitions, priority commands, in-order execution."""
import struct

import pytest
from session_rig import PTP_LONG, S, sct, sta

from tmsim.limits import CPERR_BURST, CPERR_PER_S, TurnBudget
from tmsim.protocol import codec
from tmsim.protocol.listen_protocol import FRAME_LIMIT, INPUT_DONE, INPUT_LEFT
from tmsim.protocol.listen_session import EXITING, IDLE, IN_NODE, STOPPED, TRANSITIONS, TransitionError


def budget(items, decoded, **bounds):
    """A turn of at most ``items`` handled and ``decoded`` decoded, its work not metered."""
    return TurnBudget(items=items, decoded=decoded, waiting=bounds.get("waiting"), work=None,
                      frame_limit=bounds.get("frame_limit"))


def test_nothing_is_sent_on_connect_and_enter_message_only_when_entering():
    n = S(auto_enter=False)
    n.connect(1)
    assert n.out(1) == []
    n.s.fire("enter_node")
    assert n.out(1) == ["$TMSCT,9,0,Listen1,*4C\r\n"]
    n.connect(2)
    assert n.out(2) == []


def test_tmsta_00_true_with_message_and_false_with_trailing_comma(node):
    assert node.send(1, b"$TMSTA,2,00,*41\r\n") == ["$TMSTA,15,00,true,Listen1,*79\r\n"]
    assert node.send(1, b"$TMSTA,3,00,,*6c\r\n") == ["$TMSTA,15,00,true,Listen1,*79\r\n"]
    node.s.fire("leave_node")
    assert node.send(1, b"$TMSTA,2,00,*41\r\n") == ["$TMSTA,9,00,false,,*37\r\n"]


def test_tmsta_01_echoes_the_tag_as_received(node):
    node.send(1, sct("1", "QueueTag(3)"))
    assert node.send(1, sta("01,03")) == [codec.encode("TMSTA", "01,03,false").decode()]
    assert node.send(1, sta("01,3")) == [codec.encode("TMSTA", "01,3,false").decode()]
    assert node.send(1, b"$TMSTA,5,01,88,*6B\r\n") == ["$TMSTA,10,01,88,none,*79\r\n"]
    node.advance(0.01)
    assert node.out(1) == [codec.encode("TMSTA", "01,03,true").decode()]     # the push
    assert node.send(1, sta("01,03")) == [codec.encode("TMSTA", "01,03,true").decode()]


@pytest.mark.parametrize("raw", [b"$TMSTA,4,XXXX,*47\r\n", sta("01"), sta("02,1")])
def test_tmsta_unknown_subcommand_gives_cperr_04(node, raw):
    assert node.send(1, raw) == ["$CPERR,2,04,*4C\r\n"]


@pytest.mark.parametrize("data", ['ChangeBase("RobotBase")', ',QueueTag(1)', 'a-b,QueueTag(1)', 'a b,x'])
def test_tmsct_with_missing_or_non_alphanumeric_id_gives_cperr_04(node, data):
    assert node.send(1, codec.encode("TMSCT", data)) == ["$CPERR,2,04,*4C\r\n"]


def test_manual_cperr_04_example(node):
    assert node.send(1, b'$TMSCT,23,ChangeBase("RobotBase"),*13\r\n'[:0] + codec.encode(
        "TMSCT", 'ChangeBase("RobotBase")')) == ["$CPERR,2,04,*4C\r\n"]


@pytest.mark.parametrize("raw, reply", [
    (b'$TMSCT,-100,1,ChangeBase("RobotBase"),*13\r\n', "$CPERR,2,01,*49\r\n"),
    (b'$TMSCT,25,1,ChangeBase("RobotBase"),*09\r\n', "$CPERR,2,02,*4A\r\n"),
    (b'$TMsct,25,1,ChangeBase("RobotBase"),*28\r\n', "$CPERR,2,03,*4B\r\n"),
    (b"$CPERR,2,01,*49\r\n", "$CPERR,2,03,*4B\r\n"),
])
def test_cperr_triggers(node, raw, reply):
    assert node.send(1, raw)[0] == reply


def test_tmsct_outside_node_gives_cperr_f1(node):
    node.s.fire("leave_node")
    assert node.send(1, b'$TMSCT,25,1,ChangeBase("RobotBase"),*08\r\n') == ["$CPERR,2,F1,*3F\r\n"]


def test_script_ok_reply_and_settings_apply_in_queue_order(node):
    assert node.send(1, b'$TMSCT,25,1,ChangeBase("RobotBase"),*08\r\n') == ["$TMSCT,4,1,OK,*5C\r\n"]
    node.send(1, sct("2", "ChangeBase({10,20,30,0,0,0})\r\nChangeTCP({0,0,100,0,0,0},2.5)\r\nChangeLoad(3)"))
    assert node.s.robot.base_name == "RobotBase"      # queued, not yet applied
    node.advance(0.01)
    state = node.s.snapshot()
    assert state["base"]["pose"] == [10, 20, 30, 0, 0, 0]
    assert state["tool"]["pose"][2] == 100 and state["tool"]["mass"] == 2.5 and state["load"] == 3.0


def test_error_reply_lists_lines_and_nothing_executes(node):
    script = 'int a = 1\r\nPTP("JPP",0,0,90,0,90,0,35,200,0,false)\r\nFoo()\r\nLine("XYZ",1,2,3,4,5,6,1,2,3,true)'
    assert node.send(1, sct("M2", script)) == [codec.encode("TMSCT", "M2,ERROR;3;4").decode()]
    assert node.s.robot.queue_length == 0 and "a" not in node.s.variables
    assert not any(kind == "script_line" for kind, _ in node.events)


def test_warning_lines_are_listed_after_ok(node):
    assert node.send(1, sct("2", "QueueTag(1)\r\nQueueTag(2.5)\r\nQueueTag(3.5)")) == ["$TMSCT,8,2,OK;2;3,*52\r\n"]


def test_unquoted_string_constant_runs_with_a_warning(node):
    assert node.send(1, sct("2", "ChangeBase(RobotBase)")) == [codec.encode("TMSCT", "2,OK;1").decode()]
    node.advance(0.01)
    assert node.s.robot.base_name == "RobotBase"


def test_manual_redeclaration_pair(node):
    assert node.send(1, b"$TMSCT,40,3,int var_i = 100\r\nvar_i = 1000\r\nvar_i++,*5A\r\n") == ["$TMSCT,4,3,OK,*5E\r\n"]
    assert node.s.variables["var_i"] == 1001
    assert node.send(1, b"$TMSCT,42,4,int var_i = 100\r\nvar_i = 1000\r\nvar_i++\r\n,*58\r\n") == \
        ["$TMSCT,9,4,ERROR;1,*02\r\n"]


def test_variables_are_forgotten_when_the_node_is_left(node):
    node.send(1, sct("1", "int k = 5"))
    node.s.fire("leave_node")
    node.s.fire("enter_node")
    node.out(1)
    assert node.send(1, sct("2", "k = 6")) == [codec.encode("TMSCT", "2,ERROR;1").decode()]


def test_queue_tag_wait_delays_ok_and_pushes_tag(node):
    assert node.send(1, sct("M1", PTP_LONG + "\r\nQueueTag(1,1)")) == []
    node.advance(5.0)
    assert node.out(1) == []
    node.advance(1.0)
    assert node.out(1) == ["$TMSTA,10,01,01,true,*64\r\n", "$TMSCT,5,M1,OK,*10\r\n"]


def test_scripts_of_all_clients_run_in_arrival_order_and_tmsta_answers_at_once(node):
    node.connect(2)
    node.send(1, sct("A", PTP_LONG + "\r\nQueueTag(1,1)"))
    assert node.send(2, sct("B", "QueueTag(2)")) == []
    assert node.send(2, sta("00")) == ["$TMSTA,15,00,true,Listen1,*79\r\n"]
    node.advance(6.0)
    assert codec.encode("TMSCT", "A,OK").decode() in node.out(1)
    assert codec.encode("TMSCT", "B,OK").decode() in node.out(2)


def test_priority_script_exit_0_answers_blocked_script_first_then_leaves_via_fail(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(1,1)"))
    node.advance(1.0)
    out = node.send(1, b"$TMSCT,15,2,ScriptExit(0),*55\r\n")
    assert out[-2:] == ["$TMSCT,4,1,OK,*5C\r\n", "$TMSCT,4,2,OK,*5F\r\n"]
    assert node.s.state == IDLE and node.s.exit_path == "Fail" and node.s.robot.queue_length == 0


def test_priority_script_exit_1_leaves_via_pass(node):
    node.send(1, sct("2", "ScriptExit(1)"))
    assert node.s.state == IDLE and node.s.exit_path == "Pass"


def test_priority_stop_0_keeps_current_script_and_releases_its_dropped_tag(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(1,1)\r\nint after = 7"))
    node.advance(1.0)
    out = node.send(1, b"$TMSCT,23,2,StopAndClearBuffer(0),*55\r\n")
    # TMscript 2.24 §15.8 example 2: the released script is answered first, then the priority command
    assert out == ["$TMSCT,4,1,OK,*5C\r\n", "$TMSCT,4,2,OK,*5F\r\n"]
    assert node.s.variables["after"] == 7 and node.s.state == IN_NODE
    assert node.s.robot.queue_length == 0


def test_priority_stop_1_aborts_current_and_continues_with_next_buffered(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(1,1)\r\nint after = 7"))
    node.send(1, sct("5", "int next = 1"))
    out = node.send(1, b"$TMSCT,23,3,StopAndClearBuffer(1),*55\r\n")
    assert out == ["$TMSCT,4,1,OK,*5C\r\n", "$TMSCT,4,3,OK,*5E\r\n", "$TMSCT,4,5,OK,*58\r\n"]
    assert "after" not in node.s.variables and node.s.variables["next"] == 1


def test_priority_stop_2_discards_buffered_packets_without_reply(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(1,1)"))
    node.send(1, sct("5", "int next = 1"))
    out = node.send(1, b"$TMSCT,23,3,StopAndClearBuffer(2),*56\r\n")
    assert out == ["$TMSCT,4,1,OK,*5C\r\n", "$TMSCT,4,3,OK,*5E\r\n"]
    node.advance(1.0)
    assert node.out(1) == [] and "next" not in node.s.variables


def test_priority_command_mixed_with_normal_lines_runs_alone_and_script_exit_wins(node):
    node.send(1, sct("7", 'ChangeLoad(5)\r\nStopAndClearBuffer(0)\r\nScriptExit(1)\r\nScriptExit(0)'))
    node.advance(0.1)
    assert node.s.robot.load == 0.0 and node.s.exit_path == "Pass"


def test_priority_command_needs_a_literal_argument(node):
    """TMscript 2.24 §15.8: priority commands take no variables ("StopAndClearBuffer(var_st)" answers ERROR;2);
    §15.7 defines ScriptExit() without a parameter, so ScriptExit(m) is an invalid line and the node stays."""
    node.send(1, sct("1", "int m = 0"))
    assert node.send(1, sct("2", "ScriptExit(m)")) == [codec.encode("TMSCT", "2,ERROR;1").decode()]
    assert node.s.state == IN_NODE


def test_script_exit_drains_queue_and_rejects_scripts_meanwhile(node):
    node.send(1, sct("1", PTP_LONG))
    out = node.send(1, b'$TMSCT,78,2,ChangeBase("RobotBase")\r\nChangeTCP("NOTOOL")\r\nScriptExit()\r\n'
                       b'ChangeLoad(10.1),*6C\r\n')
    assert out[-1] == codec.encode("TMSCT", "2,OK").decode()
    assert node.s.state == EXITING
    assert node.send(1, sct("3", "QueueTag(1)")) == ["$CPERR,2,F1,*3F\r\n"]
    assert node.send(1, sta("00")) == ["$TMSTA,15,00,true,Listen1,*79\r\n"]
    node.advance(6.0)
    assert node.s.state == IDLE and node.s.exit_path == "Pass" and node.s.robot.load == 0.0
    node.s.fire("enter_node")
    assert node.out(1) == ["$TMSCT,9,0,Listen1,*4C\r\n"]


def test_listen_send_text_and_binary_payloads(node):
    node.send(1, sct("1", 'ListenSend(90,"Hello World")'))
    assert node.out(1) == []                        # pushes were collected before the reply
    out = node.send(1, sct("2", "float[] f = {1,2,3,4}\r\nbyte[] b = {0x10,0x11,0x12,0x13}\r\n"
                                "ListenSend(91,f)\r\nListenSend(92,b)"))
    binary_f = codec.encode("TMSTA", b"91," + struct.pack("<4f", 1, 2, 3, 4))
    binary_b = codec.encode("TMSTA", b"92," + bytes([0x10, 0x11, 0x12, 0x13]))
    assert binary_f.endswith(b"*60\r\n") and binary_b.endswith(b"*63\r\n")
    assert out[:2] == [binary_f.decode("utf-8", "backslashreplace"), binary_b.decode("utf-8", "backslashreplace")]


def test_listen_send_hello_world_frame(node):
    out = node.send(1, sct("1", 'ListenSend(90,"Hello World")'))
    assert out[0] == "$TMSTA,14,90,Hello World,*73\r\n"


def test_listen_send_ip_filter_only_reaches_that_client(node):
    node.connect(2, peer="10.0.0.2")
    node.send(1, sct("1", 'ListenSend("10.0.0.2",95,"x")'))
    assert node.out(2) == [codec.encode("TMSTA", "95,x").decode()]


def test_wait_queue_tag_timeout_and_delay_on_virtual_time(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(4)\r\nint r = WaitQueueTag(4,500)"))
    node.advance(0.49)
    assert node.out(1) == []
    node.advance(0.03)
    assert node.out(1) == [codec.encode("TMSCT", "1,OK").decode()] and node.s.variables["r"] == 0
    node.send(1, sct("2", "int u = WaitQueueTag(9)"))
    assert node.s.variables["u"] == -1
    node.advance(6.0)
    node.out(1)
    node.send(1, sct("3", "int d = WaitQueueTag(4)"))
    assert node.s.variables["d"] == 1


def test_runtime_error_answers_error_with_the_line(node):
    assert node.send(1, sct("1", "QueueTag(1)\r\nQueueTag(20)")) == [codec.encode("TMSCT", "1,ERROR;2").decode()]


def test_unreachable_target_is_a_robot_error_that_stops_the_project(node):
    node.send(1, sct("1", 'Line("CPP",2000,0,0,180,0,0,10,200,0,true)'))
    node.advance(0.05)
    assert node.s.state == STOPPED
    assert any(kind == "motion_failed" for kind, _ in node.events)
    assert "out of reach" in node.s.snapshot()["last_error"]


def test_pause_and_resume_are_immediate(node):
    node.send(1, sct("1", PTP_LONG))
    node.advance(1.0)
    node.send(1, sct("2", "Pause()"))
    before = node.s.robot.current_joints()
    node.advance(2.0)
    assert node.s.robot.current_joints() == before and node.s.snapshot()["paused"]
    node.send(1, sct("3", "Resume()"))
    node.advance(5.0)
    assert node.s.robot.current_joints()[0] == pytest.approx(90)


def test_robot_reads_and_io_writes(node):
    node.send(1, sct("1", 'IO["ControlBox"].DO[3] = 1\r\nIO["ControlBox"].InstantDO[4] = 1\r\n'
                          "float[] p = Robot[0].CoordRobot\r\nstring n = Robot[0].BaseName"))
    assert node.s.robot.io == {"ControlBox.DO[4]": 1}
    node.advance(0.01)
    assert node.s.robot.io["ControlBox.DO[3]"] == 1
    assert node.s.variables["p"][:3] == pytest.approx([417.5, -122.3, 359.7])
    assert node.s.variables["n"] == "RobotBase"
    io = [f for kind, f in node.events if kind == "io"]
    assert io == [dict(point="ControlBox.DO[4]", value=1, instant=True), dict(point="ControlBox.DO[3]", value=1)]


def test_reply_error_fault_rejects_next_script_without_running_it(node):
    node.s.faults["reply_error"] = 1
    assert node.send(1, sct("1", "ChangeLoad(3)")) == [codec.encode("TMSCT", "1,ERROR;1").decode()]
    assert node.send(1, sct("2", "ChangeLoad(3)")) == [codec.encode("TMSCT", "2,OK").decode()]


def test_transition_table_rejects_events_that_do_not_apply():
    n = S()
    with pytest.raises(TransitionError, match="in node"):
        n.s.fire("enter_node")
    n.s.fire("stop_project")
    with pytest.raises(TransitionError):
        n.s.fire("leave_node")
    assert (STOPPED, "start_project") in TRANSITIONS


def test_stop_project_drops_buffered_scripts_without_reply(node):
    node.send(1, sct("1", PTP_LONG + "\r\nQueueTag(1,1)"))
    node.s.fire("stop_project")
    assert node.out(1) == [] and node.s.snapshot()["project_running"] is False


def test_data_timeout_leaves_the_node_via_fail():
    n = S(data_timeout=2.0)
    n.connect(1)
    n.advance(1.5)
    n.send(1, sta("00"))
    n.advance(1.9)
    assert n.s.state == IN_NODE
    n.advance(0.2)
    assert n.s.state == IDLE and n.s.exit_path == "Fail"


def test_connection_timeout_leaves_the_node_when_nobody_connects():
    n = S(connection_timeout=1.0)
    n.advance(1.05)
    assert n.s.state == IDLE and n.s.exit_path == "Fail"
    m = S(connection_timeout=1.0)
    m.connect(1)
    m.advance(3.0)
    assert m.s.state == IN_NODE


def frame(header, data):
    return codec.encode(header, data).decode()


def test_full_motion_fifo_makes_the_script_wait_for_room(monkeypatch):
    monkeypatch.setattr("tmsim.robot.model.FIFO_ITEMS_MAX", 4)
    node = S()
    node.connect()
    script = "\r\n".join(f'PTP("JPP",0,0,90,0,90,{k},100,0,0,false)' for k in range(6))
    assert node.send(1, sct("A", script)) == []              # 4 queued, the 5th waits for room
    assert len(node.s.robot.fifo) == 4 and node.s.running is not None
    assert node.send(1, codec.encode("TMSTA", "00")) == [frame("TMSTA", "00,true,Listen1")]   # still answered
    node.advance(5.0)
    assert node.out() == [frame("TMSCT", "A,OK")]               # all 6 queued once items had run
    assert node.s.robot.queue_length <= 4


def test_stop_and_clear_buffer_frees_a_script_waiting_for_room(monkeypatch):
    monkeypatch.setattr("tmsim.robot.model.FIFO_ITEMS_MAX", 2)
    node = S()
    node.connect()
    script = "\r\n".join(f"QueueTag({k})" for k in (1, 2, 3))
    node.s.robot.pause()                                       # nothing runs: the FIFO stays full
    assert node.send(1, sct("A", script)) == []
    # the priority command clears the FIFO; the third tag then finds room and A ends, and is answered before
    # the priority command (TMscript 2.24 §15.8 example 2: the script the stop lets finish goes first)
    assert node.send(1, sct("P", "StopAndClearBuffer(0)")) == [frame("TMSCT", "A,OK"), frame("TMSCT", "P,OK")]


@pytest.mark.parametrize("call,frame", [
    ('ListenPacket("1,var_i++")', "$TMSCT,9,1,var_i++,*06"),
    ('ListenPacket("TMSCT", "2,Techman Robot")', "$TMSCT,15,2,Techman Robot,*57"),
    ('ListenPacket("TMSTA", "00")', "$TMSTA,2,00,*41"),
])
def test_listen_packet_builds_the_manual_frames(node, call, frame):
    node.send(1, sct("1", f"string p = {call}"))
    assert node.s.variables["p"] == frame


def test_listen_packet_with_an_unknown_header_is_a_runtime_error(node):
    assert node.send(1, sct("1", 'string p = ListenPacket("TMXYZ", "1,x")')) == [sct("1", "ERROR;1").decode()]


def test_receive_data_takes_bytes_whole_split_and_glued_and_data_to_send_hands_out_each_frame_once():
    n = S()
    n.s.connect(1, "127.0.0.1")
    n.s.data_to_send(1)
    raw = sct("A", "int a = 1") + sct("B", "int b = 2") + sta("00")
    assert n.s.receive_data(1, raw[:7]) == 0 and n.s.data_to_send(1) == []
    assert n.s.receive_data(1, raw[7:40]) == 1
    assert n.s.receive_data(1, raw[40:]) == 2
    frames = n.s.data_to_send(1)
    assert [f.decode() for f in frames] == [codec.encode("TMSCT", "A,OK").decode(),
                                           codec.encode("TMSCT", "B,OK").decode(),
                                           codec.encode("TMSTA", "00,true,Listen1").decode()]
    assert n.s.data_to_send(1) == [] and n.s.receive_data(9, raw) == 0          # unknown connection: ignored


def test_turn_handles_buffered_input_in_bounded_turns_and_says_whether_input_is_left():
    n = S()
    n.connect(1)
    n.out(1)
    n.s.buffer_data(1, sta("00") * 3 + sta("00")[:5])
    assert n.s.turn(1, budget(2, 256)) == (2, INPUT_LEFT) and len(n.out(1)) == 2
    assert n.s.turn(1, budget(2, 256)) == (1, INPUT_DONE) and n.s.input_bytes(1) == 5      # the partial frame waits
    n.s.buffer_data(1, sta("00")[5:] + sct("A", "int a = 1") * 3)
    assert n.s.turn(1, budget(8, 2)) == (2, INPUT_LEFT)                                     # decode bound
    assert n.s.turn(1, budget(8, 256, frame_limit=6)) == (1, FRAME_LIMIT)                 # 5 frames + this one
    assert [k for k, _ in n.events].count("frame_in") == 6
    assert n.s.turn(9, budget(8, 256)) == (0, INPUT_DONE) and n.s.input_bytes(9) == 0      # unknown connection


def test_turn_stops_once_the_budgets_waiting_scripts_wait():
    n = S()
    n.connect(1)
    n.s.buffer_data(1, sct("A", "Sleep(1000)") + sct("B", "int b = 1") * 4)
    assert n.s.turn(1, budget(8, 256, waiting=2)) == (3, INPUT_LEFT) and n.s.waiting_scripts == 2


def test_bad_packets_get_cperr_burst_answers_then_cperr_per_s_and_the_rest_are_counted():
    n = S()
    n.connect(1)
    n.out(1)
    bad = sta("00")[:-4] + b"00\r\n"                        # checksum mismatch: CPERR 02
    assert n.s.receive_data(1, bad * (CPERR_BURST + 4)) == CPERR_BURST
    assert n.out(1) == [codec.encode("CPERR", codec.CPERR_CHECKSUM).decode()] * CPERR_BURST
    assert n.s.unanswered_bad(1) == 4 and not [e for e in n.events if e[0] == "cperr_suppressed"]
    n.advance(2 / CPERR_PER_S)
    assert n.s.receive_data(1, bad * 3) == 2 and n.s.unanswered_bad(1) == 1     # 2 answers refilled
    assert n.s.receive_data(1, b"$" * 1000) == 0 and n.s.unanswered_bad(1) == 1 + 999     # one '$' waits
    n.s.receive_data(1, sta("00"))
    assert [f["count"] for k, f in n.events if k == "cperr_suppressed"] == [4, 1001]    # the waiting "$" too
    assert n.events[-1][0] == "frame_in" and n.s.unanswered_bad(1) == 0


def test_disconnect_logs_the_bad_packets_left_unanswered():
    n = S()
    n.connect(1)
    n.s.receive_data(1, b"$" * (CPERR_BURST + 10))
    n.s.disconnect(1)
    assert [k for k, _ in n.events][-2:] == ["cperr_suppressed", "disconnect"]
    assert n.events[-2][1]["count"] == 9 and n.s.unanswered_bad(1) == 0


def test_control_methods_drive_the_node_without_touching_its_state():
    n = S()
    n.s.connect(1, "127.0.0.1")
    n.s.leave_node(path="Fail")
    assert n.s.state == IDLE and n.s.exit_path == "Fail"
    n.s.stop_project()
    n.s.start_project(enter_node=True)
    assert n.s.state == IN_NODE
    n.s.add_reply_errors(1)
    assert n.s.receive_data(1, sct("A", "int a = 1")) == 1
    assert n.s.data_to_send(1)[-1] == codec.encode("TMSCT", "A,ERROR;1")
    n.s.add_reply_errors(3)
    n.s.clear_reply_errors()
    n.s.receive_data(1, sct("B", "int b = 1"))
    assert n.s.data_to_send(1) == [codec.encode("TMSCT", "B,OK")] and n.s.buffered == 0


def test_robot_error_stops_a_running_project_and_is_only_latched_when_it_is_stopped():
    n = S()
    n.s.robot_error("emergency stop pressed", source="estop")
    assert n.s.state == STOPPED and n.s.last_error == "emergency stop pressed"
    assert ("state", {"event": "robot_fault", "previous": IN_NODE, "state": STOPPED,
                      "reason": "emergency stop pressed", "source": "estop"}) in n.events
    count = len(n.events)
    n.s.robot_error("emergency stop pressed")
    assert n.s.state == STOPPED and len(n.events) == count and n.s.robot.state()["robot_error"]["active"]
