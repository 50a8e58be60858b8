"""Listen-node protocol of one robot: the bytes side of the Listen node, sans-I/O (bytes in, frames out).

It owns what each client sent and what each client is to get: the receive buffers, the frame decoding, the
CPERR limit on bad packets (CPERR_BURST at once, then CPERR_PER_S per second of robot clock; the others are
counted and reported as event ``cperr_suppressed``), the outboxes, and the events ``connect``, ``disconnect``,
``frame_in`` and ``frame_out``. Every decoded item goes to the Listen node (``ListenSession.handle``, TMscript
2.24 §15: scripts, status queries, the node's CPERR answers); what the node answers comes back through
``send`` / ``push``. The node owns the clock and the work meter; the protocol reads them (``Node``).

A server calls ``connect`` / ``receive_data(conn, bytes)`` / ``disconnect`` and takes ``data_to_send(conn)``
(one bytes object per frame, so each goes out in one send). A server that shares its input fairly between
clients (tmsim/net/fairness.py) calls ``buffer_data`` and then ``turn(conn, budget)`` in bounded turns (a
``TurnBudget`` of tmsim/limits.py) instead of ``receive_data``. The events go to the ``log`` callback the
protocol was built with (the server's event log); built without one, it keeps them for ``events()``
(tmsim/protocol/port_events.py). ``configure(cperr_burst=..., cperr_per_s=...)`` sets the CPERR limit of its
clients.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from tmsim.limits import CPERR_BURST, CPERR_PER_S, CPERR_SETTING_MAX, RECEIVE_TURN, TurnBudget
from tmsim.protocol import codec
from tmsim.protocol.clients import Clients
from tmsim.protocol.port_events import EventPort
from tmsim.robot.eventlog import text as _text
from tmsim.tmscript.work import WorkMeter

# outcome of one turn of a connection's input (``turn``)
INPUT_DONE = "done"                 # no complete item is left in the receive buffer
INPUT_LEFT = "left"                 # a bound of the turn ended it: input may be left for the next turn
FRAME_LIMIT = "frame_limit"         # the connection's received frames reached the budget's ``frame_limit``

# configure(): setting -> (lowest, highest), integers
PROTOCOL_SETTINGS = {"cperr_burst": (1, CPERR_SETTING_MAX), "cperr_per_s": (0, CPERR_SETTING_MAX)}


def check_settings(port: str, settings: dict[str, Any], ranges: dict[str, tuple[int, int]]) -> dict[str, int]:
    """``settings`` checked against ``ranges`` (name -> (lowest, highest), integers); ValueError naming the
    first unknown setting or value out of its range, with what is allowed."""
    for name, value in settings.items():
        if name not in ranges:
            raise ValueError(f"unknown setting '{name}' of the {port}; known: {', '.join(ranges)}")
        low, high = ranges[name]
        if type(value) is not int or not low <= value <= high:
            raise ValueError(f"setting '{name}' of the {port} must be an integer {low}..{high}, got {value!r}")
    return dict(settings)


# a frame queued for a client: (the frame's bytes, its header, its data as given to the codec)
Outgoing = tuple[bytes, str, bytes | str]


def outgoing(header: str, data: bytes | str) -> Outgoing:
    """The frame ``header``/``data`` as the outboxes keep it."""
    return codec.encode(header, data), header, data


@dataclass
class Client:
    peer: str
    cperr_at: float                     # robot clock of the last refill of ``cperr_tokens``
    cperr_tokens: float = float(CPERR_BURST)        # CPERR answers to bad packets still allowed (a bucket)
    suppressed: int = 0                 # bad packets not answered since the last ``cperr_suppressed`` event
    frames_in: int = 0                  # well-formed frames received
    outbox: list[Outgoing] = field(default_factory=list)    # frames not handed out yet (``data_to_send``)
    rbuf: bytearray = field(default_factory=bytearray)      # bytes received and not processed yet


class Node(Protocol):
    """What the protocol needs of the Listen node it serves."""
    now: float                          # the robot clock
    meter: WorkMeter                    # the work of the current turn

    @property
    def waiting_scripts(self) -> int:
        """Scripts received and not started yet."""
        ...

    def handle(self, conn: int, item: codec.Frame | codec.BadFrame | codec.Garbage) -> None:
        """One decoded item of connection ``conn``."""
        ...


class ListenProtocol(EventPort):
    """The clients of one robot's Listen node and their bytes (see the module docstring)."""

    def __init__(self, node: Node, log: Callable[..., None] | None = None):
        super().__init__(log)
        self._node = node
        self.clients: Clients[Client] = Clients()
        self.cperr_burst = CPERR_BURST      # CPERR answers to bad packets a client gets at once ...
        self.cperr_per_s = CPERR_PER_S      # ... then at most this many per second of robot clock

    # ---- events and settings ------------------------------------------------------------------
    def configure(self, **settings: Any) -> None:
        """Set the CPERR limit on bad packets: ``cperr_burst`` (1..CPERR_SETTING_MAX) answers at once, then
        ``cperr_per_s`` (0..CPERR_SETTING_MAX) per second of robot clock; a connected client keeps the answers it
        has left (at most the new burst). ValueError naming an unknown setting or a value out of its range;
        nothing changes then."""
        checked = check_settings("Listen node protocol", settings, PROTOCOL_SETTINGS)
        if "cperr_burst" in checked:
            self.cperr_burst = checked["cperr_burst"]
            for client in self.clients.values():
                client.cperr_tokens = min(client.cperr_tokens, float(self.cperr_burst))
        if "cperr_per_s" in checked:
            self.cperr_per_s = checked["cperr_per_s"]

    def config(self) -> dict[str, Any]:
        """What ``configure`` set."""
        return {"cperr_burst": self.cperr_burst, "cperr_per_s": self.cperr_per_s}

    # ---- connections --------------------------------------------------------------------------
    def connect(self, conn: int, peer: str = "127.0.0.1") -> None:
        self.clients[conn] = Client(peer, self._node.now, float(self.cperr_burst))
        self.log("connect", conn=conn, peer=peer)

    def disconnect(self, conn: int) -> None:
        client = self.clients.pop(conn, None)
        if client is not None:
            if client.suppressed:
                self.log("cperr_suppressed", conn=conn, count=client.suppressed)
            self.log("disconnect", conn=conn)

    def is_connected(self, conn: int) -> bool:
        return conn in self.clients

    # ---- output -------------------------------------------------------------------------------
    def send(self, conn: int, header: str, data: bytes | str) -> None:
        """Queue the frame ``header``/``data`` for connection ``conn`` (unknown connection: nothing)."""
        client = self.clients.get(conn)
        if client is not None:
            client.outbox.append((codec.encode(header, data), header, data))     # (outgoing(), inlined)

    def push(self, out: Outgoing, ip_filter: str | None = None) -> int:
        """Queue the frame ``out`` for every client (of address ``ip_filter``); returns how many get it."""
        count = 0
        for client in self.clients.values():
            if ip_filter is None or client.peer == ip_filter:
                client.outbox.append(out)
                count += 1
        return count

    def data_to_send(self, conn: int) -> list[bytes]:
        """The frames for connection ``conn`` produced so far (one bytes object per frame, so each can go out
        in one send); the protocol forgets them and logs each as event ``frame_out`` (its header and data as
        the node gave them: nobody parses the frames it sends)."""
        client = self.clients.get(conn)
        if client is None or not client.outbox:
            return []
        queued, client.outbox = client.outbox, []
        log = self.log
        for frame, header, data in queued:
            log("frame_out", conn=conn, raw=_text(frame), header=header,
                data=data if isinstance(data, str) else _text(data))
        return [out[0] for out in queued]

    def has_output(self) -> bool:
        """True when a frame for some client is waiting in data_to_send."""
        for client in self.clients.values():  # noqa: SIM110 - asked at every poll: a loop costs half of any()
            if client.outbox:
                return True
        return False

    # ---- input --------------------------------------------------------------------------------
    def receive_data(self, conn: int, data: bytes) -> int:
        """Bytes received from connection ``conn``: every complete item in them (and in what an earlier call
        left incomplete) is processed at once; returns the number of items handled (bad packets beyond the
        CPERR limit are not). A partial frame waits in the buffer of that connection for the next call."""
        if conn not in self.clients:
            return 0
        self.buffer_data(conn, data)
        total = 0
        while True:
            handled, outcome = self.turn(conn, RECEIVE_TURN)
            total += handled
            if outcome != INPUT_LEFT:
                return total

    def buffer_data(self, conn: int, data: bytes) -> None:
        """Bytes received from connection ``conn``, kept for ``turn`` (unknown connection: ignored)."""
        self.clients.buffer_data(conn, data)

    def input_bytes(self, conn: int) -> int:
        """Bytes of connection ``conn`` received and not processed yet."""
        return self.clients.input_bytes(conn)

    def unanswered_bad(self, conn: int) -> int:
        """Bad packets of connection ``conn`` not answered (CPERR limit) and not logged yet."""
        client = self.clients.get(conn)
        return 0 if client is None else client.suppressed

    def turn(self, conn: int, budget: TurnBudget) -> tuple[int, str]:
        """One turn of connection ``conn``'s buffered input within ``budget`` (tmsim/limits.py TurnBudget): at
        most ``budget.decoded`` items decoded and ``budget.items`` of them handled; the turn also ends once
        ``budget.waiting`` scripts wait to start, when the turn's work is spent, or right after the item that
        brings the connection's received frames to ``budget.frame_limit``. Returns (items handled, INPUT_DONE |
        INPUT_LEFT | FRAME_LIMIT). Bad packets are answered with CPERR at most CPERR_BURST at once, then
        CPERR_PER_S per second of robot clock; the others are counted (event ``cperr_suppressed`` before the
        next item handled, or at ``disconnect``)."""
        node = self._node
        meter = node.meter
        if budget.work is not None:
            meter.begin(budget.work)
        client = self.clients.get(conn)
        if client is None:
            return 0, INPUT_DONE
        max_items, max_waiting, frame_limit = budget.items, budget.waiting, budget.frame_limit
        rbuf, handled = client.rbuf, 0
        for _ in range(budget.decoded):
            if rbuf[:2] == b"$$" and self._cperr_tokens(client) < 1.0:
                # a '$' followed by another '$' is always a bad packet (header missing, CPERR 01): a run of
                # them that gets no answer anyway is skipped at once
                run = len(rbuf) - len(rbuf.lstrip(b"$")) - 1
                del rbuf[:run]
                client.suppressed += run
                continue
            item, used = codec.decode(rbuf)
            if item is None:                    # need more bytes (decode consumed none)
                return handled, INPUT_DONE
            del rbuf[:used]
            if type(item) is codec.BadFrame and not self._may_answer_bad(client):
                client.suppressed += 1
                continue
            if client.suppressed:
                self.log("cperr_suppressed", conn=conn, count=client.suppressed)
                client.suppressed = 0
            if type(item) is codec.Frame:
                client.frames_in += 1
                self.log("frame_in", conn=conn, raw=_text(item.raw), header=item.header, data=_text(item.data))
            node.handle(conn, item)
            handled += 1
            if frame_limit is not None and client.frames_in >= frame_limit:
                return handled, FRAME_LIMIT
            if handled >= max_items or (max_waiting is not None and node.waiting_scripts >= max_waiting) or \
                    meter.spent:
                return handled, INPUT_LEFT
        return handled, INPUT_LEFT

    def _cperr_tokens(self, client: Client) -> float:
        """Token bucket of CPERR answers to bad packets: ``cperr_burst`` at once (CPERR_BURST unless configured),
        ``cperr_per_s`` per second (CPERR_PER_S)."""
        now = self._node.now
        client.cperr_tokens = min(self.cperr_burst, client.cperr_tokens + (now - client.cperr_at) * self.cperr_per_s)
        client.cperr_at = now
        return client.cperr_tokens

    def _may_answer_bad(self, client: Client) -> bool:
        if self._cperr_tokens(client) < 1.0:
            return False
        client.cperr_tokens -= 1.0
        return True
