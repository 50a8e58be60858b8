"""The control channel's protocol, sans-I/O: one JSON request object per line in, one JSON answer per line out
(docs/simulator.md, "Control channel").

``ControlProtocol`` has the shape of the simulator's other two ports (the Listen node's ListenProtocol, the
Ethernet Slave's SvrSession): a server calls ``connect`` / ``receive_data(conn, bytes)`` / ``disconnect``, gives
each client bounded turns (``turn(conn, execute, flush)``: the protocol frames the lines, hands each request line
to ``execute`` and queues the answer it returns) and takes ``data_to_send(conn)``. The protocol owns each client's
receive buffer, its unsent answers, the answers encoded a piece at a time over several turns (``Streamed``) and
the bounds of tmsim/limits.py (CONTROL_LINE_MAX, CONTROL_OUTBOX_MAX, CONTROL_TURN_REQUESTS, CONTROL_TURN_BYTES,
CONTROL_TURN_PIECES); it logs event ``control_closed`` when it ends a client.

The functions below are its parts: ``next_line(buf)`` frames the byte stream (``(line, consumed)``, 0 = need more,
as the frame codecs do); ``decode_request(line)`` checks a line (JSON, nesting, fields) and the field checkers
check each value, all raising RequestError with the answer's text; ``encode_answer`` writes an answer. The TCP
adapter and the table of commands are tmsim/net/control.py."""
from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from tmsim.limits import (
    CONTROL_DEPTH_MAX,
    CONTROL_LINE_MAX,
    CONTROL_OUTBOX_MAX,
    CONTROL_TURN_BYTES,
    CONTROL_TURN_PIECES,
    CONTROL_TURN_REQUESTS,
)
from tmsim.protocol.clients import Clients
from tmsim.protocol.port_events import EventPort


class RequestError(ValueError):
    """A request that is not valid; its text is the answer's ``error``."""


def next_line(buf: bytes | bytearray) -> tuple[bytes | None, int]:
    """The first complete request line at the front of ``buf`` without its newline, and the bytes it takes;
    ``(None, 0)`` while no newline has arrived (the caller bounds what it keeps: CONTROL_LINE_MAX)."""
    end = buf.find(b"\n")
    if end < 0:
        return None, 0
    return bytes(buf[:end]), end + 1


FIELDS = {"cmd", "robot", "since", "fault", "params", "pressed", "mode", "period", "items", "write_permission",
           "plc_time", "name", "value"}
VISION_FIELDS = {"job", "objects", "pass", "seconds", "capture", "variable"}
FIELDS |= VISION_FIELDS
_BRACKETS = re.compile(rb'"(?:[^"\\]|\\.)*"|[\[\]{}]')


def decode_request(line: bytes) -> dict:
    if line.count(b"[") + line.count(b"{") > CONTROL_DEPTH_MAX:
        depth = deepest = 0
        for match in _BRACKETS.finditer(line):
            token = match.group()
            if token in (b"[", b"{"):
                depth += 1
                deepest = max(deepest, depth)
            elif token in (b"]", b"}"):
                depth -= 1
        if deepest > CONTROL_DEPTH_MAX:
            raise RequestError(f"request nested deeper than {CONTROL_DEPTH_MAX} levels")
    try:
        request = json.loads(line, parse_constant=_no_constant, parse_int=_small_int)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RequestError(f"a request must be one JSON object on one line ({exc})") from None
    except RecursionError:
        raise RequestError(f"request nested deeper than {CONTROL_DEPTH_MAX} levels") from None
    if not isinstance(request, dict):
        raise RequestError("a request must be a JSON object")
    unknown = sorted(set(request) - FIELDS)
    if unknown:
        raise RequestError(f"unknown field {unknown[0]!r}; known: {', '.join(sorted(FIELDS))}")
    return request


def plc_time(request: dict) -> float:
    """The controller's time (s) a client such as ``vplc run --scenario`` sends with its request, logged next to
    the robot clock's ``t`` so that both logs line up."""
    value = request["plc_time"]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value < 1e9:
        raise RequestError(f"'plc_time' must be the controller time in seconds (0 .. 1e9), got {show(value)}")
    return value


def _small_int(text):
    if len(text.lstrip("-")) > 18:
        raise RequestError(f"number {text[:20]}... has more than 18 digits")
    return int(text)


def _no_constant(name):
    raise RequestError(f"{name} is not a number a request may carry")


def text_field(request: dict, name: str) -> str:
    value = request.get(name)
    if not isinstance(value, str):
        raise RequestError(f"'{name}' must be a text, got {show(value)}")
    return value


def bool_field(request: dict, name: str, default: bool) -> bool:
    value = request.get(name, default)
    if not isinstance(value, bool):
        raise RequestError(f"'{name}' must be true or false, got {show(value)}")
    return value


def int_field(request: dict, name: str, default: int, low: int, high: int | None, message: str) -> int:
    value = request.get(name, default)
    if type(value) is not int:
        raise RequestError(f"'{name}' must be an integer, got {show(value)}")
    if value < low or (high is not None and value > high):
        raise RequestError(message.format(show(value)))
    return value


def fault_params(request: dict) -> dict:
    params = request.get("params", {})
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise RequestError(f"'params' must be an object, got {show(params)}")
    for key, value in params.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise RequestError(f"parameter '{key}' must be a finite number")
        if not isinstance(value, (bool, int, float, str)) or (isinstance(value, str) and len(value) > 64):
            raise RequestError(f"parameter '{key}' must be a number, true/false or a short text, got "
                               f"{show(value)}")
    return params


def operation_mode(text: object) -> bool:
    if text not in ("auto", "manual"):
        raise RequestError(f"operation mode must be \"auto\" or \"manual\", got {show(text)}")
    return text == "auto"


def show(value: object) -> str:
    text = json.dumps(value) if isinstance(value, (dict, list, str)) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def error_answer(text: str) -> dict:
    return {"ok": False, "error": text}


def encode_answer(answer: dict) -> bytes:
    return (json.dumps(answer, allow_nan=False, ensure_ascii=False) + "\n").encode("utf-8")


# ---- the protocol object --------------------------------------------------------------------------------
# outcome of one turn of a client (``ControlProtocol.turn``)
INPUT_DONE = "done"                 # no complete request line is left in the receive buffer
INPUT_LEFT = "left"                 # a bound of the turn ended it: requests (or a large answer) wait for the next
CLOSED = "closed"                   # the protocol ended the client (or ``flush`` said it is gone): close it

LINE_TOO_LONG = f"request line longer than {CONTROL_LINE_MAX} bytes; connection closed"


class Streamed(dict):
    """An answer that is encoded a piece at a time over several turns: a ``state`` whose variables hold more
    than CONTROL_TURN_BYTES (500 arrays of 2,048 numbers encode in ~0.4 s, which no turn may take)."""


_PIECES = json.JSONEncoder(allow_nan=False, ensure_ascii=False)


@dataclass
class _Client:
    conn: int
    rbuf: bytearray = field(default_factory=bytearray)      # bytes received and not answered yet
    outbox: bytearray = field(default_factory=bytearray)    # answer bytes not handed out (or handed back) yet
    closing: bool = False               # answer what is queued, then close (a request line was too long)
    encoding: Iterator[str] | None = None                   # the pieces of a large answer still to encode ...
    pieces: list[str] = field(default_factory=list)         # ... and those encoded so far


class ControlProtocol(EventPort):
    """The clients of the control channel and their bytes (see the module docstring). ``log(kind, **fields)``
    receives the channel's events (``control_closed`` with its ``reason``); built without it, the protocol keeps
    them for ``events()`` (tmsim/protocol/port_events.py).

    Like every port of the simulator it has ``inject`` / ``clear_faults`` / ``configure`` / ``config``, but the
    control channel is the simulator's own tool, not a port of the robot: it has no faults (``inject`` raises
    ValueError "the control channel has no faults") and no settings of its own (its bounds are the CONTROL_*
    of tmsim/limits.py, the same for every channel: ``configure`` with any setting raises ValueError)."""

    def __init__(self, log: Callable[..., None] | None = None):
        super().__init__(log)
        self.clients: Clients[_Client] = Clients()

    # ---- events, faults and settings ----------------------------------------------------------
    def inject(self, fault: str, **params: Any) -> None:
        """The control channel has no faults: always ValueError naming ``fault`` (the robots' faults are
        injected with the request ``inject`` / ``svr_inject`` it carries, on the robot's ports)."""
        raise ValueError(f"the control channel has no faults (asked for '{fault}'); inject a robot's faults "
                         f"with the request \"inject\" or \"svr_inject\"")

    def clear_faults(self) -> None:
        """Nothing to clear: the control channel has no faults."""

    def configure(self, **settings: Any) -> None:
        """The control channel has no settings: a setting is a ValueError naming it (its bounds are the
        CONTROL_* of tmsim/limits.py); with none, nothing happens."""
        for name in settings:
            raise ValueError(f"unknown setting '{name}' of the control channel: it has none (its bounds are the "
                             f"CONTROL_* of tmsim/limits.py)")

    def config(self) -> dict[str, Any]:
        """What ``configure`` set: nothing (an empty dict)."""
        return {}

    # ---- connections --------------------------------------------------------------------------
    def connect(self, conn: int) -> None:
        self.clients[conn] = _Client(conn)

    def disconnect(self, conn: int) -> None:
        self.clients.pop(conn, None)

    def is_connected(self, conn: int) -> bool:
        return conn in self.clients

    # ---- input --------------------------------------------------------------------------------
    def receive_data(self, conn: int, data: bytes) -> None:
        """Bytes received from connection ``conn``, kept for its next ``turn`` (unknown connection: ignored);
        a partial line waits for the bytes that complete it."""
        self.clients.buffer_data(conn, data)

    def input_bytes(self, conn: int) -> int:
        """Bytes of connection ``conn`` received and not answered yet."""
        return self.clients.input_bytes(conn)

    # ---- output -------------------------------------------------------------------------------
    def data_to_send(self, conn: int) -> bytearray:
        """The answer bytes for connection ``conn`` (whole answers: a client never gets part of one before the
        rest is encoded); the protocol forgets them. What the socket did not take goes back with ``unsent``."""
        client = self.clients.get(conn)
        if client is None or not client.outbox:
            return bytearray()
        data, client.outbox = client.outbox, bytearray()
        return data

    def unsent(self, conn: int, rest: bytearray) -> None:
        """``rest``, the end of what ``data_to_send`` gave that the socket did not take, waits again in front of
        newer answers; it counts against CONTROL_OUTBOX_MAX."""
        client = self.clients.get(conn)
        if client is not None and rest:
            if client.outbox:
                client.outbox[:0] = rest
            else:
                client.outbox = rest

    def output_bytes(self, conn: int) -> int:
        """Answer bytes of connection ``conn`` waiting to be sent."""
        client = self.clients.get(conn)
        return 0 if client is None else len(client.outbox)

    def finished(self, conn: int) -> bool:
        """True when connection ``conn`` is to be closed now: the protocol ended it and its last answer is out
        (or it is unknown)."""
        client = self.clients.get(conn)
        return client is None or (client.closing and not client.outbox)

    def closing(self, conn: int) -> bool:
        """True when the protocol ends connection ``conn`` once its answers are out: it reads no more of it."""
        client = self.clients.get(conn)
        return client is None or client.closing

    # ---- turns --------------------------------------------------------------------------------
    def turn(self, conn: int, execute: Callable[[bytes], dict], flush: Callable[[int], bool]) -> str:
        """One turn of connection ``conn``: at most CONTROL_TURN_REQUESTS requests answered, and none more once
        this turn's answers reach CONTROL_TURN_BYTES (a turn is bounded in work: 15 clients each sending 64 KiB
        of requests must not hold the robots' servers); a ``Streamed`` answer is encoded CONTROL_TURN_PIECES
        pieces a turn. ``execute(line)`` answers one request line (never raises); ``flush(conn)`` is called
        after each answer is queued, to write what the socket takes (False: the connection is gone). A line
        longer than CONTROL_LINE_MAX is answered and ends the client; so does more than CONTROL_OUTBOX_MAX bytes
        of unread answers. Returns INPUT_DONE, INPUT_LEFT (call again in a later turn) or CLOSED."""
        client = self.clients.get(conn)
        if client is None:
            return CLOSED
        if client.encoding is not None and not self._encode_more(client, flush):
            return INPUT_LEFT
        answered = written = 0
        while not client.closing:
            line, used = next_line(client.rbuf)
            if line is None:                    # no complete line yet (used == 0)
                if len(client.rbuf) > CONTROL_LINE_MAX:
                    client.closing = True
                    self.log("control_closed", reason="request line too long")
                    self._answer(client, error_answer(LINE_TOO_LONG), flush)
                break
            if answered >= CONTROL_TURN_REQUESTS or written >= CONTROL_TURN_BYTES:
                return INPUT_LEFT
            del client.rbuf[:used]
            if len(line) > CONTROL_LINE_MAX:
                client.closing = True
                self.log("control_closed", reason="request line too long")
                answer = error_answer(LINE_TOO_LONG)
            else:
                answer = execute(line)
            before = len(client.outbox)
            if type(answer) is Streamed:
                if not self._outbox_room(client):
                    return CLOSED
                client.encoding = _PIECES.iterencode(answer)
                if not self._encode_more(client, flush):
                    return INPUT_LEFT
            elif not self._answer(client, answer, flush):
                return CLOSED
            answered += 1
            written += max(0, len(client.outbox) - before) or 1
        return CLOSED if client.closing and not client.outbox else INPUT_DONE

    def _outbox_room(self, client: _Client) -> bool:
        """False (and the client ended) when CONTROL_OUTBOX_MAX bytes of earlier answers are still unsent."""
        if len(client.outbox) > CONTROL_OUTBOX_MAX:
            self.clients.pop(client.conn, None)
            self.log("control_closed",
                     reason=f"client does not read its answers (more than {CONTROL_OUTBOX_MAX} bytes waiting)")
            return False
        return True

    def _answer(self, client: _Client, answer: dict, flush: Callable[[int], bool]) -> bool:
        """Queue one answer and flush; False when the client is gone. A client is ended when CONTROL_OUTBOX_MAX
        bytes of earlier answers are still unsent (one answer may be larger)."""
        if not self._outbox_room(client):
            return False
        try:
            client.outbox += encode_answer(answer)
        except ValueError as exc:           # e.g. a value JSON cannot carry
            client.outbox += encode_answer(error_answer(f"the answer cannot be written as JSON ({exc})"))
        return flush(client.conn)

    def _encode_more(self, client: _Client, flush: Callable[[int], bool]) -> bool:
        """Encode the next pieces of a large answer: at most CONTROL_TURN_PIECES pieces and about
        CONTROL_TURN_BYTES characters a turn. True when the answer is complete, queued whole and flushed; False
        when the rest waits for the client's next turn (or the client is gone)."""
        assert client.encoding is not None
        size = 0
        try:
            for _ in range(CONTROL_TURN_PIECES):
                piece = next(client.encoding, None)
                if piece is None:
                    client.outbox += ("".join(client.pieces) + "\n").encode("utf-8")
                    break
                client.pieces.append(piece)
                size += len(piece)
                if size >= CONTROL_TURN_BYTES:
                    return False
            else:
                return False
        except ValueError as exc:           # e.g. a value JSON cannot carry
            client.outbox += encode_answer(error_answer(f"the answer cannot be written as JSON ({exc})"))
        client.encoding, client.pieces = None, []
        return flush(client.conn)
