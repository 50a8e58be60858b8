"""Robot servers under hostile load (issue 12, Medium/Low): event log bounded in bytes, fault clearing with
held bytes, descriptor exhaustion. Virtual clock, loopback only."""
import os
import resource
import socket

from sim.limits import ACCEPT_BACKOFF_S, EVENT_BYTES_MAX

from sim_probe import Harness, sct, sta


def test_clearing_faults_while_split_replies_are_held_delivers_every_byte_and_leaves_no_fault():
    """Probe: split_replies(size=1), three requests, clear_faults mid-way (old: 3 replies lost, a truncated
    frame on the wire, faults still 'active')."""
    h = Harness()
    try:
        peer = h.connect()
        h.robot.inject("split_replies", size=1)
        for n in range(3):
            peer.send(sct(str(n), "int v%d = %d" % (n, n)))
        h.run(0.02)                                    # a few one-byte pieces have left
        assert 0 < sum(map(len, peer.raw_reads)) < 30
        h.robot.clear_faults()
        assert h.until(lambda: len(peer.frames) == 3, timeout=1.0), peer.texts()
        assert peer.texts() == [("TMSCT", "0,OK"), ("TMSCT", "1,OK"), ("TMSCT", "2,OK")]
        assert peer.rbuf == b""                        # no truncated frame left over
        h.run(0.02)
        assert not h.robot.faults.active and not any(
            v for k, v in h.robot.state()["faults"].items() if k != "close_after")
        assert h.request(peer, sta("00")) == [("TMSTA", "00,true,Listen1")]    # replies flow normally again
    finally:
        h.close()


def test_event_log_stays_within_its_byte_budget_with_large_frames():
    """Probe: large frames (old: bounded by count only, 8,000 frames of 60 KB grew the log to 1 GB)."""
    h = Harness(robots=8)                               # budget per robot: 20 MiB / 8
    try:
        peer = h.connect()
        payload = "00," + "x" * 60_000
        for _ in range(60):                            # 60 x (60 KB in + 60 KB as data) = 7 MB > 2.5 MiB
            h.request(peer, sta(payload))
        robot = h.robot
        assert robot.event_bytes <= EVENT_BYTES_MAX // 8
        assert sum(len(str(e)) for e in robot.events) <= 1.2 * EVENT_BYTES_MAX // 8
        assert robot.events[-1]["kind"] == "frame_out" and robot.events_dropped > 0
    finally:
        h.close()


def test_one_event_larger_than_a_quarter_of_the_budget_is_shortened_not_kept_whole():
    h = Harness(robots=512)                             # 40 KiB per robot: one 64 KiB frame would not fit
    try:
        peer = h.connect()
        h.request(peer, sta("00," + "y" * 60_000))
        frame_in = [e for e in h.robot.events if e["kind"] == "frame_in"][-1]
        assert frame_in["raw"].endswith("characters]") and len(frame_in["raw"]) < 20_000
        assert h.robot.event_bytes <= EVENT_BYTES_MAX // 512
    finally:
        h.close()


def _fill_descriptors():
    """Open /dev/null until the process is out of descriptors; returns the open ones."""
    held = []
    while True:
        try:
            held.append(os.open(os.devnull, os.O_RDONLY))
        except OSError:
            return held


def test_out_of_descriptors_pauses_accepting_logs_once_and_resumes():
    """Probe: EMFILE on accept (old: the listener stayed readable, the loop spun at 100 % CPU and logged
    an accept_error on every turn)."""
    h = Harness()
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    held = []
    try:
        clients = [socket.create_connection(("127.0.0.1", h.srv.ports[0]), timeout=5) for _ in range(3)]
        highest = max(int(fd) for fd in os.listdir("/proc/self/fd"))
        resource.setrlimit(resource.RLIMIT_NOFILE, (highest + 1, hard))
        held = _fill_descriptors()
        for _ in range(200):                           # 200 turns of the loop on the same virtual instant
            h.srv.poll(h.t)
        paused = [e for e in h.robot.events if e["kind"] == "accept_paused"]
        assert len(paused) == 1 and not [e for e in h.robot.events if e["kind"] == "accept_error"]
        assert h.robot.state()["clients"] == 0
        for fd in held:
            os.close(fd)
        held = []
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
        h.run(ACCEPT_BACKOFF_S + 0.01)
        assert h.robot.state()["clients"] == 3          # accepting resumed after the back-off
        for sock in clients:
            sock.close()
    finally:
        for fd in held:
            os.close(fd)
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
        h.close()
