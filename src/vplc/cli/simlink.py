"""The robot simulator's control channel as seen from a scenario (``vplc run --sim-control HOST:PORT``).

vplc speaks the simulator's documented protocol (docs/simulator.md, "Control channel": one JSON object per line
over TCP, one answer line ``{"ok": true, "result": ...}`` or ``{"ok": false, "error": "..."}``) and never imports
the simulator, so each stays usable without the other. A scenario names robots from 1, as the simulator's
start-up lines and a PLC program do; the channel counts them from 0.

Every request carries ``plc_time``, the controller time in seconds since the first scan: the simulator writes it
into its event log next to its own robot-clock time (event ``control``), which lines the two logs up.

``COMMANDS`` is the scenario's view of the channel's table of actions; tests/vplc/runtime/test_rt_scenario_sim.py
checks it against docs/simulator.md so that a command or a fault added there is not forgotten here.
"""
from __future__ import annotations

import json
import math
import queue
import socket
import threading
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any


class CommandError(ValueError):
    """A robot line that names no known command or lacks a parameter; the text says which."""


@dataclass(frozen=True)
class Command:
    fixed: dict                   # fields every request of this command carries
    positional: str | None = None  # the request field filled by the first word after the command (inject FAULT)
    choices: tuple = ()           # allowed values of the positional word (empty: any)
    keys: dict | None = None      # KEY=VALUE words allowed: name -> "number", "bool", "text" or "list"
    into_params: bool = False     # KEY=VALUE words go into "params" (faults) rather than the request itself
    needs_one_key: bool = False


# Listen-node faults and Ethernet Slave faults with their parameters (docs/simulator.md, "Fault injection" and
# "Ethernet Slave", Faults); the ranges are the simulator's to check: it refuses a value outside them by name.
FAULTS = {"reply_delay": ("seconds", "count"), "split_replies": ("size",), "glue_replies": ("count", "max_wait"),
          "corrupt_checksum": ("count",), "close_after": ("frames",), "close_mid_frame": (),
          "reply_error": ("count",), "black_hole": ("enabled",), "refuse_connections": ("enabled",),
          "leave_node": ("path",), "stop_project": (), "disconnect": ()}
SVR_FAULTS = {"stall": ("enabled",), "corrupt_checksum": ("count",), "disconnect": (), "refuse_writes": ("status",)}

COMMANDS = {
    "enter_listen_node": Command({}),
    "leave_listen_node": Command({}),
    "stop_project": Command({}),
    "start_project": Command({}),
    "inject": Command({}, positional="fault", choices=tuple(FAULTS), keys={}, into_params=True),
    "clear_faults": Command({}),
    "estop": Command({"pressed": True}, keys={"pressed": "bool"}),
    "operation_mode": Command({}, positional="mode", choices=("auto", "manual")),
    "svr_config": Command({}, keys={"period": "number", "mode": "number", "items": "list",
                                    "write_permission": "bool"}, needs_one_key=True),
    "svr_inject": Command({}, positional="fault", choices=tuple(SVR_FAULTS), keys={}, into_params=True),
    "svr_clear_faults": Command({}),
    # an input of the robot as a wired sensor changes it: End_DI0..3, Ctrl_DI0..15 (0/1), *_AI* (volts)
    "set_input": Command({}, keys={"name": "text", "value": "number"}, needs_one_key=True),
    # the robot's camera: a vision job of its project and what it finds (docs/simulator.md, Virtual camera)
    "vision_job": Command({}, positional="job", keys={"objects": "poses", "pass": "bool", "seconds": "number",
                                                      "capture": "pose", "variable": "text"}),
    "vision_remove": Command({}, positional="job"),
}
# Words of the commissioning engineer for the commonest actions, each one request of the table above.
ALIASES: dict[str, tuple[str, dict[str, object]]] = {
    "cut_link": ("inject", {"fault": "disconnect"}),        # every client connection closed now
    "release_estop": ("estop", {"pressed": False})}
QUERIES = ("ping", "robots", "state", "events", "vision")                    # answers, not actions


def build_request(words: list[str]) -> dict:
    """``["inject", "reply_delay", "seconds=0.5"]`` -> the request (without ``robot`` and ``plc_time``);
    CommandError naming what is wrong."""
    if not words:
        raise CommandError("`robot N` needs a command, e.g. `robot 1 cut_link`")
    name, args = words[0].lower(), words[1:]
    if name in ALIASES:
        if args:
            raise CommandError(f"`{name}` takes no parameters, got `{' '.join(args)}`")
        cmd, fields = ALIASES[name]
        return {"cmd": cmd, **fields}
    if name in QUERIES:
        raise CommandError(f"`{name}` asks the simulator for something; a scenario line acts: "
                           f"{', '.join(known_commands())}")
    command = COMMANDS.get(name)
    if command is None:
        raise CommandError(f"unknown simulator command `{words[0]}`; known: {', '.join(known_commands())}")
    request = {"cmd": name, **command.fixed}
    if command.positional is not None:
        if not args or "=" in args[0]:
            choices = f": one of {', '.join(command.choices)}" if command.choices else f", e.g. `{name} job1`"
            raise CommandError(f"`{name}` needs its {command.positional}{choices}")
        value = args.pop(0)
        if command.choices and value not in command.choices:
            raise CommandError(f"`{value}` is not a {command.positional} of `{name}`; known: "
                               f"{', '.join(command.choices)}")
        request[command.positional] = value
    allowed = dict(command.keys or {})
    if command.into_params:
        table = FAULTS if name == "inject" else SVR_FAULTS
        allowed = {key: "value" for key in table[request["fault"]]}
    values = {}
    for word in args:
        key, eq, text = word.partition("=")
        if not eq or not key or not text:
            raise CommandError(f"`{word}`: parameters are KEY=VALUE, e.g. "
                               f"{_example(name, allowed)}" if allowed else f"`{name}` takes no parameters")
        if key not in allowed:
            what = f"`{request.get('fault')}`" if command.into_params else f"`{name}`"
            raise CommandError(f"`{key}` is not a parameter of {what}; "
                               + (f"known: {', '.join(allowed)}" if allowed else "it takes none"))
        values[key] = _value(text, allowed[key], key)
    if command.needs_one_key and not values:
        raise CommandError(f"`{name}` needs at least one of {', '.join(allowed)}")
    if command.into_params:
        request["params"] = values
    else:
        request.update(values)
    return request


def known_commands() -> list[str]:
    return [*COMMANDS, *ALIASES]


def _example(name: str, allowed: Iterable[str]) -> str:
    return f"`{name} ... {next(iter(allowed))}=1`"


def _value(text: str, kind: str, key: str) -> Any:
    if kind == "list":
        return [item for item in text.split(",") if item]
    if kind == "text":
        return text
    if kind == "pose":
        return _pose(text, key)
    if kind == "poses":
        return [_pose(pose, key) for pose in text.split(";") if pose]
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    if kind == "bool":
        raise CommandError(f"`{key}` is true or false, got `{text}`")
    try:
        return int(text)
    except ValueError:
        pass
    try:
        number = float(text)
    except ValueError:
        if kind == "number":
            raise CommandError(f"`{key}` is a number, got `{text}`") from None
        return text
    if not math.isfinite(number):
        raise CommandError(f"`{key}` must be a finite number, got `{text}`")
    return number


def _pose(text: str, key: str) -> list[float]:
    """``300,0,5,0,0,90`` -> six finite numbers (a pose in mm and deg, or six joint angles)."""
    try:
        numbers = [float(v) for v in text.split(",")]
    except ValueError:
        numbers = []
    if len(numbers) != 6 or not all(math.isfinite(v) for v in numbers):
        raise CommandError(f"`{key}`: `{text}` is not six numbers like 300,0,5,0,0,90"
                           + (" (poses separated by `;`)" if key == "objects" else ""))
    return numbers


def describe(request: dict) -> str:
    """The request as a scenario writes it (``inject reply_delay seconds=0.5``, ``estop pressed=false``)."""
    words = [request["cmd"]] + [request[k] for k in ("fault", "mode", "job") if k in request]
    for key, value in [*request.items(), *request.get("params", {}).items()]:
        if key not in ("cmd", "fault", "mode", "job", "params", "robot", "plc_time"):
            words.append(f"{key}={_word(value)}")
    return " ".join(words)


def _word(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return (";" if value and isinstance(value[0], list) else ",").join(_word(v) for v in value)
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


# ---- the connection -----------------------------------------------------------------------------------
ANSWER_MAX = 1 << 20            # bytes of one answer line; the simulator keeps every answer of ours far below
CONNECT_TIMEOUT_S = 5.0


class LinkError(RuntimeError):
    """The control channel cannot be reached or broke; the text says where and why."""


def parse_address(text: str) -> tuple[str, int]:
    """``HOST:PORT`` or ``PORT`` (on 127.0.0.1) -> (host, port); ValueError with the reason."""
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = "127.0.0.1", text
    if not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"--sim-control {text!r} is not HOST:PORT (e.g. 127.0.0.1:5889) with a port 1..65535")
    return host or "127.0.0.1", int(port)


class SimControl:
    """One connection to the control channel. ``call`` waits for the answer (before the run and on virtual
    time); ``post`` hands the request to a sender thread so that a real-time scan never waits on the network,
    and the answers that refused something come back through ``refusals()``."""

    def __init__(self, host: str, port: int) -> None:
        self.where = f"{host}:{port}"
        try:
            self.sock = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
        except OSError as exc:
            raise LinkError(f"cannot reach the simulator's control channel at {self.where}: "
                            f"{exc.strerror or exc}") from None
        self.rfile = self.sock.makefile("rb")
        self._queue: queue.Queue = queue.Queue()
        self._refused: list[str] = []
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None

    def call(self, request: dict) -> dict:
        try:
            self.sock.sendall((json.dumps(request) + "\n").encode("utf-8"))
            line = self.rfile.readline(ANSWER_MAX + 1)
        except OSError as exc:
            raise LinkError(f"the control channel at {self.where} failed: {exc.strerror or exc}") from None
        if not line.endswith(b"\n"):
            raise LinkError(f"the control channel at {self.where} closed the connection" if not line else
                            f"the control channel at {self.where} sent an answer longer than {ANSWER_MAX} bytes")
        try:
            answer = json.loads(line)
        except ValueError:
            raise LinkError(f"the control channel at {self.where} answered something that is not JSON") from None
        if not isinstance(answer, dict) or "ok" not in answer:
            raise LinkError(f"the control channel at {self.where} answered without \"ok\"")
        return answer

    def robot_count(self) -> int:
        answer = self.call({"cmd": "robots"})
        if not answer.get("ok") or not isinstance(answer.get("result"), list):
            raise LinkError(f"the simulator at {self.where} did not list its robots: {answer.get('error')}")
        return len(answer["result"])

    def post(self, request: dict, where: str) -> None:
        if self._thread is None:
            self._thread = threading.Thread(target=self._send_loop, name="vplc-sim-control", daemon=True)
            self._thread.start()
        self._queue.put((request, where))

    def refusals(self) -> list[str]:
        with self._lock:
            out, self._refused = self._refused, []
        return out

    def send_now(self, request: dict, where: str) -> None:
        """Send and judge the answer in the calling thread (virtual time: deterministic order)."""
        self._judge(request, where)

    def _judge(self, request: dict, where: str) -> None:
        try:
            answer = self.call(request)
            problem = None if answer["ok"] else f"the simulator refused `{describe(request)}`: {answer.get('error')}"
        except LinkError as exc:
            problem = str(exc)
        if problem is not None:
            with self._lock:
                self._refused.append(f"{where}: {problem}")

    def _send_loop(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            self._judge(*item)
            self._queue.task_done()

    def drain(self, timeout: float = 2.0) -> None:
        """Wait until the posted requests were answered (at the end of a run), at most ``timeout`` seconds."""
        if self._thread is None:
            return
        done = threading.Event()
        def answered() -> None:
            self._queue.join()
            done.set()
        waiter = threading.Thread(target=answered, daemon=True)
        waiter.start()
        done.wait(timeout)

    def close(self) -> None:
        if self._thread is not None:
            self._queue.put(None)
            self._thread.join(1.0)
        try:
            self.rfile.close()
            self.sock.close()
        except OSError:
            pass
