"""POUs declared ``{native}`` in the prelude, implemented in Python.

Function blocks are classes built as ``cls(rt, path)`` whose variables are attributes named like the ST
parameters and whose ``i__run()`` executes one call. Functions take ``rt`` first, then the parameters in
declaration order; a generic (ANY_ELEMENTARY) parameter is followed by its actual type; a scalar VAR_IN_OUT
arrives as a (container, key) reference, an array as a list or an array view.
"""
from __future__ import annotations

import socket
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from . import iec
from . import sockets as S
from .motion_fbs import NATIVE_FBS as MOTION_FBS
from .sysmac_control import NATIVE_FBS as CONTROL_FBS
from .sysmac_errors import FUNCTIONS as ERROR_FUNCTIONS
from .sysmac_errors import NATIVE_FBS as ERROR_FBS
from .sysmac_fns import FUNCTIONS
from .testing import FUNCTIONS as TEST_FUNCTIONS

if TYPE_CHECKING:
    from .engine import Engine


class _SocketFB:
    """Execute/Busy/Done/Error handshake shared by the socket instructions."""

    def __init__(self, rt: Engine, path: str) -> None:
        self.i__rt, self.i__path = rt, path
        self.Execute = False
        self.Done = self.Busy = self.Error = False
        self.ErrorID = 0
        self.Socket = rt.new_struct("_sSOCKET")
        self.i__state = "idle"
        self.i__t0 = 0

    def i__run(self) -> None:
        ex = self.Execute
        st = self.i__state
        if st == "shown":
            if not ex:
                self.Done = self.Error = False
                self.ErrorID = 0
                self.i__state = st = "idle"
                self.i__last = False
                return
            return
        if st == "idle":
            if ex and not getattr(self, "i__last", False):
                self.Done = self.Error = False
                self.ErrorID = 0
                self.Busy = True
                self.i__state = "busy"
                self.i__t0 = self.i__rt.now_ns
                self.start()
            self.i__last = ex
            return
        # busy: complete at the earliest one call later and after the latency
        rt = self.i__rt
        if rt.now_ns - self.i__t0 < rt.sockets.latency_ns:
            return
        result = self.poll()
        if result is None:
            return
        self.Busy = False
        if result:
            self.Error, self.ErrorID = True, result
        else:
            self.Done = True
        self.i__state = "shown"
        self.i__last = ex

    def start(self) -> None:
        self.i__err = 0

    def poll(self) -> int | None:
        """The instruction's result once it has one: 0 (Done) or its ErrorID; None while it is still busy."""
        raise NotImplementedError(f"{type(self).__name__} does not say when it is done")

    def handle(self) -> int:
        return self.Socket.Handle


class SktTCPConnect(_SocketFB):
    def __init__(self, rt: Engine, path: str) -> None:
        super().__init__(rt, path)
        self.SrcTcpPort = 0
        self.DstAdr = ""
        self.DstTcpPort = 0

    def start(self) -> None:
        self.i__handle, self.i__err = self.i__rt.sockets.open(self.DstAdr, self.DstTcpPort, self.SrcTcpPort)

    def poll(self) -> int | None:
        if self.i__err:
            return self.i__err
        mgr = self.i__rt.sockets
        r = mgr.connect_result(self.i__handle)
        if r is None:
            return None
        if r == 0:
            (sh, sp), (dh, dp) = mgr.addresses(self.i__handle)
            self.Socket.Handle = self.i__handle
            self.Socket.SrcAdr.IpAdr, self.Socket.SrcAdr.PortNo = sh, sp
            self.Socket.DstAdr.IpAdr, self.Socket.DstAdr.PortNo = dh, dp
        return r


class SktTCPSend(_SocketFB):
    def __init__(self, rt: Engine, path: str) -> None:
        super().__init__(rt, path)
        self.Size = 0
        self.SendDat: list[int] = []

    def start(self) -> None:
        self.i__err = 0
        c = self.i__rt.sockets.get(self.Socket.Handle)
        if c is None:
            self.i__err = S.ERR_HANDLE
            return
        if self.Size > len(self.SendDat):
            self.i__err = S.ERR_PARAM
        else:
            c.pump()
        if not self.i__err and (c.eof or c.error):
            self.i__err = S.ERR_CLOSED
        if not self.i__err:
            c.tx += iec.bytes_of(self.SendDat, self.Size)
            # the controller's socket service transmits in the background as soon as the send is started;
            # only Done waits for the next call (what the OS does not take now goes out when polled)
            try:
                c.flush()
            except OSError:
                self.i__err = S.ERR_CLOSED

    def poll(self) -> int | None:
        if self.i__err:
            return self.i__err
        c = self.i__rt.sockets.get(self.Socket.Handle)
        if c is None:
            return S.ERR_HANDLE
        try:
            return 0 if c.flush() else None
        except OSError:
            return S.ERR_CLOSED


class SktTCPRcv(_SocketFB):
    def __init__(self, rt: Engine, path: str) -> None:
        super().__init__(rt, path)
        self.TimeOut = 0
        self.Size = 0
        self.RcvSize = 0
        self.RcvDat: list[int] = []

    def start(self) -> None:
        self.i__err = 0
        self.RcvSize = 0
        if self.Size > len(self.RcvDat):
            self.i__err = S.ERR_PARAM

    def poll(self) -> int | None:
        if self.i__err:
            return self.i__err
        rt = self.i__rt
        c = rt.sockets.get(self.Socket.Handle)
        if c is None:
            return S.ERR_HANDLE
        c.pump()
        if c.rx:
            n = min(len(c.rx), self.Size)
            iec.store_bytes(self.RcvDat, c.rx[:n])
            del c.rx[:n]
            self.RcvSize = n
            return 0
        if c.eof:
            return S.ERR_CLOSED
        # TimeOut in 0.1 s; 0 = no timeout: the receive stays Busy until data arrives (W506 9-2, receive
        # timeout monitoring; field evidence: Sysmac code waits seconds in a TimeOut 0 receive)
        if self.TimeOut and rt.now_ns - self.i__t0 >= self.TimeOut * 100_000_000:
            return S.ERR_TIMEOUT
        return None


class SktGetTCPStatus(_SocketFB):
    def __init__(self, rt: Engine, path: str) -> None:
        super().__init__(rt, path)
        self.TcpStatus = S.CLOSED
        self.DatRcvFlag = False

    def start(self) -> None:
        self.i__err = 0

    def poll(self) -> int | None:
        mgr = self.i__rt.sockets
        if mgr.get(self.Socket.Handle) is None:
            self.TcpStatus, self.DatRcvFlag = S.CLOSED, False
            return S.ERR_HANDLE
        self.TcpStatus, self.DatRcvFlag = mgr.status(self.Socket.Handle)
        return 0


class SktClearBuf(_SocketFB):
    def poll(self) -> int | None:
        c = self.i__rt.sockets.get(self.Socket.Handle)
        if c is None:
            return S.ERR_HANDLE
        c.pump()
        c.rx.clear()
        return 0


class SktClose(_SocketFB):
    def poll(self) -> int | None:
        return 0 if self.i__rt.sockets.close(self.Socket.Handle) else S.ERR_HANDLE


class SktTCPAccept(_SocketFB):
    """Passive open: listens on SrcTcpPort (bound to 127.0.0.1) until a client connects or TimeOut
    (0.1 s units, 0 = wait forever) expires."""

    def __init__(self, rt: Engine, path: str) -> None:
        super().__init__(rt, path)
        self.SrcTcpPort = 0
        self.TimeOut = 0
        self.i__listener: socket.socket | None = None

    def start(self) -> None:
        self.i__listener, self.i__err = self.i__rt.sockets.listen(self.SrcTcpPort)

    def poll(self) -> int | None:
        if self.i__err:
            return self.i__err
        listener = self.i__listener
        if listener is None:          # never reached: listen() gives a socket exactly when it reports no error
            return S.ERR_HANDLE
        rt = self.i__rt
        try:
            conn, _ = listener.accept()
        except (BlockingIOError, InterruptedError):
            if self.TimeOut and rt.now_ns - self.i__t0 >= self.TimeOut * 100_000_000:
                listener.close()
                return S.ERR_TIMEOUT
            return None
        listener.close()
        handle = rt.sockets.adopt(conn)
        if not handle:
            return S.ERR_RESOURCES
        (sh, sp), (dh, dp) = rt.sockets.addresses(handle)
        self.Socket.Handle = handle
        self.Socket.SrcAdr.IpAdr, self.Socket.SrcAdr.PortNo = sh, sp
        self.Socket.DstAdr.IpAdr, self.Socket.DstAdr.PortNo = dh, dp
        return 0


NATIVE_FBS: dict[str, type] = {c.__name__: c for c in (SktTCPConnect, SktTCPSend, SktTCPRcv, SktGetTCPStatus,
                                                       SktClearBuf, SktClose, SktTCPAccept)}
NATIVE_FBS.update(MOTION_FBS)           # W508 single-axis motion instructions on virtual axes
NATIVE_FBS.update(CONTROL_FBS, **ERROR_FBS)     # W502 control and system control instructions
NATIVE_FUNCTIONS: dict[str, Callable[..., Any]] = {**FUNCTIONS, **ERROR_FUNCTIONS, **TEST_FUNCTIONS}
