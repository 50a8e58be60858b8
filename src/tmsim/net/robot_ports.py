"""The control interface of one simulated robot (``SimServer.robots[i]``) and the services it holds, each
declared in its constructor: its event log, its Listen node (session, listening socket, client connections),
its output-side faults and, when the server runs one, its Ethernet Slave. The server (tmsim/net/server.py) moves
the bytes; a ``Robot`` is what the control channel, the Ethernet Slave's stick buttons and the tests drive.
"""
from __future__ import annotations

import socket
from collections.abc import Mapping
from contextlib import AbstractContextManager
from typing import TYPE_CHECKING, Any, Protocol

from tmsim.protocol.listen_session import NODE_FAULTS, ListenSession
from tmsim.protocol.svr_session import SvrSession
from tmsim.robot.camera import Camera, camera_of
from tmsim.robot.eventlog import EventLog
from tmsim.robot.faults import FaultState
from tmsim.robot.faults import check_params as check_fault_params
from tmsim.robot.model import RobotModel
from tmsim.robot.svr_source import RobotDataSource
from tmsim.tmscript.profiles import Profile

if TYPE_CHECKING:
    from tmsim.net.tcp_listener import Listener
    from tmsim.robot.eventlog import LogFile


class RobotHost(Protocol):
    """What a robot needs of the server that holds it (``SimServer``): the lock its calls take, the shares of
    the event log bounds and the log file, and the calls that open, close and refuse its Listen-node sockets."""

    @property
    def lock(self) -> AbstractContextManager[Any]: ...

    @property
    def event_limit(self) -> int: ...

    @property
    def event_bytes_limit(self) -> int: ...

    @property
    def log_file(self) -> LogFile | None: ...

    @property
    def auto_enter(self) -> bool: ...

    def open_port(self, robot: Robot) -> None:
        """Listen on the robot's Listen-node port (no-op while it listens or refuses connections)."""
        ...

    def close_robot_sockets(self, robot: Robot) -> None:
        """Close the robot's client connections and its listening socket."""
        ...

    def apply_refuse(self, robot: Robot) -> None:
        """Close or reopen the robot's listening socket as its ``refuse_connections`` fault says."""
        ...

    def drop(self, robot: Robot, conn: Conn, reason: str) -> None:
        """Close one client connection of the robot."""
        ...


class SlavePort(Protocol):
    """What a robot shows of its Ethernet Slave (``ethernet_slave.SlaveService``, attached by that adapter)."""

    @property
    def session(self) -> SvrSession: ...

    @property
    def source(self) -> RobotDataSource: ...

    @property
    def conns(self) -> Mapping[int, Any]: ...

    @property
    def port(self) -> int | None: ...


class Conn:
    """One client socket of a robot; what it received waits in the robot's session (``buffer_data``)."""
    __slots__ = ("sock", "id", "wbuf", "eof", "peer", "greedy", "_session")

    def __init__(self, sock: socket.socket, conn_id: int, peer: str, session: ListenSession):
        self.sock, self.id, self.peer = sock, conn_id, peer
        self.wbuf = bytearray()
        self.eof = False
        self.greedy = False                     # its last read filled RECV_BYTES, or input is left over
        self._session = session

    @property
    def suppressed(self) -> int:
        """Bad packets of this client not answered (CPERR limit) and not logged yet; the session counts."""
        return self._session.unanswered_bad(self.id)


class Robot:
    """Control interface of one simulated robot (``SimServer.robots[i]``) and the services it holds: its event
    log (``log``), its Listen node (``session``, ``listener``, ``conns``), its output-side faults (``faults``)
    and, when the server runs one, its Ethernet Slave (``slave``, attached by tmsim/net/ethernet_slave.py)."""

    def __init__(self, server: RobotHost, index: int, port: int, send_message: str, auto_enter: bool,
                 profile: Profile, timeouts: tuple[float | None, float | None],
                 frames: tuple[Any, Any] = (None, None)):
        self._server = server
        self.index: int = index
        self.port: int = port
        self.log: EventLog = EventLog(index, server.event_limit, server.event_bytes_limit, server.log_file)
        self.faults: FaultState = FaultState()
        self.session: ListenSession = ListenSession(RobotModel(bases=frames[0], tools=frames[1]),
                                     send_message, self.log.event,
                                     auto_enter=auto_enter, data_timeout=timeouts[0], connection_timeout=timeouts[1],
                                     profile=profile)
        self.log.follow(self.session)          # events carry the session's robot clock, bill its work meter
        self.listener: Listener | None = None
        self.port_hold: socket.socket | None = None    # the Listen-node port, bound but not listening while closed
        self.conns: dict[int, Conn] = {}
        self.reading_paused: bool = False
        self.slave: SlavePort | None = None  # the robot's Ethernet Slave; None with --no-svr

    def camera(self) -> Camera:
        """The robot's virtual camera (its vision jobs, tmsim/robot/camera.py)."""
        return camera_of(self.session.robot)

    def attach_slave(self, service: SlavePort) -> None:
        """The server runs an Ethernet Slave: this robot's (tmsim/net/ethernet_slave.py builds it)."""
        self.slave = service

    # ---- the Ethernet Slave's parts (None / empty with --no-svr) ------------------------------
    @property
    def svr(self) -> SvrSession | None:
        """The Ethernet Slave's sans-I/O session."""
        return None if self.slave is None else self.slave.session

    @property
    def svr_source(self) -> RobotDataSource | None:
        """The Ethernet Slave's data table values (and the writes acted out on the robot)."""
        return None if self.slave is None else self.slave.source

    @property
    def svr_conns(self) -> Mapping[int, Any]:
        """The Ethernet Slave's client connections (``ethernet_slave.SvrConn`` by connection number)."""
        return {} if self.slave is None else self.slave.conns

    @property
    def svr_port(self) -> int | None:
        """The port the Ethernet Slave listens on."""
        return None if self.slave is None else self.slave.port

    def next_due(self, now: float) -> float | None:
        """The earliest robot-clock time at which a poll has work for this robot's Listen node without new input:
        its session's (``ListenSession.next_due``: the arm moving, a script's wait, the node's timeouts), its held
        output (``FaultState.next_due``: reply_delay, glue_replies, split_replies), the end of an accept pause,
        ``now`` while output waits to be written or a client's socket has not taken all of it. None: nothing."""
        due = self.session.next_due(now)
        if self.conns:
            if self.session.has_output():
                return now
            for conn in self.conns.values():
                if conn.wbuf:
                    return now
            held = self.faults.next_due(now)
            if held is not None and (due is None or held < due):
                due = held
        paused = None if self.listener is None else self.listener.paused_until
        if paused is not None and (due is None or paused < due):
            due = paused
        return due

    # ---- the event log (``log``), read by the control channel, the demo and the tests -----------
    @property
    def events(self) -> list[dict]:
        """The events kept in memory, oldest first."""
        return self.log.events

    @property
    def events_dropped(self) -> int:
        """Events removed from the front of ``events`` so far."""
        return self.log.events_dropped

    @property
    def event_bytes(self) -> int:
        """Bytes the kept events count."""
        return self.log.event_bytes

    def event_sizes(self, start: int, count: int) -> list[int]:
        """Bytes the event log counts for events[start:start + count]."""
        return self.log.event_sizes(start, count)

    def wait_event(self, kind: str, timeout: float = 5.0, since: int = 0, **fields: Any) -> dict | None:
        """First event of ``kind`` whose fields equal ``fields`` (see EventLog.wait_event)."""
        return self.log.wait_event(kind, timeout, since, **fields)

    # ---- control ------------------------------------------------------------------------------
    def enter_listen_node(self) -> None:
        with self._server.lock:
            self.session.enter_node()

    def leave_listen_node(self) -> None:
        with self._server.lock:
            self.session.leave_node()

    def stop_project(self) -> None:
        with self._server.lock:
            self.session.stop_project()
            self._server.close_robot_sockets(self)

    def start_project(self, enter_node: bool | None = None) -> None:
        with self._server.lock:
            self.session.start_project(enter_node=False)
            self._server.open_port(self)
            if self._server.auto_enter if enter_node is None else enter_node:
                self.session.enter_node()

    def inject(self, fault: str, **params: Any) -> None:
        """Arm a fault (see docs/simulator.md, 'Fault injection'); raises ValueError when unknown or when a
        parameter is out of its range (faults.PARAMS)."""
        check_fault_params(fault, params)
        with self._server.lock:
            if fault in NODE_FAULTS:             # the Listen node's own faults (ListenSession.inject)
                self.session.inject(fault, **params)
                if fault == "stop_project":
                    self._server.close_robot_sockets(self)
            elif fault == "refuse_connections":
                self.faults.arm(fault, **params)
                self._server.apply_refuse(self)
            elif fault == "disconnect":
                for conn in list(self.conns.values()):
                    self._server.drop(self, conn, "fault: disconnect")
            else:
                self.faults.arm(fault, **params)
            self.log.event("fault", fault=fault, params=params)

    def clear_faults(self) -> None:
        with self._server.lock:
            held = self.faults
            self.faults = FaultState()
            self.faults.adopt(held)          # frames already held back still leave at their time
            self.session.clear_faults()
            self._server.apply_refuse(self)
            self.log.event("fault", fault="cleared", params={})

    def state(self) -> dict:
        with self._server.lock:
            data = self.session.snapshot()
            data.update(port=self.port, clients=len(self.conns), faults=self.faults.describe(),
                        events_kept=len(self.events), event_bytes=self.event_bytes)
            return data
