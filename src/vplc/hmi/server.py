"""Web HMI server: serves hmi/ and a JSON API over the PLC-HMI variable table (hmi/mapping.json).

The browser is not trusted. Every request must address this server (Host); every write must come from the
HMI's own pages, as JSON, with an access key whose role may change that variable (vplc.hmi.access). Every
write names a variable of the mapping file, is checked against its type and range here again, and reaches the
PLC only through Contract A (plc.write under plc.lock), all values or none. Reads are limited to mapped
variables too.

API (all answers are JSON objects with "ok"):
  GET  /api/mapping                         the variable table (types, ranges, enumerations, roles)
  GET  /api/session                         {"ok", "role"}: the role the request's X-HMI-Key grants
  GET  /api/read?names=A,B.C,...            {"ok", "time_ns", "values": {name: value}}
  GET  /api/program[/state?pou=NAME]        ladder drawings and their live power flow (vplc.hmi.program)
  POST /api/write   {"values": {path: v}}   validate all, then write all in one scan gap
  POST /api/execute {"execute": "X_Execute", "values": {path: v}}
                                            validate, write the values and Execute := FALSE, wait for one
                                            PLC scan, then Execute := TRUE (a clean rising edge per press)

The server is a bounded pool of worker threads: a connection idle for CONNECTION_TIMEOUT_S is closed, and
beyond WORKERS + WAITING connections a new one is answered 503 at once.
"""
from __future__ import annotations

import datetime
import ipaddress
import json
import logging
import math
import mimetypes
import pathlib
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, HTTPServer
from urllib.parse import parse_qs, urlsplit

from .access import AccessDenied, AccessPolicy, role_at_least
from .ranges import RangeTableError, apply_ranges, load_ranges
from .trail import Trail

HMI_DIR = pathlib.Path(__file__).resolve().parents[3] / "hmi"
DEFAULT_MAPPING = HMI_DIR / "mapping.json"
DEFAULT_RANGES = HMI_DIR / "ranges.json"
MAX_BODY = 16 * 1024
MAX_NAMES = 400
SCAN_WAIT_S = 1.0
CONNECTION_TIMEOUT_S = 10.0        # a client that sends nothing for this long is disconnected
WORKERS = 16                       # requests served at once
WAITING = 48                       # connections queued for a worker before new ones get 503
LISTEN_BACKLOG = 128

log = logging.getLogger("vplc.hmi")

INT_RANGES = {
    "SINT": (-2**7, 2**7 - 1), "INT": (-2**15, 2**15 - 1), "DINT": (-2**31, 2**31 - 1),
    "LINT": (-2**63, 2**63 - 1), "USINT": (0, 2**8 - 1), "UINT": (0, 2**16 - 1), "UDINT": (0, 2**32 - 1),
    "ULINT": (0, 2**64 - 1), "BYTE": (0, 2**8 - 1), "WORD": (0, 2**16 - 1), "DWORD": (0, 2**32 - 1),
    "LWORD": (0, 2**64 - 1),
}
REAL_TYPES = {"REAL", "LREAL"}


class MappingError(Exception):
    """The mapping file is unreadable, inconsistent, or does not match the PLC program."""


class RequestError(Exception):
    """A request the HMI server refuses; str() is the message shown to the operator."""

    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST):
        super().__init__(message)
        self.status = status


class Leaf:
    """One scalar PLC variable reachable from the HMI (a mapped variable or a field inside one)."""

    __slots__ = ("path", "type", "access", "role", "min", "max", "enum", "maxlen", "pattern", "execute", "unit")

    def __init__(self, path: str, spec: dict, access: str, role: str, enum: dict | None = None):
        self.path = path
        self.type = spec["type"]
        self.access = access
        self.role = role                  # the least role that may write it: "operator" or "engineer"
        self.enum = enum
        self.min = spec.get("min")
        self.max = spec.get("max")
        self.maxlen = spec.get("maxlen")
        self.pattern = spec.get("pattern")
        self.execute = bool(spec.get("execute"))
        self.unit = spec.get("unit", "")

    def describe_range(self) -> str:
        if self.enum:
            return "one of " + ", ".join(f"{k} ({v})" for k, v in self.enum.items())
        return f"{self.min} .. {self.max}"


def _string_length(type_text: str) -> int | None:
    if type_text.startswith("STRING[") and type_text.endswith("]"):
        return int(type_text[7:-1])
    return 80 if type_text == "STRING" else None


class Mapping:
    """The PLC-HMI variable table flattened to leaf paths such as 'PnP_MoveParameters[2].TargetPosition.X'."""

    def __init__(self, document: dict, source: str = "mapping"):
        self.document = document
        self.source = source
        self.leaves: dict[str, Leaf] = {}
        self.roots: dict[str, dict] = {}
        try:
            self.pages = frozenset(document.get("pages", ["index"]))
            types = document["types"]
            for name, spec in document["variables"].items():
                self.roots[name] = spec
                access = spec.get("access", "r")
                if access not in ("r", "rw"):
                    raise MappingError(f"{source}: variable '{name}': access must be 'r' or 'rw', not {access!r}")
                role = spec.get("role", "operator")
                if role not in ("operator", "engineer"):
                    raise MappingError(f"{source}: variable '{name}': role must be 'operator' or 'engineer', "
                                       f"not {role!r}")
                self._expand(name, spec, access, role, types)
        except (KeyError, TypeError, ValueError) as exc:
            raise MappingError(f"{source}: malformed variable table ({type(exc).__name__}: {exc})") from None

    @classmethod
    def load(cls, path: pathlib.Path | str = DEFAULT_MAPPING) -> "Mapping":
        path = pathlib.Path(path)
        try:
            document = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise MappingError(f"{path}: cannot read the HMI variable table ({exc.strerror})") from None
        except json.JSONDecodeError as exc:
            raise MappingError(f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
        ranges_file = path.with_name(DEFAULT_RANGES.name)
        if ranges_file.exists():                # the limits come from the library's range table
            try:
                apply_ranges(document, load_ranges(ranges_file), str(ranges_file))
            except RangeTableError as exc:
                raise MappingError(str(exc)) from None
        return cls(document, str(path))

    def _expand(self, path: str, spec: dict, access: str, role: str, types: dict) -> None:
        if "array" in spec:
            low, high = spec["array"]
            for index in range(low, high + 1):
                self._expand_element(f"{path}[{index}]", spec, access, role, types)
        else:
            self._expand_element(path, spec, access, role, types)

    def _expand_element(self, path: str, spec: dict, access: str, role: str, types: dict) -> None:
        type_name = spec["type"]
        definition = types.get(type_name)
        if definition is None:
            if type_name not in INT_RANGES and type_name not in REAL_TYPES and type_name != "BOOL" \
                    and _string_length(type_name) is None and type_name not in ("DATE_AND_TIME", "DT", "TIME"):
                raise MappingError(f"{self.source}: '{path}' has unknown type '{type_name}'")
            self.leaves[path] = Leaf(path, spec, access, role)
        elif "enum" in definition:
            self.leaves[path] = Leaf(path, spec, access, role, enum=dict(definition["enum"]))
        else:
            for field, field_spec in definition["fields"].items():
                if "min" in spec and "min" not in field_spec:      # e.g. TargetPosition's range on X..RZ
                    field_spec = {**field_spec, "min": spec["min"], "max": spec["max"]}
                self._expand(f"{path}.{field}", field_spec, access, role, types)

    def why_not_a_leaf(self, path) -> str:
        """Why ``path`` cannot be written as one value: a whole structure/array, an index out of its range,
        or a name that is not in the table."""
        if not isinstance(path, str):
            return f"{json.dumps(path)} is not a variable name"
        if path in self.roots or self.is_readable(path):
            example = next(leaf for leaf in self.leaves if leaf.startswith(path))
            return f"'{path}' is a structure or array: write its elements one by one, e.g. '{example}'"
        root = path.split(".")[0].split("[")[0]
        spec = self.roots.get(root)
        if spec is not None and "array" in spec and path[len(root):].startswith("["):
            low, high = spec["array"]
            return f"'{path}': the index is outside {root}[{low}..{high}]"
        return f"'{path}' is not in the HMI variable table"

    def is_readable(self, name: str) -> bool:
        """A mapped variable, a leaf inside one, or an inner struct/array element of one."""
        if name in self.roots or name in self.leaves:
            return True
        return any(leaf.startswith(name + ".") or leaf.startswith(name + "[") for leaf in self.leaves)

    def check_against_plc(self, plc) -> None:
        """Raise MappingError listing every mapped leaf the PLC does not have with the same type."""
        problems = []
        for path, leaf in self.leaves.items():
            try:
                with plc.lock:
                    actual = plc.var_type(path)
            except (KeyError, ValueError) as exc:
                problems.append(f"  {path}: not found in the PLC program ({exc})")
                continue
            bare = actual.rsplit("\\", 1)[-1]
            expected = leaf.type
            same = bare == expected or (expected in ("DATE_AND_TIME", "DT") and bare in ("DATE_AND_TIME", "DT"))
            if not same and _string_length(expected) is not None and _string_length(bare) is not None:
                same = _string_length(bare) >= _string_length(expected) or leaf.access == "r"
            if not same:
                problems.append(f"  {path}: the table says {expected}, the PLC program declares {actual}")
        if problems:
            raise MappingError(f"{self.source} does not match the PLC program:\n" + "\n".join(problems))


def validate(leaf: Leaf, value):
    """Return the value to hand to plc.write, or raise RequestError saying what is wrong."""
    where = f"'{leaf.path}'"
    if leaf.enum is not None:
        if isinstance(value, str) and value in leaf.enum:
            return leaf.enum[value]
        if isinstance(value, int) and not isinstance(value, bool) and value in leaf.enum.values():
            return value
        raise RequestError(f"{where}: {value!r} is not valid, expected {leaf.describe_range()}")
    if leaf.type == "BOOL":
        if not isinstance(value, bool):
            raise RequestError(f"{where} is BOOL: expected true or false, got {json.dumps(value)}")
        return value
    if leaf.type in INT_RANGES:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int) or isinstance(value, bool):
            raise RequestError(f"{where} is {leaf.type}: expected a whole number, got {json.dumps(value)}")
        low, high = INT_RANGES[leaf.type]
        low = low if leaf.min is None else max(low, leaf.min)
        high = high if leaf.max is None else min(high, leaf.max)
        if not low <= value <= high:
            raise RequestError(f"{where}: {value} is out of range {low} .. {high}")
        return value
    if leaf.type in REAL_TYPES:
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise RequestError(f"{where} is {leaf.type}: expected a number, got {json.dumps(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise RequestError(f"{where}: the value must be a finite number")
        if (leaf.min is not None and value < leaf.min) or (leaf.max is not None and value > leaf.max):
            raise RequestError(f"{where}: {value:g} is out of range {leaf.min} .. {leaf.max}")
        return value
    size = _string_length(leaf.type)
    if size is not None:
        if not isinstance(value, str):
            raise RequestError(f"{where} is {leaf.type}: expected text, got {json.dumps(value)}")
        limit = min(size - 1, leaf.maxlen or size)   # Sysmac STRING[n] holds n-1 characters (NUL)
        if len(value) > limit or not value.isascii():
            raise RequestError(f"{where}: text must be at most {limit} ASCII characters")
        if leaf.pattern == "ipv4":
            try:
                ipaddress.IPv4Address(value)
            except ValueError:
                raise RequestError(f"{where}: '{value}' is not an IPv4 address such as 192.168.1.10") from None
        return value
    raise RequestError(f"{where} ({leaf.type}) cannot be written from the HMI")


def format_dt(value) -> str:
    """DATE_AND_TIME as the runtime holds it (ns since 1970-01-01) -> 'DT#2026-11-22-21:42:38'; 0 -> '—'."""
    if not isinstance(value, int) or isinstance(value, bool):
        return str(value)
    if value == 0:
        return "—"
    moment = datetime.datetime(1970, 1, 1) + datetime.timedelta(microseconds=value // 1000)
    return moment.strftime("DT#%Y-%m-%d-%H:%M:%S")


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if hasattr(value, "value") and isinstance(getattr(value, "value"), int):
        return value.value
    return str(value)


class _PooledHTTPServer(HTTPServer):
    """HTTPServer whose connections are served by a bounded pool of threads (not a thread per connection)."""

    request_queue_size = LISTEN_BACKLOG
    allow_reuse_address = True

    def __init__(self, address, handler):
        # the pool exists before the base class binds: a refused bind calls server_close(), which shuts it down
        self._pool = ThreadPoolExecutor(WORKERS, thread_name_prefix="hmi-http")
        self._slots = threading.BoundedSemaphore(WORKERS + WAITING)
        super().__init__(address, handler)

    def process_request(self, request, client_address):
        if not self._slots.acquire(blocking=False):
            try:
                request.sendall(b"HTTP/1.0 503 Service Unavailable\r\nContent-Type: application/json\r\n"
                                b"Content-Length: 58\r\nConnection: close\r\n\r\n"
                                b'{"ok": false, "error": "the HMI server is busy, retry"}\r\n\r\n')
            except OSError:
                pass
            self.shutdown_request(request)
            return
        self._pool.submit(self._serve, request, client_address)

    def _serve(self, request, client_address):
        try:
            self.finish_request(request, client_address)
        except Exception:           # noqa: BLE001 - one broken connection must never stop the server
            self.handle_error(request, client_address)
        finally:
            self.shutdown_request(request)
            self._slots.release()

    def handle_error(self, request, client_address):
        exc = sys.exc_info()[1]
        if isinstance(exc, (BrokenPipeError, ConnectionResetError, ConnectionAbortedError)):
            log.debug("HMI client %s:%s left before the answer was sent (%s)", *client_address[:2],
                      type(exc).__name__)       # a browser leaving a page mid-request: normal, one line
            return
        log.debug("HMI connection from %s ended abnormally", client_address[0], exc_info=True)

    def server_close(self):
        super().server_close()
        self._pool.shutdown(wait=False, cancel_futures=True)


class HmiServer:
    """HTTP server for one PLC. start() binds (port 0 = ephemeral), serves in a thread; stop() ends it."""

    def __init__(self, plc, mapping: Mapping | None = None, host: str = "127.0.0.1", port: int = 8080,
                 root: pathlib.Path = HMI_DIR, access: AccessPolicy | None = None):
        self.plc = plc
        self.mapping = mapping or Mapping.load()
        self.host = host
        self.requested_port = port
        self.root = pathlib.Path(root).resolve()
        self.access = access or AccessPolicy()
        self._httpd: _PooledHTTPServer | None = None
        self._thread: threading.Thread | None = None
        self.requests = 0
        self._execute_lock = threading.Lock()
        self.program = None            # ProgramMonitor, built at the Program page's first request
        spec = self.mapping.document.get("trail")
        self.trail = Trail(plc, spec["valid"], spec["position"]) if spec else None

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
        self._httpd = _PooledHTTPServer((self.host, self.requested_port), handler)
        self.access.bind(self.host, self.port)
        self._thread = threading.Thread(target=self._httpd.serve_forever, kwargs={"poll_interval": 0.1},
                                        name="hmi-http", daemon=True)
        self._thread.start()
        if self.trail is not None:
            self.trail.start()

    def stop(self) -> None:
        if self.trail is not None:
            self.trail.stop()
        if self._httpd:
            self._httpd.shutdown()
            self._httpd.server_close()
            self._thread.join(timeout=5)
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
        for name in names:
            leaf = self.mapping.leaves.get(name)
            if leaf is not None and leaf.type in ("DATE_AND_TIME", "DT"):
                values[name] = format_dt(values[name])
        return {"ok": True, "time_ns": now, "values": _jsonable(values)}

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
            raise RequestError(f"'{path}' is an engineering setting: open the engineer address printed at "
                               f"start-up to change it", HTTPStatus.FORBIDDEN)
        return leaf

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
        with self.plc.lock:
            now = self._write_all(checked)
        return {"ok": True, "time_ns": now}

    def execute(self, body: dict, role: str) -> dict:
        name = body.get("execute")
        leaf = self.mapping.leaves.get(name) if isinstance(name, str) else None
        if leaf is None or not leaf.execute:
            raise RequestError(f'"execute" must name an Execute variable of the table, not {name!r}')
        self._writable(name, role)
        values = body.get("values") or {}
        checked = self._checked(values, role) if values else []
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
        while not all(now > then for now, then in zip(self.plc.task_cycles, cycles_at)):
            if time.monotonic() > deadline:
                raise RequestError(f"the PLC is not scanning: {what}", HTTPStatus.SERVICE_UNAVAILABLE)
            time.sleep(0.0005)


class _Handler(BaseHTTPRequestHandler):
    hmi: HmiServer
    server_version = "CBT-HMI/1.0"
    timeout = CONNECTION_TIMEOUT_S

    def log_message(self, format, *args):  # noqa: A002 - signature of the base class
        """Quiet: the demo prints its own status lines; details go to the debug log."""
        log.debug("HMI %s: " + format, self.client_address[0], *args)

    def handle(self):
        try:
            super().handle()
        except (ConnectionError, TimeoutError) as exc:
            log.debug("HMI client %s left early: %s", self.client_address[0], exc)

    def send_error(self, code, message=None, explain=None):
        """Malformed requests (bad request line, oversized headers) get a short JSON answer too."""
        try:
            self.close_connection = True
            self.request_version = "HTTP/1.0"           # also when the request line itself was unreadable
            status = HTTPStatus(code)
            self._json(status, {"ok": False, "error": message or status.phrase})
        except (ValueError, OSError):
            pass

    def _send(self, status: HTTPStatus, payload: bytes, content_type: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(payload)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("X-Frame-Options", "DENY")
        self.send_header("Referrer-Policy", "no-referrer")
        self.end_headers()
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

    def do_GET(self):  # noqa: N802 - http.server naming
        self.hmi.requests += 1
        try:
            self.hmi.access.check_host(self.headers)
            url = self._url()
            if url.path == "/api/mapping":
                self._json(HTTPStatus.OK, {"ok": True, **self.hmi.mapping.document})
            elif url.path == "/api/session":
                self._json(HTTPStatus.OK, {"ok": True, "role": self.hmi.access.role_of(self.headers)})
            elif url.path == "/api/read":
                query = parse_qs(url.query, max_num_fields=MAX_NAMES)
                names = [n for part in query.get("names", []) for n in part.split(",") if n]
                self._json(HTTPStatus.OK, self.hmi.read(names))
            elif url.path in ("/api/program", "/api/program/state"):
                self._program(url)
            elif url.path == "/api/trail" and self.hmi.trail is not None:
                since = parse_qs(url.query).get("since", ["0"])[0]
                if not since.isdigit():
                    raise RequestError("since must be a point number: /api/trail?since=0")
                self._json(HTTPStatus.OK, self.hmi.trail.since(int(since)))
            elif url.path in ("/api/write", "/api/execute"):
                raise RequestError(f"{url.path} takes POST with a JSON body", HTTPStatus.METHOD_NOT_ALLOWED)
            elif url.path.startswith("/api/"):
                raise RequestError(f"unknown API endpoint {url.path}", HTTPStatus.NOT_FOUND)
            else:
                self._static(url.path)
        except (RequestError, AccessDenied) as exc:
            self._fail(exc)
        except ValueError as exc:                       # parse_qs: too many fields
            self._fail(RequestError(f"malformed address: {exc}"))

    do_HEAD = do_GET

    def _program(self, url) -> None:
        """The Program page's ladder drawings and their live state (vplc.hmi.program)."""
        from .program import ProgramError, ProgramMonitor
        if self.hmi.program is None:
            self.hmi.program = ProgramMonitor(self.hmi.plc)
        try:
            if url.path == "/api/program":
                self._json(HTTPStatus.OK, self.hmi.program.page())
            else:
                self._json(HTTPStatus.OK, self.hmi.program.state(parse_qs(url.query).get("pou", [""])[0]))
        except ProgramError as exc:
            raise RequestError(str(exc), exc.status) from None

    def do_POST(self):  # noqa: N802 - http.server naming
        self.hmi.requests += 1
        try:
            self.hmi.access.check_host(self.headers)
            url = self._url()
            operation = {"/api/write": self.hmi.write, "/api/execute": self.hmi.execute}.get(url.path)
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
        try:
            length = int(self.headers.get("Content-Length", ""))
        except ValueError:
            raise RequestError("the request needs a Content-Length header", HTTPStatus.LENGTH_REQUIRED) from None
        if length > MAX_BODY or length < 0:
            self.close_connection = True
            raise RequestError(f"request body of {length} bytes exceeds the limit of {MAX_BODY} bytes",
                               HTTPStatus.REQUEST_ENTITY_TOO_LARGE)
        raw = self.rfile.read(length)
        try:
            body = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RequestError(f"the request body is not valid JSON ({exc})") from None
        except ValueError as exc:                       # e.g. a number of more than 4,300 digits
            raise RequestError(f"the request body holds a value out of range ({exc})") from None
        except RecursionError:
            raise RequestError("the request body is nested too deeply") from None
        if not isinstance(body, dict):
            raise RequestError("the request body must be a JSON object")
        return body

    def _static(self, path: str) -> None:
        relative = "index.html" if path in ("", "/") else path.lstrip("/")
        if relative.endswith(".html") and relative[:-5] in self.hmi.mapping.pages:
            relative = "index.html"          # one page shell; hmi.js builds the page named in the address
        target = (self.hmi.root / relative).resolve()
        if self.hmi.root not in target.parents or not target.is_file():
            raise RequestError(f"no such page: {path}", HTTPStatus.NOT_FOUND)
        content_type = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if content_type.startswith("text/") or content_type.endswith(("javascript", "json")):
            content_type += "; charset=utf-8"
        self._send(HTTPStatus.OK, target.read_bytes(), content_type)
