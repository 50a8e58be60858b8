"""The HMI's HTTP front end: deadlines for every request and connection limits per client address.

One thread owns every socket and reads requests without blocking; a request is answered only when its header
and its body have arrived whole, so a client that sends slowly or not at all holds no thread, only one of a
bounded number of connections until its deadline (docs/hmi.md, "Serving every client"). What a request means
is the handler's business (cbt_hmi.web.server); this module only moves bytes. An answer may go on (a Stream):
after it the same thread sends the stream's next part every period for as long as the client takes them.
"""
from __future__ import annotations

import contextlib
import json
import logging
import math
import queue
import selectors
import socket
import sys
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from http import HTTPStatus

# The bounds (docs/hmi.md, "Serving every client"); HttpLimits carries the first six.
HEADER_DEADLINE_S = 5.0            # a request's header must be whole this long after its first byte: else 408
BODY_DEADLINE_S = 5.0              # and its body (at most MAX_BODY) this long after the header: else 408
IDLE_TIMEOUT_S = 10.0              # a new connection that sends nothing is closed after this
SEND_DEADLINE_S = 10.0             # a client must take its answer within this, else the connection is closed
MAX_CONNECTIONS = 512              # open connections in all
MAX_CONNECTIONS_PER_CLIENT = 128   # open connections of one client address
MAX_HEAD = 32 * 1024               # request line and headers of one request (400 names in /api/read fit): 431
MAX_BODY = 16 * 1024               # request body: the handler answers 413 beyond
LINGER_S = 1.0                     # after answering a request not read to its end, what still comes is
                                   # read and dropped this long (a close with unread bytes resets the answer)
WORKERS = 16                       # requests answered in worker threads at once (complete requests only)
LISTEN_BACKLOG = 128

log = logging.getLogger("cbt_hmi.web")


@dataclass(frozen=True)
class HttpLimits:
    """The bounds of the HTTP front end, in seconds and connections (docs/hmi.md, "Serving every client").

    The defaults are the module constants; tests give short deadlines to see them pass quickly."""

    header_s: float = HEADER_DEADLINE_S
    body_s: float = BODY_DEADLINE_S
    idle_s: float = IDLE_TIMEOUT_S
    send_s: float = SEND_DEADLINE_S
    connections: int = MAX_CONNECTIONS
    per_client: int = MAX_CONNECTIONS_PER_CLIENT

    def __post_init__(self):
        for name in ("header_s", "body_s", "idle_s", "send_s"):
            if not getattr(self, name) > 0:
                raise ValueError(f"HttpLimits.{name} must be a positive number of seconds")
        if not 1 <= self.per_client <= self.connections:
            raise ValueError("HttpLimits: 1 <= per_client <= connections")


@dataclass(frozen=True)
class Stream:
    """An answer that goes on. A handler that sets ``stream`` on itself leaves its connection open after its answer:
    the front-end thread calls ``next()`` ``period_s`` seconds after the client took the last part and sends what it
    returns, until it returns None (the answer ends: the connection is closed, as an HTTP/1.0 body without a length
    ends) or raises. A part the client does not take within the send deadline closes the connection; no part is
    made while the last one waits, so a client that reads slowly gets fewer parts, never a growing queue."""

    next: Callable[[], bytes | None]
    period_s: float


# states of a connection in the front end (_STREAM: between two parts of a Stream)
_IDLE, _HEAD, _BODY, _BUSY, _SEND, _LINGER, _STREAM = range(7)


def _head_end(data: bytearray) -> int:
    """Offset just after the blank line that ends the request header, -1 while it has not arrived."""
    ends = [at + len(blank) for blank in (b"\n\r\n", b"\n\n") if (at := data.find(blank)) >= 0]
    return min(ends) if ends else -1


def _declared_body(head: bytes) -> int | None:
    """Bytes of body the front end waits for: the Content-Length when it is a whole number within MAX_BODY, 0
    without one, None when it is refused (the handler answers 400 or 413 and the body is not read): also two
    Content-Length headers, or one beside a Transfer-Encoding (RFC 9112 6.3: they can be read two ways)."""
    found = None
    for line in head.split(b"\n")[1:]:
        name, colon, value = line.partition(b":")
        name = name.strip().lower()
        if colon and name == b"transfer-encoding":
            return None
        if colon and name == b"content-length":
            if found is not None:
                return None
            digits = value.strip()
            found = int(digits) if digits.isdigit() and len(digits) <= 12 and int(digits) <= MAX_BODY else -1
    return 0 if found is None else (None if found < 0 else found)


def _answer(status: HTTPStatus, message: str) -> bytes:
    """A complete JSON answer that ends the connection, for refusals made before a request reaches a worker."""
    payload = json.dumps({"ok": False, "error": message}).encode()
    return (f"HTTP/1.0 {status.value} {status.phrase}\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(payload)}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n"
            ).encode() + payload


class _Connection:
    """One client connection and what the front end knows of its current request."""

    __slots__ = ("sock", "peer", "client", "data", "state", "since", "deadline", "need", "whole", "out", "events",
                 "stream")

    def __init__(self, sock, peer, now: float, idle_s: float):
        self.sock, self.peer, self.client = sock, peer, peer[0]
        self.data = bytearray()
        self.state, self.since, self.deadline = _IDLE, now, now + idle_s
        self.need = 0                  # bytes of the current request: header + declared body
        self.whole = False             # the request was read to its end and nothing may follow: close at once
        self.out = memoryview(b"")
        self.events = 0                # what the selector watches for
        self.stream: Stream | None = None


class HttpFront:
    """The HMI's HTTP front end: one thread owns every socket, worker threads only build answers.

    The front-end thread reads requests without blocking and answers a request only when its header and body
    are complete (reads itself, writes through the bounded worker pool), so a slow client holds no thread: it
    holds one of a bounded number of connections, and only until its deadline (HttpLimits). When a client
    address has per_client connections open, or all connections are taken, a new connection closes the one of
    that address (or of the address holding the most) that has waited longest for its request to arrive or its
    answer to be taken: a client that sends a whole request at once is always served, whatever other
    connections are open. Answers are sent without waiting (what the socket does not take at once, by the
    front-end thread), so a client that does not read holds no thread either. The server speaks HTTP/1.0: one
    request per connection, closed after its answer.
    """

    def __init__(self, address, handler, limits: HttpLimits, at_once=lambda request: False):
        self.handler, self.limits, self.at_once = handler, limits, at_once
        family = socket.AF_INET6 if ":" in address[0] else socket.AF_INET
        self.socket = socket.socket(family, socket.SOCK_STREAM)
        try:
            self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self.socket.bind(address)
            self.socket.listen(LISTEN_BACKLOG)
        except OSError:
            self.socket.close()
            raise
        self.socket.setblocking(False)
        self.server_address = self.socket.getsockname()
        self._pool = ThreadPoolExecutor(WORKERS, thread_name_prefix="hmi-http")
        self._selector = selectors.DefaultSelector()
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector.register(self.socket, selectors.EVENT_READ, None)
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._answers: queue.SimpleQueue = queue.SimpleQueue()
        self._connections: set[_Connection] = set()
        self._by_client: dict[str, set[_Connection]] = {}
        self._stopping = False
        self._next_due = math.inf                # no deadline of a waiting connection is earlier than this
        self.evicted = self.refused = 0          # connections closed to make room / refused with 503 (counters)

    # --- what is open (for monitoring: read from any thread, a snapshot of a moment) ---------------------------
    @property
    def open_connections(self) -> int:
        """Connections open now: waiting for their request, being answered or sending their answer."""
        return len(self._connections)

    def connections_by_client(self) -> dict[str, int]:
        """Open connections per client address (addresses with none are absent)."""
        return {client: len(held) for client, held in list(self._by_client.items())}

    # --- the front-end thread ------------------------------------------------------------------------------
    def serve_forever(self) -> None:
        try:
            while not self._stopping:
                now = time.monotonic()
                waiting = False
                for key, mask in self._selector.select(min(max(self._next_due - now, 0.0), 1.0)):
                    if key.data is None:
                        waiting = True
                    elif key.data == "wake":
                        self._drain_wake()
                    elif mask & selectors.EVENT_WRITE:
                        self._send(key.data)
                    else:
                        self._receive(key.data)
                self._take_answers()
                if waiting:                    # after the reads: a request already here is safe from eviction
                    self._accept()
                now = time.monotonic()
                if now >= self._next_due:
                    self._expire(now)
        finally:
            for connection in list(self._connections):
                self._close(connection)

    def shutdown(self) -> None:
        self._stopping = True
        self._wake()

    def server_close(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._selector.close()
        for sock in (self.socket, self._wake_r, self._wake_w):
            sock.close()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):       # full (a wake-up is pending anyway) or closed at shutdown
            self._wake_w.send(b"\0")

    def _drain_wake(self) -> None:
        try:
            while self._wake_r.recv(4096):
                pass
        except OSError:
            pass

    def _watch(self, connection: _Connection, events: int) -> None:
        if events == connection.events:
            return
        if not events:
            self._selector.unregister(connection.sock)
        elif not connection.events:
            self._selector.register(connection.sock, events, connection)
        else:
            self._selector.modify(connection.sock, events, connection)
        connection.events = events

    def _accept(self) -> None:
        for _ in range(64):
            try:
                sock, peer = self.socket.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                # out of file descriptors (the process holds other sockets too): free one, else pause briefly
                # rather than turn the loop on a listening socket that stays readable
                log.warning("HMI server cannot accept a connection: %s", exc)
                if not self._evict(self._connections):
                    time.sleep(0.05)
                return
            sock.setblocking(False)
            if not self._make_room(peer[0]):
                self.refused += 1
                with contextlib.suppress(OSError):
                    sock.send(_answer(HTTPStatus.SERVICE_UNAVAILABLE, "the HMI server is busy, retry"))
                sock.close()
                continue
            connection = _Connection(sock, peer, time.monotonic(), self.limits.idle_s)
            self._next_due = min(self._next_due, connection.deadline)
            self._connections.add(connection)
            self._by_client.setdefault(connection.client, set()).add(connection)
            self._watch(connection, selectors.EVENT_READ)
            self._receive(connection)         # a request sent with the connection is answered at once

    def _make_room(self, client: str) -> bool:
        """Close the longest-waiting connection of ``client`` when it has per_client open, and one of the
        address holding the most when all are taken; False when every candidate is being served."""
        mine = self._by_client.get(client, ())
        if len(mine) >= self.limits.per_client and not self._evict(mine):
            return False
        if len(self._connections) >= self.limits.connections:
            heaviest = max(self._by_client.values(), key=len)
            if not (self._evict(heaviest) or self._evict(self._connections)):
                return False
        return True

    def _evict(self, candidates) -> bool:
        waiting = [c for c in candidates if c.state != _BUSY]
        if not waiting:
            return False
        self.evicted += 1
        self._close(min(waiting, key=lambda c: c.since))
        return True

    def _close(self, connection: _Connection) -> None:
        if connection not in self._connections:
            return
        self._connections.discard(connection)
        mine = self._by_client.get(connection.client)
        if mine is not None:
            mine.discard(connection)
            if not mine:
                del self._by_client[connection.client]
        if connection.events:
            self._selector.unregister(connection.sock)
            connection.events = 0
        connection.sock.close()

    def _receive(self, connection: _Connection) -> None:
        try:
            chunk = connection.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            self._close(connection)
            return
        if connection.state in (_LINGER, _STREAM):    # the answer is sent (or goes on): what comes is dropped
            if not chunk:
                self._close(connection)
            return
        if not chunk:
            if connection.data:                       # a request cut short: the handler says what is missing
                self._dispatch(connection, late=False, ended=True)
            else:
                self._close(connection)
            return
        connection.data += chunk
        if connection.state == _IDLE:
            self._start_request(connection, time.monotonic())
        self._advance(connection)

    def _start_request(self, connection: _Connection, now: float) -> None:
        connection.state, connection.since, connection.deadline = _HEAD, now, now + self.limits.header_s
        self._next_due = min(self._next_due, connection.deadline)

    def _advance(self, connection: _Connection) -> None:
        """Hand the request to a worker as soon as its header and its declared body are here."""
        data = connection.data
        if connection.state == _HEAD:
            end = _head_end(data)
            if end < 0 and len(data) <= MAX_HEAD:
                return
            if end < 0 or end > MAX_HEAD:
                self._refuse(connection, HTTPStatus.REQUEST_HEADER_FIELDS_TOO_LARGE,
                             f"the request header is larger than {MAX_HEAD // 1024} KiB")
                return
            declared = _declared_body(bytes(data[:end]))
            connection.need, connection.whole = end + (declared or 0), declared is not None
            connection.state, connection.deadline = _BODY, time.monotonic() + self.limits.body_s
            self._next_due = min(self._next_due, connection.deadline)
        if connection.state == _BODY and len(data) >= connection.need:
            self._dispatch(connection, late=False)

    def _dispatch(self, connection: _Connection, late: bool, ended: bool = False) -> None:
        """``late``: the body's deadline passed; ``ended``: the client closed its side of the connection."""
        request = bytes(connection.data[:connection.need or len(connection.data)])
        connection.whole = ended or (connection.whole and not late and len(connection.data) == len(request))
        connection.data.clear()                       # one request per connection: what follows is dropped
        connection.state = _BUSY
        self._watch(connection, 0)
        if self.at_once(request):
            self._finish(connection, *self._answer(connection, request, late))
        else:
            self._pool.submit(self._work, connection, request, late)

    def _refuse(self, connection: _Connection, status: HTTPStatus, message: str) -> None:
        connection.data.clear()
        connection.whole = False
        self._start_sending(connection, _answer(status, message))

    def _expire(self, now: float) -> None:
        """Act on every deadline that has passed; learn the next one (one pass over the connections)."""
        due, self._next_due = [], math.inf
        for connection in self._connections:
            if connection.state == _BUSY:
                continue
            if connection.deadline <= now:
                due.append(connection)
            elif connection.deadline < self._next_due:
                self._next_due = connection.deadline
        for connection in due:
            if connection.state == _STREAM:
                self._next_part(connection)                    # the stream's next part is due
            elif connection.state == _HEAD:
                self._refuse(connection, HTTPStatus.REQUEST_TIMEOUT,
                             f"the request header did not arrive within {self.limits.header_s:g} s")
            elif connection.state == _BODY:
                self._dispatch(connection, late=True)          # the handler answers 408 for its body
            else:
                self._close(connection)        # idle, an answer not taken in time, or the lingering close ended

    # --- answers ---------------------------------------------------------------------------------------------
    def _work(self, connection: _Connection, request: bytes, late: bool) -> None:
        """In a worker thread: answer one request, hand the connection back to the front-end thread."""
        self._answers.put((connection, *self._answer(connection, request, late)))
        self._wake()

    def _answer(self, connection: _Connection, request: bytes, late: bool) -> tuple[bytes | None, Stream | None]:
        """The answer to one complete request and the Stream that goes on after it, if any. What the socket takes
        at once is sent here without waiting (the front-end thread leaves a connection alone while it is
        answered); returns the rest (None to close) and the stream."""
        stream = None
        try:
            handled = self.handler(request, connection.peer, late)
            answer, stream = handled.wfile.getvalue(), getattr(handled, "stream", None)
        except Exception:          # noqa: BLE001 - one broken request must never stop the server
            self.handle_error(None, connection.peer)
            answer = b""
        rest = answer or None                         # nothing to answer (an empty request line): close
        if answer:
            try:
                rest = answer[connection.sock.send(answer):]
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                self.handle_error(None, connection.peer)
                rest = None
        return rest, stream

    def _take_answers(self) -> None:
        while True:
            try:
                connection, rest, stream = self._answers.get_nowait()
            except queue.Empty:
                return
            if connection in self._connections:       # else closed at shutdown meanwhile
                self._finish(connection, rest, stream)

    def _finish(self, connection: _Connection, rest: bytes | None, stream: Stream | None = None) -> None:
        if rest is None:
            self._close(connection)
        else:
            connection.stream = stream
            self._start_sending(connection, rest)     # what could not be sent at once (often nothing)

    def _next_part(self, connection: _Connection) -> None:
        """Send the next part of the connection's stream; close the connection when the stream ends."""
        try:
            part = connection.stream.next() if connection.stream is not None else None
        except Exception:          # noqa: BLE001 - one broken stream must never stop the server
            self.handle_error(None, connection.peer)
            part = None
        if part is None:
            self._close(connection)
        else:
            self._start_sending(connection, part)

    def _start_sending(self, connection: _Connection, answer: bytes) -> None:
        connection.out = memoryview(answer)
        connection.state, connection.deadline = _SEND, time.monotonic() + self.limits.send_s
        self._next_due = min(self._next_due, connection.deadline)
        self._send(connection)

    def _send(self, connection: _Connection) -> None:
        try:
            sent = connection.sock.send(connection.out)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError:
            self.handle_error(None, connection.peer)
            self._close(connection)
            return
        connection.out = connection.out[sent:]
        if connection.out:
            self._watch(connection, selectors.EVENT_WRITE)
            return
        if connection.stream is not None:          # taken: the next part after the stream's period
            now = time.monotonic()
            connection.state, connection.since = _STREAM, now
            connection.deadline = now + connection.stream.period_s
            self._next_due = min(self._next_due, connection.deadline)
            self._watch(connection, selectors.EVENT_READ)      # to see the client leave
            return
        if connection.whole:
            self._close(connection)
            return
        # a lingering close: the client reads the whole answer before the connection goes (closing with unread
        # request bytes would reset it and could destroy the answer on the way)
        try:
            connection.sock.shutdown(socket.SHUT_WR)
        except OSError:
            self._close(connection)
            return
        now = time.monotonic()
        connection.state, connection.since, connection.deadline = _LINGER, now, now + LINGER_S
        self._next_due = min(self._next_due, connection.deadline)
        self._watch(connection, selectors.EVENT_READ)

    def handle_error(self, request, client_address) -> None:
        exc = sys.exc_info()[1]
        if isinstance(exc, (BrokenPipeError, ConnectionResetError, ConnectionAbortedError)):
            log.debug("HMI client %s:%s left before the answer was sent (%s)", *client_address[:2],
                      type(exc).__name__)       # a browser leaving a page mid-request: normal, one line
            return
        log.debug("HMI connection from %s ended abnormally", client_address[0], exc_info=True)
