"""TCP adapter of the Ethernet Slave ($TMSVR): one listening port per robot, served by the SimServer's
selector and clock (thin: bytes in and out; the protocol is ``tmsim.protocol.svr_session``).

TMscript 2.24 chapter 17: the robot's Ethernet Slave listens on port 5891; the simulator gives robot i
the port ``svr_port + i`` (the CLI's default ``svr_port`` is the first port after the Listen node ports,
so one robot gets 5890 and 5891). The Ethernet Slave keeps serving while the project is stopped; it is
a service of the controller, not of the project.

Limits: a received frame's DATA <= FRAME_DATA_MAX (longer: CPERR 01); SVR_CLIENTS_MAX connections per robot;
a client that leaves more than SVR_OUTBOX_MAX bytes unread is dropped (tmsim/limits.py).
"""
from __future__ import annotations

import contextlib
import selectors
import socket
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from tmsim.limits import SVR_CLIENTS_MAX, SVR_OUTBOX_MAX
from tmsim.net.tcp_listener import Listener, receive, send_out
from tmsim.protocol.svr_session import DEFAULT_STREAM, SvrSession
from tmsim.robot.svr_source import RobotDataSource

if TYPE_CHECKING:
    from tmsim.net.robot_ports import Robot


class SlaveHost(Protocol):
    """What the Ethernet Slave adapter needs of the server it joins (``SimServer``): its one selector, the
    host it listens on, the robot clock, the robots, and a handler for its own selector keys."""

    @property
    def selector(self) -> selectors.BaseSelector: ...

    @property
    def host(self) -> str: ...

    @property
    def now(self) -> float: ...

    @property
    def robots(self) -> Sequence[Robot]: ...

    def handle(self, kind: str, handler: Callable[[Any, Any], None]) -> None:
        """Serve the selector keys of ``kind`` with ``handler(robot, conn)``."""
        ...


class SvrConn:
    """One Ethernet Slave client socket of a robot."""
    __slots__ = ("sock", "id", "wbuf", "robot")

    def __init__(self, sock: socket.socket, conn_id: int, robot: Robot):
        self.sock, self.id, self.robot = sock, conn_id, robot
        self.wbuf = bytearray()


@dataclass(eq=False)
class SlaveService:
    """The Ethernet Slave of one robot (``Robot.slave``): the data table's values, the sans-I/O session, the
    listening socket and the client connections."""
    source: RobotDataSource
    session: SvrSession
    listener: Listener | None = None
    conns: dict[int, SvrConn] = field(default_factory=dict)

    @property
    def port(self) -> int | None:
        """The port it listens on (None before it listens)."""
        return None if self.listener is None else self.listener.port


class EthernetSlave:
    """Ethernet Slave of every robot of ``server``; ``port`` 0 = ephemeral ports."""

    def __init__(self, server: SlaveHost, port: int = 0, period: float = 0.1, mode: int = 1,
                 items: Iterable[str] = DEFAULT_STREAM, variables: Iterable = ()):
        self.server = server
        self.listeners: list[Listener] = []
        self._services: dict[int, SlaveService] = {}      # robot index -> its Ethernet Slave
        self._next_conn = 1
        server.handle("svr_listen", self._accept)
        server.handle("svr_conn", self._read)
        try:
            for robot in server.robots:
                log = robot.log.event
                source = RobotDataSource(robot, log)
                service = SlaveService(source, SvrSession(source, log, items, mode, period, variables=variables))
                self._services[robot.index] = service
                robot.attach_slave(service)
                self._listen(robot, service, port + robot.index if port else 0)
        except OSError:
            self.close()
            raise

    def _listen(self, robot: Robot, service: SlaveService, port: int) -> None:
        service.listener = Listener(self.server.selector, self.server.host, port, ("svr_listen", None, robot),
                                    f"open the Ethernet Slave of robot {robot.index + 1} on {{where}}")
        self.listeners.append(service.listener)
        robot.log.event("svr_listening", host=self.server.host, port=service.port)

    # ---- per poll -----------------------------------------------------------------------------
    def poll(self, now: float) -> None:
        """Stream the data tables that are due and send what is waiting (called by SimServer.poll)."""
        for robot in self.server.robots:
            service = self._services.get(robot.index)
            if service is None:
                continue
            listener = service.listener
            if listener is not None and listener.paused_until is not None:
                listener.tick(now)
            if service.session.clients:
                service.session.advance(now)
                self._flush(robot)

    def next_due(self, now: float) -> float | None:
        """The earliest robot-clock time at which ``poll`` has work: a data table due (``SvrSession.next_due``), the
        end of an accept pause, ``now`` while a client's socket has not taken all its output. None: nothing."""
        due = None
        for service in self._services.values():
            for conn in service.conns.values():
                if conn.wbuf:
                    return now
            paused = None if service.listener is None else service.listener.paused_until
            for at in (service.session.next_due(now), paused):
                if at is not None and (due is None or at < due):
                    due = at
        return due

    def _accept(self, _none: None, robot: Robot) -> None:
        service = self._service(robot)
        listener = service.listener
        if listener is None:
            return
        for _ in range(16):
            accepted = listener.accept(self.server.now, robot.log.event, prefix="svr_")
            if accepted is None:
                return
            sock, addr = accepted
            if len(service.conns) >= SVR_CLIENTS_MAX:
                robot.log.event("svr_rejected_connection", peer=addr[0],
                                reason=f"more than {SVR_CLIENTS_MAX} clients")
                sock.close()
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            conn = SvrConn(sock, self._next_conn, robot)
            self._next_conn += 1
            service.conns[conn.id] = conn
            service.session.connect(conn.id, addr[0])
            self.server.selector.register(sock, selectors.EVENT_READ, ("svr_conn", None, conn))

    def _read(self, _none: None, conn: SvrConn) -> None:
        robot = conn.robot
        service = self._service(robot)
        if conn.id not in service.conns:
            return
        data, failed = receive(conn.sock)
        if failed or data == b"":
            self._drop(robot, conn, failed or "peer closed")
            return
        if data is None:
            return
        try:
            service.session.receive_data(conn.id, data)
        except Exception as exc:          # noqa: BLE001 - safety net: one bad client never stops the others
            robot.log.event("internal_error", conn=conn.id, error=f"{type(exc).__name__}: {exc}")
            self._drop(robot, conn, "internal error while handling this Ethernet Slave client")
            return
        self._flush(robot)

    def _flush(self, robot: Robot) -> None:
        service = self._service(robot)
        session = service.session
        for conn_id in list(session.clients):
            conn = service.conns.get(conn_id)
            if conn is None or (not conn.wbuf and not session.has_output(conn_id)):
                continue
            frames = session.data_to_send(conn_id)
            try:
                send_out(conn.sock, conn.wbuf, frames)
            except OSError as exc:
                self._drop(robot, conn, f"send failed: {exc.strerror}")
                continue
            if len(conn.wbuf) > SVR_OUTBOX_MAX:
                self._drop(robot, conn, f"client does not read (more than {SVR_OUTBOX_MAX} bytes waiting)")

    def _drop(self, robot: Robot, conn: SvrConn, reason: str) -> None:
        service = self._service(robot)
        if service.conns.pop(conn.id, None) is None:
            return
        with contextlib.suppress(KeyError, ValueError):
            self.server.selector.unregister(conn.sock)
        conn.sock.close()
        service.session.disconnect(conn.id)
        robot.log.event("svr_closed", conn=conn.id, reason=reason)

    # ---- fault injection ----------------------------------------------------------------------
    def inject(self, robot: Robot, fault: str, **params: Any) -> None:
        """``stall`` (enabled=True): no data table and no answers, connections stay open;
        ``corrupt_checksum`` (count=1): the next frames leave with a wrong checksum;
        ``disconnect``: every Ethernet Slave client of the robot is closed now;
        ``refuse_writes`` (status=6): every well-formed write is answered with that status code (1..7), nothing is
        written; ``answer_other_item`` (item, instead): ``instead`` is sent wherever ``item`` would be.
        ValueError when unknown."""
        service = self._service(robot)
        service.session.inject(fault, **params)   # checks the fault and its parameters; arms the protocol's
        if fault == "disconnect":                 # ... the sockets are this adapter's
            for conn in list(service.conns.values()):
                self._drop(robot, conn, "fault: disconnect")
        robot.log.event("svr_fault", fault=fault, params=params)

    def clear_faults(self, robot: Robot) -> None:
        self._service(robot).session.clear_faults()
        robot.log.event("svr_fault", fault="cleared", params={})

    def close(self) -> None:
        for robot in self.server.robots:
            service = self._services.get(robot.index)
            if service is not None:
                for conn in list(service.conns.values()):
                    self._drop(robot, conn, "simulator closed")
        for listener in self.listeners:
            listener.close()
        self.listeners = []

    def _service(self, robot: Robot) -> SlaveService:
        """The robot's Ethernet Slave (every robot of a server that runs one has it from the start)."""
        service = self._services.get(robot.index)
        if service is None:
            raise RuntimeError(f"robot {robot.index + 1} has no Ethernet Slave")
        return service


