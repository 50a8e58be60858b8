"""Sysmac TCP socket instructions over real non-blocking OS sockets.

Every instruction is asynchronous like on the NJ/NX controller: the rising edge of Execute starts the
operation and sets Busy; the result (Done or Error + ErrorID) appears at the earliest in the next call,
and not before ``SocketManager.latency_ns`` of controller time has passed (latency model). Done/Error stay
TRUE while Execute stays TRUE; if Execute is already FALSE at completion they are TRUE for one call.
ErrorIDs are listed in ``ERRORS`` and docs/toolchain/runtime_sysmac.md.
"""
from __future__ import annotations

import contextlib
import errno
import ipaddress
import select
import socket

ERR_PARAM = 0x0400            # input value out of range (port 0, Size larger than the array, ...)
ERR_ADDRESS = 0x2002          # destination address is not a valid IPv4 address
ERR_HANDLE = 0x2003           # the socket does not exist (never opened, or already closed)
ERR_RESOURCES = 0x2004        # no free socket: the controller's socket limit is reached
ERR_PORT_IN_USE = 0x2005      # SktTCPAccept: the local port cannot be opened (already in use)
ERR_TIMEOUT = 0x2006          # SktTCPRcv / SktTCPAccept: nothing within TimeOut (never for TimeOut 0)
ERR_CLOSED = 0x2007           # connection closed or reset by the remote node
ERR_REFUSED = 0x2008          # connection refused / remote node unreachable
ERRORS = {ERR_PARAM: "input value out of range", ERR_ADDRESS: "invalid destination IP address",
          ERR_HANDLE: "socket does not exist", ERR_RESOURCES: "too many sockets open",
          ERR_PORT_IN_USE: "local port already in use", ERR_TIMEOUT: "timeout",
          ERR_CLOSED: "connection closed by the remote node",
          ERR_REFUSED: "connection refused or remote node unreachable"}

# _eCONNECTION_STATE values (declaration order in prelude/sysmac_types.st)
CLOSED, LISTEN, SYN_SENT, SYN_RECEIVED, ESTABLISHED, CLOSE_WAIT = 0, 1, 2, 3, 4, 5


class _Conn:
    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        # asking the OS whether anything arrived is cheaper than a receive that fails with "would block"
        # (most scans); select.poll is not on every platform: there a receive asks
        self.poller = select.poll() if hasattr(select, "poll") else None
        if self.poller is not None:
            self.poller.register(sock, select.POLLIN)
        self.rx = bytearray()
        self.eof = False
        self.error = 0
        self.connected = False
        self.tx = bytearray()

    def pump(self) -> None:
        """Move whatever the OS has received into ``rx``; note end of stream and resets."""
        if not self.connected or self.eof:
            return
        while self.poller is None or self.poller.poll(0):
            try:
                data = self.sock.recv(65536)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.eof, self.error = True, ERR_CLOSED
                return
            if not data:
                self.eof = True
                return
            self.rx += data

    def flush(self) -> bool:
        """Send pending bytes; True when all are handed to the OS."""
        while self.tx:
            try:
                n = self.sock.send(self.tx)
            except (BlockingIOError, InterruptedError):
                return False
            except OSError:
                self.error = ERR_CLOSED
                raise
            del self.tx[:n]
        return True


class SocketManager:
    """The controller's socket table (handles 1..N) shared by all socket instructions of one PLC."""

    def __init__(self, limit: int = 30, latency_ns: int = 0) -> None:
        self.limit = limit
        self.latency_ns = latency_ns
        self.conns: dict[int, _Conn] = {}
        self._next = 1

    def open(self, host: str, port: int, src_port: int = 0) -> tuple[int, int]:
        """Start a non-blocking connect; returns (handle, 0) or (0, ErrorID)."""
        if len(self.conns) >= self.limit:
            return 0, ERR_RESOURCES
        try:
            ipaddress.IPv4Address(host)
        except ValueError:
            return 0, ERR_ADDRESS
        if not 0 < port < 65536:
            return 0, ERR_PARAM
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.setblocking(False)
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        try:
            if src_port:
                s.bind(("0.0.0.0", src_port))
            rc = s.connect_ex((host, port))
        except OSError:
            s.close()
            return 0, ERR_REFUSED
        if rc not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK, errno.EALREADY):
            s.close()
            return 0, ERR_REFUSED
        handle = self._next
        self._next = self._next % 0xFFFF_FFFF + 1
        self.conns[handle] = _Conn(s)
        return handle, 0

    def connect_result(self, handle: int) -> int | None:
        """None while connecting, 0 when connected, else an ErrorID (the handle is then released)."""
        c = self.conns.get(handle)
        if c is None:
            return ERR_HANDLE
        err = c.sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
        if err == 0:
            try:
                c.sock.getpeername()
            except OSError:
                return None
            c.connected = True
            return 0
        if err in (errno.EINPROGRESS, errno.EALREADY):
            return None
        self.close(handle)
        return ERR_REFUSED

    def listen(self, port: int, host: str = "127.0.0.1") -> tuple[socket.socket | None, int]:
        """Open a non-blocking listening socket for a passive open; returns (socket, 0) or (None, ErrorID)."""
        if len(self.conns) >= self.limit:
            return None, ERR_RESOURCES
        if not 0 < port < 65536:
            return None, ERR_PARAM
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.setblocking(False)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
            s.listen(1)
        except OSError:
            s.close()
            return None, ERR_PORT_IN_USE
        return s, 0

    def adopt(self, sock: socket.socket) -> int:
        """Register an accepted connection; returns its handle (0 when the table is full)."""
        if len(self.conns) >= self.limit:
            sock.close()
            return 0
        sock.setblocking(False)
        handle = self._next
        self._next = self._next % 0xFFFF_FFFF + 1
        c = _Conn(sock)
        c.connected = True
        self.conns[handle] = c
        return handle

    def get(self, handle: int) -> _Conn | None:
        return self.conns.get(handle)

    def addresses(self, handle: int) -> tuple[tuple[str, int], tuple[str, int]]:
        c = self.conns.get(handle)
        if c is None:
            return ("", 0), ("", 0)
        try:
            return c.sock.getsockname(), c.sock.getpeername()
        except (OSError, AttributeError):
            return ("", 0), ("", 0)

    def status(self, handle: int) -> tuple[int, bool]:
        c = self.conns.get(handle)
        if c is None:
            return CLOSED, False
        if not c.connected:
            if self.connect_result(handle) is None:
                return SYN_SENT, False
            c = self.conns.get(handle)
            if c is None:
                return CLOSED, False
        c.pump()
        return (CLOSE_WAIT if c.eof else ESTABLISHED), bool(c.rx)

    def close(self, handle: int) -> bool:
        c = self.conns.pop(handle, None)
        if c is None:
            return False
        with contextlib.suppress(OSError):
            c.sock.close()
        return True

    def close_all(self) -> None:
        for h in list(self.conns):
            self.close(h)
