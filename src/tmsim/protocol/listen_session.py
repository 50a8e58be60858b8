"""Listen node of one robot: a sans-I/O state machine (frames and time in, frames out).

The node follows an explicit transition table (project stopped / not in the node / in the node / exiting);
the scripts of all clients are checked and run strictly in arrival order, one at a time, on the robot model
(TMscript 2.24 §15: TMSCT scripts, TMSTA status queries, priority commands). Its bytes are its protocol's
(``ListenProtocol``, tmsim/protocol/listen_protocol.py: receive buffers, decoding, the CPERR limit on bad
packets, outboxes, the frame events); the node hands a server the protocol's port interface unchanged:
``connect`` / ``receive_data(conn, bytes)`` or ``buffer_data`` + ``turn(conn, budget)`` / ``disconnect`` /
``data_to_send(conn)``, and ``events()``: the events of the node and of its protocol, in the order they happened,
when the node was built without a ``log`` callback (with one, the callback gets them: the server's event log).
A server also calls ``advance(now)``; the control channel uses the control methods (``enter_node``,
``stop_project`` ...) and the queries (``node_state()``, ``snapshot()`` ...). Like every port of the simulator
the node has ``inject(fault, **params)`` / ``clear_faults()`` for its own faults (``NODE_FAULTS``: the faults on
the wire are the TCP adapter's, tmsim/robot/faults.py) and ``configure(**settings)`` / ``config()``
(``NODE_SETTINGS``).
"""
from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any

from tmsim.limits import NODE_TIMEOUT_MAX_S, WORK_CHAR, WORK_LINE, WORK_LOG_BYTES, WORK_TOKEN, TurnBudget
from tmsim.protocol import codec
from tmsim.protocol.listen_protocol import PROTOCOL_SETTINGS, Client, ListenProtocol, outgoing
from tmsim.robot.faults import check_params as check_fault_params
from tmsim.robot.model import RobotModel
from tmsim.tmscript.interp import Context, ScriptRuntimeError, run_script, variable_memory
from tmsim.tmscript.parser import Line, iter_lines
from tmsim.tmscript.profiles import Profile
from tmsim.tmscript.static_check import ScriptChecker

STOPPED, IDLE, IN_NODE, EXITING = "project_stopped", "not_in_node", "in_node", "exiting"

# (state, event) -> next state. Actions with the same name as the event run on the transition.
TRANSITIONS = {
    (STOPPED, "start_project"): IDLE,
    (IDLE, "stop_project"): STOPPED,
    (IN_NODE, "stop_project"): STOPPED,
    (EXITING, "stop_project"): STOPPED,
    (IDLE, "enter_node"): IN_NODE,
    (IN_NODE, "script_exit"): EXITING,        # ScriptExit(): drain the FIFO, then leave (Pass)
    (EXITING, "drain_done"): IDLE,
    (IN_NODE, "leave_node"): IDLE,            # control channel / priority ScriptExit(0|1)
    (EXITING, "leave_node"): IDLE,
    (IDLE, "robot_fault"): STOPPED,
    (IN_NODE, "robot_fault"): STOPPED,        # a failed motion is a robot error: the project stops
    (EXITING, "robot_fault"): STOPPED,
}

# TMscript 2.24 §15.8: a priority command is a line that is literally ScriptExit(0|1) or StopAndClearBuffer(0|1|2)
# ("not the use with variables and functions"); StopAndClearBuffer with any other argument goes to the checker,
# which refuses it (tmscript.py: §13.4 defines no parameter)
_PRIORITY = re.compile(r"^\s*(ScriptExit|StopAndClearBuffer)\s*\(\s*(\d)\s*\)\s*$")
_PRIORITY_ARGS = {"ScriptExit": (0, 1), "StopAndClearBuffer": (0, 1, 2)}

# the node's own faults (``inject``); their parameters and ranges are tmsim/robot/faults.py PARAMS
NODE_FAULTS = ("reply_error", "leave_node", "stop_project")
# ``configure``: the node's settings (the protocol's, PROTOCOL_SETTINGS, are passed on to it)
NODE_SETTINGS = ("data_timeout", "connection_timeout", "profile", *PROTOCOL_SETTINGS)


@dataclass
class Packet:
    conn: int
    id: str
    script: str


@dataclass
class Running:
    packet: Packet
    gen: Generator[Any, Any, tuple[str, bool]]     # the script checked, then run (``_script``)
    wait: tuple | None = None          # ("tag", tag, deadline or None), ("delay", None, deadline) or
                                       # ("room" | "idle" | "turn", None, None): see _resume_waits


class TransitionError(Exception):
    """An event that is not allowed in the current node state."""


class ListenSession:
    def __init__(self, robot: RobotModel | None = None, send_message: str = "Listen1",
                 log: Callable[..., None] | None = None, auto_enter: bool = True, data_timeout: float | None = None,
                 connection_timeout: float | None = None, profile: Profile | None = None):
        self.profile = profile or Profile()
        self.robot = robot or RobotModel()
        self.robot.tag_history, self.robot.stop_tags = self.profile.tag_history, self.profile.stop_tags
        self.meter = self.robot.meter       # work of the current turn (tmsim/tmscript/work.py), shared with the robot
        self.send_message = send_message
        self.protocol = ListenProtocol(self, log)         # the node's bytes: buffers, decoding, CPERR limit
        self.log: Callable[..., None] = self.protocol.log  # ``log``, or the protocol's store of events()
        self.state = STOPPED
        self.exit_path: str | None = None
        self.now = 0.0
        self.clients: dict[int, Client] = self.protocol.clients     # (the same dict: who is connected)
        self.pending: deque[Packet] = deque()
        self.running: Running | None = None
        self.variables: dict[str, Any] = {}          # the node's variables, while it stays in the node
        self.types: dict[str, Any] = {}              # ... and their declared types
        self.faults = {"reply_error": 0}
        # node parameters (seconds; None or <= 0 = none): no packet / no client while in the node -> Fail exit
        self.data_timeout = data_timeout if data_timeout and data_timeout > 0 else None
        self.connection_timeout = connection_timeout if connection_timeout and connection_timeout > 0 else None
        self.last_packet = 0.0
        self.entered_at = 0.0
        self.last_error: str | None = None              # text of the last robot error (failed motion)
        self.fire("start_project")
        if auto_enter:
            self.fire("enter_node")

    # ---- node state machine -------------------------------------------------------------------
    def fire(self, event: str, **info: Any) -> None:
        nxt = TRANSITIONS.get((self.state, event))
        if nxt is None:
            raise TransitionError(f"'{event}' is not possible while the robot is {self.state.replace('_', ' ')}")
        previous, self.state = self.state, nxt
        self.log("state", event=event, previous=previous, state=nxt, **info)
        action = getattr(self, "_on_" + event, None)
        if action:
            action(**info)

    def _on_enter_node(self, **_):
        self.variables, self.types = {}, {}
        self.entered_at = self.last_packet = self.now
        self.exit_path = None
        self.protocol.push(outgoing("TMSCT", "0," + self.send_message))

    def _on_stop_project(self, **_):
        self.robot.stop_and_clear()
        self.robot.resume()
        self._abort_scripts(reply=False)
        self.variables, self.types = {}, {}

    def _on_robot_fault(self, reason="", **_):
        self.last_error = reason
        self.robot.latch_error(reason, self.now)
        self._on_stop_project()

    def _on_leave_node(self, path="Pass", **_):
        self.exit_path = path
        self._stop_robot()
        self.variables, self.types = {}, {}
        self._abort_scripts(reply=True)

    def _on_drain_done(self, **_):
        self.exit_path = "Pass"
        self.variables, self.types = {}, {}
        self._pump()

    def _abort_scripts(self, reply):
        if self.running is not None:
            if reply:
                self._reply(self.running.packet, "OK")
            self.running = None
        if reply:
            self._pump()
        else:
            self.pending.clear()

    # ---- the protocol's port interface (ListenProtocol) ---------------------------------------
    def connect(self, conn: int, peer: str = "127.0.0.1") -> None:
        self.protocol.connect(conn, peer)

    def disconnect(self, conn: int) -> None:
        self.protocol.disconnect(conn)

    def receive_data(self, conn: int, data: bytes) -> int:
        """Bytes received from connection ``conn``, processed at once (ListenProtocol.receive_data)."""
        return self.protocol.receive_data(conn, data)

    def buffer_data(self, conn: int, data: bytes) -> None:
        """Bytes received from connection ``conn``, kept for ``turn``."""
        self.protocol.buffer_data(conn, data)

    def turn(self, conn: int, budget: TurnBudget) -> tuple[int, str]:
        """One bounded turn of ``conn``'s buffered input (ListenProtocol.turn)."""
        return self.protocol.turn(conn, budget)

    def data_to_send(self, conn: int) -> list[bytes]:
        """The frames for connection ``conn`` produced so far (ListenProtocol.data_to_send)."""
        return self.protocol.data_to_send(conn)

    def input_bytes(self, conn: int) -> int:
        """Bytes of connection ``conn`` received and not processed yet."""
        return self.protocol.input_bytes(conn)

    def unanswered_bad(self, conn: int) -> int:
        """Bad packets of connection ``conn`` not answered (CPERR limit) and not logged yet."""
        return self.protocol.unanswered_bad(conn)

    def has_output(self) -> bool:
        """True when a frame for some client is waiting in data_to_send."""
        return self.protocol.has_output()

    def is_connected(self, conn: int) -> bool:
        return conn in self.clients         # the protocol's own table: asked at every poll, one call fewer

    def events(self) -> list[dict[str, Any]]:
        """The events of the node and of its protocol since the last call, oldest first, each
        ``{"kind": ..., **fields}`` (the kinds of docs/simulator.md "Event log"); they are forgotten. Empty when
        the node was built with a ``log`` callback."""
        return self.protocol.events()

    @property
    def events_dropped(self) -> int:
        """Events not taken by ``events()`` and dropped (PORT_EVENTS_MAX, tmsim/limits.py)."""
        return self.protocol.events_dropped

    # ---- input --------------------------------------------------------------------------------
    def handle(self, conn: int, item: codec.Frame | codec.BadFrame | codec.Garbage) -> None:
        """Process one decoded item (codec.Frame / BadFrame / Garbage) from connection ``conn``, as it is
        (no CPERR limit, no ``frame_in`` event: ``turn`` adds those)."""
        self.last_packet = self.now
        if isinstance(item, codec.Garbage):
            self.log("garbage", conn=conn, bytes=len(item.raw))
        elif isinstance(item, codec.BadFrame):
            self.log("bad_frame", conn=conn, code=item.code, reason=item.reason)
            self.protocol.send(conn, "CPERR", item.code)
        elif item.header == "TMSTA":
            self._tmsta(conn, item.data)
        elif item.header == "TMSCT":
            self._tmsct(conn, item.data)
        else:
            self.protocol.send(conn, "CPERR", codec.CPERR_HEADER)

    def _tmsta(self, conn, data: bytes):
        text = data.decode("utf-8", "replace")
        sub, _, param = text.partition(",")
        if sub == "00":
            reply = f"00,true,{self.send_message}" if self.state in (IN_NODE, EXITING) else "00,false,"
        elif sub == "01" and param:
            try:
                tag = int(param)
            except ValueError:
                tag = None
            reply = f"01,{param},{self.robot.tag_status(tag) if tag is not None else 'none'}"
        else:       # TMscript 2.24 §15.4: a client asks 00 and 01 only (90-99 go robot -> client, "Receive: None")
            self.protocol.send(conn, "CPERR", codec.CPERR_DATA)
            return
        self.protocol.send(conn, "TMSTA", reply)

    def _tmsct(self, conn, data: bytes):
        ident, comma, body = data.partition(b",")
        try:
            ident_text, script = ident.decode("ascii"), body.decode("utf-8")
        except UnicodeDecodeError:
            ident_text, script = "", ""
        if not comma or not ident_text or not ident_text.isalnum():
            self.protocol.send(conn, "CPERR", codec.CPERR_DATA)
            return
        packet = Packet(conn, ident_text, script)
        if self.state not in (IN_NODE, EXITING):
            self._not_in_node(packet)
            return
        priority = priority_command(script)
        if priority is not None:
            self._priority(packet, *priority)
            return
        self.pending.append(packet)
        self._pump()

    def _not_in_node(self, packet):
        self.log("rejected", conn=packet.conn, id=packet.id, reason="not in the Listen node")
        self.protocol.send(packet.conn, "CPERR", codec.CPERR_NOT_IN_NODE)

    # ---- priority commands --------------------------------------------------------------------
    def _priority(self, packet, name, arg):
        self.log("priority", conn=packet.conn, id=packet.id, command=f"{name}({arg})")
        self._stop_robot()
        if name == "ScriptExit":
            if self.running is not None:
                self._reply(self.running.packet, "OK")
                self.running = None
            self._reply(packet, "OK")
            self.fire("leave_node", path="Pass" if arg == 1 else "Fail")
            return
        if arg >= 1 and self.running is not None:
            self._reply(self.running.packet, "OK")
            self.running = None
        if arg == 2:
            for dropped in self.pending:
                self.log("discarded", conn=dropped.conn, id=dropped.id)
            self.pending.clear()
        if arg == 0:
            # TMscript 2.24 §15.8, example 2: the current script goes on first (a wait on a dropped tag
            # returns), so a script the stop lets finish is answered before the priority command
            # ("Respond 1 OK", then "Respond 2 OK"); one still blocked (example 3, WaitQueueTag(0,60000))
            # is answered later.
            self._resume_waits()
        self._reply(packet, "OK")
        self._pump()

    def _stop_robot(self):
        dropped = self.robot.stop_and_clear()
        self.log("stop", dropped_tags=dropped)

    # ---- script execution ---------------------------------------------------------------------
    def _reply(self, packet, status):
        self.protocol.send(packet.conn, "TMSCT", f"{packet.id},{status}")

    def _pump(self):
        """Resume the running script if it may continue, then run buffered scripts in order until
        one blocks or none is left (a loop, so any number of buffered scripts costs no stack)."""
        while True:
            self._resume_waits()
            if self.running is not None or not self.pending:
                return
            packet = self.pending.popleft()
            if packet.conn not in self.clients:
                continue
            if self.state != IN_NODE:
                self._not_in_node(packet)
                continue
            self._start(packet)

    def _start(self, packet):
        if self.faults["reply_error"] > 0:
            self.faults["reply_error"] -= 1
            self.log("fault", fault="reply_error", id=packet.id)
            self._reply(packet, "ERROR;1")
            return
        self.running = Running(packet, self._script(packet))
        self._step(None)

    def _script(self, packet):
        """Check the packet line by line, then run it (a generator, like tmsim.tmscript.interp.run_script, whose waits
        it passes on). Returns the reply status and whether ScriptExit() ran. Parsing and checking count
        WORK_CHAR per character and WORK_LINE per line, a long line WORK_TOKEN per token as its parsing goes
        (PARSE_SLICE tokens at a time); when the turn's budget is spent, the rest waits for a later turn
        (wait "turn"): a 64 KiB script, or one line of 10,000 tokens, never holds the other robots."""
        meter = self.meter
        checker = ScriptChecker(self.types, self.profile.tmflow)
        lines: list[Line] = []
        sliced = 0
        for line in iter_lines(packet.script):
            if meter.spent:
                yield ("turn", None, None)
            if isinstance(line, int):           # PARSE_SLICE more tokens of a long line parsed
                meter.add(line * WORK_TOKEN)
                sliced += line * WORK_TOKEN
                continue
            checker.check(line)
            lines.append(line)
            meter.add(max(0, WORK_LINE + WORK_CHAR * len(line.text) - sliced))
            sliced = 0
        errors = [line.number for line in lines if line.error]
        for line in lines:
            if line.error:
                self.log("script_error", id=packet.id, line=line.number, text=line.text, reason=line.error)
        if errors:
            return "ERROR;" + ";".join(map(str, errors)), False
        warnings = [line.number for line in lines if line.warnings]
        ctx = Context(self.robot, self.variables, self.types, self._listen_send, self._stop_robot,
                      lambda line, p=packet: self.log("script_line", conn=p.conn, id=p.id,
                                                      line=line.number, text=line.text),
                      self.log, meter)
        exit_ = yield from run_script(lines, ctx)
        return "OK" + "".join(f";{n}" for n in warnings), exit_ == "exit"

    def _step(self, value):
        run = self.running
        if run is None:                     # (called only while a script runs)
            return
        try:
            request = run.gen.send(value)
        except StopIteration as stop:
            self.running = None
            status, exit_ = stop.value
            self._reply(run.packet, status)
            if exit_:
                self.fire("script_exit")
                self._check_drain()
            return
        except ScriptRuntimeError as exc:
            self.running = None
            line = str(exc).split(":")[0].replace("line ", "")
            self.log("runtime_error", id=run.packet.id, reason=str(exc))
            self._reply(run.packet, "ERROR;" + line)
            return
        kind, tag, timeout = request
        run.wait = (kind, tag, None if timeout is None else self.now + timeout)

    def _resume_waits(self):
        """Resume the running script if what it waits for has happened. Waits (see tmsim.tmscript.interp):
        turn (the budget of a turn ended its checking or running: a new turn), room (FIFO full), idle
        (WaitQueueTag(): every queued motion done), delay (Sleep, tag 0), and
        tag: 1 completed / -1 not existed end the wait at once, 0 when the timeout passes (§13.2)."""
        while self.running is not None and self.running.wait is not None:
            kind, tag, deadline = self.running.wait
            if kind == "turn":                  # the budget of a turn ended its work: go on in a new turn
                if self.meter.spent:
                    return
                result = None
            elif kind == "room":                  # a queued statement waits for room in the full FIFO
                if not self.robot.has_room:
                    return
                result = None
            elif kind == "idle":
                if not self.robot.idle:
                    return
                result = None
            elif kind == "delay":
                if self.now < deadline:
                    return
                result = 0
            else:
                result = self.robot.tag_result(tag)
                if result == 0 and (deadline is None or self.now < deadline):
                    return
            self.running.wait = None
            self._step(result)

    def _listen_send(self, ip_filter, sub, payload):
        out = outgoing("TMSTA", f"{sub},".encode() + payload)
        recipients = self.protocol.push(out, ip_filter)
        self.meter.add(len(out[0]) * recipients // WORK_LOG_BYTES)     # sending it and its event, per client

    # ---- time ---------------------------------------------------------------------------------
    def advance(self, now: float) -> None:
        previous = self.now
        if now > previous:
            self.now = now
        if self.state == IN_NODE and (self.data_timeout or self.connection_timeout):
            self._check_timeouts()
        # (cheapest test first: a server advances every robot at every poll, most of them idle)
        if (self.running is None and self.state != EXITING and self.robot.idle) or self.state == STOPPED:
            return
        for event in self.robot.tick(max(0.0, now - previous)):
            kind = event.pop("kind")
            self.log(kind, **event)
            if kind == "tag_reached":
                self.protocol.push(outgoing("TMSTA", f"01,{event['tag']:02d},true"))
        if self.robot.fault:
            reason, self.robot.fault = self.robot.fault, None
            self.fire("robot_fault", reason=reason)
            return
        self._pump()
        self._check_drain()

    def next_due(self, now: float) -> float | None:
        """The earliest robot-clock time at which ``advance`` has work without new input (a server sleeps until
        then): ``now`` while the arm moves or has queued items to start (its events, the next motion on time) or a
        turn's work is left; the deadline of the running script's wait (Sleep, a WaitQueueTag timeout, a vision
        job's time); the node's data / connection timeout. None while nothing is due until a client or a control
        call changes something (a paused arm, a script waiting for a tag of a paused arm, a stopped project)."""
        if self.state == STOPPED:
            return None
        robot = self.robot
        if not robot.idle and not robot.paused:
            return now
        if self.state == EXITING and robot.idle and self.running is None:
            return now
        due = None
        run = self.running
        if run is not None and run.wait is not None:
            kind, _tag, due = run.wait
            if kind == "turn":
                return now
        if self.state == IN_NODE:
            if self.connection_timeout and not self.clients:
                at = self.entered_at + self.connection_timeout
                due = at if due is None else min(due, at)
            if self.data_timeout:
                at = self.last_packet + self.data_timeout
                due = at if due is None else min(due, at)
        return due

    def _check_timeouts(self):
        if self.connection_timeout and not self.clients and self.now - self.entered_at >= self.connection_timeout:
            self.fire("leave_node", path="Fail", reason="connection timeout")
        elif self.data_timeout and self.now - self.last_packet >= self.data_timeout:
            self.fire("leave_node", path="Fail", reason="data timeout")

    def _check_drain(self):
        if self.state == EXITING and self.robot.idle and self.running is None:
            self.fire("drain_done")

    # ---- queries ------------------------------------------------------------------------------
    def has_work_for(self, conn: int) -> bool:
        """True while a script of ``conn`` runs or waits (its replies are still to come)."""
        if self.running is not None and self.running.packet.conn == conn:
            return True
        return any(p.conn == conn for p in self.pending)

    @property
    def has_turn_work(self) -> bool:
        """Work that a spent turn left for a later one: a script to check or run on, motions owed time."""
        return (self.running is not None and self.running.wait is not None and self.running.wait[0] == "turn") \
            or (self.robot.owed > 0.0 and not self.robot.idle)

    @property
    def buffered(self) -> int:
        """Scripts received and not answered yet (running or waiting)."""
        return len(self.pending) + (1 if self.running else 0)

    @property
    def waiting_scripts(self) -> int:
        """Scripts received and not started yet."""
        return len(self.pending)

    def variable_bytes(self) -> int:
        """The memory the node's variables use, as VARIABLE_BYTES_MAX counts it."""
        return variable_memory(self.variables)

    def waiting_script_bytes(self) -> int:
        return sum(len(p.script) for p in self.pending)

    def node_state(self) -> str:
        """The node's state: STOPPED ("project_stopped"), IDLE ("not_in_node"), IN_NODE or EXITING."""
        return self.state

    def project_running(self) -> bool:
        """The robot's project runs (in the Listen node or not)."""
        return self.state != STOPPED

    # ---- control (the control channel, fault injection) ---------------------------------------------
    def enter_node(self, source: str = "control") -> None:
        self.fire("enter_node", source=source)

    def leave_node(self, path: str = "Pass", source: str = "control") -> None:
        self.fire("leave_node", path=path, source=source)

    def stop_project(self, source: str = "control") -> None:
        self.fire("stop_project", source=source)

    def start_project(self, enter_node: bool = True, source: str = "control") -> None:
        self.fire("start_project", source=source)
        if enter_node:
            self.fire("enter_node", source=source)

    def robot_error(self, reason: str, source: str = "control") -> None:
        """A robot error from outside the Listen node (the emergency stop): the project stops with it; when
        it is stopped already, the error is latched only."""
        if self.state != STOPPED:
            self.fire("robot_fault", reason=reason, source=source)
        else:
            self.robot.latch_error(reason, self.now)

    def internal_error(self, reason: str) -> None:
        """The simulator failed while advancing: a robot error of this robot (arm stops, project stops)."""
        self.robot.stop_and_clear()
        if self.state != STOPPED:
            self.fire("robot_fault", reason=reason)

    def inject(self, fault: str, **params: Any) -> None:
        """Arm one of the node's faults (docs/simulator.md, "Fault injection"; ranges: tmsim/robot/faults.py):
        ``reply_error`` (count=1, 1..10^6): the next ``count`` scripts are answered ``ID,ERROR;1`` without
        running (the reply of an invalid script, TMscript 2.24 §15.3 "Return" 2); ``leave_node`` (path="Pass" or
        "Fail"): the flow leaves the Listen node by that exit (§15.1, the node's two exit conditions), as
        ``leave_node``; ``stop_project``: the project stops, as ``stop_project``. ValueError naming an unknown
        fault, an unknown parameter or a value out of its range; TransitionError when the node's state does not
        allow it (``leave_node`` outside the node); nothing changes then. The faults on the wire (delays,
        split and glued frames, black hole ...) act on sockets and timing: the server's (``Robot.inject``)."""
        if fault not in NODE_FAULTS:
            raise ValueError(f"unknown Listen node fault '{fault}'; the node's faults: {', '.join(NODE_FAULTS)}")
        checked = check_fault_params(fault, params)
        if fault == "reply_error":
            self.add_reply_errors(checked["count"])
        elif fault == "leave_node":
            self.leave_node(path=checked["path"], source="fault")
        else:
            self.stop_project()         # source "control", as the event has always said for this fault

    def clear_faults(self) -> None:
        """End the node's faults: the scripts still to be answered ERROR;1 are run again."""
        self.clear_reply_errors()

    def configure(self, **settings: Any) -> None:
        """Set what a user of the node sets on its constructor or the command line: ``data_timeout`` /
        ``connection_timeout`` (seconds, 0 .. NODE_TIMEOUT_MAX_S; 0 or None: none; no packet / no client while
        in the node for that long leaves it by its Fail path, TMscript 2.24 §15.1 "Connection Timeout" / "Data
        Timeout"), ``profile`` (a tmsim.tmscript.profiles.Profile:
        the TMflow version whose functions the checker knows from the next script on, the queue tags kept and
        what a stop does to them), and the protocol's CPERR limit ``cperr_burst`` / ``cperr_per_s``
        (ListenProtocol.configure). ValueError naming an unknown setting or a value out of its range; nothing
        changes then."""
        for name in settings:
            if name not in NODE_SETTINGS:
                raise ValueError(f"unknown setting '{name}' of the Listen node; known: {', '.join(NODE_SETTINGS)}")
        timeouts = {}
        for name in ("data_timeout", "connection_timeout"):
            if name in settings:
                value = settings[name]
                if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                          or not 0 <= value <= NODE_TIMEOUT_MAX_S):
                    raise ValueError(f"setting '{name}' of the Listen node must be 0 (none) .. "
                                     f"{NODE_TIMEOUT_MAX_S:g} seconds or None, got {value!r}")
                timeouts[name] = float(value) if value else None
        profile = settings.get("profile", self.profile)
        if not isinstance(profile, Profile):
            raise ValueError(f"setting 'profile' of the Listen node must be a tmsim.tmscript.profiles.Profile, "
                             f"got {profile!r}")
        # the protocol checks its settings before it changes any, and the node's are checked above: a bad one
        # leaves everything as it was
        self.protocol.configure(**{name: settings[name] for name in PROTOCOL_SETTINGS if name in settings})
        for name, seconds in timeouts.items():
            setattr(self, name, seconds)
        self.profile = profile
        self.robot.tag_history, self.robot.stop_tags = profile.tag_history, profile.stop_tags

    def config(self) -> dict[str, Any]:
        """What ``configure`` set (timeouts in seconds, None: none)."""
        return {"data_timeout": self.data_timeout, "connection_timeout": self.connection_timeout,
                "profile": self.profile, **self.protocol.config()}

    def add_reply_errors(self, count: int) -> None:
        """The next ``count`` scripts are answered ERROR;1 without running (fault injection)."""
        self.faults["reply_error"] = min(self.faults["reply_error"] + count, 10 ** 6)

    def clear_reply_errors(self) -> None:
        self.faults["reply_error"] = 0

    def snapshot(self) -> dict:
        data = self.robot.state()
        data.update(in_listen_node=self.state in (IN_NODE, EXITING), node_state=self.state,
                    project_running=self.state != STOPPED, exit_path=self.exit_path, last_error=self.last_error,
                    buffered_scripts=len(self.pending) + (1 if self.running else 0),
                    variables={name: list(value) if isinstance(value, list) else value    # a snapshot: a
                               for name, value in self.variables.items()})            # large one is sent later
        return data


def priority_command(script: str) -> tuple[str, int] | None:
    """(name, arg) of the priority command in a packet, or None. ScriptExit wins; first one wins."""
    found = []
    for text in script.split("\r\n"):
        match = _PRIORITY.match(text)
        if match and int(match.group(2)) in _PRIORITY_ARGS[match.group(1)]:
            found.append((match.group(1), int(match.group(2))))
    for name in ("ScriptExit", "StopAndClearBuffer"):
        for item in found:
            if item[0] == name:
                return item
    return None
