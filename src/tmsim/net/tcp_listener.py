"""A listening TCP socket of the simulator, watched by the server's selector (Listen node, Ethernet Slave and
control channel ports share it).

Out of file descriptors, ``accept()`` fails while the listener stays readable: watching it then would spin the
loop at 100 % CPU and log an error on every turn. The listener stops being watched for ACCEPT_BACKOFF_S instead,
says so once, and ``tick(now)`` watches it again; pending connections wait in the kernel's backlog meanwhile.
"""
from __future__ import annotations

import contextlib
import errno
import selectors
import socket
from collections.abc import Callable, Iterable
from typing import Any

from tmsim.limits import ACCEPT_BACKOFF_S, OUT_OF_DESCRIPTORS, RECV_BYTES


def receive(sock: socket.socket) -> tuple[bytes | None, str | None]:
    """One non-blocking read of an accepted connection: ``(data, None)``; ``(b"", None)`` when the peer closed;
    ``(None, None)`` when nothing is there yet; ``(None, reason)`` when the socket failed."""
    try:
        return sock.recv(RECV_BYTES), None
    except (BlockingIOError, InterruptedError):
        return None, None
    except OSError as exc:
        return None, f"receive failed: {exc.strerror}"


def send_out(sock: socket.socket, wbuf: bytearray, frames: Iterable[bytes | bytearray]) -> None:
    """Hand ``frames`` to a non-blocking connection: each straight to the socket while nothing waits before it (one
    send per frame when the peer keeps up), the rest appended to ``wbuf``, which is then offered again; what the
    socket does not take stays in ``wbuf``, in order. A failed send raises OSError (the caller drops the client)."""
    for frame in frames:
        if wbuf:
            wbuf += frame
        else:
            wbuf += frame[_send(sock, frame):]
    if wbuf:
        del wbuf[:_send(sock, wbuf)]


def _send(sock: socket.socket, data: bytes | bytearray) -> int:
    try:
        return sock.send(data)
    except (BlockingIOError, InterruptedError):
        return 0


class Listener:
    def __init__(self, selector: selectors.BaseSelector, host: str, port: int, key: tuple, what: str, backlog: int = 16,
                 held: socket.socket | None = None):
        """Bind and listen; ``key`` is the selector data of the listener, ``what`` is the OSError's text when the port
        cannot be opened, ``{where}`` standing for host:port (e.g. "listen on {where} for robot 1"). ``held``: a
        socket already bound to the port by ``close(hold_port=True)``, which starts listening instead."""
        sock = held
        if sock is not None:
            # held by close(), which gave SO_REUSEADDR up: a listener needs it again (the old listener's
            # connections may still be in TIME_WAIT on the port)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        else:
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.bind((host, port))
            except OSError as exc:
                sock.close()
                raise OSError(exc.errno, f"cannot {what.format(where=f'{host}:{port}')}: {exc.strerror}") from None
        sock.listen(backlog)
        sock.setblocking(False)
        self.sock = sock
        self.port = sock.getsockname()[1]
        self._selector = selector
        self._key = key
        self.paused_until: float | None = None
        selector.register(sock, selectors.EVENT_READ, key)

    def accept(self, now: float, log: Callable[..., None], prefix: str = "") -> tuple[socket.socket, Any] | None:
        """One pending connection as ``(sock, addr)``, or None: none waiting, or an error that ``log`` was told
        (``<prefix>accept_paused`` once per pause when out of descriptors, ``<prefix>accept_error`` otherwise)."""
        try:
            return self.sock.accept()
        except (BlockingIOError, InterruptedError):
            return None
        except OSError as exc:
            if exc.errno in OUT_OF_DESCRIPTORS:
                self._selector.unregister(self.sock)
                self.paused_until = now + ACCEPT_BACKOFF_S
                log(f"{prefix}accept_paused", reason=exc.strerror, seconds=ACCEPT_BACKOFF_S)
            else:
                log(f"{prefix}accept_error", reason=exc.strerror)
            return None

    def tick(self, now: float) -> None:
        """Watch the listener again once a pause is over (called once a poll)."""
        if self.paused_until is not None and now >= self.paused_until:
            self.paused_until = None
            self._selector.register(self.sock, selectors.EVENT_READ, self._key)

    def close(self, hold_port: bool = False) -> socket.socket | None:
        """Stop listening. ``hold_port``: keep the port bound by a socket that does not listen, returned for a later
        ``Listener(..., held=...)``: connection attempts are refused as by a closed port, but no other program can
        take the port meanwhile (a robot whose project stopped comes back on the same port). None when not held."""
        if self.paused_until is None:
            with contextlib.suppress(KeyError, ValueError):
                self._selector.unregister(self.sock)
        self.paused_until = None
        host = self.sock.getsockname()[0]
        self.sock.close()
        if not hold_port:
            return None
        # The holder binds without SO_REUSEADDR, so another program's SO_REUSEADDR bind (a server, or a check of
        # whether the port is free, as our default control ports do) is refused instead of sharing the port. Only
        # when the closed listener's connections still hold the port (TIME_WAIT) does it need SO_REUSEADDR to
        # bind; it gives it up once bound. (Binding with it first would let kernels before 6.8 mark the port as
        # shared by reusing sockets, and clearing the option afterwards would not undo that.)
        hold = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            hold.bind((host, self.port))
        except OSError as exc:
            if exc.errno != errno.EADDRINUSE:
                hold.close()
                return None
            hold.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                hold.bind((host, self.port))
            except OSError:
                hold.close()
                return None
            hold.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 0)
        return hold
