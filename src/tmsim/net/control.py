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
from collections.abc import Callable, Iterable, Sequence
from contextlib import AbstractContextManager
from typing import TYPE_CHECKING, Any, Protocol

from tmsim.limits import (
    CONTROL_ANSWER_BYTES,
    CONTROL_CLIENTS_MAX,
    CONTROL_EVENTS_MAX,
    CONTROL_TURN_BYTES,
)
from tmsim.net.tcp_listener import Listener, receive
from tmsim.protocol.control import (
    CLOSED,
    INPUT_LEFT,
    ControlProtocol,
    RequestError,
    Streamed,
    bool_field,
    decode_request,
    error_answer,
    fault_params,
    int_field,
    operation_mode,
    plc_time,
    show,
    text_field,
)
from tmsim.protocol.listen_session import TransitionError

if TYPE_CHECKING:
    from tmsim.net.ethernet_slave import EthernetSlave
    from tmsim.net.robot_ports import Robot, SlavePort


class ControlHost(Protocol):
    """What the control channel needs of the server it joins (``SimServer``): its one selector, lock and robot
    clock, its robots and Ethernet Slave adapter, a handler for its own selector keys, the server's event log,
    and ``breathe`` (serve the robots' sockets between two control turns)."""

    @property
    def selector(self) -> selectors.BaseSelector: ...

    @property
    def lock(self) -> AbstractContextManager[Any]: ...

    @property
    def now(self) -> float: ...

    @property
    def robots(self) -> Sequence[Robot]: ...

    @property
    def svr(self) -> EthernetSlave | None: ...

    def handle(self, kind: str, handler: Callable[[Any, Any], None]) -> None:
        """Serve the selector keys of ``kind`` with ``handler(robot, conn)``."""
        ...

    def log_server(self, kind: str, **fields: Any) -> None:
        """Log an event of the server as a whole."""
        ...

    def breathe(self) -> None:
        """Serve the robots' sockets that are ready now."""
        ...


class ControlChannel:
    """The control channel's TCP adapter and its table of commands: the sockets, the selector, the round robin
    of the clients' turns; the bytes, the bounds and the turns' contents are the ControlProtocol's
    (tmsim/protocol/control.py)."""

    def __init__(self, server: ControlHost, host: str = "127.0.0.1", port: int = 0):
        self.server = server
        server.handle("control_listen", self._accept)
        server.handle("control_conn", self._serve_client)
        self.listener = Listener(server.selector, host, port, ("control_listen", None, None),
                                 "open the control channel on {where}")
        self.host = host
        self.port = self.listener.port
        self.protocol = ControlProtocol(server.log_server)
        self.clients: dict[int, socket.socket] = {}          # connection number -> its socket
        self.backlog: dict[int, None] = {}                    # clients with requests left after their turn, in order
        self.turns_deferred = 0                               # turns that left requests for a later turn
        self._next_conn = 0
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
        self._next_conn += 1
        conn = self._next_conn
        self.clients[conn] = sock
        self.protocol.connect(conn)
        self.server.selector.register(sock, selectors.EVENT_READ, ("control_conn", None, conn))

    def tick(self, now: float) -> None:
        """Called once a poll: resume accepting after a pause."""
        self.listener.tick(now)

    def next_due(self, now: float) -> float | None:
        """When ``tick`` has work: the end of an accept pause (None: none). Requests left over from a turn are
        ``has_backlog``; unsent answers wait for their socket to be writable (the selector)."""
        return self.listener.paused_until

    def _serve_client(self, _robot: None, conn: int) -> None:
        """The socket is ready: write what waits, then read; the requests are answered in the client's turn
        (``serve_backlog``, right after in the same poll). A client who has requests left over from its
        last turn is not read meanwhile."""
        sock = self.clients.get(conn)
        if sock is None:
            return
        protocol = self.protocol
        if conn in self.backlog:                # (the frequent case under a flood: checked first)
            if protocol.output_bytes(conn):
                self._flush(conn)
            return
        if protocol.output_bytes(conn) and not self._flush(conn):
            return
        if protocol.closing(conn):
            return
        data, failed = receive(sock)
        if data is None and not failed:
            return
        if not data:
            self._close(conn)
            return
        self.protocol.receive_data(conn, data)
        self.backlog[conn] = None               # its turn comes in serve_backlog, between the robots' turns

    def _turn(self, conn: int) -> None:
        """One turn of the client ``conn`` (ControlProtocol.turn: bounded in requests, answer bytes and
        encoding work); a client with requests left waits in ``backlog`` for its next turn."""
        self.backlog.pop(conn, None)
        outcome = self.protocol.turn(conn, self.execute, self._flush)
        if outcome == INPUT_LEFT:
            self.backlog[conn] = None
            self.turns_deferred += 1
        elif outcome == CLOSED:
            self._close(conn)

    def serve_backlog(self) -> None:
        """One turn for every client with requests left over (round robin). A client that does not read its
        answers piles them up and is closed at CONTROL_OUTBOX_MAX (the protocol ends it)."""
        for conn in list(self.backlog):
            if conn not in self.clients:
                self.backlog.pop(conn, None)
            else:
                self._turn(conn)
                self.server.breathe()          # the robots' sockets are served between two turns

    @property
    def has_backlog(self) -> bool:
        return bool(self.backlog)

    def _flush(self, conn: int) -> bool:
        """Write what the socket takes of the client's answers (the rest goes back to the protocol and the
        socket is watched for writing); False when the client is gone (a send failed, or the protocol ended it
        and its last answer is out)."""
        sock = self.clients.get(conn)
        if sock is None:
            return False
        data = self.protocol.data_to_send(conn)
        try:
            sent = sock.send(data) if data else 0
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError:
            self._close(conn)
            return False
        del data[:sent]
        self.protocol.unsent(conn, data)
        events = selectors.EVENT_READ | (selectors.EVENT_WRITE if data else 0)
        key = self.server.selector.get_key(sock)
        if key.events != events:
            self.server.selector.modify(sock, events, key.data)
        if self.protocol.finished(conn):
            self._close(conn)
            return False
        return True

    def _close(self, conn: int) -> None:
        self.backlog.pop(conn, None)
        self.protocol.disconnect(conn)
        sock = self.clients.pop(conn, None)
        if sock is None:
            return
        with contextlib.suppress(KeyError, ValueError):
            self.server.selector.unregister(sock)
        sock.close()

    def close(self) -> None:
        for conn in list(self.clients):
            self._close(conn)
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
            return Streamed(ok=True, result=result) if type(result) is Streamed else {"ok": True, "result": result}
        except (ValueError, TypeError, TransitionError) as exc:
            return error_answer(str(exc))
        except Exception as exc:          # noqa: BLE001 - a request never ends the simulator
            return error_answer(f"internal error of the simulator ({type(exc).__name__}: {exc})")

    @staticmethod
    def _state(robot: Robot) -> dict:
        state = robot.state()
        return Streamed(state) if robot.session.variable_bytes() > CONTROL_TURN_BYTES else state

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


def default_port(robot_port: int, host: str = "127.0.0.1", taken: Iterable[int] = ()) -> int:
    """The control channel's default port: the one before robot 1's (5889 for 5890), so simulators on different
    robot ports do not collide; 0 (any free port, printed at start) when that one is not a port, is one of
    ``taken``, or is in use. The check binds as the control channel's server does (SO_REUSEADDR): connections of a
    simulator just stopped (TIME_WAIT) do not count; a port something listens on, or that a simulator holds for a
    robot whose project stopped, does."""
    derived = robot_port - 1
    if derived < 1 or derived in taken:
        return 0
    probe = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        probe.bind((host, derived))
    except OSError:
        return 0
    finally:
        probe.close()
    return derived


_NO_SLAVE = "the Ethernet Slave is not running (simulator started with --no-svr)"


def _svr(robot: Robot) -> SlavePort:
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
