"""Control channel under hostile requests (issue 12, "One request kills the simulator", "A control-channel
client that never reads its answers hangs the whole simulator", "binds whatever --host says").
Each probe is answered with {"ok": false, "error": ...} and the simulator keeps serving."""
import json
import socket

import pytest
from sim_harness import Harness
from sim_probe import ControlClient

from tmsim.limits import CONTROL_LINE_MAX, CONTROL_OUTBOX_MAX
from tmsim.net.server import SimServer


@pytest.fixture
def channel():
    srv = SimServer(port=0, control_port=0).start_background()
    client = ControlClient(srv.control.port)
    yield srv, client
    client.close()
    srv.close()


@pytest.mark.parametrize("line, reason", [
    (b'{"cmd":"state","robot":1e400}', "'robot' must be an integer"),
    (b'{"cmd":"events","since":1e400}', "'since' must be an integer"),
    (b'{"cmd":"events","since":-5}', "since must be 0 or more"),
    (b'{"cmd":"state","robot":"0"}', "'robot' must be an integer"),
    (b'{"cmd":"state","robot":true}', "'robot' must be an integer"),
    (b'{"cmd":"state","robot":1.0}', "'robot' must be an integer"),
    (b'{"cmd":"state","robot":-1}', "robot -1 does not exist"),
    (b'{"cmd":"state","robot":' + b"9" * 5000 + b"}", "more than 18 digits"),
    (b"[" * 30_000 + b"]" * 30_000, "nested deeper than"),
    (b'{"cmd":"ping","x":' + b"[" * 50 + b"]" * 50 + b"}", "nested deeper than"),
    (b'{"cmd":["ping"]}', "'cmd' must be a text"),
    (b'{"cmd":"ping","robt":0}', "unknown field 'robt'"),
    (b'{"cmd":"inject","fault":"reply_delay","params":{"seconds":NaN}}', "NaN is not a number"),
    (b'{"cmd":"inject","fault":"reply_delay","params":{"seconds":1e400}}', "finite"),
    (b'{"cmd":"inject","fault":"reply_delay","params":{"seconds":-1}}', "seconds must be 0.0..3600.0"),
    (b'{"cmd":"inject","fault":"split_replies","params":{"size":0}}', "size must be 1..65536"),
    (b'{"cmd":"inject","fault":"split_replies","params":{"size":2.5}}', "size must be an integer"),
    (b'{"cmd":"inject","fault":"reply_delay","params":{"secs":1}}', "unknown parameter 'secs'"),
    (b'{"cmd":"inject","fault":"reply_delay","params":[1]}', "'params' must be an object"),
    (b'{"cmd":"inject","fault":"leave_node","params":{"path":"Elsewhere"}}', "path must be one of Pass, Fail"),
    (b'{"cmd":"inject","fault":7}', "'fault' must be a text"),
    (b'\xff\xfe{"cmd":"ping"}', "one JSON object on one line"),
    (b'"ping"', "must be a JSON object"),
])
def test_bad_request_is_a_json_error_and_the_simulator_keeps_answering(channel, line, reason):
    srv, client = channel
    answer = client.ask(line)
    assert answer["ok"] is False and reason in answer["error"], answer
    assert client.ask({"cmd": "ping"}) == {"ok": True, "result": "pong"}       # same connection still usable
    assert srv.robots[0].state()["faults"]["reply_delay"] == 0                # nothing was armed


@pytest.mark.parametrize("line", [b'{"cmd":"ping","x":"' + b"a" * (CONTROL_LINE_MAX + 10),
                                  b"[" * 60_000 + b"]" * 60_000 + b"\n"])
def test_overlong_request_line_is_answered_then_the_connection_closed(channel, line):
    srv, client = channel
    client.sock.sendall(line)
    answer = client.answer()
    assert answer["ok"] is False and "longer than 65536 bytes" in answer["error"]
    with pytest.raises(ConnectionError):
        client.answer()
    other = ControlClient(srv.control.port)
    assert other.ask({"cmd": "ping"})["ok"]
    other.close()


def test_a_client_that_never_reads_its_answers_is_closed_and_never_stalls_the_others():
    """The simulator is polled here, turn by turn, and every wait is counted in polls, not in wall-clock seconds:
    closing the lazy client takes thousands of answers (4 MiB of them, plus what the loopback buffers hold), CPU
    work that a loaded machine stretched past the 10 s this test once waited for a background thread (flaky)."""
    h = Harness(control_port=0)
    port = h.srv.control.port

    def ask(client, payload) -> dict:
        client.send_line(json.dumps(payload).encode())
        assert h.until(client.answer_ready, timeout=10), f"no answer to {payload}"
        return client.answer()

    try:
        lazy = socket.socket()
        lazy.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)   # before connecting: its window stays small
        lazy.connect(("127.0.0.1", port))
        lazy.setblocking(False)
        probe = ControlClient(port)
        answer_size = len(json.dumps(ask(probe, {"cmd": "state"})))
        unsent = memoryview(b'{"cmd":"state"}\n' * (3 * CONTROL_OUTBOX_MAX // answer_size))   # answers it never reads

        def flooded() -> bool:
            nonlocal unsent
            try:
                unsent = unsent[lazy.send(unsent):]
            except BlockingIOError:
                return False
            except ConnectionError:             # closed for its unread answers before the last request went
                return True
            return not unsent

        def closed():
            return h.robot.wait_event("control_closed", timeout=0)
        assert h.until(flooded, timeout=10)
        other = ControlClient(port)
        assert ask(other, {"cmd": "ping"})["ok"]                             # the old code blocked here
        assert h.until(closed, timeout=60)      # up to 12,000 polls; the whole flood takes ~3,150 turns of 4
        assert "does not read its answers" in closed()["reason"]
        assert ask(other, {"cmd": "ping"})["ok"]
        for client in (probe, other):
            client.close()
        lazy.close()
    finally:
        h.close()


def test_control_channel_binds_loopback_even_when_the_robots_listen_elsewhere():
    srv = SimServer(host="127.0.0.2", port=0, control_port=0).start()
    try:
        assert srv.robots[0].listener.sock.getsockname()[0] == "127.0.0.2"
        assert srv.control.listener.sock.getsockname()[0] == "127.0.0.1"
    finally:
        srv.close()


def test_events_are_paged_by_absolute_index_across_the_log_trimming():
    srv = SimServer(port=0, control_port=0, event_limit=100).start_background()
    client = ControlClient(srv.control.port)
    try:
        for n in range(250):
            srv.robots[0].log.event("io", point="x", value=n)
        first = client.ask({"cmd": "events", "since": 0})["result"]
        assert first["first"] > 0 and first["events"][0] is not None
        nxt = client.ask({"cmd": "events", "since": first["next"]})["result"]
        assert nxt["events"] == [] and nxt["next"] == first["next"]
        assert first["events"][-1]["value"] == 249
    finally:
        client.close()
        srv.close()


def test_events_of_large_frames_are_paged_by_bytes_and_a_reading_client_is_never_closed():
    srv = SimServer(port=0, control_port=0).start_background()
    client = ControlClient(srv.control.port)
    try:
        for n in range(60):                                   # 60 events of ~120 KB: 7 MB in all
            srv.robots[0].log.event("frame_in", conn=1, raw="r" * 60_000, header="TMSTA", data="d" * 60_000, n=n)
        since, seen = 0, []
        while True:
            page = client.ask({"cmd": "events", "since": since})
            assert page["ok"], page
            if not page["result"]["events"]:
                break
            assert sum(e["kind"] == "frame_in" for e in page["result"]["events"]) <= 9    # ~1 MiB a page
            seen += [e.get("n") for e in page["result"]["events"] if e["kind"] == "frame_in"]
            since = page["result"]["next"]
        assert seen == list(range(60))
        big = client.ask({"cmd": "state"})                          # the connection is still open
        assert big["ok"]
    finally:
        client.close()
        srv.close()
