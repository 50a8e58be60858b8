"""Ethernet Slave session of one robot ($TMSVR): a sans-I/O state machine (frames and time in, frames out).

TMscript 2.24 chapter 17. Data of a $TMSVR packet is ``TransactionID , Mode , Content`` (§17.4):

    mode 1 / 2 / 3     client writes items (binary / string / JSON); the server answers in mode 0
    mode 11 / 12 / 13  client reads items; the server answers in the same mode, or in mode 0 on failure
    mode 0             server status ``ID,0,EE,Text`` with EE 00..07 (§17.4.1)

The server also sends the configured data table to every client periodically, transaction IDs 0..9 in turn
(§17.4 "ID Transaction Number"). A write is checked in the manual's order (§17.4 "Writing or Reading
Confirmation": mode, write permission, content vs mode, item exists, not read only, M/A mode, value type)
and performed only when every item passes.

``source`` gives the values and performs writes (``tmsim.robot.svr_source.RobotDataSource``): ``values(names)``
-> {name: value}, ``write({name: value})``, ``auto_mode``. The global variables of the robot's project (§17.2
"Global Variable") are items of the session itself: ``declare`` adds one, ``variables`` holds their values.
The events go to the ``log`` callback the session was built with (the server's event log); built without one,
it keeps them for ``events()`` (tmsim/protocol/port_events.py).
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from tmsim.protocol import codec
from tmsim.protocol import svr_table as table
from tmsim.protocol.port_events import EventPort
from tmsim.protocol.svr_table import ITEMS, Item, SvrContentError, SvrValueError

if TYPE_CHECKING:
    from tmsim.robot.svr_source import RobotDataSource

HEADERS = frozenset({"TMSVR"})

# §17.4.1 status codes and their texts
OK, NOT_SUPPORT, WRITE_PERMISSION, INVALID_DATA, NOT_EXIST, READ_ONLY, MODE_ERROR, VALUE_ERROR = range(8)
STATUS_TEXT = ("OK", "NotSupport", "WritePermission", "InvalidData", "NotExist", "ReadOnly", "ModeError",
               "ValueError")

WRITE_MODES = {1: "binary", 2: "string", 3: "json"}
READ_MODES = {11: "binary", 12: "string", 13: "json"}

# The data table streamed by default: every item the official Techman ROS driver requires
# (tmr_ros2 tm_robot_state.cpp, TmDataTable), then the status items the PLC library reads.
DEFAULT_STREAM = (
    "Robot_Link", "Robot_Error", "Project_Run", "Project_Pause", "Safeguard_A", "ESTOP", "Camera_Light",
    "Error_Code", "Joint_Angle", "Coord_Robot_Flange", "Coord_Robot_Tool", "TCP_Force", "TCP_Force3D",
    "TCP_Speed", "TCP_Speed3D", "Joint_Speed", "Joint_Torque", "Project_Speed", "MA_Mode", "Robot_Light",
    *(f"Ctrl_DO{i}" for i in range(8)), *(f"Ctrl_DI{i}" for i in range(8)), "Ctrl_AO0", "Ctrl_AI0",
    *(f"End_DO{i}" for i in range(4)), *(f"End_DI{i}" for i in range(3)), "End_AI0",
    "Coord_Base_Tool", "Operation_Mode", "Robot_State", "Error_Content",
)


# fault injection (docs/simulator.md); clear_faults() ends them
FAULTS = ("stall", "corrupt_checksum", "disconnect", "refuse_writes", "answer_other_item")


class SvrConfigError(ValueError):
    """A stream configuration the simulator cannot serve (unknown item, mode, period)."""


@dataclass
class Client:
    peer: str
    outbox: list = field(default_factory=list)
    rbuf: bytearray = field(default_factory=bytearray)      # received bytes of an incomplete frame


class SvrSession(EventPort):
    def __init__(self, source: RobotDataSource, log: Callable[..., None] | None = None,
                 stream_items: Iterable[str] = DEFAULT_STREAM, stream_mode: int = 1, period: float = 0.1,
                 write_permission: bool = True, variables: Iterable = ()):
        self.source = source
        super().__init__(log)
        self.items: dict[str, Item] = dict(ITEMS)   # the predefined items and the declared global variables
        self.variables: dict[str, object] = {}      # value of every declared global variable
        for variable in variables:
            self.declare(*((variable,) if isinstance(variable, Item) else variable))
        self.clients: dict[int, Client] = {}
        self.now = 0.0
        self.write_permission = write_permission   # §17.1 IP filter "Write Permission" of the clients
        self.stream_items: list[str] = []           # the streamed data table, set by configure
        self.stream_mode = 1
        self.period = 0.0
        self.configure(stream_items, stream_mode, period)
        self.next_stream = 0.0
        self.stream_id = 0
        self.stalled = False      # fault "stall": no data table, requests read and dropped unanswered
        self.corrupt = 0          # fault "corrupt_checksum": this many more frames leave with a wrong checksum
        self.refuse = 0           # fault "refuse_writes": every well-formed write is answered with this status
        self.swap: tuple[str, str] | None = None   # fault "answer_other_item": (item, the item sent in its place)

    def configure(self, items: Iterable[str] | None = None, mode: int | None = None, period: float | None = None,
                  write_permission: bool | None = None) -> None:
        """Set the streamed data table (TransmitFile, §17.2): items in order, mode 1/2/3, period in s (0 = off);
        ``write_permission`` False refuses every write (status 02). None keeps what is set."""
        items = list(self.stream_items if items is None else items)
        mode = self.stream_mode if mode is None else mode
        period = self.period if period is None else period
        unknown = [name for name in items if name not in self.items]
        if unknown:
            raise SvrConfigError(f"unknown data table item(s): {', '.join(unknown)}")
        if mode not in WRITE_MODES:
            raise SvrConfigError(f"stream mode must be 1 (binary), 2 (string) or 3 (JSON), got {mode}")
        if not 0 <= period <= 3600:
            raise SvrConfigError(f"stream period must be 0 (off) .. 3600 s, got {period:g}")
        if "Robot_Link" in items:                       # §17.2: always there, first
            items.remove("Robot_Link")
        self.stream_items = ["Robot_Link", *dict.fromkeys(items)]
        self.stream_mode, self.period = mode, period
        if write_permission is not None:
            self.write_permission = bool(write_permission)

    def config(self) -> dict:
        """What ``configure`` set: the streamed items in order, the mode, the period and the write permission."""
        return {"items": self.stream_items, "mode": self.stream_mode, "period": self.period,
                "write_permission": self.write_permission}

    def declare(self, item: Item, value: Any = None) -> None:
        """Add (or redeclare) a global variable of the robot's project (``svr_table.variable_item`` /
        ``parse_variable``); ``value`` None = zeros / empty texts. SvrConfigError names what is wrong."""
        if not isinstance(item, Item) or item.name in ITEMS:
            raise SvrConfigError(f"not a global variable: {getattr(item, 'name', item)!r}")
        try:
            value = table.check_value(item, table.default_value(item) if value is None else value)
        except SvrValueError as exc:
            raise SvrConfigError(f"global variable {item.name}: {exc}") from None
        self.items[item.name] = item
        self.variables[item.name] = value
        self.log("svr_variable", name=item.name, type=item.type, size=item.size, writable=item.writable)

    # ---- connections --------------------------------------------------------------------------
    def connect(self, conn: int, peer: str = "127.0.0.1") -> None:
        self.clients[conn] = Client(peer)
        self.log("svr_connect", conn=conn, peer=peer)

    def disconnect(self, conn: int) -> None:
        if self.clients.pop(conn, None) is not None:
            self.log("svr_disconnect", conn=conn)

    def receive_data(self, conn: int, data: bytes) -> None:
        """Bytes received from connection ``conn``: every complete item in them (and in what an earlier call left
        incomplete) is handled at once; a partial frame waits in the session's buffer of that connection (at most
        one frame: a longer declared length is a packet error at once, codec.decode)."""
        client = self.clients.get(conn)
        if client is None:
            return
        client.rbuf += data
        for item in codec.decode_all(client.rbuf, HEADERS):
            self.handle(conn, item)

    def data_to_send(self, conn: int) -> list[bytes]:
        """The frames for connection ``conn`` produced so far (one bytes object per frame); the session forgets
        them."""
        client = self.clients.get(conn)
        if client is None or not client.outbox:
            return []
        frames, client.outbox = client.outbox, []
        return frames

    def has_output(self, conn: int) -> bool:
        client = self.clients.get(conn)
        return client is not None and bool(client.outbox)

    # ---- faults -------------------------------------------------------------------------------
    def inject(self, fault: str, **params: Any) -> None:
        """``stall`` (enabled=True): no data table and no answers, connections stay open; ``corrupt_checksum``
        (count=1): the next frames leave with a wrong checksum; ``refuse_writes`` (status=6): every well-formed
        write is answered with that status code (1..7), nothing is written; ``answer_other_item`` (item, instead):
        every frame that would carry ``item`` (a read's answer, the data table) carries ``instead``, its name and
        value, in its place. (``disconnect`` closes sockets: the TCP adapter's.) ValueError naming what is unknown
        or out of range."""
        if fault not in FAULTS:
            raise ValueError(f"unknown Ethernet Slave fault '{fault}'; known: {', '.join(FAULTS)}")
        unknown = set(params) - {"stall": {"enabled"}, "corrupt_checksum": {"count"}, "disconnect": set(),
                                 "refuse_writes": {"status"}, "answer_other_item": {"item", "instead"}}[fault]
        if unknown:
            raise ValueError(f"Ethernet Slave fault '{fault}' has no parameter {', '.join(sorted(unknown))}")
        if fault == "stall":
            self.stalled = bool(params.get("enabled", True))
        elif fault == "corrupt_checksum":
            count = params.get("count", 1)
            if type(count) is not int or not 1 <= count <= 1_000_000:
                raise ValueError(f"'count' of fault 'corrupt_checksum' must be 1..1000000, got {count!r}")
            self.corrupt += count
        elif fault == "refuse_writes":
            status = params.get("status", 6)
            if type(status) is not int or not 1 <= status <= 7:
                raise ValueError(f"'status' of fault 'refuse_writes' must be 1..7 (a §17.4.1 code), got {status!r}")
            self.refuse = status
        elif fault == "answer_other_item":
            for key in ("item", "instead"):
                name = params.get(key)
                if not isinstance(name, str) or name not in self.items:
                    raise ValueError(f"'{key}' of fault 'answer_other_item' must name an item or a declared "
                                     f"variable, got {params.get(key)!r}")
            self.swap = (params["item"], params["instead"])

    def clear_faults(self) -> None:
        self.stalled, self.corrupt, self.refuse, self.swap = False, 0, 0, None

    def _send(self, conn, data):
        self._out(conn, codec.encode("TMSVR", data))

    def _out(self, conn, frame):
        client = self.clients.get(conn)
        if client is not None:
            client.outbox.append(self._damage(frame) if self.corrupt else frame)

    def _damage(self, frame):
        """Fault ``corrupt_checksum``: the frame's checksum digits inverted (a real checksum error)."""
        self.corrupt -= 1
        digits = "%02X" % (int(frame[-4:-2], 16) ^ 0xFF)
        return frame[:-4] + digits.encode() + b"\r\n"

    def _status(self, conn, ident, code, item=None):
        text = STATUS_TEXT[code] + (f";{item}" if item is not None else "")
        self._send(conn, f"{ident},0,{code:02d},{text}")
        if code != OK:
            self.log("svr_status", conn=conn, id=ident, code=f"{code:02d}", text=text)

    # ---- time ---------------------------------------------------------------------------------
    def advance(self, now: float) -> None:
        """Send the data table to every client when a period is due (one frame, however late we are)."""
        self.now = max(self.now, now)
        if not self.period or not self.clients or self.now < self.next_stream or self.stalled:
            return
        self.next_stream = max(self.next_stream + self.period, self.now)
        if self.next_stream <= self.now:
            self.next_stream = self.now + self.period
        frame = codec.encode("TMSVR", f"{self.stream_id},{self.stream_mode},".encode()
                             + self._content(self.stream_mode, self.stream_items))
        self.stream_id = (self.stream_id + 1) % 10
        for conn in self.clients:
            self._out(conn, frame)

    def next_due(self, now: float) -> float | None:
        """The robot-clock time the next data table is due (``advance`` sends it then); None while none is streamed
        (period 0, no client, or the fault ``stall``)."""
        if not self.period or not self.clients or self.stalled:
            return None
        return max(now, self.next_stream)

    def _content(self, mode, names) -> bytes:
        if self.swap is not None:
            asked, instead = self.swap
            names = [instead if name == asked else name for name in names]
        variables = self.variables
        values = self.source.values([name for name in names if name not in variables]) if variables else \
            self.source.values(names)
        pairs = [(self.items[name], variables[name] if name in variables else values[name]) for name in names]
        kind = WRITE_MODES.get(mode) or READ_MODES[mode]
        if kind == "binary":
            return table.encode_binary(pairs)
        if kind == "string":
            return table.encode_string(pairs).encode("utf-8")
        return table.encode_json(pairs).encode("utf-8")

    # ---- input --------------------------------------------------------------------------------
    def handle(self, conn: int, item: codec.Frame | codec.BadFrame | codec.Garbage) -> None:
        """One decoded item (codec.Frame / BadFrame / Garbage, decoded with HEADERS) from ``conn``."""
        if self.stalled:
            self.log("svr_stalled", conn=conn, bytes=len(item.raw))
        elif isinstance(item, codec.Garbage):
            self.log("svr_garbage", conn=conn, bytes=len(item.raw))
        elif isinstance(item, codec.BadFrame):
            self.log("svr_bad_frame", conn=conn, code=item.code, reason=item.reason)
            self._send_cperr(conn, item.code)
        else:
            self._tmsvr(conn, item.data)

    def _send_cperr(self, conn, code):
        self._out(conn, codec.encode("CPERR", code))

    def _tmsvr(self, conn, data: bytes):
        raw_ident, comma1, rest = data.partition(b",")
        mode_field, comma2, content = rest.partition(b",")
        if not comma1 or not raw_ident.isalnum() or not raw_ident.isascii():
            self.log("svr_bad_frame", conn=conn, code=codec.CPERR_DATA, reason="transaction ID is not alphanumeric")
            self._send_cperr(conn, codec.CPERR_DATA)          # §17.4 "ID": CPERR 04 for a non-alphanumeric byte
            return
        ident = raw_ident.decode("ascii")
        mode = int(mode_field) if mode_field.isdigit() and len(mode_field) <= 3 else None
        if not comma2 or (mode not in WRITE_MODES and mode not in READ_MODES):
            self._status(conn, ident, NOT_SUPPORT)
            return
        if mode in WRITE_MODES:
            self._write(conn, ident, mode, content)
        else:
            self._read(conn, ident, mode, content)

    def _pairs(self, kind, content, with_values):
        if kind == "binary":
            return table.split_binary(content, with_values)
        try:
            text = content.decode("utf-8")
        except UnicodeDecodeError:
            raise SvrContentError("the content is not UTF-8 text") from None
        return (table.split_string if kind == "string" else table.split_json)(text, with_values)

    def _read(self, conn, ident, mode, content):
        try:
            names = [name for name, _ in self._pairs(READ_MODES[mode], content, False)]
        except SvrContentError as exc:
            self.log("svr_invalid", conn=conn, id=ident, reason=str(exc))
            self._status(conn, ident, INVALID_DATA)
            return
        for name in names:
            if name not in self.items:
                self._status(conn, ident, NOT_EXIST, name)
                return
        self.log("svr_read", conn=conn, id=ident, mode=mode, items=names)
        self._send(conn, f"{ident},{mode},".encode() + self._content(mode, names))

    def _write(self, conn, ident, mode, content):
        if not self.write_permission:
            self._status(conn, ident, WRITE_PERMISSION)
            return
        kind = WRITE_MODES[mode]
        try:
            pairs = self._pairs(kind, content, True)
        except SvrContentError as exc:
            self.log("svr_invalid", conn=conn, id=ident, reason=str(exc))
            self._status(conn, ident, INVALID_DATA)
            return
        if self.refuse:
            self._status(conn, ident, self.refuse, pairs[0][0] if self.refuse >= NOT_EXIST and pairs else None)
            return
        checks = ((NOT_EXIST, lambda item: item is None),
                  (READ_ONLY, lambda item: not item.writable),
                  (MODE_ERROR, lambda item: item.writable == "A" and not self.source.auto_mode))
        for code, failed in checks:
            for name, _ in pairs:
                if failed(self.items.get(name)):
                    self._status(conn, ident, code, name)
                    return
        values = {}
        for name, raw in pairs:
            item = self.items[name]
            try:
                if kind == "binary":
                    value = table.decode_binary_value(item, raw)
                elif kind == "string":
                    value = table.parse_string_value(item, raw)
                else:
                    value = raw
                values[name] = table.check_value(item, value)
            except SvrValueError as exc:
                self.log("svr_invalid", conn=conn, id=ident, reason=str(exc))
                self._status(conn, ident, VALUE_ERROR, name)
                return
        self.log("svr_write", conn=conn, id=ident, mode=mode, items=values)
        self._status(conn, ident, OK)
        items = {}
        for name, value in values.items():
            if name in self.variables:
                self.variables[name] = value
            else:
                items[name] = value
        if items:
            self.source.write(items)
