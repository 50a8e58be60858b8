"""Local control channel: JSON lines over TCP (127.0.0.1 only by default) for a separate process.

Each request is one JSON object on one line; each answer is one line ``{"ok": true, "result": ...}``
or ``{"ok": false, "error": "..."}``. Requests (``robot`` defaults to 0):

    {"cmd": "ping"}
    {"cmd": "robots"}                                         ports and node state of every robot
    {"cmd": "state", "robot": 0}
    {"cmd": "events", "robot": 0, "since": 0}                 events[since:], plus "next" index
    {"cmd": "enter_listen_node" | "leave_listen_node" | "stop_project" | "start_project", "robot": 0}
    {"cmd": "inject", "robot": 0, "fault": "reply_delay", "params": {"seconds": 0.5}}
    {"cmd": "clear_faults", "robot": 0}
    {"cmd": "estop", "robot": 0, "pressed": true}             Ethernet Slave: the operator at the robot
    {"cmd": "operation_mode", "robot": 0, "mode": "manual"}
    {"cmd": "svr_config", "robot": 0, "period": 0.1, "mode": 1, "items": [...], "write_permission": true}
"""
from __future__ import annotations

import json
import selectors
import socket

from .session import TransitionError

MAX_REQUEST = 65536


class ControlChannel:
    def __init__(self, server, host="127.0.0.1", port=0):
        self.server = server
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, port))
        except OSError as exc:
            sock.close()
            raise OSError(exc.errno, f"cannot open the control channel on {host}:{port}: {exc.strerror}") from None
        sock.listen(16)
        sock.setblocking(False)
        self.sock = sock
        self.port = sock.getsockname()[1]
        self.buffers: dict[socket.socket, bytearray] = {}
        server._dispatch["control_listen"] = self._accept
        server._dispatch["control_conn"] = self._read
        server.selector.register(sock, selectors.EVENT_READ, ("control_listen", None, None))
        self._commands = {
            "ping": lambda robot, req: "pong",
            "robots": lambda robot, req: [{"robot": r.index, "port": r.port, "node_state": r.session.state,
                                           "svr_port": getattr(r, "svr_port", None)} for r in server.robots],
            "state": lambda robot, req: robot.state(),
            "events": self._events,
            "enter_listen_node": lambda robot, req: robot.enter_listen_node(),
            "leave_listen_node": lambda robot, req: robot.leave_listen_node(),
            "stop_project": lambda robot, req: robot.stop_project(),
            "start_project": lambda robot, req: robot.start_project(),
            "inject": lambda robot, req: robot.inject(str(req.get("fault", "")), **dict(req.get("params") or {})),
            "clear_faults": lambda robot, req: robot.clear_faults(),
            "estop": lambda robot, req: _svr(robot).set_estop(bool(req.get("pressed", True))),
            "operation_mode": lambda robot, req: _svr(robot).set_auto_mode(_mode(req.get("mode"))),
            "svr_config": self._svr_config,
        }

    def _accept(self, _robot, _conn):
        try:
            sock, _addr = self.sock.accept()
        except (BlockingIOError, InterruptedError, OSError):
            return
        sock.setblocking(False)
        self.buffers[sock] = bytearray()
        self.server.selector.register(sock, selectors.EVENT_READ, ("control_conn", None, sock))

    def _read(self, _robot, sock):
        try:
            data = sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        buf = self.buffers.get(sock)
        if not data or buf is None:
            self._close(sock)
            return
        buf += data
        while b"\n" in buf:
            line, _, rest = bytes(buf).partition(b"\n")
            buf[:] = rest
            answer = self.execute(line)
            try:
                sock.setblocking(True)
                sock.sendall((json.dumps(answer) + "\n").encode())
                sock.setblocking(False)
            except OSError:
                self._close(sock)
                return
        if len(buf) > MAX_REQUEST:
            self._close(sock)

    def execute(self, line: bytes) -> dict:
        try:
            request = json.loads(line)
            if not isinstance(request, dict):
                raise ValueError("a request must be a JSON object")
            command = self._commands.get(request.get("cmd"))
            if command is None:
                raise ValueError(f"unknown command {request.get('cmd')!r}; known: {', '.join(self._commands)}")
            index = int(request.get("robot", 0))
            if not 0 <= index < len(self.server.robots):
                raise ValueError(f"robot {index} does not exist (0..{len(self.server.robots) - 1})")
            return {"ok": True, "result": command(self.server.robots[index], request)}
        except (ValueError, TypeError, TransitionError) as exc:
            return {"ok": False, "error": str(exc)}

    def _svr_config(self, robot, request):
        _svr(robot)
        with self.server.lock:
            robot.svr.configure(request.get("items"), request.get("mode"), request.get("period"))
            if "write_permission" in request:
                robot.svr.write_permission = bool(request["write_permission"])
        return {"items": robot.svr.stream_items, "mode": robot.svr.stream_mode, "period": robot.svr.period,
                "write_permission": robot.svr.write_permission}

    def _events(self, robot, request):
        since = max(0, int(request.get("since", 0)))
        events = robot.events[since:]
        return {"events": events, "next": since + len(events)}

    def _close(self, sock):
        self.buffers.pop(sock, None)
        try:
            self.server.selector.unregister(sock)
        except (KeyError, ValueError):
            pass
        sock.close()

    def close(self):
        for sock in list(self.buffers):
            self._close(sock)
        try:
            self.server.selector.unregister(self.sock)
        except (KeyError, ValueError):
            pass
        self.sock.close()


def _svr(robot):
    source = getattr(robot, "svr_source", None)
    if source is None:
        raise ValueError("the Ethernet Slave is not running (simulator started with --no-svr)")
    return source


def _mode(text):
    if text not in ("auto", "manual"):
        raise ValueError(f"operation mode must be \"auto\" or \"manual\", got {text!r}")
    return text == "auto"


def request(port: int, payload: dict, host="127.0.0.1", timeout=5.0) -> dict:
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
