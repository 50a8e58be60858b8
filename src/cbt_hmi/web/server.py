"""Web HMI server: serves cbt_hmi/pages/ and a JSON API over the PLC-HMI variable table (pages/mapping.json).

The browser is not trusted. Every request must address this server (Host); every write must come from the
HMI's own pages, as JSON, with an access key whose role may change that variable (cbt_hmi.web.access). Every
write names a variable of the mapping file, is checked against its type and range here again, and reaches the
PLC only through Contract A (plc.write under plc.lock), all values or none. Reads are limited to mapped
variables too.

API (all answers are JSON objects with "ok"):
  GET  /api/mapping                         the variable table (types, ranges, enumerations, roles)
  GET  /api/session                         {"ok", "role"}: the role the request's X-HMI-Key grants
  GET  /api/read?names=A,B.C,...            {"ok", "time_ns", "clock", "plc": "run"|"fault", ["fault",] "alarms",
                                            "robot", "values": {...}}: "alarms" changes with the alarm list
  GET  /api/stream?names=A,B.C,...          the same answer every STREAM_PERIOD_S on one connection, one JSON
                                            object a line (application/x-ndjson), until the client leaves
  GET  /api/alarms[?history=N]              the alarm list and the newest N history entries (cbt_hmi.web.alarms)
  POST /api/alarms/ack {"alarms": [n, ...]} | {"all": true}   acknowledge (operator or engineer)
  GET  /api/program[/state?pou=NAME]        ladder drawings and their live power flow (cbt_hmi.web.program)
  POST /api/write   {"values": {path: v}}   validate all, then write all in one scan gap
  POST /api/execute {"execute": "X_Execute", "values": {path: v}}
                                            validate, write the values and Execute := FALSE, wait for one
                                            PLC scan, then Execute := TRUE (a clean rising edge per press)

One thread reads every request without blocking, each within its deadlines (header, body), answers complete
reads itself and passes complete writes to a bounded pool of workers; connections are limited per client
address and in all, and the longest-waiting one makes room for a new one (cbt_hmi.web.front), so slow or idle
clients cannot lock the operator out. After a major fault of the PLC every answer says so (/api/read:
"plc": "fault") and writes are refused.
"""
from __future__ import annotations

import argparse
import io
import json
import logging
import mimetypes
import pathlib
import re
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, urlsplit

from .access import AccessDenied, AccessPolicy, role_at_least
from .alarms import HISTORY, AlarmSystem, plc_fault, stamp
from .assets import NEVER_KEPT, SHELL, Assets, asked_version
from .front import MAX_BODY, HttpFront, HttpLimits, Stream
from .mapping import HMI_DIR, Leaf, Mapping, RequestError, format_dt, jsonable, validate
from .trail import Trail

if TYPE_CHECKING:
    from .program import ProgramMonitor

MAX_DIGITS = 40                    # digits of one number in a request body (a LINT has 19, an LREAL 17)
MAX_NAMES = 400
SCAN_WAIT_S = 1.0
STREAM_PERIOD_S = 0.05             # /api/stream: a new answer every 50 ms, the pages' 20 updates a second
# What a page may load and run (W3C Content Security Policy Level 3): scripts only from the HMI's own files, none
# written into the page (an onerror= in a text that reached the HTML is not run), styles also as style attributes,
# images also as data: addresses (the shell's empty icon), nothing framed, no forms or links to other servers.
CONTENT_SECURITY_POLICY = ("default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
                           "img-src 'self' data:; object-src 'none'; base-uri 'none'; form-action 'self'; "
                           "frame-ancestors 'none'")

log = logging.getLogger("cbt_hmi.web")

_POINT_NUMBER = re.compile(r"[0-9]{1,18}")       # /api/trail?since=N: ASCII digits, within an int64
_HISTORY_COUNT = re.compile(r"[0-9]{1,6}")        # /api/alarms?history=N


def _number_digits(text: str) -> str:
    """A JSON number as the decoder found it, refused beyond MAX_DIGITS digits (before Python converts it:
    a 5,000-digit integer once answered with Python's own limit text)."""
    mantissa = text.partition("e")[0].partition("E")[0]
    if sum(c.isdigit() for c in mantissa) > MAX_DIGITS:
        raise RequestError(f"a number in the request has more than {MAX_DIGITS} digits")
    return text


def _line(answer: dict) -> bytes:
    """One answer of /api/stream: a JSON object on a line of its own."""
    return json.dumps(answer).encode("utf-8") + b"\n"


def _json_body(raw: bytes):
    """The decoded request body; RequestError saying what is wrong with it."""
    try:
        return json.loads(raw.decode("utf-8"), parse_int=lambda t: int(_number_digits(t)),
                          parse_float=lambda t: float(_number_digits(t)))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RequestError(f"the request body is not valid JSON ({exc})") from None
    except RecursionError:
        raise RequestError("the request body is nested too deeply") from None


# Requests the front-end thread answers itself: they only read (a file, the table, variables under plc.lock for
# microseconds), so a hand-over to a worker would cost more than the answer. Writes, which wait for PLC scans,
# and the Program page, whose first request compiles the ladder drawings, go to the workers.
_ANSWERED_AT_ONCE = (b"GET ", b"HEAD ")
_PROGRAM_PAGE = b"/api/program"


def _answered_at_once(request: bytes) -> bool:
    return request.startswith(_ANSWERED_AT_ONCE) and not request.startswith(_PROGRAM_PAGE, request.find(b" ") + 1)


def host_argument(text: str) -> str:
    """The ``--host`` of a command line (an argparse type): an address to bind. An empty one (a script's unset
    variable) is a usage error: the socket would take every network interface while the start-up line said
    loopback."""
    address = text.strip()
    if not address:
        raise argparse.ArgumentTypeError("an address is needed: 127.0.0.1 for this computer only, 0.0.0.0 for "
                                         "every interface")
    return address


class HmiServer:
    """HTTP server for one PLC. start() binds (port 0 = ephemeral), serves in a thread; stop() ends it."""

    def __init__(self, plc, mapping: Mapping | None = None, host: str = "127.0.0.1", port: int = 8080,
                 root: pathlib.Path = HMI_DIR, access: AccessPolicy | None = None, limits: HttpLimits | None = None,
                 alarm_log: pathlib.Path | str | None = None, clock=time.time):
        self.plc = plc
        self.limits = limits or HttpLimits()
        self.mapping = mapping or Mapping.load()
        self.host = host
        self.requested_port = port
        self.root = pathlib.Path(root).resolve()
        self.assets = Assets(self.root)
        self.access = access or AccessPolicy()
        self._httpd: HttpFront | None = None
        self._thread: threading.Thread | None = None
        self.requests = 0
        self._execute_lock = threading.Lock()
        self.program: ProgramMonitor | None = None     # built at the Program page's first request
        spec = self.mapping.document.get("trail")
        self.trail = Trail(plc, spec["valid"], spec["position"]) if spec else None
        # the alarm list and its history (alarm_log: a JSON-lines file kept across restarts; None: memory only)
        self.clock = clock
        self.alarms = AlarmSystem(plc, self.mapping, alarm_log, clock=clock)

    @property
    def front(self) -> HttpFront | None:
        """The HTTP front end while the server runs (None before start() and after stop()): its listening
        ``socket``, ``open_connections``, ``connections_by_client()`` and the counters ``evicted`` / ``refused``."""
        return self._httpd

    @property
    def port(self) -> int:
        return self._httpd.server_address[1] if self._httpd else self.requested_port

    @property
    def url(self) -> str:
        """The address to open on this machine (a server bound to every interface is reached on loopback)."""
        host = {"0.0.0.0": "127.0.0.1", "::": "[::1]", "": "127.0.0.1"}.get(self.host, self.host)
        return f"http://{host}:{self.port}/"

    def page_url(self, page: str = "index", role: str = "operator") -> str:
        """The address of a page that carries the access key of ``role`` (in the fragment: never sent on)."""
        path = "" if page == "index" else f"{page}.html"
        return f"{self.url}{path}#key={self.access.keys[role]}"

    def start(self) -> None:
        handler = type("BoundHandler", (_Handler,), {"hmi": self})
        self._httpd = HttpFront((self.host, self.requested_port), handler, self.limits, _answered_at_once)
        self.access.bind(self.host, self.port)
        self._thread = threading.Thread(target=self._httpd.serve_forever, name="hmi-http", daemon=True)
        self._thread.start()
        if self.trail is not None:
            self.trail.start()
        self.alarms.start()

    def stop(self) -> None:
        if self.trail is not None:
            self.trail.stop()
        self.alarms.stop()
        if self._httpd:
            self._httpd.shutdown()
            if self._thread is not None:
                self._thread.join(timeout=5)
            self._httpd.server_close()
            self._httpd = None

    # --- operations behind the API -------------------------------------------------------------
    def read(self, names: list[str]) -> dict:
        if not names:
            raise RequestError("give the variables to read: /api/read?names=Name1,Name2")
        if len(names) > MAX_NAMES:
            raise RequestError(f"at most {MAX_NAMES} variables per read")
        unknown = [n for n in names if not self.mapping.is_readable(n)]
        if unknown:
            raise RequestError("not in the HMI variable table: " + ", ".join(unknown[:10]), HTTPStatus.FORBIDDEN)
        with self.plc.lock:
            values = {name: self.plc.read(name) for name in names}
            now = self.plc.now_ns
            fault = plc_fault(self.plc)
        for name in names:
            leaf = self.mapping.leaves.get(name)
            if leaf is not None and leaf.type in ("DATE_AND_TIME", "DT"):
                values[name] = format_dt(values[name])
        answer = {"ok": True, "time_ns": now, "clock": stamp(self.clock()), "plc": "run",
                  "alarms": self.alarms.seq, "robot": self.alarms.robot_state, "values": jsonable(values)}
        if fault is not None:
            # the values are those of the faulted scan's moment: shown, but marked as no longer valid
            answer["plc"], answer["fault"] = "fault", fault
        return answer

    def acknowledge(self, body: dict, role: str) -> dict:
        numbers = body.get("alarms")
        if body.get("all") is True and numbers is None:
            count = self.alarms.acknowledge(None, role)
        elif isinstance(numbers, list) and numbers and all(type(n) is int for n in numbers):
            count = self.alarms.acknowledge(numbers, role)
        else:
            raise RequestError('give the alarms to acknowledge: {"alarms": [number, ...]} or {"all": true}')
        return {"ok": True, "acknowledged": count, "seq": self.alarms.seq}

    def _refuse_when_faulted(self) -> None:
        fault = plc_fault(self.plc)
        if fault is not None:
            raise RequestError(f"the PLC has stopped with a major fault ({fault['what']}): nothing was written; "
                               f"restart the PLC", HTTPStatus.SERVICE_UNAVAILABLE)

    def _checked(self, values, role: str) -> list[tuple[str, object]]:
        if not isinstance(values, dict) or not values:
            raise RequestError('"values" must be a non-empty object {"Variable": value, ...}')
        checked = []
        for path, value in values.items():
            leaf = self._writable(path, role)
            checked.append((path, validate(leaf, value)))
        return checked

    def _writable(self, path, role: str) -> Leaf:
        leaf = self.mapping.leaves.get(path) if isinstance(path, str) else None
        if leaf is None:
            raise RequestError(self.mapping.why_not_a_leaf(path), HTTPStatus.FORBIDDEN)
        if leaf.access != "rw":
            raise RequestError(f"'{path}' is read-only for the HMI", HTTPStatus.FORBIDDEN)
        if not role_at_least(role, leaf.role):
            member = path.rpartition(".")[2]
            why = (" (it would make the robot leave its Listen node)" if member == "ExitNode" else "")
            raise RequestError(f"'{path}' is an engineering setting{why}: the operator may not change it; "
                               f"open the engineer address printed at start-up", HTTPStatus.FORBIDDEN)
        return leaf

    def _refuse_engineering_settings_set(self, name: str) -> None:
        """An engineering setting the engineer left set in the PLC (Exit Listen Node ticked for one move) goes with
        every later Execute of that command: the operator's Execute would leave the Listen node again with a box
        the operator may not untick. Refused (403) before anything is written."""
        paths = self.mapping.execute_settings.get(name, [])
        if not paths:
            return
        with self.plc.lock:
            found = [path for path in paths if self.plc.read(path) is True]
        if found:
            member = found[0].rpartition(".")[2]
            what = "Exit Listen Node is ticked" if member == "ExitNode" else f"'{member}' is set"
            why = " (it would make the robot leave its Listen node)" if member == "ExitNode" else ""
            raise RequestError(f"{what} for this command ('{found[0]}', an engineering setting{why}): the operator "
                               f"may not send it; ask the engineer to clear it. Nothing was sent",
                               HTTPStatus.FORBIDDEN)

    def _write_all(self, checked) -> int:
        """Write every value or none: on a refusal the ones already written get their old values back.

        The caller holds plc.lock, so no scan runs in between and the PLC never sees a partial write."""
        before = []
        try:
            for path, value in checked:
                before.append((path, self.plc.read(path)))
                self.plc.write(path, value)
        except (ValueError, KeyError, TypeError) as exc:
            self._restore(before)
            raise RequestError(f"the PLC refused '{path}': {exc}; nothing was written") from None
        return self.plc.now_ns

    def _restore(self, before) -> None:
        for path, value in reversed(before):
            try:
                self.plc.write(path, value)
            except (ValueError, KeyError, TypeError):
                log.warning("HMI: could not restore %s after a refused write", path)

    def write(self, body: dict, role: str) -> dict:
        checked = self._checked(body.get("values"), role)
        self._refuse_when_faulted()
        with self.plc.lock:
            now = self._write_all(checked)
        return {"ok": True, "time_ns": now}

    def execute(self, body: dict, role: str) -> dict:
        name = body.get("execute")
        leaf = self.mapping.leaves.get(name) if isinstance(name, str) else None
        if leaf is None or not leaf.execute:
            raise RequestError(f'"execute" must name an Execute variable of the table, not {name!r}')
        self._writable(name, role)
        values = body.get("values", {})          # absent or {}: the command alone; [], 0, false: refused
        checked = self._checked(values, role) if values != {} else []
        self._refuse_when_faulted()
        if not role_at_least(role, "engineer"):
            self._refuse_engineering_settings_set(leaf.path)
        # A clean rising edge: every task completes a cycle with Execute FALSE, then one with it TRUE, before
        # the answer goes back. A scan that only advances the clock (no task due) does not count, and
        # Execute requests are taken one at a time, so no command is ever merged with another or lost.
        # All or nothing: nothing is written unless the PLC is scanning, and if it stops scanning before it
        # has seen Execute TRUE, every value goes back to what it was, so a 503 always means "nothing done".
        with self._execute_lock:
            self._await_task_cycles("nothing was written")
            with self.plc.lock:
                before = [(path, self.plc.read(path)) for path, _ in checked + [(name, False)]]
                self._write_all(checked + [(name, False)])
            try:
                self._await_task_cycles("nothing was written")
                with self.plc.lock:
                    now = self._write_all([(name, True)])
                self._await_task_cycles("nothing was written")
            except RequestError:
                with self.plc.lock:
                    self._restore(before)
                raise
        return {"ok": True, "time_ns": now}

    def _await_task_cycles(self, what: str) -> None:
        with self.plc.lock:
            cycles_at = self.plc.task_cycles
        deadline = time.monotonic() + SCAN_WAIT_S
        while not all(now > then for now, then in zip(self.plc.task_cycles, cycles_at, strict=False)):
            if time.monotonic() > deadline:
                self._refuse_when_faulted()          # a fault since the request came: say so, not "not scanning"
                raise RequestError(f"the PLC is not scanning: {what}", HTTPStatus.SERVICE_UNAVAILABLE)
            time.sleep(0.0005)


class _Handler(BaseHTTPRequestHandler):
    """The answer to one complete request the front end has read (``wfile`` holds it afterwards).

    ``body_late``: the request's body did not arrive whole within its deadline (the front end passes what came)."""

    hmi: HmiServer
    server_version = "CBT-HMI/1.0"
    stream: Stream | None = None       # set by an answer that goes on (/api/stream)

    def __init__(self, request: bytes, client_address, body_late: bool = False):  # noqa: D107
        self.client_address = client_address
        self.request = None
        # no socketserver behind the front end: nothing of the base class reads the server
        self.server = None  # type: ignore[assignment]
        self.rfile, self.wfile = io.BytesIO(request), io.BytesIO()
        self.body_late = body_late
        self.close_connection = True
        self.handle_one_request()

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002 - signature of the base class
        """Quiet: the demo prints its own status lines; details go to the debug log."""
        log.debug("HMI %s: " + format, self.client_address[0], *args)

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        """Malformed requests (bad request line, oversized headers) get a short JSON answer too."""
        try:
            self.close_connection = True
            self.request_version = "HTTP/1.0"           # also when the request line itself was unreadable
            status = HTTPStatus(code)
            self._json(status, {"ok": False, "error": message or status.phrase})
        except (ValueError, OSError):
            pass

    def _head(self, status: HTTPStatus, content_type: str | None, more: dict[str, str],
              cache: str = NEVER_KEPT) -> None:
        """The header of every answer: its ``content_type`` (None: no body, a 304), kept by the browser as ``cache``
        says (an API answer: never), never framed, no referrer; and ``more``."""
        self.send_response(status)
        if content_type is not None:
            self.send_header("Content-Type", content_type)
        for name, value in more.items():
            self.send_header(name, value)
        self.send_header("Cache-Control", cache)
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("X-Frame-Options", "DENY")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Content-Security-Policy", CONTENT_SECURITY_POLICY)
        self.end_headers()

    def _send(self, status: HTTPStatus, payload: bytes, content_type: str) -> None:
        self._head(status, content_type, {"Content-Length": str(len(payload))})
        if self.command != "HEAD":
            self.wfile.write(payload)

    def _json(self, status: HTTPStatus, obj: dict) -> None:
        self._send(status, json.dumps(obj).encode("utf-8"), "application/json")

    def _fail(self, error: Exception) -> None:
        self._json(getattr(error, "status", HTTPStatus.BAD_REQUEST), {"ok": False, "error": str(error)})

    def _url(self):
        if any(ord(c) < 0x20 or ord(c) == 0x7F for c in self.path):
            raise RequestError("the address contains control characters")
        return urlsplit(self.path)

    def do_GET(self) -> None:  # noqa: N802 - http.server naming
        self.hmi.requests += 1
        try:
            self.hmi.access.check_host(self.headers)
            url = self._url()
            if url.path == "/api/mapping":
                self._json(HTTPStatus.OK, {"ok": True, **self.hmi.mapping.document})
            elif url.path == "/api/session":
                self._json(HTTPStatus.OK, {"ok": True, "role": self.hmi.access.role_of(self.headers)})
            elif url.path == "/api/read":
                self._json(HTTPStatus.OK, self.hmi.read(self._names(url)))
            elif url.path == "/api/stream":
                self._stream(self._names(url))
            elif url.path in ("/api/program", "/api/program/state"):
                self._program(url)
            elif url.path == "/api/trail" and self.hmi.trail is not None:
                since = parse_qs(url.query).get("since", ["0"])[0]
                if not _POINT_NUMBER.fullmatch(since):
                    raise RequestError("since must be a point number: /api/trail?since=0")
                self._json(HTTPStatus.OK, self.hmi.trail.since(int(since)))
            elif url.path == "/api/alarms":
                count = parse_qs(url.query).get("history", ["0"])[0]
                if not _HISTORY_COUNT.fullmatch(count) or int(count) > HISTORY:
                    raise RequestError(f"history must be a number of entries, 0 .. {HISTORY}: /api/alarms?history=500")
                self._json(HTTPStatus.OK, self.hmi.alarms.summary(int(count)))
            elif url.path in ("/api/write", "/api/execute", "/api/alarms/ack"):
                raise RequestError(f"{url.path} takes POST with a JSON body", HTTPStatus.METHOD_NOT_ALLOWED)
            elif url.path.startswith("/api/"):
                raise RequestError(f"unknown API endpoint {url.path}", HTTPStatus.NOT_FOUND)
            else:
                self._static(url)
        except (RequestError, AccessDenied) as exc:
            self._fail(exc)
        except ValueError as exc:                       # parse_qs: too many fields
            self._fail(RequestError(f"malformed address: {exc}"))

    do_HEAD = do_GET

    @staticmethod
    def _names(url) -> list[str]:
        query = parse_qs(url.query, max_num_fields=MAX_NAMES)
        return [n for part in query.get("names", []) for n in part.split(",") if n]

    def _stream(self, names: list[str]) -> None:
        """The /api/read answer of ``names`` now and then every STREAM_PERIOD_S, a line each, on this connection
        (the front end sends the parts: cbt_hmi.web.front.Stream). A name the table does not allow is refused
        before anything is streamed, as by /api/read."""
        first = self.hmi.read(names)
        # no length: the answer ends with the connection; X-Accel-Buffering: a reverse proxy passes each part on
        self._head(HTTPStatus.OK, "application/x-ndjson", {"X-Accel-Buffering": "no"})
        if self.command == "HEAD":
            return
        read = self.hmi.read
        self.wfile.write(_line(first))
        self.stream = Stream(lambda: _line(read(names)), STREAM_PERIOD_S)

    def _program(self, url) -> None:
        """The Program page's ladder drawings and their live state (cbt_hmi.web.program)."""
        from .program import ProgramError, ProgramMonitor
        program = self.hmi.program
        if program is None:
            program = self.hmi.program = ProgramMonitor(self.hmi.plc)
        try:
            if url.path == "/api/program":
                self._json(HTTPStatus.OK, program.page())
            else:
                self._json(HTTPStatus.OK, program.state(parse_qs(url.query).get("pou", [""])[0]))
        except ProgramError as exc:
            raise RequestError(str(exc), exc.status) from None

    def do_POST(self) -> None:  # noqa: N802 - http.server naming
        self.hmi.requests += 1
        try:
            self.hmi.access.check_host(self.headers)
            url = self._url()
            operation = {"/api/write": self.hmi.write, "/api/execute": self.hmi.execute,
                         "/api/alarms/ack": self.hmi.acknowledge}.get(url.path)
            if operation is None:
                raise RequestError(f"unknown API endpoint {url.path}", HTTPStatus.NOT_FOUND)
            role = self.hmi.access.check_write(self.headers)
            self._json(HTTPStatus.OK, operation(self._body(), role))
        except (RequestError, AccessDenied) as exc:
            self._fail(exc)

    def _refuse_method(self):
        """No CORS preflight is ever answered positively, and nothing but GET and POST is served."""
        self.hmi.requests += 1
        self.close_connection = True
        self.send_response(HTTPStatus.METHOD_NOT_ALLOWED)
        payload = json.dumps({"ok": False, "error": f"{self.command} is not supported: use GET or POST"}).encode()
        self.send_header("Allow", "GET, HEAD, POST")
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(payload)))
        self.end_headers()
        self.wfile.write(payload)

    do_OPTIONS = do_PUT = do_DELETE = do_PATCH = _refuse_method

    def _body(self) -> dict:
        declared = self.headers.get("Content-Length")
        if len(self.headers.get_all("Content-Length") or ()) > 1 or "Transfer-Encoding" in self.headers:
            # two lengths, or a length beside a transfer coding, can be read two ways (RFC 9112 6.3): refused
            raise self._unread("the request must have one Content-Length and no Transfer-Encoding")
        if declared is None:
            raise RequestError("the request needs a Content-Length header", HTTPStatus.LENGTH_REQUIRED)
        digits = declared.strip()
        if not (digits.isascii() and digits.isdigit()):         # "-5", "abc", "1.5", "+5", "1_0"
            raise self._unread("Content-Length must be a whole number of bytes")
        if len(digits) > 12 or int(digits) > MAX_BODY:
            shown = digits if len(digits) <= 12 else digits[:12] + "..."
            raise self._unread(f"request body of {shown} bytes exceeds the limit of {MAX_BODY} bytes",
                               HTTPStatus.REQUEST_ENTITY_TOO_LARGE)
        length = int(digits)
        raw = self.rfile.read(length)
        if len(raw) < length and self.body_late:
            raise self._unread(f"the request body did not arrive: Content-Length announced {length} bytes, "
                               f"fewer came within {self.hmi.limits.body_s:g} s", HTTPStatus.REQUEST_TIMEOUT)
        if len(raw) < length:
            raise self._unread(f"the request body ended after {len(raw)} of the {length} bytes that "
                               f"Content-Length announced")
        body = _json_body(raw)
        if not isinstance(body, dict):
            raise RequestError("the request body must be a JSON object")
        return body

    def _unread(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST) -> RequestError:
        """A refused body that was not read whole: the answer closes the connection (the bytes that follow
        are not the next request)."""
        self.close_connection = True
        return RequestError(message, status)

    def _static(self, url) -> None:
        """A file of the pages folder; the page shell for every page's address (cbt_hmi.web.assets: what the
        browser may keep)."""
        relative = SHELL if url.path in ("", "/") else url.path.lstrip("/")
        if relative.endswith(".html") and relative[:-5] in self.hmi.mapping.pages:
            relative = SHELL                 # one page shell; hmi.js builds the page named in the address
        target = self.hmi.assets.find(relative)
        if target is None:
            raise RequestError(f"no such page: {url.path}", HTTPStatus.NOT_FOUND)
        try:
            answer = self.hmi.assets.answer(target, asked_version(url.query), self.headers.get("If-None-Match"),
                                            self.headers.get("If-Modified-Since"))
        except OSError as exc:
            raise RequestError(f"the page file {url.path} cannot be read: {exc.strerror or exc}",
                               HTTPStatus.INTERNAL_SERVER_ERROR) from None
        if answer.status == HTTPStatus.NOT_MODIFIED:
            self._head(HTTPStatus.NOT_MODIFIED, None, answer.validators, answer.cache)
            return
        content_type = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if content_type.startswith("text/") or content_type.endswith(("javascript", "json")):
            content_type += "; charset=utf-8"
        self._head(HTTPStatus.OK, content_type, {"Content-Length": str(len(answer.body)), **answer.validators},
                   answer.cache)
        if self.command != "HEAD":
            self.wfile.write(answer.body)
