"""The pages' values on one streamed answer, GET /api/stream (docs/hmi.md, Updates): the server sends the /api/read
answer every 50 ms on one connection, a JSON object a line; the front end sends the parts (cbt_hmi.web.front.Stream)
and gives up a client that leaves or does not read. In Chromium a page takes its polls from the stream (a new one
after a command) and falls back to /api/read while it is hidden."""
from __future__ import annotations

import io
import json
import socket
import threading
import time

import pytest
from browser import chromium_paths
from fake_plc import FakePlc, scanning, serving

from cbt_hmi.web.front import HttpFront, HttpLimits, Stream

NAMES = "Stop_Busy,Stop_Done,Connect_Connected"


def open_stream(port: int, path: str = f"/api/stream?names={NAMES}", method: str = "GET") -> socket.socket:
    sock = socket.create_connection(("127.0.0.1", port), timeout=5)
    sock.sendall(f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
    return sock


def read_head(sock: socket.socket) -> tuple[bytes, bytes]:
    """The answer's header and what came after it."""
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = sock.recv(65536)
        assert chunk, f"closed before the header ended: {data!r}"
        data += chunk
    head, _, rest = data.partition(b"\r\n\r\n")
    return head, rest


def read_lines(sock: socket.socket, rest: bytes, count: int) -> list[dict]:
    while rest.count(b"\n") < count:
        chunk = sock.recv(65536)
        assert chunk, "the stream ended"
        rest += chunk
    return [json.loads(line) for line in rest.split(b"\n")[:count]]


def until(condition, what: str, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.01)


# --- the server: /api/stream ---------------------------------------------------------------------------------

def test_a_stream_sends_the_read_answer_every_50_ms_and_shows_a_change(server, fake_plc):
    with open_stream(server.port) as sock:
        head, rest = read_head(sock)
        assert head.startswith(b"HTTP/1.0 200 ")
        assert b"Content-Type: application/x-ndjson" in head and b"Cache-Control: no-store" in head
        assert b"Content-Length" not in head                 # the body ends when the connection does
        started = time.monotonic()
        lines = read_lines(sock, rest, 6)
        took = time.monotonic() - started
        fake_plc.write("Stop_Param.Mode", 3)
        assert all(line["ok"] and line["plc"] == "run" and set(line["values"]) == set(NAMES.split(","))
                   for line in lines)
        times = [line["time_ns"] for line in lines]
        assert times == sorted(times) and len(set(times)) == 6      # each a read of its own moment
        assert took >= 0.2, f"6 answers in {took:.3f} s: not one every 50 ms"
    with open_stream(server.port, "/api/stream?names=Stop_Param.Mode") as sock:
        head, rest = read_head(sock)
        assert read_lines(sock, rest, 1)[0]["values"] == {"Stop_Param.Mode": 3}


def test_a_stream_of_a_variable_the_table_does_not_allow_is_refused_as_a_read_is(server):
    for path, status, text in [("/api/stream?names=Stop_Busy,Secret_Recipe", b"403", "Secret_Recipe"),
                               ("/api/stream", b"400", "give the variables to read")]:
        with open_stream(server.port, path) as sock:
            sock.settimeout(5)
            answer = b""
            while chunk := sock.recv(65536):                  # a plain answer: the server closes after it
                answer += chunk
        head, _, body = answer.partition(b"\r\n\r\n")
        assert head.split()[1] == status and text in json.loads(body)["error"], answer


def test_a_head_request_of_a_stream_is_its_header_only(server):
    with open_stream(server.port, method="HEAD") as sock:
        answer = b""
        while chunk := sock.recv(65536):
            answer += chunk
    assert answer.startswith(b"HTTP/1.0 200 ") and answer.endswith(b"\r\n\r\n")


def test_a_client_that_leaves_its_stream_frees_the_connection(server):
    with open_stream(server.port) as sock:
        head, rest = read_head(sock)
        read_lines(sock, rest, 2)
        assert server.front.open_connections == 1
    until(lambda: server.front.open_connections == 0, "the server to close the stream")


# --- the front end: parts, their end, a client that does not read ---------------------------------------------

class PartsHandler:
    """A handler for HttpFront alone: answers a header, then streams ``parts`` (None ends the answer)."""

    parts: list = []
    period_s = 0.01

    def __init__(self, request: bytes, peer, late: bool):
        self.wfile = io.BytesIO(b"HTTP/1.0 200 OK\r\nContent-Type: text/plain\r\n\r\n")
        parts = iter(type(self).parts)
        self.stream = Stream(lambda: next(parts, None), type(self).period_s)


def front_with(handler, limits: HttpLimits | None = None) -> HttpFront:
    front = HttpFront(("127.0.0.1", 0), handler, limits or HttpLimits(), at_once=lambda request: True)
    threading.Thread(target=front.serve_forever, daemon=True).start()
    return front


def test_a_stream_that_ends_closes_its_connection_after_its_last_part():
    handler = type("Three", (PartsHandler,), {"parts": [b"one\n", b"two\n", b"three\n"]})
    front = front_with(handler)
    try:
        with open_stream(front.server_address[1], "/") as sock:
            answer = b""
            while chunk := sock.recv(65536):
                answer += chunk
        assert answer.endswith(b"\r\n\r\none\ntwo\nthree\n")
        until(lambda: front.open_connections == 0, "the connection to close")
    finally:
        front.shutdown()


def test_a_stream_client_that_reads_nothing_is_closed_at_the_send_deadline_and_others_are_served():
    """Parts of 1 MiB every 10 ms to a client that reads nothing: no part is made while the last one waits (the
    server's memory holds one part), and after the send deadline the connection is closed."""
    made = []

    def part():
        made.append(1)
        return b"x" * (1 << 20)

    class Flood:
        def __init__(self, request, peer, late):
            flood = b"flood" in request
            self.wfile = io.BytesIO(b"HTTP/1.0 200 OK\r\n\r\n" + (b"" if flood else b"served"))
            self.stream = Stream(part, 0.01) if flood else None

    front = front_with(Flood, HttpLimits(send_s=0.3))
    try:
        with open_stream(front.server_address[1], "/flood") as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            until(lambda: made, "the first part")
            until(lambda: front.open_connections == 0, "the server to give the silent client up")
            with open_stream(front.server_address[1], "/other") as other:
                assert other.recv(4096).endswith(b"served")
        assert len(made) < 40, f"{len(made)} parts of 1 MiB made for a client that read none"
    finally:
        front.shutdown()


# --- the page -----------------------------------------------------------------------------------------------

needs_chromium = pytest.mark.skipif(chromium_paths() is None, reason="chromium/chromedriver: run `make browser`")


READS = ("performance.setResourceTimingBufferSize(100000); return performance.getEntriesByType('resource')"
         ".filter((e) => e.name.includes('/api/read?')).length")


@pytest.fixture
def openings(monkeypatch):
    """The streams the server opened (a list that grows by one with each /api/stream answered)."""
    from cbt_hmi.web import server as server_module
    opened, original = [], server_module._Handler._stream

    def counted(handler, names):
        opened.append(names)
        return original(handler, names)

    monkeypatch.setattr(server_module._Handler, "_stream", counted)
    return opened


@needs_chromium
def test_a_page_takes_its_polls_from_one_stream_and_reads_while_hidden(chromium, server, openings):
    chromium.open(server.page_url("stop", "engineer"))
    polls = lambda: chromium.driver.execute_script("return live.polls")   # noqa: E731
    reads = lambda: chromium.driver.execute_script(READS)                 # noqa: E731
    # 20 polls on at most a few streams (a new one only after 800 ms without an answer, on a loaded machine), none
    # of them a read: not a request per poll
    streams, count, start = len(openings), reads(), polls()      # (the form's first values: one read)
    chromium.wait_for(lambda d: polls() >= start + 20, "20 polls")
    assert len(openings) - streams <= 3 and reads() == count
    # another tab in front: the page leaves its stream and reads /api/read instead
    chromium.driver.execute_script("Object.defineProperty(document, 'visibilityState', "
                                   "{ configurable: true, get: () => 'hidden' })")
    chromium.wait_for(lambda d: reads() >= 1, "the first read while hidden")
    count, start = reads(), polls()
    chromium.wait_for(lambda d: polls() >= start + 5, "5 polls while hidden")
    assert reads() - count >= 4, "the hidden page's polls are reads of their own"
    streams = len(openings)
    chromium.driver.execute_script("delete document.visibilityState")
    chromium.wait_for(lambda d: len(openings) > streams, "a stream again in front")
    streams, count, start = len(openings), reads(), polls()
    chromium.wait_for(lambda d: polls() >= start + 20, "20 polls in front again")
    assert len(openings) - streams <= 3 and reads() - count <= 1
    assert chromium.text("pill-plc") == "PLC online"


@needs_chromium
def test_a_command_opens_a_new_stream_so_its_answer_is_read_after_it(chromium, server, openings):
    """Stop Motion's Execute: the page takes Done only from answers read after the press (a new stream)."""
    chromium.open(server.page_url("stop", "engineer"))
    chromium.wait_for(lambda d: len(openings) >= 1, "the page's stream")
    streams = len(openings)
    chromium.click("btn-execute")
    chromium.wait_for(lambda d: "Stop Motion: Done" in chromium.message(), "Done on the message line")
    assert len(openings) > streams, "no new stream after the command"


def refusing_stop(plc: FakePlc) -> None:
    """A stand-in CBT_Stop that refuses every command (16#200C, robot not connected) and clears its Error when
    Execute falls, as the FB does."""
    execute = plc.vars["Stop_Execute"]
    if execute and not plc.executes_seen.get("Stop"):
        plc.vars.update(Stop_Error=True, Stop_ErrorID=0x200C, Stop_ErrorDescrip="Robot not connected")
    elif not execute:
        plc.vars.update(Stop_Error=False, Stop_ErrorID=0, Stop_ErrorDescrip="")
    plc.executes_seen["Stop"] = execute


@needs_chromium
def test_a_refused_command_is_reported_refused_though_its_release_clears_the_error(chromium, mapping, monkeypatch):
    """The page releases Execute after the FB answered; the polls that follow show Error FALSE again. The message
    must be the answer the page judged (it once read the values anew after the release and said Done), here with
    the release's answer held back until such polls have come."""
    from cbt_hmi.web.server import HmiServer
    write = HmiServer.write

    def slow_write(server, body, role):
        answer = write(server, body, role)
        time.sleep(0.3)                       # the stream's answers of the released FB reach the page first
        return answer

    monkeypatch.setattr(HmiServer, "write", slow_write)
    with scanning(FakePlc(mapping, refusing_stop)) as plc, serving(plc, mapping) as server:
        chromium.open(server.page_url("stop", "engineer"))
        chromium.click("btn-execute")
        chromium.wait_for(lambda d: plc.read("Stop_Execute") is False and "Stop Motion:" in chromium.message()
                          and "…" not in chromium.message(), "the command released and its answer shown")
        time.sleep(0.2)
        assert "Error 16#200C" in chromium.message() and "Done" not in chromium.message(), chromium.message()
