"""SimServer over real loopback sockets, driven by poll() on a virtual clock (no sleeps)."""
import json
import pathlib
import signal
import socket
import subprocess
import sys

import pytest
from sim_harness import Harness, sct, sta

from tmsim.net.control import request as control_request
from tmsim.net.server import SimServer
from tmsim.protocol import codec

ROOT = pathlib.Path(__file__).resolve().parents[2]
PTP_LONG = 'PTP("JPP",90,0,90,0,90,0,10,200,0,false)'


def test_ports_are_bound_on_loopback_and_listed(harness):
    assert len(harness.srv.ports) == 1 and harness.srv.ports[0] > 0
    assert harness.robot.state()["port"] == harness.srv.ports[0]


def test_status_query_and_script_round_trip(harness):
    peer = harness.connect()
    assert harness.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]
    assert harness.request(peer, b'$TMSCT,25,1,ChangeBase("RobotBase"),*08\r\n') == [("TMSCT", "1,OK")]


def test_nothing_is_sent_on_accept(harness):
    peer = harness.connect()
    harness.run(0.5)
    assert peer.raw_reads == []


def test_each_reply_is_written_in_its_own_send_with_upper_case_checksum(harness):
    peer = harness.connect()
    harness.request(peer, b"$TMSTA,3,00,,*6c\r\n")
    assert peer.raw_reads == [b"$TMSTA,15,00,true,Listen1,*79\r\n"]


def test_motion_with_tag_and_event_log_order(harness):
    peer = harness.connect()
    script = "\r\n".join([f'PTP("JPP",{10 * i},0,90,0,90,0,100,100,0,true)' for i in range(1, 7)] + ["QueueTag(1,1)"])
    replies = harness.request(peer, sct("M1", script), count=2)
    assert replies == [("TMSTA", "01,01,true"), ("TMSCT", "M1,OK")]
    events = harness.robot.events
    ends = [e for e in events if e["kind"] == "motion_end"]
    assert [e["joints"][0] for e in ends] == [10, 20, 30, 40, 50, 60]
    assert all(json.dumps(e) for e in events)
    kinds = [e["kind"] for e in events]
    assert kinds.index("frame_in") < kinds.index("script_line") < kinds.index("motion_start")
    assert kinds[-1] == "frame_out"


def test_two_clients_are_served_in_arrival_order(harness):
    a, b = harness.connect(), harness.connect()
    a.send(sct("A", PTP_LONG + "\r\nQueueTag(1,1)"))
    harness.run(0.1)
    b.send(sct("B", "ChangeLoad(2)"))
    harness.run(1.0)
    assert ("TMSCT", "B,OK") not in b.texts()
    assert harness.until(lambda: ("TMSCT", "B,OK") in b.texts(), timeout=10)
    assert ("TMSCT", "A,OK") in a.texts()


def test_enter_message_goes_to_every_connected_client(harness):
    a, b = harness.connect(), harness.connect()
    harness.robot.leave_listen_node()
    harness.robot.enter_listen_node()
    assert harness.until(lambda: a.frames and b.frames)
    assert a.texts() == b.texts() == [("TMSCT", "0,Listen1")]


def test_stop_project_closes_everything_and_start_project_listens_again():
    h = Harness()
    try:
        peer = h.connect()
        port = h.srv.ports[0]
        h.robot.stop_project()
        assert h.until(lambda: peer.closed)
        with pytest.raises(OSError):
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
        h.robot.start_project()
        again = h.connect()
        assert h.request(again, sta("00")) == [("TMSTA", "00,true,Listen1")]
        assert h.srv.ports[0] == port
    finally:
        h.close()


def test_fault_reply_delay_holds_replies_on_the_virtual_clock(harness):
    peer = harness.connect()
    harness.robot.inject("reply_delay", seconds=0.5)
    peer.send(sta("00"))
    harness.run(0.4)
    assert peer.frames == []
    assert harness.until(lambda: peer.frames, timeout=1.0)
    assert harness.t >= 0.5


def test_fault_split_replies_sends_pieces(harness):
    peer = harness.connect()
    harness.robot.inject("split_replies", size=4)
    harness.request(peer, sta("00"))
    assert len(peer.raw_reads) >= 2 and b"".join(peer.raw_reads) == b"$TMSTA,15,00,true,Listen1,*79\r\n"


def test_fault_glue_replies_sends_frames_in_one_chunk(harness):
    peer = harness.connect()
    harness.robot.inject("glue_replies", count=2, max_wait=10)
    peer.send(sta("00"))
    harness.run(0.1)
    assert peer.frames == []
    peer.send(sta("01,1"))
    assert harness.until(lambda: len(peer.frames) == 2)
    assert len(peer.raw_reads) == 1


def test_fault_corrupt_checksum_affects_only_the_next_reply(harness):
    peer = harness.connect()
    harness.robot.inject("corrupt_checksum")
    peer.send(sta("00"))
    assert harness.until(lambda: peer.rbuf or peer.raw_reads)
    assert peer.raw_reads[0] != b"$TMSTA,15,00,true,Listen1,*79\r\n" and not peer.frames
    peer.rbuf.clear()
    assert harness.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_fault_close_after_frames_answers_then_closes(harness):
    peer = harness.connect()
    harness.robot.inject("close_after", frames=2)
    harness.request(peer, sta("00"))
    peer.send(sta("00"))
    assert harness.until(lambda: peer.closed)
    assert len(peer.frames) == 2


def test_fault_close_mid_frame(harness):
    peer = harness.connect()
    harness.robot.inject("close_mid_frame")
    peer.send(sta("00"))
    assert harness.until(lambda: peer.closed)
    assert peer.frames == [] and 0 < len(b"".join(peer.raw_reads)) < 32


def test_fault_reply_error(harness):
    peer = harness.connect()
    harness.robot.inject("reply_error")
    assert harness.request(peer, sct("1", "ChangeLoad(1)")) == [("TMSCT", "1,ERROR;1")]
    assert not any(e["kind"] == "script_line" for e in harness.robot.events)


def test_fault_black_hole_then_clear(harness):
    peer = harness.connect()
    harness.robot.inject("black_hole")
    peer.send(sta("00"))
    harness.run(1.0)
    assert peer.frames == []
    harness.robot.clear_faults()
    assert harness.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_fault_refuse_connections_keeps_existing_clients(harness):
    peer = harness.connect()
    harness.robot.inject("refuse_connections")
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", harness.srv.ports[0]), timeout=1).close()
    assert harness.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]
    harness.robot.inject("refuse_connections", enabled=False)
    assert harness.request(harness.connect(), sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_a_closed_listen_node_port_stays_held_so_the_robot_comes_back_on_it(harness):
    """While refusing (and while the project is stopped) the port is bound by a socket that does not listen:
    connects are refused as by a closed port, but no other program can take the port meanwhile."""
    port = harness.srv.ports[0]
    harness.robot.inject("refuse_connections")
    other = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        with pytest.raises(OSError):
            other.bind(("127.0.0.1", port))
    finally:
        other.close()
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
    harness.robot.inject("refuse_connections", enabled=False)
    assert harness.srv.ports[0] == port
    assert harness.request(harness.connect(), sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_fault_leave_node_and_stop_project(harness):
    peer = harness.connect()
    harness.robot.inject("leave_node")
    assert harness.request(peer, sct("1", "QueueTag(1)")) == [("CPERR", "F1")]
    harness.robot.inject("stop_project")
    assert harness.until(lambda: peer.closed)


def test_unknown_fault_is_a_clear_error(harness):
    with pytest.raises(ValueError, match="unknown fault 'explode'"):
        harness.robot.inject("explode")
    with pytest.raises(ValueError, match="bad parameter"):
        harness.robot.inject("split_replies", size="big")


def test_half_closed_client_still_gets_its_reply_then_is_closed(harness):
    peer = harness.connect()
    peer.send(sct("H", PTP_LONG + "\r\nQueueTag(1,1)"))
    peer.sock.shutdown(socket.SHUT_WR)
    assert harness.until(lambda: peer.closed, timeout=10)
    assert ("TMSCT", "H,OK") in peer.texts()


def test_many_robots_on_consecutive_ports_are_independent(free_port):
    base = free_port(3)
    srv = SimServer(port=base, robots=3).start()
    try:
        assert srv.ports == [base, base + 1, base + 2]
        srv.robots[1].leave_listen_node()
        assert [r.state()["in_listen_node"] for r in srv.robots] == [True, False, True]
    finally:
        srv.close()


def test_control_channel_answers_during_the_longest_sleep_and_ends_it_by_leaving_the_node():
    """Sleep(2147483647) (24.8 days, legal TMscript) never makes the simulator unresponsive: the control
    channel answers while the script sleeps, and leaving the node ends the script with OK (as the robot's
    flow leaving the Listen node does)."""
    srv = SimServer(port=0, control_port=0).start_background()
    try:
        port = srv.control.port
        with socket.create_connection(("127.0.0.1", srv.ports[0]), timeout=5) as robot:
            robot.sendall(sct("A", "Sleep(2147483647)"))
            assert srv.robots[0].wait_event("script_line", timeout=5) is not None
            state = control_request(port, {"cmd": "state", "robot": 0})["result"]
            assert state["buffered_scripts"] == 1 and state["in_listen_node"] is True
            assert control_request(port, {"cmd": "leave_listen_node"})["ok"]
            buffer = bytearray()
            while b"\r\n" not in buffer:                          # blocking read, 5 s socket timeout
                buffer += robot.recv(4096)
            assert bytes(buffer).startswith(codec.encode("TMSCT", "A,OK"))
    finally:
        srv.close()


def test_control_channel_commands():
    srv = SimServer(port=0, control_port=0).start()
    port = srv.control.port
    try:
        srv.start_background()
        assert control_request(port, {"cmd": "ping"}) == {"ok": True, "result": "pong"}
        assert control_request(port, {"cmd": "leave_listen_node"})["ok"]
        state = control_request(port, {"cmd": "state", "robot": 0})["result"]
        assert state["in_listen_node"] is False
        assert control_request(port, {"cmd": "enter_listen_node"})["ok"]
        assert control_request(port, {"cmd": "inject", "fault": "reply_delay", "params": {"seconds": 0.1}})["ok"]
        events = control_request(port, {"cmd": "events", "since": 0})["result"]
        assert any(e["kind"] == "fault" for e in events["events"]) and events["next"] == len(events["events"])
        bad = control_request(port, {"cmd": "enter_listen_node"})
        assert bad["ok"] is False and "in node" in bad["error"]
        assert "unknown command" in control_request(port, {"cmd": "fly"})["error"]
        assert control_request(port, {"cmd": "state", "robot": 1})["error"] == (
            'robot 1 does not exist: this simulator has 1 robot; "robot": 0 is robot 1 of the start-up lines')
        assert control_request(port, {"cmd": "inject", "fault": "nope"})["ok"] is False
    finally:
        srv.close()


def test_event_log_file_is_json_lines(tmp_path):
    log = tmp_path / "events.jsonl"
    h = Harness(log_path=str(log))
    try:
        peer = h.connect()
        h.request(peer, sta("00"))
    finally:
        h.close()
    lines = [json.loads(line) for line in log.read_text().splitlines()]
    assert {"listening", "frame_in", "frame_out"} <= {e["kind"] for e in lines}
    assert all("t" in e and "robot" in e for e in lines)


def test_cli_starts_prints_one_line_per_robot_and_stops_on_terminate(tmp_path):
    proc = subprocess.Popen([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), "--port", "0",
                             "--robots", "2", "--control-port", "0", "--speedup", "5",
                             "--log", str(tmp_path / "log.jsonl")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        lines = [proc.stdout.readline() for _ in range(3)]
        assert lines[0].startswith("robot 1: TM5-700 listening on 127.0.0.1:")
        assert lines[1].startswith("robot 2: ")
        assert lines[2].startswith("control channel: ")
        port = int(lines[2].split(":")[2].split()[0])
        assert control_request(port, {"cmd": "robots"})["result"][1]["node_state"] == "in_node"
        # the start-up lines count robots from 1 as a PLC program does, the control channel from 0: the
        # control channel line and the error for a robot that does not exist say how they match
        assert lines[2].rstrip().endswith('(JSON lines; "robot": 0 to 1 are robots 1 to 2)')
        robot_2_port = int(lines[1].split("listening on 127.0.0.1:")[1].split()[0])
        assert control_request(port, {"cmd": "state", "robot": 1})["result"]["port"] == robot_2_port
        assert control_request(port, {"cmd": "state", "robot": 2})["error"] == (
            'robot 2 does not exist: this simulator has 2 robots; "robot": 0 to 1 are robots 1 to 2 of the '
            'start-up lines')
    finally:
        proc.terminate()
        out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err


@pytest.mark.parametrize("args, message", [
    (["--robots", "0"], "--robots must be between 1 and 512"),
    (["--speedup", "0"], "--speedup must be positive"),
    (["--port", "65535", "--robots", "2"], "leaves the port range"),
    (["--stop-tags", "maybe"], "invalid choice: 'maybe'"),
    (["--tmflow", "3.0"], "invalid choice: '3.0'"),
    (["--host", ""], "argument --host: an address is needed: 127.0.0.1 for this computer only"),  # not every one
    (["--control-host", " "], "argument --control-host: an address is needed"),
    (["--svr-items", ""], "--svr-items names no item"),
])
def test_cli_rejects_bad_arguments_with_a_clear_message(args, message):
    result = subprocess.run([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), *args],
                            capture_output=True, text=True, timeout=20)
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr


def test_cli_reports_a_busy_port_without_traceback():
    blocker = socket.socket()
    blocker.bind(("127.0.0.1", 0))
    blocker.listen(1)
    port = blocker.getsockname()[1]
    try:
        result = subprocess.run([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), "--port", str(port),
                                 "--no-control"], capture_output=True, text=True, timeout=20)
    finally:
        blocker.close()
    assert result.returncode == 1 and f"cannot listen on 127.0.0.1:{port}" in result.stderr
    assert "Traceback" not in result.stderr


def test_poll_is_deterministic_for_the_same_inputs():
    def run_once():
        h = Harness()
        try:
            peer = h.connect()
            h.request(peer, sct("1", PTP_LONG + "\r\nQueueTag(1,1)"), count=2)
            return [(e["t"], e["kind"]) for e in h.robot.events if e["kind"].startswith("motion")]
        finally:
            h.close()
    assert run_once() == run_once()


def test_listen_send_int_array_goes_out_as_little_endian_binary(harness):
    peer = harness.connect()
    replies = harness.request(peer, sct("1", "int[] v = {1,2}\r\nListenSend(93,v)"), count=2)
    assert replies[0][0] == "TMSTA" and \
        peer.frames[0].data == b"93," + (1).to_bytes(4, "little") + (2).to_bytes(4, "little")
    assert codec.checksum(peer.frames[0].raw[1:-5]) == int(peer.frames[0].raw[-4:-2], 16)


def test_event_log_proves_a_discarded_frame_was_never_executed(harness):
    peer = harness.connect()
    peer.send(sct("A", PTP_LONG + "\r\nQueueTag(1,1)"))
    peer.send(sct("B", "ChangeLoad(4)"))
    harness.run(0.1)
    assert harness.request(peer, sct("C", "StopAndClearBuffer(2)"), count=2) == [("TMSCT", "A,OK"), ("TMSCT", "C,OK")]
    harness.run(1.0)
    events = harness.robot.events
    assert any(e["kind"] == "frame_in" and e["data"].startswith("B,") for e in events)
    assert not any(e["kind"] == "script_line" and e["id"] == "B" for e in events)
    assert [e["id"] for e in events if e["kind"] == "discarded"] == ["B"]
    assert harness.robot.state()["load"] == 0.0


def test_robot_error_stops_the_project_and_closes_connections(harness):
    peer = harness.connect()
    harness.request(peer, sct("1", 'Line("CPP",2000,0,0,180,0,0,10,200,0,true)'))
    assert harness.until(lambda: peer.closed, timeout=2)
    state = harness.robot.state()
    assert state["project_running"] is False and "out of reach" in state["last_error"]
    closed = [e for e in harness.robot.events if e["kind"] == "closed"]
    assert closed and "out of reach" in closed[-1]["reason"]
    harness.robot.start_project()
    assert harness.request(harness.connect(), sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_clearing_faults_still_delivers_held_replies(harness):
    peer = harness.connect()
    harness.robot.inject("reply_delay", seconds=0.3)
    peer.send(sta("00"))
    harness.run(0.1)
    harness.robot.clear_faults()
    assert harness.until(lambda: peer.frames, timeout=1.0)


def test_wait_event_returns_an_event_logged_by_the_background_thread():
    srv = SimServer(port=0).start_background()
    try:
        robot = srv.robots[0]
        sock = socket.create_connection(("127.0.0.1", srv.ports[0]), timeout=5)
        sock.sendall(sta("00"))
        event = robot.wait_event("frame_out", timeout=5, header="TMSTA")
        assert event is not None and event["data"] == "00,true,Listen1"
        assert robot.wait_event("frame_out", timeout=0.05, header="CPERR") is None
        sock.close()
    finally:
        srv.close()


def test_event_log_is_bounded_per_robot_and_overall():
    srv = SimServer(port=0, robots=32)
    try:
        assert srv.event_limit * 32 <= 40_000
        robot = srv.robots[0]
        for n in range(3 * srv.event_limit):
            robot.log.event("io", point="x", value=n)
        assert srv.event_limit // 2 <= len(robot.events) <= srv.event_limit
        assert robot.events[-1]["value"] == 3 * srv.event_limit - 1      # the newest are kept
    finally:
        srv.close()
    single = SimServer(port=0, robots=1)
    assert single.event_limit == 40_000
    single.close()


def _start_cli(tmp_path, *args: str, robots: int = 1) -> tuple[subprocess.Popen, list[str]]:
    """The simulator's command line started with ``args`` (no Ethernet Slave), and its start-up lines: one per
    robot, then the control channel's."""
    proc = subprocess.Popen([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), *args, "--no-svr"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    return proc, [proc.stdout.readline() for _ in range(robots + 1)]


def _stop_cli(proc: subprocess.Popen) -> None:
    proc.terminate()
    _out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err, err


def test_cli_control_port_is_the_port_before_robot_1_or_a_free_one_when_that_is_taken(tmp_path, free_port):
    q = free_port(2)                                   # q busy, robot 1 on q + 1: the derived port q is taken
    blocker = socket.socket()
    blocker.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    blocker.bind(("127.0.0.1", q))
    blocker.listen(1)
    proc, lines = _start_cli(tmp_path, "--port", str(q + 1))
    try:
        assert lines[0].startswith(f"robot 1: TM5-700 listening on 127.0.0.1:{q + 1} ")
        port = int(lines[1].split(":")[2].split()[0])
        assert lines[1].startswith("control channel: ") and port != q
        assert control_request(port, {"cmd": "robots"})["result"][0]["port"] == q + 1
    finally:
        blocker.close()
        _stop_cli(proc)


def test_cli_control_port_defaults_to_the_port_before_robot_1(tmp_path, free_port):
    q = free_port(2)                                   # q free (reserved for this test): the derived control port
    proc, lines = _start_cli(tmp_path, "--port", str(q + 1))
    try:
        assert lines[1].startswith(f"control channel: 127.0.0.1:{q} ")
    finally:
        _stop_cli(proc)


def _listen_then_wait_out(port: int) -> bool:
    """Serve one connection on ``port`` and close it first, as a stopped simulator's control channel did: the
    server's end waits out (TIME_WAIT) on the port. False when ``port`` is taken."""
    server = socket.socket()
    try:
        server.bind(("127.0.0.1", port))  # without SO_REUSEADDR: refused next to any socket (a reservation too)
    except OSError:
        server.close()
        return False
    server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)        # then as the control channel has it
    server.listen(1)
    client = socket.create_connection(("127.0.0.1", port), timeout=5)
    served, _ = server.accept()
    served.close()
    client.close()
    server.close()
    return True


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "Ctrl-C"])
def test_cli_stopped_right_after_its_first_start_up_line_stops_cleanly(tmp_path, stop):
    """A supervisor (or a user) that waits for the first start-up line and stops the simulator at once gets the clean
    stop. With 200 robots the stop comes while the start-up lines are still being written (it was the signal's
    default action then, exit -15, or a KeyboardInterrupt's traceback, and no "simulator stopped")."""
    proc = subprocess.Popen([sys.executable, str(ROOT / "sim" / "tmflow_listener.py"), "--port", "0",
                             "--control-port", "0", "--robots", "200", "--no-svr"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    assert proc.stdout.readline().startswith("robot 1: TM5-700 listening on 127.0.0.1:")
    proc.send_signal(stop)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "simulator stopped" in out and "Traceback" not in err, (out[-300:], err)


def test_cli_control_port_is_the_port_before_robot_1_even_while_old_connections_on_it_wait_out(tmp_path, free_port):
    """A simulator stopped after serving control requests leaves their connections on the port in TIME_WAIT (it
    closed them first). Restarted at once, it takes the same control port: the check binds as its server does."""
    for _attempt in range(20):
        robot = free_port()
        if _listen_then_wait_out(robot - 1):
            break
    else:
        pytest.skip("no free port before a free port")
    proc, lines = _start_cli(tmp_path, "--port", str(robot))
    try:
        assert lines[1].startswith(f"control channel: 127.0.0.1:{robot - 1} "), lines
    finally:
        _stop_cli(proc)


def test_a_robot_port_held_while_its_project_is_stopped_is_not_another_simulators_control_port(tmp_path, free_port):
    """Simulator A's robot 2 stops its project: A holds its port (nothing listens there). Simulator B, started with
    its robot 1 right after that port, does not take it for its default control channel, and A's robot 2 comes
    back on it."""
    base = free_port(3)
    a, a_lines = _start_cli(tmp_path, "--port", str(base), "--robots", "2", "--control-port", "0", robots=2)
    try:
        assert a_lines[2].startswith("control channel: "), a_lines
        a_control = int(a_lines[2].split(":")[2].split()[0])
        assert control_request(a_control, {"cmd": "stop_project", "robot": 1})["ok"] is True
        b, b_lines = _start_cli(tmp_path, "--port", str(base + 2))
        try:
            assert b_lines[0].startswith(f"robot 1: TM5-700 listening on 127.0.0.1:{base + 2} "), b_lines
            assert b_lines[1].startswith("control channel: ") and f":{base + 1} " not in b_lines[1], b_lines
            assert control_request(a_control, {"cmd": "start_project", "robot": 1})["ok"] is True
            with socket.create_connection(("127.0.0.1", base + 1), timeout=5) as peer:
                peer.sendall(sct("1", "QueueTag(1)"))
                assert peer.recv(256).startswith(b"$TMSCT")
        finally:
            _stop_cli(b)
    finally:
        _stop_cli(a)
