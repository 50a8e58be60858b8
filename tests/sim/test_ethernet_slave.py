"""Ethernet Slave over loopback on virtual time (TMscript 2.24 chapter 17, TMflow 2.24 Appendix D): every item
read in every mode, the status codes 00-07 with the manual's worked replies, the periodic data table, and the
stick buttons acting on the project and the Listen node."""
import json

import pytest
from sim_harness import Harness, sct, sta
from svr_client import ask, svr, values

from tmsim.net.server import SimServer
from tmsim.protocol import codec
from tmsim.protocol import svr_table as table
from tmsim.protocol.svr_table import ITEMS


@pytest.fixture
def h():
    harness = Harness(svr_port=0, svr_options={"period": 0})      # no stream unless a test asks for it
    yield harness
    harness.close()


def test_every_item_is_read_in_string_json_and_binary_mode_17_4_5_to_17_4_7(h):
    peer = h.connect_svr()
    names = list(ITEMS)
    header, data = ask(h, peer, "A,12," + "\r\n".join(names))
    assert [line.split("=")[0] for line in data[5:].decode().split("\r\n")] == names
    header, data = ask(h, peer, "B,13," + json.dumps([{"Item": n} for n in names]))
    assert [entry["Item"] for entry in json.loads(data[5:])] == names
    request = b"".join(len(n).to_bytes(2, "little") + n.encode() for n in names)
    header, data = ask(h, peer, b"C,11," + request)
    pairs = table.split_binary(data[5:], True)
    assert [name for name, _ in pairs] == names
    decoded = {name: table.decode_binary_value(ITEMS[name], raw) for name, raw in pairs}
    assert decoded["Joint_Angle"] == pytest.approx([0, 0, 90, 0, 90, 0])
    assert decoded["Robot_Link"] == 1 and decoded["Project_Run"] == 1 and decoded["Error_Code"] == 0


def test_manual_17_4_5_binary_read_reply_is_byte_exact(h):
    peer = h.connect_svr()
    request = bytes.fromhex("0800" "4374726C5F444F30" "0800" "5443505F4D617373")
    start = len(peer.raw_reads)
    ask(h, peer, b"Q1,11," + request)
    assert b"".join(peer.raw_reads[start:]) == bytes.fromhex(
        "24544D5356522C" "33352C" "51312C31312C" "0800" "4374726C5F444F30" "0100" "00"
        "0800" "5443505F4D617373" "0400" "00000000" "2C2A37380D0A")


def test_manual_17_4_7_json_read_and_17_4_5_unknown_item_replies_are_exact(h):
    peer = h.connect_svr()
    peer.send(b'$TMSVR,27,Q3,13,[{"Item":"TCP_Mass"}],*3C\r\n')
    peer.send(svr("Q2,12,Ctrl_DO0\r\nTCP_MaXX"))
    assert h.until(lambda: len(peer.frames) >= 2)
    assert [f.raw for f in peer.frames] == [b'$TMSVR,39,Q3,13,[{"Item":"TCP_Mass","Value":0.0}],*40\r\n',
                                            b"$TMSVR,25,Q2,0,04,NotExist;TCP_MaXX,*17\r\n"]


@pytest.mark.parametrize("request_frame, reply", [
    (b"$TMSVR,15,S0,2,Ctrl_DO0=1,*76\r\n", b"$TMSVR,10,S0,0,00,OK,*18\r\n"),
    (b"$TMSVR,16,S1,99,Ctrl_DO0=1,*46\r\n", b"$TMSVR,18,S1,0,01,NotSupport,*0E\r\n"),
    (b"$TMSVR,15,S3,3,Ctrl_DO0=1,*74\r\n", b"$TMSVR,19,S3,0,03,InvalidData,*74\r\n"),
    (b"$TMSVR,16,S4,2,Ctrl_DO32=1,*40\r\n", b"$TMSVR,26,S4,0,04,NotExist;Ctrl_DO32,*58\r\n"),
    (b"$TMSVR,17,S5,2,Robot_Link=1,*07\r\n", b"$TMSVR,27,S5,0,05,ReadOnly;Robot_Link,*1E\r\n"),
], ids=["00", "01", "03", "04", "05"])
def test_manual_17_4_1_status_replies_are_exact(h, request_frame, reply):
    peer = h.connect_svr()
    peer.send(request_frame)
    assert h.until(lambda: peer.frames) and peer.frames[0].raw == reply


def test_status_02_write_permission_and_reads_still_allowed_17_1(h):
    h.robot.svr.configure(write_permission=False)
    peer = h.connect_svr()
    peer.send(b"$TMSVR,15,S2,2,Ctrl_DO0=1,*74\r\n")
    assert h.until(lambda: peer.frames) and peer.frames[0].raw == b"$TMSVR,23,S2,0,02,WritePermission,*6A\r\n"
    assert values(h, peer, ["Ctrl_DO0"]) == {"Ctrl_DO0": 0}


def test_status_06_mode_error_for_an_auto_only_item_in_manual_mode(h):
    h.robot.svr_source.set_auto_mode(False)
    peer = h.connect_svr()
    assert ask(h, peer, 'M1,2,Project_Name="Cell2"') == ("TMSVR", b"M1,0,06,ModeError;Project_Name")
    assert ask(h, peer, "M2,2,Stick_Plus=1") == ("TMSVR", b"M2,0,00,OK")        # sticks: M/A
    assert values(h, peer, ["Operation_Mode", "MA_Mode", "Project_Speed"]) == \
        {"Operation_Mode": 0, "MA_Mode": 1, "Project_Speed": 100}
    h.robot.svr_source.set_auto_mode(True)
    assert ask(h, peer, 'M3,2,Project_Name="Cell2"') == ("TMSVR", b"M3,0,00,OK")
    assert values(h, peer, ["Project_Name"]) == {"Project_Name": "Cell2"}


@pytest.mark.parametrize("content", ["Ctrl_DO0=2", "Project_Speed=42", "Project_Speed=200", "Ctrl_AO0=volts",
                                     'Project_Name="' + "x" * 300 + '"', "Stick_Play={1,1}"])
def test_status_07_value_error_names_the_item(h, content):
    peer = h.connect_svr()
    item = content.split("=")[0]
    assert ask(h, peer, "V1,2," + content) == ("TMSVR", f"V1,0,07,ValueError;{item}".encode())


def test_a_write_with_one_bad_item_performs_nothing_17_4(h):
    peer = h.connect_svr()
    assert ask(h, peer, "W1,2,Ctrl_DO0=1\r\nCtrl_DO1=7")[1] == b"W1,0,07,ValueError;Ctrl_DO1"
    assert ask(h, peer, "W2,2,Ctrl_DO0=1\r\nRobot_Error=1")[1] == b"W2,0,05,ReadOnly;Robot_Error"
    assert values(h, peer, ["Ctrl_DO0", "Ctrl_DO1"]) == {"Ctrl_DO0": 0, "Ctrl_DO1": 0}
    assert ask(h, peer, "W3,3," + json.dumps([{"Item": "Ctrl_DO0", "Value": 1}, {"Item": "End_DO2", "Value": 1}]))[1] \
        == b"W3,0,00,OK"
    binary = table.encode_binary([(ITEMS["Ctrl_AO0"], 2.5)])
    assert ask(h, peer, b"W4,1," + binary)[1] == b"W4,0,00,OK"
    assert values(h, peer, ["Ctrl_DO0", "End_DO2", "Ctrl_AO0"]) == {"Ctrl_DO0": 1, "End_DO2": 1, "Ctrl_AO0": 2.5}
    assert h.robot.state()["io"]["ControlBox.DO[0]"] == 1           # the robot's IO, as the Listen node sees it


def test_data_table_is_sent_every_period_on_virtual_time_ids_0_to_9(h):
    peer = h.connect_svr()
    h.robot.svr.configure(mode=2, period=0.1)
    h.run(2.0, dt=0.01)
    streams = [f for f in peer.frames if f.data[:2] in {b"%d," % i for i in range(10)}]
    assert len(streams) in (20, 21)
    assert [int(f.data.split(b",")[0]) for f in streams[:12]] == [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 0, 1]
    first = streams[0].data.decode().split(",", 2)[2].split("\r\n")
    assert first[0] == "Robot_Link=1" and any(line.startswith("Joint_Angle=") for line in first)
    h.robot.svr.configure(period=0.5)
    before = len(peer.frames)
    h.run(2.0, dt=0.01)
    assert len(peer.frames) - before in (4, 5)
    h.robot.svr.configure(period=0)
    before = len(peer.frames)
    h.run(1.0, dt=0.05)
    assert len(peer.frames) == before


def test_stream_items_modes_and_period_are_checked():
    from tmsim.protocol.svr_session import SvrConfigError
    for options in ({"items": ["Joint_Angel"]}, {"mode": 4}, {"period": -1}):
        with pytest.raises(SvrConfigError):
            Harness(svr_port=0, svr_options=options)


def test_out_of_reach_motion_shows_error_code_and_text_and_play_restarts_the_project(h):
    node, peer = h.connect(), h.connect_svr()
    h.request(node, sct("1", 'Line("CPP",2000,0,0,180,0,0,10,200,0,true)'))
    assert h.until(lambda: node.closed), "the robot error stops the project and closes the Listen node"
    status = values(h, peer, ["Robot_Error", "Error_Code", "Error_Content", "Project_Run", "Robot_State",
                              "Error_Time"])
    assert status["Robot_Error"] is True and status["Error_Code"] == 0x00010001 and status["Robot_State"] == 3
    assert "out of reach" in status["Error_Content"] and status["Project_Run"] is False
    assert len(status["Error_Time"]) == len("2026-01-01T00:00:00.000")
    assert ask(h, peer, "P1,2,Stick_Play=1")[1] == b"P1,0,00,OK"
    h.step()
    status = values(h, peer, ["Robot_Error", "Error_Code", "Project_Run"])
    assert status == {"Robot_Error": False, "Error_Code": 0x00010001, "Project_Run": True}   # last code kept
    again = h.connect()
    assert h.request(again, sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_stick_stop_stops_the_project_and_acknowledges_a_stopped_robots_error(h):
    node, peer = h.connect(), h.connect_svr()
    assert ask(h, peer, "K1,2,Stick_Stop=1")[1] == b"K1,0,00,OK"
    assert h.until(lambda: node.closed)
    assert values(h, peer, ["Project_Run"]) == {"Project_Run": False}
    h.robot.svr_source.set_estop(True)
    assert values(h, peer, ["Robot_Error", "ESTOP", "Robot_State"]) == {"Robot_Error": True, "ESTOP": True,
                                                                        "Robot_State": 4}
    assert ask(h, peer, "K2,2,Stick_Play=1")[1] == b"K2,0,00,OK"
    h.step()
    assert values(h, peer, ["Project_Run"]) == {"Project_Run": False}
    assert any(e["kind"] == "stick_refused" for e in h.robot.events)
    h.robot.svr_source.set_estop(False)
    assert ask(h, peer, "K3,2,Stick_Stop=1")[1] == b"K3,0,00,OK"
    assert values(h, peer, ["Robot_Error", "Project_Run"]) == {"Robot_Error": False, "Project_Run": False}
    assert ask(h, peer, "K4,2,Stick_PlayPause=1")[1] == b"K4,0,00,OK"
    h.step()
    assert values(h, peer, ["Project_Run", "Project_Pause"]) == {"Project_Run": True, "Project_Pause": False}


def test_stick_pause_holds_the_motion_and_play_resumes_it(h):
    node, peer = h.connect(), h.connect_svr()
    h.request(node, sct("1", 'PTP("JPP",30,0,90,0,90,0,100,200,0,false)'))
    h.run(0.2)
    assert ask(h, peer, "P1,2,Stick_Pause=1")[1] == b"P1,0,00,OK"
    held = values(h, peer, ["Joint_Angle", "Project_Pause", "Joint_Speed"])
    h.run(1.0)
    after = values(h, peer, ["Joint_Angle", "Project_Pause"])
    assert held["Project_Pause"] is True and after["Joint_Angle"] == held["Joint_Angle"]
    assert held["Joint_Speed"] == [0.0] * 6
    assert h.request(node, sta("00")) == [("TMSTA", "00,true,Listen1")]        # the Listen node keeps serving
    assert ask(h, peer, "P2,2,Stick_PlayPause=1")[1] == b"P2,0,00,OK"
    h.run(0.05)
    moving = values(h, peer, ["Joint_Angle", "Project_Pause", "Joint_Speed"])
    assert moving["Project_Pause"] is False and moving["Joint_Angle"][0] > held["Joint_Angle"][0]
    assert moving["Joint_Speed"][0] > 0


def test_project_speed_scales_the_motion_time(h):
    node, peer = h.connect(), h.connect_svr()
    assert ask(h, peer, "V1,2,Project_Speed=50")[1] == b"V1,0,00,OK"
    h.request(node, sct("1", 'PTP("JPP",30,0,90,0,90,0,100,200,0,false)'))
    start = h.t
    assert h.until(lambda: any(e["kind"] == "motion_end" for e in h.robot.events), dt=0.01)
    slow = h.t - start
    started = next(e for e in h.robot.events if e["kind"] == "motion_start")
    assert slow == pytest.approx(2 * started["duration_s"], abs=0.03)
    assert ask(h, peer, "V2,2,Stick_Minus=1")[1] == b"V2,0,00,OK"
    assert values(h, peer, ["Project_Speed"]) == {"Project_Speed": 45}


def test_bad_input_gets_cperr_or_status_and_both_ports_keep_serving(h):
    node, peer = h.connect(), h.connect_svr()
    cases = [
        (b"$TMSVR,15,S0,2,Ctrl_DO0=1,*00\r\n", ("CPERR", b"02")),                  # checksum
        (codec.encode("TMSCT", "1,ScriptExit()"), ("CPERR", b"03")),               # not this port's header
        (svr("S-1,2,Ctrl_DO0=1"), ("CPERR", b"04")),                                # ID not alphanumeric
        (b"$TMSVR,99999999,x", ("CPERR", b"01")),                                   # length beyond the limit
        (svr("S1,2"), ("TMSVR", b"S1,0,01,NotSupport")),                            # no content field
        (svr("S2,x,Ctrl_DO0=1"), ("TMSVR", b"S2,0,01,NotSupport")),
        (svr("S3,0,00,OK"), ("TMSVR", b"S3,0,01,NotSupport")),                      # mode 0 is the server's
        (svr(b"S4,1,\x05\x00Ab"), ("TMSVR", b"S4,0,03,InvalidData")),              # binary cut off
        (svr(b"S5,2,\xff\xfe=1"), ("TMSVR", b"S5,0,03,InvalidData")),              # not UTF-8
        (svr("S6,13,{not json"), ("TMSVR", b"S6,0,03,InvalidData")),
        (svr("S7,12,"), ("TMSVR", b"S7,0,03,InvalidData")),
        (svr("S8,2,Joint_Angle={1,2,3,4,5,6}"), ("TMSVR", b"S8,0,05,ReadOnly;Joint_Angle")),
    ]
    for frame, expected in cases:
        peer.send(b"garbage before the frame " + frame)
        assert h.until(lambda: len(peer.frames) >= 1, timeout=2), frame
        assert (peer.frames[-1].header, peer.frames[-1].data) == expected, frame
        peer.frames.clear()
    assert not peer.closed
    assert values(h, peer, ["Project_Run"]) == {"Project_Run": True}
    assert h.request(node, sta("00")) == [("TMSTA", "00,true,Listen1")]
    assert not any(e["kind"] == "internal_error" for e in h.robot.events)


@pytest.mark.slow
def test_a_client_that_never_reads_the_stream_is_dropped_not_the_others():
    h = Harness(svr_port=0, svr_options={"period": 0.001, "mode": 2, "items": list(ITEMS)})
    try:
        stalled, reader = h.connect_svr(), h.connect_svr()
        h.peers.remove(stalled)                     # nobody reads this one
        assert h.until(lambda: any(e["kind"] == "svr_closed" for e in h.robot.events), timeout=60, dt=0.001)
        assert reader.frames and not reader.closed
    finally:
        stalled.close()
        h.close()


def test_control_channel_presses_the_estop_switches_mode_and_configures_the_stream():
    from tmsim.net.control import request
    srv = SimServer(port=0, control_port=0, svr_port=0)
    srv.start_background()
    try:
        port = srv.control.port
        assert request(port, {"cmd": "robots"})["result"][0]["svr_port"] == srv.robots[0].svr_port
        assert request(port, {"cmd": "estop", "pressed": True})["ok"]
        assert srv.robots[0].wait_event("state", event="robot_fault", timeout=5) is not None
        assert request(port, {"cmd": "operation_mode", "mode": "manual"})["ok"]
        assert "auto" in request(port, {"cmd": "operation_mode", "mode": "T1"})["error"]
        config = request(port, {"cmd": "svr_config", "period": 0.5, "mode": 3, "items": ["Joint_Angle"],
                                "write_permission": False})["result"]
        assert config == {"items": ["Robot_Link", "Joint_Angle"], "mode": 3, "period": 0.5,
                          "write_permission": False}
        assert "unknown data table item" in request(port, {"cmd": "svr_config", "items": ["Nope"]})["error"]
        assert request(port, {"cmd": "svr_inject", "fault": "stall", "params": {"enabled": True}})["ok"]
        assert srv.robots[0].svr.stalled
        assert "known: stall" in request(port, {"cmd": "svr_inject", "fault": "fly"})["error"]
        assert request(port, {"cmd": "svr_clear_faults"})["ok"] and not srv.robots[0].svr.stalled
        state = srv.robots[0].state()
        assert state["project_running"] is False and "emergency stop" in state["last_error"]
    finally:
        srv.close()
    plain = SimServer(port=0, control_port=0)
    plain.start_background()
    try:
        assert "not running" in request(plain.control.port, {"cmd": "estop"})["error"]
    finally:
        plain.close()


def test_each_robot_has_its_own_ethernet_slave_with_its_own_data():
    h = Harness(robots=3, svr_port=0, svr_options={"period": 0})
    try:
        ports = [r.svr_port for r in h.srv.robots]
        assert len(set(ports)) == 3 and not set(ports) & set(h.srv.ports)
        node, peers = h.connect(robot=1), [h.connect_svr(robot=i) for i in range(3)]
        h.request(node, sct("1", 'Line("CPP",2000,0,0,180,0,0,10,200,0,true)'))
        assert h.until(lambda: node.closed)
        assert [values(h, p, ["Robot_Error"])["Robot_Error"] for p in peers] == [False, True, False]
        assert h.srv.robots[1].state()["robot_error"]["code"] == 0x00010001
    finally:
        h.close()


def test_random_damaged_frames_never_stop_either_port():
    import random
    rng = random.Random(14)
    good = [svr("A1,2,Ctrl_DO0=1"), svr("A2,12,Joint_Angle"), svr('A3,13,[{"Item":"Error_Code"}]'),
            svr(b"A4,1," + table.encode_binary([(ITEMS["Ctrl_AO0"], 1.0)])), svr("A5,2,Stick_Plus=1")]
    h = Harness(svr_port=0, svr_options={"period": 0.05})
    try:
        node, peer = h.connect(), h.connect_svr()
        for _ in range(300):
            frame = bytearray(rng.choice(good))
            for _ in range(rng.randint(1, 4)):
                action, pos = rng.randrange(3), rng.randrange(len(frame))
                if action == 0:
                    frame[pos] = rng.randrange(256)
                elif action == 1:
                    del frame[pos]
                else:
                    frame.insert(pos, rng.choice(b"$,*\r\n=0{}\x00\xff"))
            peer.send(bytes(frame))
            h.step(0.002)
        peer.send(b",*00\r\n" * 3)                       # close a frame a damaged length left open
        h.run(0.1)
        assert not peer.closed and not any(e["kind"] == "internal_error" for e in h.robot.events)
        assert ask(h, peer, "Z9,12,Project_Run") == ("TMSVR", b"Z9,12,Project_Run=true")
        assert h.request(node, sta("00")) == [("TMSTA", "00,true,Listen1")]
    finally:
        h.close()


def test_cli_opens_the_ethernet_slave_next_to_the_listen_node_and_no_svr_disables_it():
    import pathlib
    import subprocess
    import sys
    script = pathlib.Path(__file__).resolve().parents[2] / "sim" / "tmflow_listener.py"
    for extra, expect in (([], True), (["--no-svr"], False)):
        proc = subprocess.Popen([sys.executable, str(script), "--port", "0", "--no-control", *extra],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            line = proc.stdout.readline()
            assert line.startswith("robot 1: TM5-700 listening on 127.0.0.1:")
            assert ("Ethernet Slave on 127.0.0.1:" in line) == expect
            if expect:
                assert proc.stdout.readline().startswith("Ethernet Slave data table: every 0.1 s, binary")
        finally:
            proc.terminate()
            _out, err = proc.communicate(timeout=10)
        assert "Traceback" not in err
    bad = subprocess.run([sys.executable, str(script), "--port", "0", "--no-control", "--svr-items",
                          "Joint_Angel"],
                         capture_output=True, text=True, timeout=20)
    assert bad.returncode == 2 and "unknown data table item(s): Joint_Angel" in bad.stderr


def test_poses_follow_the_base_and_tool_in_use(h):
    node, peer = h.connect(), h.connect_svr()
    h.request(node, sct("1", "ChangeBase(100,50,20,0,0,30)\r\nChangeTCP(0,0,150,0,0,0)\r\n"
                             'PTP("JPP",20,10,80,0,90,0,100,200,0,false)\r\nQueueTag(1,1)'), count=2)
    state = h.robot.state()
    got = values(h, peer, ["Coord_Base_Tool", "Coord_Robot_Tool", "Coord_Robot_Flange", "Coord_Base_Flange",
                           "Joint_Angle", "Base_Value", "TCP_Value"])
    assert got["Joint_Angle"] == pytest.approx(state["joints"], abs=1e-4)
    assert got["Coord_Base_Tool"] == pytest.approx(state["tcp"], abs=1e-3)
    assert got["Coord_Robot_Tool"] == pytest.approx(state["tcp_robot"], abs=1e-3)
    assert got["Coord_Robot_Flange"][2] == pytest.approx(state["tcp_robot"][2] + 150, abs=1e-3)   # tool points down
    assert got["Base_Value"] == [100, 50, 20, 0, 0, 30] and got["TCP_Value"] == [0, 0, 150, 0, 0, 0]
    assert got["Coord_Base_Flange"] != got["Coord_Robot_Flange"]


def test_fault_stall_stops_the_table_and_the_answers_until_cleared(h):
    peer = h.connect_svr()
    h.robot.svr.configure(period=0.1)
    h.srv.svr.inject(h.robot, "stall")
    h.run(0.5)
    peer.frames.clear()
    peer.send(svr("S1,12,Project_Run"))
    h.run(1.0)
    assert peer.frames == [] and not peer.closed
    assert any(e["kind"] == "svr_stalled" for e in h.robot.events)
    h.srv.svr.clear_faults(h.robot)
    assert h.until(lambda: len(peer.frames) >= 2, timeout=1)


def test_fault_refuse_writes_answers_every_write_with_its_status_and_writes_nothing(h):
    peer = h.connect_svr()
    h.srv.svr.inject(h.robot, "refuse_writes", status=6)
    assert ask(h, peer, "W1,2,Stick_Pause=1") == ("TMSVR", b"W1,0,06,ModeError;Stick_Pause")
    h.srv.svr.inject(h.robot, "refuse_writes", status=1)
    assert ask(h, peer, "W2,2,Ctrl_DO0=1") == ("TMSVR", b"W2,0,01,NotSupport")
    assert values(h, peer, ["Project_Pause", "Ctrl_DO0"]) == {"Project_Pause": False, "Ctrl_DO0": 0}
    with pytest.raises(ValueError, match="must be 1..7"):
        h.srv.svr.inject(h.robot, "refuse_writes", status=0)
    h.srv.svr.clear_faults(h.robot)
    assert ask(h, peer, "W3,2,Ctrl_DO0=1") == ("TMSVR", b"W3,0,00,OK")


def test_fault_corrupt_checksum_damages_the_next_frames_only(h):
    peer = h.connect_svr()
    h.srv.svr.inject(h.robot, "corrupt_checksum", count=2)
    for ident in ("C1", "C2", "C3"):
        peer.send(svr(f"{ident},12,Project_Run"))
    h.run(0.1)
    buf = bytearray(b"".join(peer.raw_reads))
    items = codec.decode_all(buf, {"TMSVR"})
    assert [type(i).__name__ for i in items] == ["BadFrame", "BadFrame", "Frame"]
    assert items[0].code == codec.CPERR_CHECKSUM and items[2].data == b"C3,12,Project_Run=true"


def test_fault_disconnect_closes_the_ethernet_slave_clients_not_the_listen_node(h):
    node, peer = h.connect(), h.connect_svr()
    h.srv.svr.inject(h.robot, "disconnect")
    assert h.until(lambda: peer.closed, timeout=1)
    assert h.request(node, sta("00")) == [("TMSTA", "00,true,Listen1")]
    again = h.connect_svr()
    assert ask(h, again, "D1,12,Robot_Link") == ("TMSVR", b"D1,12,Robot_Link=1")
    for fault, params in (("fly", {}), ("stall", {"seconds": 1}), ("corrupt_checksum", {"count": 0})):
        with pytest.raises(ValueError):
            h.srv.svr.inject(h.robot, fault, **params)


def test_clients_beyond_the_limit_are_closed_at_once(h, monkeypatch):
    from tmsim.net import ethernet_slave
    monkeypatch.setattr(ethernet_slave, "SVR_CLIENTS_MAX", 2)
    first, second, third = h.connect_svr(), h.connect_svr(), h.connect_svr()
    assert h.until(lambda: third.closed, timeout=1)
    assert not first.closed and not second.closed
    assert any(e["kind"] == "svr_rejected_connection" for e in h.robot.events)


def test_project_speed_leaves_absolute_speed_d_formats_alone_13_10(h):
    node, peer = h.connect(), h.connect_svr()
    assert ask(h, peer, "V1,2,Project_Speed=50")[1] == b"V1,0,00,OK"

    def timed(script):
        start, count = h.t, sum(e["kind"] == "motion_end" for e in h.robot.events)
        h.request(node, sct("1", script))
        assert h.until(lambda: sum(e["kind"] == "motion_end" for e in h.robot.events) > count, dt=0.002)
        planned = [e for e in h.robot.events if e["kind"] == "motion_start"][-1]["duration_s"]
        return h.t - start, planned

    taken, planned = timed('Line("CAP",417.5,-22.3,359.7,180,0,90,100,200,0,false)')
    assert taken == pytest.approx(2 * planned, abs=0.01)                 # A: scaled by the project speed
    taken, planned = timed('Line("CDP",417.5,-122.3,359.7,180,0,90,100,200,0,false)')
    assert taken == pytest.approx(planned, abs=0.01)                     # D: absolute speed, not scaled
