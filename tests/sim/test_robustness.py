"""Bad input and load: the simulator answers per protocol or drops that client, and keeps serving."""
import contextlib
import random
import socket
import time

from sim_harness import Harness, sct, sta

from tmsim.limits import FRAME_DATA_MAX
from tmsim.limits import PENDING_SCRIPTS_MAX as MAX_PENDING
from tmsim.protocol import codec
from tmsim.tmscript.parser import split_lines
from tmsim.tmscript.static_check import check_script


def alive(h):
    peer = h.connect()
    return h.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_random_bytes_from_a_client_never_break_the_server(harness):
    h = harness
    rng = random.Random(1234)
    noisy = h.connect()
    for _ in range(200):
        noisy.send(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 300))))
        h.step()
    h.run(0.2)
    assert alive(h)
    assert all(f.header == "CPERR" for f in noisy.frames)


def test_oversized_frame_is_rejected_with_cperr_01_and_bytes_are_skipped(harness):
    h = harness
    peer = h.connect()
    huge = b"$TMSCT,%d,1," % (FRAME_DATA_MAX + 10) + b"x" * (FRAME_DATA_MAX + 10) + b",*00\r\n"
    peer.send(huge + sta("00"))
    assert h.until(lambda: ("TMSTA", "00,true,Listen1") in peer.texts(), timeout=5)
    assert peer.texts()[0] == ("CPERR", "01")
    assert len(peer.frames) == 2


def test_largest_allowed_frame_is_processed(harness):
    h = harness
    peer = h.connect()
    body = "1," + "\r\n".join(["ChangeLoad(1)"] * ((FRAME_DATA_MAX - 10) // 15))
    assert h.request(peer, codec.encode("TMSCT", body), timeout=20) == [("TMSCT", "1,OK")]


def test_flood_of_small_frames_is_answered_in_order(harness):
    h = harness
    peer = h.connect()
    peer.send(b"".join(sta(f"01,{i % 15 + 1}") for i in range(2000)))
    assert h.until(lambda: len(peer.frames) >= 2000, timeout=60, dt=0.001)
    assert [t for _, t in peer.texts()][:3] == ["01,1,none", "01,2,none", "01,3,none"]
    assert alive(h)


def test_hundred_clients_connecting_and_vanishing(harness):
    h = harness
    for round_ in range(100):
        s = socket.create_connection(("127.0.0.1", h.srv.ports[0]), timeout=5)
        if round_ % 3 == 0:
            s.sendall(sct(f"c{round_}", "ChangeLoad(1)")[:10])      # vanish mid-frame
        elif round_ % 3 == 1:
            s.sendall(sta("00"))
        s.close()
        h.step()
    h.run(0.3)
    assert alive(h)
    assert h.robot.state()["clients"] == 1


def test_client_that_never_reads_is_dropped_when_its_buffer_limit_is_reached(harness):
    h = harness
    lazy = socket.create_connection(("127.0.0.1", h.srv.ports[0]), timeout=5)
    lazy.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    frame = sct("1", 'ListenSend(90,"' + "x" * 60000 + '")')
    lazy.setblocking(False)

    def dropped():
        return any(e["kind"] == "closed" and "does not read" in e["reason"] for e in h.robot.events)

    for _ in range(1000):
        if dropped():
            break
        with contextlib.suppress(BlockingIOError, ConnectionError):
            lazy.sendall(frame)
        h.step()
    assert dropped()
    lazy.close()
    assert alive(h)


def test_seeded_fuzz_of_mutated_valid_frames_is_time_bounded():
    rng = random.Random(20261122)
    seeds = [sta("00"), sta("01,03"), sct("1", 'PTP("JPP",0,0,90,0,90,0,35,200,0,false)\r\nQueueTag(1)'),
             sct("A", 'Line("CAR",400,-100,350,180,0,90,100,200,5,true)'), sct("Z", "int x = 1\r\nx++"),
             sct("P", "StopAndClearBuffer(2)"), sct("Q", "ListenSend(90,GetString(Robot[0].Joint))"),
             sct("R", "Circle(\"CAP\",{1,2,3,4,5,6},{7,8,9,10,11,12},100,200,0,0,false)")]
    h = Harness()
    deadline = time.monotonic() + 8.0
    try:
        peer = h.connect()
        cases = 0
        while time.monotonic() < deadline and cases < 3000:
            frame = bytearray(rng.choice(seeds))
            for _ in range(rng.randrange(1, 4)):
                op = rng.randrange(3)
                pos = rng.randrange(len(frame))
                if op == 0:
                    frame[pos] = rng.randrange(256)
                elif op == 1:
                    del frame[pos]
                else:
                    frame.insert(pos, rng.choice(b"$,*\r\n(){}\"0123456789"))
            if peer.closed:
                peer = h.connect()
            peer.send(bytes(frame))
            h.step(0.01)
            cases += 1
            if not h.robot.state()["project_running"]:
                h.robot.start_project()
            elif not h.robot.state()["in_listen_node"] and h.robot.session.state == "not_in_node":
                h.robot.enter_listen_node()
        h.run(0.5)
        assert not any(e["kind"] == "internal_error" for e in h.robot.events)
        assert cases > 100
        assert alive(h)
    finally:
        h.close()


def test_fuzzed_script_lines_never_raise_from_parser_or_checker():
    rng = random.Random(99)
    alphabet = 'PTPLineQueTag()[]{},."=+-*/!<>&|0123456789 abcxyzIORobot\t'
    for _ in range(3000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randrange(0, 60)))
        lines = split_lines(text)
        check_script(lines, {})
        assert all(line.error is None or isinstance(line.error, str) for line in lines)


def test_full_script_buffer_pauses_reading_and_resumes_when_it_drains(harness):
    h = harness
    peer = h.connect()
    peer.send(sct("A", 'PTP("JPP",90,0,90,0,90,0,10,200,0,false)\r\nQueueTag(1,1)'))
    peer.send(b"".join(sct(f"B{i}", "ChangeLoad(1)") for i in range(1100)))
    h.run(0.1)
    peer.send(b"".join(sct(f"C{i}", "ChangeLoad(2)") for i in range(100)))
    h.run(0.4)
    assert h.robot.reading_paused and len(h.robot.session.pending) == MAX_PENDING    # exactly, not one read more
    assert h.until(lambda: len(peer.frames) >= 1202, timeout=30, dt=0.01)
    assert not h.robot.reading_paused
    assert peer.texts()[-1] == ("TMSCT", "C99,OK")


NON_FINITE = [
    'Line("CPP",1e309,0,300,180,0,90,100,200,0,false)',
    'PTP("CPP",417,0,300,1e309,0,90,10,200,0,false)',
    'Circle("CPP",417,0,300,180,0,90,1e309,0,300,180,0,90,50,200,0,0,false)',
    'Move_Line("CPP",0,0,-1e309,0,0,0,100,200,0,false)',
    'ChangeBase(1e309,0,0,0,0,0)',
    'ChangeTCP(0,0,1e309,0,0,0)',
    'ChangeLoad(1e309)',
    'PVTEnter(1)\r\nPVTPoint(417,0,300,180,0,90,0,0,0,0,0,-1e309,1)',
]


def test_non_finite_numbers_are_robot_errors_and_the_other_robots_keep_being_served():
    h = Harness(robots=2)
    try:
        for n, script in enumerate(NON_FINITE):
            if h.robot.state()["node_state"] == "project_stopped":     # the previous robot error stopped it
                h.robot.start_project()
                h.run(0.05)
            failures = sum(e["kind"] == "motion_failed" for e in h.robot.events)
            peer = h.connect()
            peer.send(sct(str(n), script))
            assert h.until(lambda: sum(e["kind"] == "motion_failed" for e in h.robot.events) > failures,  # noqa: B023
                           timeout=2), script
            failed = [e for e in h.robot.events if e["kind"] == "motion_failed"][-1]
            assert "finite" in failed["reason"] or "valid mass" in failed["reason"], failed
            other = h.connect(robot=1)
            assert h.request(other, sta("00")) == [("TMSTA", "00,true,Listen1")]   # robot 1 unaffected
        assert not [e for e in h.robot.events if e["kind"] == "internal_error"]
    finally:
        h.close()


def test_an_unexpected_error_while_advancing_stops_that_robot_only(monkeypatch):
    h = Harness(robots=2)
    try:
        broken = h.srv.robots[0].session

        def explode(now):
            raise RuntimeError("boom")
        monkeypatch.setattr(broken, "advance", explode)
        h.run(0.05)                                           # the serving loop survives
        (event,) = [e for e in h.srv.robots[0].events if e["kind"] == "internal_error"][:1]
        assert event["error"] == "RuntimeError: boom"
        assert h.srv.robots[0].state()["node_state"] == "project_stopped"
        peer = h.connect(robot=1)
        assert h.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]
    finally:
        h.close()
