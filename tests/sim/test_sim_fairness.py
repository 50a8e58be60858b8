"""One client cannot starve another (issue 23 item 5): the scheduler's turns are bounded in work
(tmsim/tmscript/work.py, limits.TURN_WORK), so a client of robot 1 attacking with costly scripts, huge string sends,
Cartesian PVT streams or a control-channel flood leaves robot 2 served. Each test reproduces one attack on
loopback with the virtual clock and asserts on the server's own counters (work of a turn, turns ended by
the budget) and on the order of the answers, never on wall time; the latency figures are in
bench/bench_fairness.py."""
import contextlib
import json
import math
import socket

from sim_harness import Harness, sct, sta

from tmsim.limits import (
    CONTROL_TURN_PIECES,
    CONTROL_TURN_REQUESTS,
    PARSE_SLICE,
    STEPS_MAX,
    TURN_WORK,
    WORK_CHAR,
    WORK_LINE,
    WORK_LOG_BYTES,
    WORK_PVT_CARTESIAN,
    WORK_TOKEN,
)
from tmsim.protocol.listen_session import ListenSession
from tmsim.robot import eventlog
from tmsim.robot.model import RobotModel

TCP_HOME = (417.5, -122.3, 359.7)


def pvt_script(points=998, seconds=0.002):
    lines = ["PVTEnter(1)"]
    for k in range(points):
        a = 2 * math.pi * k / points
        x, y = TCP_HOME[0] + 20 * math.cos(a) - 20, TCP_HOME[1] + 20 * math.sin(a)
        lines.append(f"PVTPoint({x:.1f},{y:.1f},{TCP_HOME[2]},180,0,90,0,0,0,0,0,0,{seconds})")
    lines.append("PVTExit()")
    return "\r\n".join(lines)


def replies(peer, header="TMSCT"):
    return [text for kind, text in peer.texts() if kind == header]


def test_a_64k_script_is_checked_over_several_turns_and_another_robot_is_answered_first():
    """Attack: 64 KiB scripts (old: robot 2's p99 78 ms, each script checked in one go). The checking stops
    when the turn's work is spent; robot 2's TMSTA 00, sent after the script, is answered in the same poll."""
    h = Harness(robots=2)
    try:
        attacker, other = h.connect(0), h.connect(1)
        lines = [f"float position_of_the_axis_number_{n:05d} = {n}.5*2+{n}" for n in range(990)]
        frame = sct("F", "\r\n".join(lines))
        assert len(frame) > 50_000
        attacker.send(frame)
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")] and replies(attacker) == []
        assert h.until(lambda: replies(attacker), timeout=10)
        assert replies(attacker) == ["F,OK"]
        meter = h.robot.session.meter
        longest = max(WORK_LINE + WORK_CHAR * len(line) for line in lines)
        assert meter.deferred >= sum(WORK_LINE + WORK_CHAR * len(line) for line in lines) // (TURN_WORK + longest)
        assert meter.most() <= TURN_WORK + longest + len(frame) * 2 // WORK_LOG_BYTES     # + the frame's event
    finally:
        h.close()


def test_deeply_nested_lines_are_checked_line_by_line_across_turns():
    """Attack: scripts of lines nested 95 levels deep (old: 131-216 ms for robot 2)."""
    h = Harness(robots=2)
    try:
        attacker, other = h.connect(0), h.connect(1)
        deep = "(" * 95 + "1" + ")" * 95
        attacker.send(sct("N", "\r\n".join(f"int n{i} = {deep}" for i in range(48))))
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")] and replies(attacker) == []
        assert h.until(lambda: replies(attacker), timeout=10) and replies(attacker) == ["N,OK"]
        assert h.robot.session.meter.deferred >= 48 * (WORK_LINE + len(deep)) // (TURN_WORK + 220)
        assert h.robot.session.variables["n47"] == 1
    finally:
        h.close()


def test_one_line_of_ten_thousand_nested_tokens_is_parsed_in_slices_across_turns():
    """Attack: one line of ~10,000 tokens nested 95 levels deep per script (the parser's largest item: ~40 ms
    at once). The tokenizer and the parser stop every PARSE_SLICE tokens; a spent turn leaves the rest of
    the line for a later turn."""
    h = Harness(robots=2)
    try:
        attacker, other = h.connect(0), h.connect(1)
        deep = "(" * 95 + "1" + ")" * 95
        line = "int w = " + "+".join([deep] * 52)
        attacker.send(sct("W", line))
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")] and replies(attacker) == []
        assert h.until(lambda: replies(attacker), timeout=10) and replies(attacker) == ["W,OK"]
        meter = h.robot.session.meter
        assert meter.deferred >= len(line) // (TURN_WORK + PARSE_SLICE * WORK_TOKEN)
        slice_work = PARSE_SLICE * WORK_TOKEN
        assert meter.most() <= TURN_WORK + slice_work + len(line) * 2 // WORK_LOG_BYTES + WORK_LINE
        assert h.robot.session.variables["w"] == 52
    finally:
        h.close()


def test_cartesian_pvt_points_are_planned_one_turn_at_a_time_on_the_same_timeline():
    """Attack: Cartesian PVTPoints of 2 ms (old: each plan ~5 ms, a poll that fell behind planned all the
    points it owed at once: 7 scripts of 998 stalled robot 2 for 1.1-1.5 s, its PLC lost the link). A turn
    plans no motion once its work is spent; the robot clock owes the time and the motions keep their
    timeline: the arm ends where a robot without any budget ends."""
    script = pvt_script(200)
    h = Harness(robots=2)
    try:
        attacker, other = h.connect(0), h.connect(1)
        assert h.request(attacker, sct("P", script), timeout=30) == [("TMSCT", "P,OK")]
        h.step(0.3)                                   # one poll owes 0.3 s: 150 points, never planned at once
        before = h.robot.session.meter.most()
        assert h.request(other, sta("00")) == [("TMSTA", "00,true,Listen1")]
        assert h.robot.session.robot.owed > 0 and h.robot.session.has_turn_work
        assert h.until(lambda: h.robot.session.robot.idle, timeout=30, dt=0.05)
        ends = [e for e in h.robot.events if e["kind"] == "motion_end" and e["function"] == "PVTPoint"]
        assert len(ends) == 200 and h.robot.state()["fault"] is None
        assert max(before, h.robot.session.meter.most()) <= TURN_WORK + WORK_PVT_CARTESIAN + 200
        joints = h.robot.session.robot.joints
    finally:
        h.close()
    free = ListenSession(RobotModel())                # no server, no budget: planned as soon as due
    free.connect(1)
    free.receive_data(1, sct("P", script))
    free.advance(0.3)
    free.advance(30.0)
    assert free.robot.idle and free.robot.joints == joints


def test_listen_send_of_a_long_string_is_work_counted_by_its_size():
    """Attack: 1,420 x ListenSend of a 64,000-character string (old: not counted by the step limit, robot 2
    stalled 0.4-3 s). Sending counts one step per 256 bytes: the script ends with ERROR at the send that
    passes STEPS_MAX (80 sends of 64,000 characters), and each turn sends only a few."""
    h = Harness(robots=2)
    try:
        attacker, other = h.connect(0), h.connect(1)
        build = ['string s = "' + "x" * 125 + '"'] + ["s = s + s"] * 9          # 64,000 characters
        assert h.request(attacker, sct("D", "\r\n".join(build))) == [("TMSCT", "D,OK")]
        assert len(h.robot.session.variables["s"]) == 64_000
        attacker.send(sct("L", "\r\n".join(["ListenSend(90,s)"] * 1420)))
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")]
        assert h.until(lambda: len(replies(attacker)) == 2, timeout=30)
        status = replies(attacker)[1]
        assert status.startswith("L,ERROR;")
        line = int(status.split(";")[1])
        assert STEPS_MAX // 252 <= line <= STEPS_MAX // 250 + 1
        sends = [text for text in replies(attacker, "TMSTA") if text.startswith("90,")]
        assert len(sends) == line - 1
        reason = [e["reason"] for e in h.robot.events if e["kind"] == "runtime_error"]
        assert reason and f"more than {STEPS_MAX} steps" in reason[-1]
        one_send = 64_000 // 256 + 4 + 3 * (64_000 + 300) // WORK_LOG_BYTES    # steps, sending, the frame's event
        assert h.robot.session.meter.most() <= TURN_WORK + one_send + 70_000 * 2 // WORK_LOG_BYTES
    finally:
        h.close()


def test_listen_send_to_many_clients_counts_its_work_for_each_of_them():
    """A ListenSend reaches every client of the robot: its turn counts the frame once per client, so a
    64,000-character send to 40 clients ends the turn (the script goes on in a later turn)."""
    h = Harness()
    try:
        peers = [h.connect() for _ in range(40)]
        h.request(peers[0], sct("D", "\r\n".join(['string s = "' + "x" * 125 + '"'] + ["s = s + s"] * 9)))
        meter = h.robot.session.meter
        deferred = meter.deferred
        assert h.request(peers[0], sct("L", "ListenSend(90,s)\r\nListenSend(90,s)"), count=3)[-1] == ("TMSCT", "L,OK")
        assert meter.deferred > deferred                 # the second send waited for a later turn
        assert h.until(lambda: all(len([f for f in p.frames if f.header == "TMSTA"]) == 2 for p in peers))
    finally:
        h.close()


def test_a_control_channel_flood_is_answered_in_bounded_turns_between_the_robots():
    """Attack: control clients writing many state requests at once (old: the whole 64 KiB read was
    answered in one turn: robot 2 unanswered 4-5 s, its PLC lost the link). A client gets at most
    CONTROL_TURN_REQUESTS answers a turn; robot 2's TMSTA 00 is answered long before the flood is; nothing
    is lost."""
    h = Harness(robots=2, control_port=0)
    try:
        other = h.connect(1)
        flooders = [socket.create_connection(("127.0.0.1", h.srv.control.port)) for _ in range(3)]
        line = json.dumps({"cmd": "state", "robot": 0}).encode() + b"\n"
        count = 16384 // len(line)
        for sock in flooders:
            sock.sendall(line * count)
            sock.setblocking(False)
        received = [bytearray() for _ in flooders]

        def read_all():
            for sock, buf in zip(flooders, received, strict=False):
                try:
                    while True:
                        chunk = sock.recv(1 << 20)
                        if not chunk:
                            break
                        buf += chunk
                except BlockingIOError:
                    pass
            return sum(buf.count(b"\n") for buf in received)
        h.step()
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")]
        assert read_all() < 3 * count // 4
        assert h.srv.control.turns_deferred > 0
        assert h.until(lambda: read_all() == 3 * count, timeout=60)
        assert all(json.loads(answer)["ok"] for buf in received for answer in buf.splitlines())
        assert CONTROL_TURN_REQUESTS * h.srv.control.turns_deferred >= 3 * count - 3 * CONTROL_TURN_REQUESTS
        for sock in flooders:
            sock.close()
    finally:
        h.close()


def test_a_state_with_large_variables_is_encoded_over_several_turns_and_arrives_whole():
    """Attack: a client of robot 1 fills the variable memory with arrays, a control client asks for the
    state (100 arrays of 2,048 numbers: ~80 ms of JSON in one go; 500 arrays ~0.4 s). The answer is encoded
    CONTROL_TURN_PIECES pieces a turn; robot 2 is answered meanwhile; the answer arrives whole, a snapshot
    of the moment it was asked for."""
    h = Harness(robots=2, control_port=0)
    try:
        other = h.connect(1)
        variables = h.robot.session.variables
        for n in range(100):
            variables[f"a{n}"] = [n + 0.5] * 2048
            h.robot.session.types[f"a{n}"] = "float[]"
        asker = socket.create_connection(("127.0.0.1", h.srv.control.port))
        asker.sendall(json.dumps({"cmd": "state", "robot": 0}).encode() + b"\n")
        asker.setblocking(False)
        assert h.until(lambda: h.srv.control.turns_deferred > 0, timeout=1)
        deferred = h.srv.control.turns_deferred
        other.send(sta("00"))
        h.step()
        assert other.texts() == [("TMSTA", "00,true,Listen1")]
        variables["a0"][0] = -1.0                      # changed after the request: not in the answer
        answer = bytearray()

        def whole():
            with contextlib.suppress(BlockingIOError):
                answer.extend(asker.recv(1 << 20))
            return answer.endswith(b"\n")
        assert h.until(whole, timeout=30)
        state = json.loads(answer)
        assert state["ok"] and state["result"]["variables"]["a0"] == [0.5] * 2048
        assert state["result"]["variables"]["a99"] == [99.5] * 2048
        assert h.srv.control.turns_deferred >= deferred + 100 * 2048 // CONTROL_TURN_PIECES - 2
        asker.close()
    finally:
        h.close()


def test_the_event_log_file_is_renamed_and_begun_anew_at_its_size_bound(tmp_path, monkeypatch):
    """With --log, 1,420 sends of 64 KB wrote 1.09 GB in 10 s (old: no bound). The file is renamed to
    FILE.1 at LOG_FILE_BYTES_MAX; the two files stay below twice the bound plus one event."""
    monkeypatch.setattr(eventlog, "LOG_FILE_BYTES_MAX", 100_000)
    path = tmp_path / "events.jsonl"
    h = Harness(log_path=str(path))
    try:
        for n in range(200):
            h.robot.log.event("io", point="x", value="y" * 5000, n=n)
        assert h.srv.log_file.rotations >= 4
    finally:
        h.close()
    rotated = tmp_path / "events.jsonl.1"
    assert path.stat().st_size <= 100_000 + 5300 and rotated.stat().st_size <= 100_000 + 5300
    kept = [json.loads(text) for text in rotated.read_text().splitlines() + path.read_text().splitlines()]
    assert [e["n"] for e in kept if e["kind"] == "io"][-1] == 199
