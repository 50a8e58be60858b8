"""Local control channel: JSON lines over TCP (127.0.0.1 unless ``control_host`` says otherwise).

Each request is one JSON object on one line; each answer is one line ``{"ok": true, "result": ...}``
or ``{"ok": false, "error": "..."}``. Requests (``robot`` defaults to 0):

    {"cmd": "ping"}
    {"cmd": "robots"}                                         ports and node state of every robot
    {"cmd": "state", "robot": 0}
    {"cmd": "events", "robot": 0, "since": 0}                 up to 1,000 events (1 MiB) from index
                                                              ``since`` on, plus "next" (the index to ask next)
    {"cmd": "enter_listen_node" | "leave_listen_node" | "stop_project" | "start_project", "robot": 0}
    {"cmd": "inject", "robot": 0, "fault": "reply_delay", "params": {"seconds": 0.5}}
    {"cmd": "clear_faults", "robot": 0}
    {"cmd": "estop", "robot": 0, "pressed": true}             Ethernet Slave: the operator at the robot
    {"cmd": "operation_mode", "robot": 0, "mode": "manual"}
    {"cmd": "svr_config", "robot": 0, "period": 0.1, "mode": 1, "items": [...], "write_permission": true}
    {"cmd": "svr_inject", "robot": 0, "fault": "stall", "params": {"enabled": true}}   / "svr_clear_faults"
    {"cmd": "set_input", "robot": 0, "name": "End_DI0", "value": 1}   a digital (0/1) or analog (V) input
    {"cmd": "vision_job", "robot": 0, "job": "job1", "objects": [[x, y, z, rx, ry, rz], ...], "pass": true,
     "seconds": 0.2, "capture": [j1, ..., j6], "variable": "job1_Base_TM"}   a vision job (tmsim/robot/camera.py)
    {"cmd": "vision_remove", "robot": 0, "job": "job1"} / {"cmd": "vision", "robot": 0}   remove / show
Any request may carry "plc_time": the client's controller time in seconds, logged as event ``control`` (with
``cmd``) next to the robot clock's ``t``.

Every field is checked (type, range, finite numbers, nesting, line length: tmsim/limits.py); a bad
request gets ``ok: false`` with the reason and the connection stays usable, except after a line
longer than CONTROL_LINE_MAX (answered, then closed). Answers are written without blocking; a client
that lets more than CONTROL_OUTBOX_MAX bytes of answers pile up is closed. Each client is served in
turns bounded in work (CONTROL_TURN_REQUESTS requests, CONTROL_TURN_BYTES of answers; a large ``state``
is encoded CONTROL_TURN_PIECES pieces a turn); a client is not read while requests of it wait for their
turn (back-pressure).
"""
from __future__ import annotations

import contextlib
import json
import math
import selectors
import socket
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from tmsim.limits import (
    CONTROL_ANSWER_BYTES,
    CONTROL_CLIENTS_MAX,
    CONTROL_EVENTS_MAX,
    CONTROL_LINE_MAX,
    CONTROL_OUTBOX_MAX,
    CONTROL_TURN_BYTES,
    CONTROL_TURN_PIECES,
    CONTROL_TURN_REQUESTS,
)
from tmsim.net.tcp_listener import Listener, receive
from tmsim.protocol.control import (
    RequestError,
    bool_field,
    decode_request,
    encode_answer,
    error_answer,
    fault_params,
    int_field,
    next_line,
    operation_mode,
    plc_time,
    show,
    text_field,
)
from tmsim.protocol.listen_session import TransitionError

if TYPE_CHECKING:
    from tmsim.net.ethernet_slave import EthernetSlave, SlaveService
    from tmsim.net.robot_ports import Robot
    from tmsim.net.server import SimServer


class _Client:
    __slots__ = ("sock", "rbuf", "wbuf", "closing", "encoding", "pieces")

    def __init__(self, sock: socket.socket):
        self.sock = sock
        self.rbuf = bytearray()
        self.wbuf = bytearray()
        self.closing = False
        self.encoding: Iterator[str] | None = None    # the pieces of a large answer still to encode (an iterator)
        self.pieces: list[str] = []         # ... and those encoded so far


class _Streamed(dict):
    """An answer that is encoded a piece at a time over several turns (``ControlChannel._encode_more``):
    a ``state`` whose variables hold more than CONTROL_TURN_BYTES (500 arrays of 2,048 numbers encode in
    ~0.4 s, which no turn may take)."""


_PIECES = json.JSONEncoder(allow_nan=False, ensure_ascii=False)


class ControlChannel:
    def __init__(self, server: SimServer, host: str = "127.0.0.1", port: int = 0):
        self.server = server
        server.handle("control_listen", self._accept)
        server.handle("control_conn", self._serve_client)
        self.listener = Listener(server.selector, host, port, ("control_listen", None, None),
                                 "open the control channel on {where}")
        self.host = host
        self.port = self.listener.port
        self.clients: dict[socket.socket, _Client] = {}
        self.backlog: dict[socket.socket, _Client] = {}      # clients with requests left after their turn
        self.turns_deferred = 0                               # turns that left requests for a later turn
        self._commands = {
            "ping": lambda robot, req: "pong",
            "robots": lambda robot, req: [{"robot": r.index, "port": r.port, "node_state": r.session.node_state(),
                                           "svr_port": r.svr_port} for r in server.robots],
            "state": lambda robot, req: self._state(robot),
            "events": self._events,
            "enter_listen_node": lambda robot, req: robot.enter_listen_node(),
            "leave_listen_node": lambda robot, req: robot.leave_listen_node(),
            "stop_project": lambda robot, req: robot.stop_project(),
            "start_project": lambda robot, req: robot.start_project(),
            "inject": lambda robot, req: robot.inject(text_field(req, "fault"), **fault_params(req)),
            "clear_faults": lambda robot, req: robot.clear_faults(),
            "estop": lambda robot, req: _svr(robot).source.set_estop(bool_field(req, "pressed", True)),
            "operation_mode": lambda robot, req: _svr(robot).source.set_auto_mode(operation_mode(req.get("mode"))),
            "svr_config": self._svr_config,
            "svr_inject": self._svr_inject,
            "svr_clear_faults": self._svr_clear_faults,
            "set_input": self._set_input,
            "vision_job": self._vision_job,
            "vision_remove": self._vision_remove,
            "vision": self._vision,
        }

    # ---- sockets ------------------------------------------------------------------------------
    def _accept(self, _robot: None, _conn: None) -> None:
        accepted = self.listener.accept(self.server.now, self.server.log_server, prefix="control_")
        if accepted is None:
            return
        sock, _addr = accepted
        if len(self.clients) >= CONTROL_CLIENTS_MAX:
            sock.close()
            return
        sock.setblocking(False)
        self.clients[sock] = _Client(sock)
        self.server.selector.register(sock, selectors.EVENT_READ, ("control_conn", None, sock))

    def tick(self, now: float) -> None:
        """Called once a poll: resume accepting after a pause."""
        self.listener.tick(now)

    def _serve_client(self, _robot: None, sock: socket.socket) -> None:
        """The socket is ready: write what waits, then read; the requests are answered in the client's turn
        (``serve_backlog``, right after in the same poll). A client who has requests left over from its
        last turn is not read meanwhile."""
        client = self.clients.get(sock)
        if client is None:
            return
        if client.wbuf and not self._write(client):
            return
        if client.closing or sock in self.backlog:
            return
        data, failed = receive(sock)
        if data is None and not failed:
            return
        if not data:
            self._close(sock)
            return
        client.rbuf += data
        self.backlog[sock] = client             # its turn comes in serve_backlog, between the robots' turns

    def _turn(self, client: _Client) -> None:
        """Answer at most CONTROL_TURN_REQUESTS requests of ``client``, and none more once the answers of this
        turn reach CONTROL_TURN_BYTES (a turn is bounded in work: 15 clients each sending 64 KiB of requests
        must not hold the robots' servers); the rest waits in ``backlog`` for the next turn."""
        sock, answered, written = client.sock, 0, 0
        self.backlog.pop(sock, None)
        if client.encoding is not None and not self._encode_more(client):
            self.backlog[sock] = client
            self.turns_deferred += 1
            return
        while not client.closing:
            line, used = next_line(client.rbuf)
            if line is None:                    # no complete line yet (used == 0)
                if len(client.rbuf) > CONTROL_LINE_MAX:
                    client.closing = True
                    self.server.log_server("control_closed", reason="request line too long")
                    self._answer(client, error_answer(f"request line longer than {CONTROL_LINE_MAX} bytes; "
                                                f"connection closed"))
                break
            if answered >= CONTROL_TURN_REQUESTS or written >= CONTROL_TURN_BYTES:
                self.backlog[sock] = client
                self.turns_deferred += 1
                return
            del client.rbuf[:used]
            if len(line) > CONTROL_LINE_MAX:
                client.closing = True
                self.server.log_server("control_closed", reason="request line too long")
                answer = error_answer(f"request line longer than {CONTROL_LINE_MAX} bytes; connection closed")
            else:
                answer = self.execute(line)
            before = len(client.wbuf)
            if type(answer) is _Streamed:
                if not self._outbox_room(client):
                    return
                client.encoding = _PIECES.iterencode(answer)
                if not self._encode_more(client):
                    self.backlog[sock] = client
                    self.turns_deferred += 1
                    return
            elif not self._answer(client, answer):
                return
            answered += 1
            written += max(0, len(client.wbuf) - before) or 1
        if client.closing and not client.wbuf:
            self._close(sock)

    def serve_backlog(self) -> None:
        """One turn for every client with requests left over (round robin). A client that does not read its
        answers piles them up and is closed at CONTROL_OUTBOX_MAX (``_answer``)."""
        for sock, client in list(self.backlog.items()):
            if sock not in self.clients:
                self.backlog.pop(sock, None)
            else:
                self._turn(client)
                self.server.breathe()          # the robots' sockets are served between two turns

    @property
    def has_backlog(self) -> bool:
        return bool(self.backlog)

    def _outbox_room(self, client) -> bool:
        """False (and the client closed) when CONTROL_OUTBOX_MAX bytes of earlier answers are still unread."""
        if len(client.wbuf) > CONTROL_OUTBOX_MAX:
            self._close(client.sock, f"client does not read its answers (more than {CONTROL_OUTBOX_MAX} bytes waiting)")
            return False
        return True

    def _encode_more(self, client) -> bool:
        """Encode the next pieces of a large answer: at most CONTROL_TURN_PIECES pieces and about
        CONTROL_TURN_BYTES characters a turn. True when the answer is complete (and queued whole: the
        client never sees part of one), False when the rest waits for the client's next turn."""
        size = 0
        try:
            for _ in range(CONTROL_TURN_PIECES):
                piece = next(client.encoding, None)
                if piece is None:
                    client.wbuf += ("".join(client.pieces) + "\n").encode("utf-8")
                    break
                client.pieces.append(piece)
                size += len(piece)
                if size >= CONTROL_TURN_BYTES:
                    return False
            else:
                return False
        except ValueError as exc:           # e.g. a value JSON cannot carry
            client.wbuf += encode_answer(error_answer(f"the answer cannot be written as JSON ({exc})"))
        client.encoding, client.pieces = None, []
        return self._write(client)

    def _answer(self, client, answer) -> bool:
        """Queue one answer and write what the socket takes; False when the client was closed. A client is
        closed when CONTROL_OUTBOX_MAX bytes of earlier answers are still unread (one answer may be larger)."""
        if not self._outbox_room(client):
            return False
        try:
            client.wbuf += encode_answer(answer)
        except ValueError as exc:           # e.g. a value JSON cannot carry
            client.wbuf += encode_answer(error_answer(f"the answer cannot be written as JSON ({exc})"))
        return self._write(client)

    def _write(self, client) -> bool:
        try:
            sent = client.sock.send(client.wbuf)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError:
            self._close(client.sock)
            return False
        del client.wbuf[:sent]
        events = selectors.EVENT_READ | (selectors.EVENT_WRITE if client.wbuf else 0)
        key = self.server.selector.get_key(client.sock)
        if key.events != events:
            self.server.selector.modify(client.sock, events, key.data)
        if client.closing and not client.wbuf:
            self._close(client.sock)
            return False
        return True

    def _close(self, sock: socket.socket, reason: str | None = None) -> None:
        self.backlog.pop(sock, None)
        if self.clients.pop(sock, None) is not None and reason:
            self.server.log_server("control_closed", reason=reason)
        with contextlib.suppress(KeyError, ValueError):
            self.server.selector.unregister(sock)
        sock.close()

    def close(self) -> None:
        for sock in list(self.clients):
            self._close(sock)
        self.listener.close()

    # ---- requests -----------------------------------------------------------------------------
    def execute(self, line: bytes) -> dict:
        """The answer to one request line (never raises)."""
        try:
            request = decode_request(line)
            name = text_field(request, "cmd")
            command = self._commands.get(name)
            if command is None:
                raise RequestError(f"unknown command {name!r}; known: {', '.join(self._commands)}")
            count = len(self.server.robots)
            index = int_field(request, "robot", 0, 0, count - 1,
                               f"robot {{}} does not exist: this simulator has {count} "
                               f"robot{'s' if count > 1 else ''}; {robot_numbering(count)} of the start-up lines")
            robot = self.server.robots[index]
            if "plc_time" in request:
                robot.log.event("control", cmd=name, plc_time=plc_time(request))
            result = command(robot, request)
            return _Streamed(ok=True, result=result) if type(result) is _Streamed else {"ok": True, "result": result}
        except (ValueError, TypeError, TransitionError) as exc:
            return error_answer(str(exc))
        except Exception as exc:          # noqa: BLE001 - a request never ends the simulator
            return error_answer(f"internal error of the simulator ({type(exc).__name__}: {exc})")

    @staticmethod
    def _state(robot: Robot) -> dict:
        state = robot.state()
        return _Streamed(state) if robot.session.variable_bytes() > CONTROL_TURN_BYTES else state

    def _svr_config(self, robot: Robot, request: dict) -> dict:
        session = _svr(robot).session
        items = request.get("items")
        if items is not None and not (isinstance(items, list) and all(isinstance(i, str) for i in items)):
            raise RequestError(f"'items' must be a list of item names, got {show(items)}")
        mode = request.get("mode")
        if mode is not None and type(mode) is not int:
            raise RequestError(f"'mode' must be an integer, got {show(mode)}")
        period = request.get("period")
        if period is not None and (isinstance(period, bool) or not isinstance(period, (int, float))
                                   or not math.isfinite(period)):
            raise RequestError(f"'period' must be a finite number of seconds, got {show(period)}")
        with self.server.lock:
            permission = bool_field(request, "write_permission", True) if "write_permission" in request else None
            session.configure(items, mode, period, write_permission=permission)
            return session.config()

    def _set_input(self, robot: Robot, request: dict) -> None:
        """An input of the robot changes as a wired sensor would change it (RobotDataSource.set_input checks the
        item and the value and names either when it is refused)."""
        source = _svr(robot).source
        name = text_field(request, "name")
        if "value" not in request:
            raise RequestError(f"'value' missing: the new value of {name} (0 or 1; volts in -10..10 if analog)")
        with self.server.lock:
            source.set_input(name, request["value"])

    def _svr_inject(self, robot: Robot, request: dict) -> None:
        self._slave_adapter(robot).inject(robot, text_field(request, "fault"), **fault_params(request))

    def _svr_clear_faults(self, robot: Robot, _request: dict) -> None:
        self._slave_adapter(robot).clear_faults(robot)

    def _slave_adapter(self, robot: Robot) -> EthernetSlave:
        """The server's Ethernet Slave adapter; RequestError when the simulator runs none."""
        _svr(robot)
        adapter = self.server.svr
        if adapter is None:
            raise RequestError(_NO_SLAVE)
        return adapter

    def _vision_job(self, robot: Robot, request: dict) -> Any:
        """A vision job of the robot's project and what it finds (tmsim/robot/camera.py checks every value)."""
        with self.server.lock:
            return robot.camera().define(
                name=request.get("job"), objects=request.get("objects", []), passed=request.get("pass", True),
                seconds=request.get("seconds", 0.2), capture=request.get("capture"), variable=request.get("variable"))

    def _vision_remove(self, robot: Robot, request: dict) -> Any:
        with self.server.lock:
            return robot.camera().remove(text_field(request, "job"))

    def _vision(self, robot: Robot, _request: dict) -> Any:
        return robot.camera().state()

    def _events(self, robot: Robot, request: dict) -> dict:
        since = int_field(request, "since", 0, 0, None, "since must be 0 or more, got {}")
        first = robot.events_dropped
        start = max(since, first)
        sizes = robot.event_sizes(start - first, CONTROL_EVENTS_MAX)
        count, total = 0, 0
        for size in sizes:                  # at most CONTROL_ANSWER_BYTES of events (at least one)
            if count and total + size > CONTROL_ANSWER_BYTES:
                break
            count, total = count + 1, total + size
        events = robot.events[start - first: start - first + count]
        return {"events": events, "next": start + len(events), "first": first}


def robot_numbering(count: int) -> str:
    """'"robot": 0 is robot 1' for ``count`` robots: the control channel counts them from 0, the start-up
    lines (and the demo's log) from 1, as a PLC program does."""
    if count == 1:
        return '"robot": 0 is robot 1'
    return f'"robot": 0 to {count - 1} are robots 1 to {count}'


_NO_SLAVE = "the Ethernet Slave is not running (simulator started with --no-svr)"


def _svr(robot: Robot) -> SlaveService:
    """The robot's Ethernet Slave; RequestError when the simulator runs none."""
    service = robot.slave
    if service is None:
        raise RequestError(_NO_SLAVE)
    return service


def request(port: int, payload: dict, host: str = "127.0.0.1", timeout: float = 5.0) -> dict:
    """Send one control request and return the decoded answer (helper for scripts and tests)."""
    with socket.create_connection((host, port), timeout=timeout) as sock:
        sock.sendall((json.dumps(payload) + "\n").encode())
        data = b""
        while not data.endswith(b"\n"):
            chunk = sock.recv(65536)
            if not chunk:
                raise ConnectionError("the simulator closed the control connection")
            data += chunk
    return json.loads(data)
