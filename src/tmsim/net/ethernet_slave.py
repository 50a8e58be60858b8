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

import selectors
import socket

from tmsim.limits import SVR_CLIENTS_MAX, SVR_OUTBOX_MAX
from tmsim.net.tcp_listener import Listener, receive
from tmsim.protocol.svr_session import DEFAULT_STREAM, SvrSession
from tmsim.robot.svr_source import RobotDataSource


class _Conn:
    __slots__ = ("sock", "id", "wbuf", "robot")

    def __init__(self, sock, conn_id, robot):
        self.sock, self.id, self.robot = sock, conn_id, robot
        self.wbuf = bytearray()


class EthernetSlave:
    """Ethernet Slave of every robot of ``server``; ``port`` 0 = ephemeral ports."""

    def __init__(self, server, port=0, period=0.1, mode=1, items=DEFAULT_STREAM, variables=()):
        self.server = server
        self.listeners = []
        self._next_conn = 1
        server.handle("svr_listen", self._accept)
        server.handle("svr_conn", self._read)
        try:
            for robot in server.robots:
                robot.svr_source = RobotDataSource(robot, robot._log)
                robot.svr = SvrSession(robot.svr_source, robot._log, items, mode, period, variables=variables)
                robot.svr_conns = {}
                self._listen(robot, port + robot.index if port else 0)
        except OSError:
            self.close()
            raise

    def _listen(self, robot, port):
        robot.svr_listener = Listener(self.server.selector, self.server.host, port, ("svr_listen", None, robot),
                                      f"open the Ethernet Slave of robot {robot.index + 1} on {{where}}")
        robot.svr_port = robot.svr_listener.port
        self.listeners.append(robot.svr_listener)
        robot._log("svr_listening", host=self.server.host, port=robot.svr_port)

    # ---- per poll -----------------------------------------------------------------------------
    def poll(self, now):
        """Stream the data tables that are due and send what is waiting (called by SimServer.poll)."""
        for robot in self.server.robots:
            if robot.svr_listener is not None:
                robot.svr_listener.tick(now)
            if robot.svr.clients:
                robot.svr.advance(now)
                self._flush(robot)

    def _accept(self, _none, robot):
        for _ in range(16):
            accepted = robot.svr_listener.accept(self.server.now, robot._log, prefix="svr_")
            if accepted is None:
                return
            sock, addr = accepted
            if len(robot.svr_conns) >= SVR_CLIENTS_MAX:
                robot._log("svr_rejected_connection", peer=addr[0], reason=f"more than {SVR_CLIENTS_MAX} clients")
                sock.close()
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            conn = _Conn(sock, self._next_conn, robot)
            self._next_conn += 1
            robot.svr_conns[conn.id] = conn
            robot.svr.connect(conn.id, addr[0])
            self.server.selector.register(sock, selectors.EVENT_READ, ("svr_conn", None, conn))

    def _read(self, _none, conn):
        robot = conn.robot
        if conn.id not in robot.svr_conns:
            return
        data, failed = receive(conn.sock)
        if failed or data == b"":
            self._drop(robot, conn, failed or "peer closed")
            return
        if data is None:
            return
        try:
            robot.svr.receive_data(conn.id, data)
        except Exception as exc:          # noqa: BLE001 - safety net: one bad client never stops the others
            robot._log("internal_error", conn=conn.id, error=f"{type(exc).__name__}: {exc}")
            self._drop(robot, conn, "internal error while handling this Ethernet Slave client")
            return
        self._flush(robot)

    def _flush(self, robot):
        for conn_id in list(robot.svr.clients):
            conn = robot.svr_conns.get(conn_id)
            if conn is None or (not conn.wbuf and not robot.svr.has_output(conn_id)):
                continue
            frames = robot.svr.data_to_send(conn_id)
            try:
                for frame in frames:
                    if conn.wbuf:
                        conn.wbuf += frame
                    else:
                        conn.wbuf += frame[_send(conn.sock, frame):]
                if conn.wbuf:
                    del conn.wbuf[:_send(conn.sock, conn.wbuf)]
            except OSError as exc:
                self._drop(robot, conn, f"send failed: {exc.strerror}")
                continue
            if len(conn.wbuf) > SVR_OUTBOX_MAX:
                self._drop(robot, conn, f"client does not read (more than {SVR_OUTBOX_MAX} bytes waiting)")

    def _drop(self, robot, conn, reason):
        if robot.svr_conns.pop(conn.id, None) is None:
            return
        try:
            self.server.selector.unregister(conn.sock)
        except (KeyError, ValueError):
            pass
        conn.sock.close()
        robot.svr.disconnect(conn.id)
        robot._log("svr_closed", conn=conn.id, reason=reason)

    # ---- fault injection ----------------------------------------------------------------------
    def inject(self, robot, fault, **params):
        """``stall`` (enabled=True): no data table and no answers, connections stay open;
        ``corrupt_checksum`` (count=1): the next frames leave with a wrong checksum;
        ``disconnect``: every Ethernet Slave client of the robot is closed now;
        ``refuse_writes`` (status=6): every well-formed write is answered with that status code (1..7), nothing is
        written. ValueError when unknown."""
        robot.svr.inject(fault, **params)         # checks the fault and its parameters; arms the protocol's
        if fault == "disconnect":                 # ... the sockets are this adapter's
            for conn in list(robot.svr_conns.values()):
                self._drop(robot, conn, "fault: disconnect")
        robot._log("svr_fault", fault=fault, params=params)

    def clear_faults(self, robot):
        robot.svr.clear_faults()
        robot._log("svr_fault", fault="cleared", params={})

    def close(self):
        for robot in self.server.robots:
            for conn in list(robot.svr_conns.values()):
                self._drop(robot, conn, "simulator closed")
        for listener in self.listeners:
            listener.close()
        self.listeners = []


def _send(sock, data) -> int:
    try:
        return sock.send(data)
    except (BlockingIOError, InterruptedError):
        return 0
