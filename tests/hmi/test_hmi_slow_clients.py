"""Slow and idle HTTP clients cannot lock the operator out of the HMI (issue 23, item 6).

The review's scenario: 70 connections sending one header byte every 5 s made every other request get 503 for
as long as they kept it up; slow bodies and 600 idle connections did the same, and the operator could not
press Stop. Here the same attacks run on loopback against a server whose deadlines are set short (HttpLimits),
and the operator's page, a read and a Stop press must all be served while they go on.
"""
from __future__ import annotations

import contextlib
import http.client
import json
import socket
import threading

import pytest
from fake_plc import FakePlc, command_program, scanning
from hmi_http import Client

from cbt_hmi.web.front import MAX_HEAD, HttpLimits
from cbt_hmi.web.mapping import Mapping
from cbt_hmi.web.server import HmiServer

SHORT = HttpLimits(header_s=0.4, body_s=0.4, idle_s=0.4, send_s=2.0)
GAP_S = 0.05                      # an attacker sends its next byte after this (the review: 5 s; deadlines 5 s)
STOP = {"execute": "Stop_Execute", "values": {}}


@pytest.fixture(scope="module")
def mapping():
    return Mapping.load()


@contextlib.contextmanager
def hmi_with(mapping, limits: HttpLimits):
    with scanning(FakePlc(mapping, command_program)) as plc:
        server = HmiServer(plc, mapping, port=0, limits=limits)
        server.start()
        try:
            yield server
        finally:
            server.stop()


class Attack:
    """``count`` connections from ``source`` that each send one byte every GAP_S and never finish their request;
    a connection the server closes is opened again, so the attack keeps its strength (as the review's did).

    mode "header": the request header, byte by byte; "body": a whole header announcing 100 bytes of body, then
    the body byte by byte; "idle": nothing at all. ``key``: the access key sent (a body is read only after the
    key was checked). ``answers`` collects what the server said before closing."""

    def __init__(self, port: int, count: int, mode: str, source: str = "127.0.0.1", reconnect: bool = True,
                 key: str = ""):
        self.port, self.count, self.mode, self.source, self.reconnect = port, count, mode, source, reconnect
        head = (f"POST /api/write HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
                f"X-HMI-Key: {key}\r\n")
        if mode == "header":
            self.opening, self.drip = b"", (head + "X-Padding: " + "p" * 200 + "\r\n\r\n").encode()
        else:
            self.opening, self.drip = (head + "Content-Length: 100\r\n\r\n").encode(), b"{" + b" " * 99
        self.answers: list[bytes] = []
        self.connects = 0
        self.sockets: list[socket.socket] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _open(self) -> tuple[socket.socket, int]:
        sock = socket.create_connection(("127.0.0.1", self.port), timeout=5, source_address=(self.source, 0))
        sock.sendall(self.opening)
        sock.setblocking(False)
        self.connects += 1
        return sock, 0

    def _run(self):
        held = [self._open() for _ in range(self.count)]
        self.sockets = [sock for sock, _ in held]
        while not self._stop.wait(GAP_S):
            for i, (sock, sent) in enumerate(held):
                try:
                    answer = sock.recv(4096)
                except BlockingIOError:
                    answer = None
                except OSError:
                    answer = b""
                if answer is None and self.mode != "idle" and sent < len(self.drip):
                    try:
                        sock.send(self.drip[sent:sent + 1])
                        held[i] = (sock, sent + 1)
                    except OSError:
                        answer = b""
                if answer is not None:                    # the server answered or closed: attack again
                    if answer:
                        self.answers.append(answer)
                    sock.close()
                    if self.reconnect:
                        held[i] = self._open()
        for sock, _ in held:
            sock.close()

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(timeout=10)


def operator_is_served(server) -> None:
    """The operator's page, a read of its status and a Stop press: each answered 200."""
    client = Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"])
    status, body, _ = client.request("/stop.html")
    assert status == 200 and b"hmi.js" in body
    status, answer = client.json("/api/read?names=Stop_Busy,Stop_Done,Connect_Connected")
    assert status == 200 and answer["values"]["Stop_Busy"] is False
    status, answer = client.json("/api/execute", STOP)
    assert status == 200 and answer["ok"] is True


def status_of(answer: bytes) -> int:
    return int(answer.split(b" ", 2)[1])


def test_70_connections_dripping_their_headers_do_not_lock_the_operator_out(mapping):
    with hmi_with(mapping, SHORT) as server, Attack(server.port, 70, "header") as attack:
        for _ in range(4):                                  # over several header deadlines of the attack
            operator_is_served(server)
            threading.Event().wait(SHORT.header_s / 2)
    assert {status_of(a) for a in attack.answers} <= {408}
    assert any(b"the request header did not arrive within 0.4 s" in a for a in attack.answers)


def test_70_connections_dripping_their_bodies_do_not_lock_the_operator_out(mapping):
    with hmi_with(mapping, SHORT) as server, Attack(server.port, 70, "body",
                                                           key=server.access.keys["operator"]) as attack:
        for _ in range(4):
            operator_is_served(server)
            threading.Event().wait(SHORT.body_s / 2)
        writes = list(server.plc.writes)
    assert all(path == "Stop_Execute" for path, _ in writes)    # no dripped body was ever written
    assert any(status_of(a) == 408 and b"fewer came within 0.4 s" in a for a in attack.answers)


def test_600_idle_connections_do_not_lock_the_operator_out(mapping):
    with hmi_with(mapping, SHORT) as server, Attack(server.port, 600, "idle", reconnect=False) as attack:
        while attack.connects < 600:
            threading.Event().wait(0.01)
        operator_is_served(server)
        front = server.front
        assert front.open_connections <= SHORT.connections and front.evicted >= 600 - SHORT.per_client


def test_a_client_address_holds_at_most_its_share_of_connections(mapping):
    """Another address's connections are never the ones closed to make room for this one's."""
    limits = HttpLimits(idle_s=30, per_client=8, connections=64)
    with hmi_with(mapping, limits) as server:
        mine = socket.create_connection(("127.0.0.1", server.port), timeout=5)
        others = [socket.create_connection(("127.0.0.1", server.port), timeout=5, source_address=("127.0.0.2", 0))
                  for _ in range(20)]
        try:
            closed = [sock for sock in others[:12] if sock.recv(1) == b""]      # the oldest 12 were closed
            front = server.front
            client_counts = {}
            for _ in range(200):                            # the front end has taken every connection
                client_counts = front.connections_by_client()
                if sum(client_counts.values()) == 9:
                    break
                threading.Event().wait(0.01)
            assert len(closed) == 12 and client_counts == {"127.0.0.1": 1, "127.0.0.2": 8}
            operator_is_served(server)
        finally:
            for sock in [mine, *others]:
                sock.close()


def test_a_header_that_misses_its_deadline_is_answered_408_then_closed(mapping):
    with hmi_with(mapping, SHORT) as server, socket.create_connection(("127.0.0.1", server.port), timeout=5) as sock:
        sock.sendall(b"GET /api/session HTTP/1.1\r\nHost: 127.0.0.1")
        answer = b""
        while chunk := sock.recv(4096):
            answer += chunk
    head, _, body = answer.partition(b"\r\n\r\n")
    assert status_of(head) == 408
    assert json.loads(body) == {"ok": False, "error": "the request header did not arrive within 0.4 s"}


def test_a_header_larger_than_the_limit_is_431(mapping):
    with hmi_with(mapping, SHORT) as server:
        connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=5)
        connection.request("GET", "/api/session", headers={"X-Padding": "p" * MAX_HEAD})
        response = connection.getresponse()
        answer = json.loads(response.read())
        connection.close()
    assert response.status == 431 and answer["error"] == f"the request header is larger than {MAX_HEAD // 1024} KiB"


@pytest.mark.parametrize("field, value", [("header_s", 0), ("idle_s", -1.0), ("per_client", 0),
                                          ("per_client", 10_000)])
def test_limits_that_cannot_work_are_refused(field, value):
    with pytest.raises(ValueError, match=field if field != "per_client" else "per_client"):
        HttpLimits(**{field: value})


def test_a_client_that_does_not_take_its_answer_is_closed_at_the_send_deadline(mapping, tmp_path):
    """The answer is sent without waiting: what the socket does not take has SEND_DEADLINE_S to go, then the
    connection is closed (a 16 MiB file to a client that reads nothing, 0.3 s here)."""
    size = 16 * 1024 * 1024
    (tmp_path / "large.js").write_bytes(b"/" * size)
    with scanning(FakePlc(mapping, command_program)) as plc:
        server = HmiServer(plc, mapping, port=0, root=tmp_path, limits=HttpLimits(send_s=0.3))
        server.start()
        try:
            with socket.create_connection(("127.0.0.1", server.port), timeout=5) as sock:
                sock.sendall(f"GET /large.js HTTP/1.0\r\nHost: 127.0.0.1:{server.port}\r\n\r\n".encode())
                front = server.front
                for held in (True, False):                  # until the front end has taken it, then given it up
                    for _ in range(500):
                        if bool(front.open_connections) == held:
                            break
                        threading.Event().wait(0.01)
                received = 0
                with contextlib.suppress(ConnectionResetError):
                    while chunk := sock.recv(1 << 20):
                        received += len(chunk)
            status, _ = Client(f"http://127.0.0.1:{server.port}").json("/api/read?names=Stop_Busy")
        finally:
            server.stop()
    assert not front.open_connections and 0 < received < size and status == 200
