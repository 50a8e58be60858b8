"""SimServer: TCP adapter around the sans-I/O sessions (selectors, non-blocking, bounded buffers).

``poll(now_s)`` is one non-blocking step on a virtual clock: advance the robot models, accept,
read, process, write. ``start_background()`` runs the same step in a thread on the wall clock, and between two
steps sleeps until the next thing is due (``next_due``), a socket is ready or another thread wakes it.

Limits (per robot unless noted):
* frame DATA <= FRAME_DATA_MAX (64 KiB); longer declared lengths are answered with CPERR 01
* LISTEN_CLIENTS_MAX simultaneous connections; more are accepted and closed at once
* PENDING_SCRIPTS_MAX buffered scripts or their share of PENDING_BYTES_MAX (all robots together); beyond that the
  server stops reading from that robot's clients (TCP back-pressure) until the buffer is half empty
* LISTEN_OUTBOX_MAX bytes waiting to be sent to one client, OUTBOX_TOTAL_MAX to all clients of a robot; a client
  that does not read (the one with most waiting, for the total) is dropped
* fairness: each client's input is processed in bounded turns, floods after the others (tmsim/net/fairness.py);
  CPERR answers to bad packets limited per client (the session, tmsim/protocol/listen_session.py)
* the event log: bounded by count and bytes in memory, the file rotated at LOG_FILE_BYTES_MAX (tmsim/robot/eventlog.py)
* work: every turn of a robot (a client's input, advancing its motions and script) does at most TURN_WORK
  units; what is left goes on in its next turn, after the others (tmsim/tmscript/work.py)
"""
from __future__ import annotations

import contextlib
import gc
import math
import os
import selectors
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

from tmsim.limits import (
    EVENT_BYTES_MAX,
    EVENTS_KEPT_MAX,
    FRAME_DATA_MAX,
    IO_SLICE_S,
    LISTEN_CLIENTS_MAX,
    LISTEN_OUTBOX_MAX,
    LOOP_WAIT_MAX_S,
    LOOP_WAIT_MIN_S,
    OUTBOX_TOTAL_MAX,
    PENDING_BYTES_MAX,
    POLL_BUDGET_S,
    RECV_BYTES,
    TURN_WORK,
)
from tmsim.net.control import ControlChannel
from tmsim.net.ethernet_slave import EthernetSlave
from tmsim.net.fairness import FairScheduler
from tmsim.net.fairness import is_greedy as _is_greedy
from tmsim.net.robot_ports import Conn, Robot
from tmsim.net.tcp_listener import Listener, receive, send_out
from tmsim.robot.eventlog import LogFile
from tmsim.tmscript.profiles import Profile

RBUF_READ_BELOW = FRAME_DATA_MAX + 64     # a receive buffer this full holds a complete item: process it first
GC_IDLE = 700               # manage_gc: collect young objects in an idle poll once this many are waiting...
GC_FORCE = 20_000           # ...and in any poll once this many are (a flood leaves no idle poll)


class ServerLock:
    """The server's lock: re-entrant, and when a thread other than the one serving the loop lets go of it (its
    outermost release: a ``Robot`` call, a control call, a test's ``with server.lock:``), what is due may have
    changed (a node entered, a fault armed, a motion queued): ``on_release`` then wakes the sleeping loop."""

    def __init__(self, on_release: Callable[[], None]) -> None:
        self._lock = threading.RLock()
        self._depth = 0                     # the owner's nesting (changed by the owning thread only)
        self._on_release = on_release

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        if not self._lock.acquire(blocking, timeout):
            return False
        self._depth += 1
        return True

    def release(self) -> None:
        """RuntimeError, as an RLock's, when the calling thread does not hold the lock."""
        self._depth -= 1
        try:
            if self._depth == 0:
                self._on_release()
            self._lock.release()
        except RuntimeError:
            self._depth += 1
            raise

    def __enter__(self) -> bool:
        return self.acquire()

    def __exit__(self, *_exc: object) -> None:
        self.release()


class SimServer:
    def __init__(self, host: str = "127.0.0.1", port: int = 0, robots: int = 1, speedup: float = 1.0,
                 auto_enter: bool = True, send_message: str = "Listen1", log_path: str | os.PathLike[str] | None = None,
                 tag_history: int = 4, event_limit: int | None = None, control_port: int | None = None,
                 data_timeout: float | None = None, connection_timeout: float | None = None, bases: Any = None,
                 tools: Any = None, manage_gc: bool = False, svr_port: int | None = None,
                 svr_options: dict[str, Any] | None = None, control_host: str = "127.0.0.1",
                 profile: Profile | None = None):
        if not 1 <= robots <= 512:
            raise ValueError(f"robots must be 1..512, got {robots}")
        if not (math.isfinite(speedup) and speedup > 0):
            raise ValueError(f"speedup must be a positive number, got {speedup}")
        self.host, self.speedup, self.auto_enter = host, speedup, auto_enter
        self._serving: int | None = None     # the thread in serve_forever
        self._sleeping = False                # ... waits in select() for what is due (next_due)
        self._wake_pending = False            # a wake-up byte is on its way
        self.loop_waits = 0                   # serve_forever's waits so far (public counters, for tests and benches)
        self.wakeups = 0                      # wake-ups sent to it (``wake``: a call from another thread)
        self.lock = ServerLock(self._released)
        self.event_limit = event_limit or EVENTS_KEPT_MAX // robots    # per robot: all robots together keep <= 40,000
        self.event_bytes_limit = EVENT_BYTES_MAX // robots           # per robot: all together keep <= 20 MiB
        try:
            self.log_file = LogFile(log_path) if log_path else None
        except OSError as exc:
            raise OSError(exc.errno, f"cannot open the event log {log_path}: {exc.strerror}") from None
        self.selector = selectors.DefaultSelector()
        self._waker, self._wake_socket = socket.socketpair()    # written by ``wake``, read by the loop
        for end in (self._waker, self._wake_socket):
            end.setblocking(False)
        self.selector.register(self._wake_socket, selectors.EVENT_READ, ("wake", None, None))
        profile = profile or Profile(tag_history=tag_history)
        self.robots = [Robot(self, i, port + i if port else 0, send_message, auto_enter, profile,
                             (data_timeout, connection_timeout), (bases, tools)) for i in range(robots)]
        self._next_conn = 1
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._now = 0.0
        # selector key kind -> handler (see handle)
        self._dispatch: dict[str, Callable[[Any, Any], None]] = {"listen": self._accept, "conn": self._read,
                                                                  "wake": self._woken}
        self._touched: list[Robot] = []       # robots that received data and still have to advance
        # which client's input goes next and how much; a robot's share of PENDING_BYTES_MAX (at least 4 frames)
        self.fair = FairScheduler(self, max(4 * FRAME_DATA_MAX, PENDING_BYTES_MAX // robots))
        self._starting = False
        self._slice_start = self._poll_end = 0.0
        self.started = False
        self.manage_gc = manage_gc            # the CLI: garbage collection between bursts, see _collect_garbage
        self.control: ControlChannel | None = None
        self._control_port = control_port
        self.svr: EthernetSlave | None = None  # Ethernet Slave (tmsim/net/ethernet_slave.py) when svr_port is not None
        self._svr = (svr_port, svr_options or {})
        self._control_host = control_host

    @property
    def pending_bytes_limit(self) -> int:
        """Bytes of buffered scripts one robot may hold before its clients are no longer read."""
        return self.fair.pending_bytes_limit

    @property
    def ports(self) -> list[int]:
        return [r.port for r in self.robots]

    # ---- lifecycle ----------------------------------------------------------------------------
    def start(self) -> SimServer:
        with self.lock:
            try:
                for robot in self.robots:
                    self.open_port(robot)
                if self._control_port is not None:
                    self.control = ControlChannel(self, self._control_host, self._control_port)
                if self._svr[0] is not None:
                    self.svr = EthernetSlave(self, self._svr[0], **self._svr[1])
            except OSError:
                self.close()
                raise
            self.started = True
        return self

    def open_port(self, robot: Robot) -> None:
        if robot.listener is not None or robot.faults.refuse:
            return
        held, robot.port_hold = robot.port_hold, None
        robot.listener = Listener(self.selector, self.host, robot.port, ("listen", robot, None),
                                  f"listen on {{where}} for robot {robot.index + 1}", backlog=128, held=held)
        robot.port = robot.listener.port
        robot.log.event("listening", host=self.host, port=robot.port)

    def _close_listener(self, robot: Robot, hold_port: bool = True) -> None:
        """The port stays held (refusing connections) while the robot's server is down, so it comes back on it."""
        if robot.listener is not None:
            robot.port_hold = robot.listener.close(hold_port=hold_port)
            robot.listener = None

    def handle(self, kind: str, handler: Callable[[Any, Any], None]) -> None:
        """Serve the selector keys of ``kind`` with ``handler(robot, conn)``: how a port's TCP adapter (Ethernet
        Slave, control channel) joins the server's one selector and clock."""
        if kind in self._dispatch:
            raise ValueError(f"selector key kind {kind!r} is already served")
        self._dispatch[kind] = handler

    @property
    def now(self) -> float:
        """The robot clock (s) of the poll in progress."""
        return self._now

    def log_server(self, kind: str, **fields: Any) -> None:
        """An event of the server as a whole (control channel): logged in robot 0's log."""
        self.robots[0].log.event(kind, **fields)

    def apply_refuse(self, robot: Robot) -> None:
        if robot.faults.refuse and robot.listener is not None:
            self._close_listener(robot)
        elif not robot.faults.refuse and robot.listener is None and robot.session.project_running():
            self.open_port(robot)

    def close_robot_sockets(self, robot: Robot, reason: str = "project stopped") -> None:
        for conn in list(robot.conns.values()):
            self.drop(robot, conn, reason)
        if robot.listener is not None:
            self._close_listener(robot)

    def close(self) -> None:
        self.stop()
        with self.lock:
            for robot in self.robots:
                self.close_robot_sockets(robot, "simulator closed")
                if robot.port_hold is not None:
                    robot.port_hold.close()
                    robot.port_hold = None
            if self.control is not None:
                self.control.close()
                self.control = None
            if self.svr is not None:
                self.svr.close()
                self.svr = None
            self.selector.close()
            self._waker.close()
            self._wake_socket.close()
            if self.log_file is not None:
                for robot in self.robots:
                    robot.log.stop_writing()
                self.log_file.close()
                self.log_file = None

    def serve_forever(self, stop_event: threading.Event) -> None:
        """Serve in the calling thread on the wall clock (scaled by ``speedup``) until stop_event is set (seen
        within LOOP_WAIT_MAX_S; ``stop()`` wakes the loop at once).

        Between two polls the loop sleeps in the selector until the next thing is due (``next_due``, converted
        to wall seconds through ``speedup``), at least LOOP_WAIT_MIN_S (while an arm moves or a data table
        streams densely: the 2 ms steps the robot clock always had) and at most LOOP_WAIT_MAX_S; a ready socket
        ends the wait at once, and so does any call from another thread that takes the server's lock
        (``ServerLock``) or ``wake()``. Work left over from a turn (a flood's backlog) is served without a wait.
        An idle robot costs no CPU."""
        if not self.started:
            self.start()
        origin = time.monotonic()
        offset = self._now

        def clock() -> float:
            return offset + (time.monotonic() - origin) * self.speedup

        self._serving = threading.get_ident()
        ready: list[tuple[selectors.SelectorKey, int]] | None = None
        due: float | None = None
        fresh = LOOP_WAIT_MIN_S * self.speedup
        try:
            while not stop_event.is_set():
                with self.lock:         # one hold: a call of another thread comes before the poll or wakes the sleep
                    now = clock()
                    # a request right after the last poll, nothing due: served at once on the robots' state of that
                    # poll (at most LOOP_WAIT_MIN_S old, as the 2 ms steps always were); else they advance first
                    current = ready is not None and now - self._now <= fresh and (due is None or now < due)
                    self._poll(now, 0.0, ready, advance=not current)
                    now = clock()
                    due = self._next_due(now)
                    wait = self._loop_wait(now, due)
                    self._sleeping = wait > 0.0
                ready = None
                if wait > 0.0 and not stop_event.is_set():       # (a poll may have read stop()'s wake-up)
                    self.loop_waits += 1
                    ready = self.selector.select(wait) or None    # served by the next poll (no second select)
                    self._sleeping = False
        finally:
            self._serving = None
            self._sleeping = False

    def next_due(self, now: float | None = None) -> float | None:
        """The earliest robot-clock time (s) at which a poll has work without new input, or None when nothing is
        due until a client or a call changes something: each robot's (``Robot.next_due``: motions, scripts'
        waits, Listen node timeouts, held output), the Ethernet Slave's (data tables), the control channel's;
        ``now`` (default: the clock of the last poll) when work is left over from a turn."""
        with self.lock:
            return self._next_due(self._now if now is None else now)

    def _next_due(self, now: float) -> float | None:
        if self.fair.has_backlog or (self.control is not None and self.control.has_backlog):
            return now
        due = None
        for robot in self.robots:      # (the loop asks after every poll: no lists, stop at the first "now")
            at = robot.next_due(now)
            if at is not None and (due is None or at < due):
                if at <= now:
                    return now
                due = at
        for port in (self.svr, self.control):
            at = None if port is None else port.next_due(now)
            if at is not None and (due is None or at < due):
                due = at
        return due

    def _loop_wait(self, now: float, due: float | None) -> float:
        """Wall seconds serve_forever may sleep after a poll until ``due`` (0: none, work is left over)."""
        if due is None:
            return LOOP_WAIT_MAX_S
        if due <= now:
            return 0.0 if self._has_work() else LOOP_WAIT_MIN_S
        return min(LOOP_WAIT_MAX_S, max(LOOP_WAIT_MIN_S, (due - now) / self.speedup))

    def wake(self) -> None:
        """End serve_forever's wait now (thread-safe): what is due may have changed. Taking and releasing the
        server's lock from another thread does it."""
        if self._wake_pending:
            return
        self._wake_pending = True
        self.wakeups += 1
        with contextlib.suppress(OSError):      # (a full pipe: a wake-up is waiting already; closed: stopped)
            self._waker.send(b"w")

    def _released(self) -> None:
        """ServerLock: another thread lets go of the lock while the loop sleeps."""
        if self._sleeping and threading.get_ident() != self._serving:
            self.wake()

    def _woken(self, _robot: None, _conn: None) -> None:
        """The wake-up socket is readable: read what ``wake`` wrote (the poll that reads it is the wake-up)."""
        self._wake_pending = False
        with contextlib.suppress(OSError):
            while self._wake_socket.recv(4096):
                pass

    def start_background(self) -> SimServer:
        """Serve in a thread on the wall clock (scaled by ``speedup``) until ``stop()``."""
        if not self.started:
            self.start()
        self._stop.clear()
        thread = threading.Thread(target=self.serve_forever, args=(self._stop,), name="tmflow-sim", daemon=True)
        self._thread = thread
        thread.start()
        return self

    def stop(self) -> None:
        if self._thread is not None:
            self._stop.set()
            self.wake()
            self._thread.join(timeout=5)
            self._thread = None

    # ---- one step -----------------------------------------------------------------------------
    def poll(self, now_s: float, timeout: float = 0.0) -> None:
        """Advance to ``now_s`` and serve every socket that is ready; never blocks unless timeout>0.

        Replies leave as soon as their request is processed (before the motions it queued are
        started). Planning a motion (inverse kinematics, ~0.2 ms) happens when the motion starts;
        every IO_SLICE_S of such work the sockets are served in between, so a reply never waits for
        the planning of all robots (and the pushes of a tag reached leave robot by robot).
        """
        with self.lock:
            self._poll(now_s, timeout)

    def _poll(self, now_s: float, timeout: float, ready: list[tuple[selectors.SelectorKey, int]] | None = None,
              advance: bool = True) -> None:
        """``poll``, the lock held. From serve_forever: ``ready``, what its wait found ready (instead of a first
        select: a key that went stale meanwhile finds its connection gone, or nothing to read, and is passed
        over); ``advance`` False: the robots, the Ethernet Slave and the control channel stay at the last poll's
        time (nothing of theirs is due) and the sockets are served at once."""
        self._slice_start = time.perf_counter()
        self._poll_end = self._slice_start + POLL_BUDGET_S
        settled = advance and self._advance_all(max(self._now, now_s))
        if timeout and self._has_work():        # work left over from a turn: the sockets are not waited for
            timeout = 0.0
        served = self._serve(timeout, selected=ready)
        if settled and not served and not self._touched and not self.fair.has_backlog and \
                (self.control is None or not self.control.backlog):
            # the usual poll of a virtual-time rig (one per 1 ms PLC scan): no socket was ready, nothing is left
            # over, and every robot was settled after advancing - the steps below would find nothing to do
            if self.manage_gc:
                _collect_garbage(idle=True)
            return
        if self.fair.has_backlog:
            self.fair.serve_backlog()
        if self.control is not None and self.control.backlog:
            self.control.serve_backlog()
        if self._touched:
            self._start_touched()
        for robot in self.robots:
            if robot.conns:
                self.flush(robot)
            session = robot.session
            if (robot.listener is not None or robot.conns) and not session.project_running():
                self.close_robot_sockets(robot, "project stopped: " + (session.last_error or "stopped"))
            if robot.reading_paused and not self.fair.buffer_full(robot, 0.5):
                self._set_reading(robot, True)
        if self.manage_gc:
            _collect_garbage(idle=not served)

    def _advance_all(self, now: float) -> bool:
        """The robots, the Ethernet Slave and the control channel to ``now``: every robot's session advances
        (its clock and its turn's work meter move on even when nothing is due); what it pushed leaves at once.
        Returns whether every robot is settled: no output held or left to write, no client that closed its side
        or left the session, its project running while it has sockets, its clients read. Then the end of the
        poll has nothing to do unless a socket was ready or work is left over (``_poll``)."""
        self._now = now
        clock = time.perf_counter
        settled = True
        for robot in self.robots:
            listener = robot.listener
            if listener is not None and listener.paused_until is not None:
                listener.tick(now)
            self._advance(robot)
            session = robot.session
            conns = robot.conns
            if conns:
                faulty = robot.faults.active
                if session.has_output():
                    settled = False
                    if not faulty:
                        self.flush(robot)    # pushes (tag reached) leave at once; faulty output once a poll
                elif faulty:
                    settled = False
                elif settled:
                    for conn in conns.values():
                        if conn.wbuf or conn.eof or not session.is_connected(conn.id):
                            settled = False
                            break
            if settled and (robot.reading_paused or
                            ((robot.listener is not None or robot.conns) and not session.project_running())):
                settled = False
            if clock() - self._slice_start > IO_SLICE_S:
                self.breathe()
                settled = False
        if self.svr is not None:
            self.svr.poll(now)
        if self.control is not None:
            self.control.tick(now)
        return settled

    def _has_work(self) -> bool:
        """Work is left over from earlier turns (client input, control requests): the next poll must not wait."""
        return self.fair.has_backlog or (self.control is not None and self.control.has_backlog) or \
            any(robot.session.has_turn_work for robot in self.robots)

    def breathe(self, budgeted: bool = False) -> None:
        """Between two pieces of work: serve the sockets when IO_SLICE_S has passed since they were
        served. ``budgeted``: not after POLL_BUDGET_S (work that new requests extend - a flood of
        requests must not hold the clock)."""
        clock = time.perf_counter()
        if clock - self._slice_start <= IO_SLICE_S or (budgeted and clock > self._poll_end):
            return
        self._serve(0.0)
        self._slice_start = time.perf_counter()
        if not self._starting:
            self._start_touched()

    def _set_reading(self, robot: Robot, reading: bool) -> None:
        """Back-pressure: stop reading this robot's clients while its script buffer is full."""
        robot.reading_paused = not reading
        robot.log.event("reading_resumed" if reading else "reading_paused", buffered=robot.session.waiting_scripts)
        for conn in robot.conns.values():
            if reading and robot.session.input_bytes(conn.id):
                self.fair.requeue(robot, conn)    # input read before the pause
            if conn.eof:
                continue
            try:
                if reading:
                    self.selector.register(conn.sock, selectors.EVENT_READ, ("conn", robot, conn))
                else:
                    self.selector.unregister(conn.sock)
            except (KeyError, ValueError):
                pass

    # ---- the fair scheduler's host (tmsim/net/fairness.py TurnHost) ------------------------------
    def serve_ready(self, quick_only: bool = False) -> int:
        """Serve the sockets that are ready now, without waiting (``quick_only``: not the greedy clients)."""
        return self._serve(0.0, quick_only=quick_only)

    def touch(self, robot: Robot) -> None:
        """``robot`` received input: it advances with dt = 0 before the poll ends (``_start_touched``)."""
        if robot not in self._touched:
            self._touched.append(robot)

    def pause_reading(self, robot: Robot) -> None:
        """Back-pressure: the robot's script buffer is full; its clients are read again once it is half empty."""
        self._set_reading(robot, False)

    def _serve(self, timeout: float, quick_only: bool = False,
               selected: list[tuple[selectors.SelectorKey, int]] | None = None) -> int:
        """Accept and read every ready socket; the replies are written at once. Robots that received
        something are remembered in ``_touched`` for ``_start_touched``.

        Fairness: clients whose last read filled the receive size or who have input left over ("greedy",
        i.e. flooding) are served after the others, and every IO_SLICE_S in between them the sockets are
        polled again for the others' new requests (``quick_only``: serve only those). ``selected``: the
        sockets found ready already (no select)."""
        ready = self.selector.select(timeout) if selected is None else selected
        if not ready:
            return 0
        ready.sort(key=_is_greedy)
        checked = time.perf_counter()
        for key, _mask in ready:
            kind, robot, conn = key.data
            greedy = _is_greedy((key, _mask))
            if greedy:
                if quick_only:
                    continue
                if time.perf_counter() - checked > IO_SLICE_S:
                    self._serve(0.0, quick_only=True)
                    checked = time.perf_counter()
            try:
                self._dispatch[kind](robot, conn)
            except Exception as exc:          # safety net: one bad client never stops the others
                if robot is None or conn is None:
                    raise
                robot.log.event("internal_error", conn=conn.id, error=f"{type(exc).__name__}: {exc}")
                self.drop(robot, conn, "internal error while handling this client")
            if robot is not None:
                if robot not in self._touched:
                    self._touched.append(robot)
                if not robot.faults.active:
                    self.flush(robot, conn)
        return len(ready)

    def _advance(self, robot: Robot) -> None:
        """Advance one robot's session; an unexpected error becomes a robot error of that robot (its project
        stops, event ``internal_error``) instead of ending the thread that serves every robot."""
        robot.session.meter.begin(TURN_WORK)
        try:
            robot.session.advance(self._now)
        except Exception as exc:          # noqa: BLE001 - safety net, see docstring
            robot.log.event("internal_error", conn=None, error=f"{type(exc).__name__}: {exc}")
            robot.session.internal_error(f"internal error of the simulator ({type(exc).__name__})")

    def _start_touched(self) -> None:
        """Advance the robots that received scripts with dt = 0, so a motion queued now starts now."""
        self._starting = True
        try:
            while self._touched:
                robot = self._touched.pop(0)
                self._advance(robot)
                self.flush(robot)
                self.breathe(budgeted=True)
        finally:
            self._starting = False

    def _accept(self, robot: Robot, _conn: None) -> None:
        listener = robot.listener
        if listener is None:                # (closed by a fault since the selector reported it)
            return
        for _ in range(64):
            accepted = listener.accept(self._now, robot.log.event)
            if accepted is None:
                return
            sock, addr = accepted
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if len(robot.conns) >= LISTEN_CLIENTS_MAX:
                robot.log.event("rejected_connection", peer=addr[0], reason=f"more than {LISTEN_CLIENTS_MAX} clients")
                sock.close()
                continue
            conn = Conn(sock, self._next_conn, addr[0], robot.session)
            self._next_conn += 1
            robot.conns[conn.id] = conn
            robot.session.connect(conn.id, addr[0])
            self.selector.register(sock, selectors.EVENT_READ, ("conn", robot, conn))

    def _read(self, robot: Robot, conn: Conn) -> None:
        """Read what ``conn`` sent into the robot's session and give it a turn (unless it waits in the
        backlog). The server never decodes: the session owns the bytes (h11's model)."""
        if conn.id not in robot.conns or conn.eof:
            return
        if self.fair.buffer_full(robot):
            self._set_reading(robot, False)
            return
        if robot.session.input_bytes(conn.id) < RBUF_READ_BELOW:    # else: what is buffered goes first (fairness)
            data, failed = receive(conn.sock)
            if failed:
                self.drop(robot, conn, failed)
                return
            if data is None:
                return
            if not data:
                conn.eof = True
                self.selector.unregister(conn.sock)
                robot.log.event("peer_closed", conn=conn.id)
                return
            conn.greedy = len(data) == RECV_BYTES
            if robot.faults.black_hole:
                robot.log.event("black_hole", conn=conn.id, bytes=len(data))
                return
            robot.session.buffer_data(conn.id, data)
        if not self.fair.waits(robot, conn):     # else it waits for its turn in fair.serve_backlog
            self.fair.turn(robot, conn)

    def flush(self, robot: Robot, only: Conn | None = None) -> None:
        """Write what the robot's session produced; ``only``: just that client's output (cheap, right after
        its request), else every client's plus the per-robot checks (once a poll at least)."""
        if not robot.conns:                       # (the session has no client without a connection)
            return
        now = self._now
        faulty = robot.faults.active
        waiting = 0
        session = robot.session
        if only is not None:
            conns = [only]
        elif faulty or session.has_output():
            conns = list(robot.conns.values())
        else:                   # no frame to hand out: only a socket with bytes waiting or a closed side has work
            conns = [conn for conn in robot.conns.values() if conn.wbuf or conn.eof]
        for conn in conns:
            conn_id = conn.id
            if not session.is_connected(conn_id):
                continue
            frames = session.data_to_send(conn_id)          # the session logs them (event frame_out)
            if faulty:
                robot.faults.queue(conn_id, frames, now)
                chunks, close = robot.faults.take(conn_id, now)
            elif not frames and not conn.wbuf and not conn.eof:
                continue
            else:
                chunks, close = frames, False
            try:
                send_out(conn.sock, conn.wbuf, chunks)
            except OSError as exc:
                self.drop(robot, conn, f"send failed: {exc.strerror}")
                continue
            if len(conn.wbuf) > LISTEN_OUTBOX_MAX:
                self.drop(robot, conn, f"client does not read (more than {LISTEN_OUTBOX_MAX} bytes waiting)")
                continue
            waiting += len(conn.wbuf)
            if close:
                self.drop(robot, conn, "fault: close_mid_frame")
            elif conn.eof and not conn.wbuf and not robot.faults.holding(conn_id) and \
                    not robot.session.has_work_for(conn_id):
                self.drop(robot, conn, "peer closed its side")
        if only is not None:
            return
        for conn in [c for c in robot.conns.values() if not session.is_connected(c.id)]:
            self.drop(robot, conn, "session ended")
        while waiting > OUTBOX_TOTAL_MAX:             # e.g. a large ListenSend to many clients that do not read
            laziest = max(robot.conns.values(), key=lambda c: len(c.wbuf))
            waiting -= len(laziest.wbuf)
            self.drop(robot, laziest, f"client does not read (its robot's clients have more than "
                                       f"{OUTBOX_TOTAL_MAX} bytes waiting)")

    def drop(self, robot: Robot, conn: Conn, reason: str) -> None:
        if robot.conns.pop(conn.id, None) is None:
            return
        if not conn.eof:
            with contextlib.suppress(KeyError, ValueError):
                self.selector.unregister(conn.sock)
        with contextlib.suppress(OSError):
            conn.sock.close()
        robot.faults.forget(conn.id)
        self.fair.forget(robot, conn)
        robot.session.disconnect(conn.id)
        robot.log.event("closed", conn=conn.id, reason=reason)


def _collect_garbage(idle: bool) -> None:
    """Run the collector between bursts of requests, not in the middle of one (SimServer(manage_gc=True),
    the CLI, which also switches the automatic collector off): young objects when a poll found no
    socket ready, or at the latest after GC_FORCE allocations; older generations as CPython would
    (every 10 collections of the one below). Start-up objects are frozen (gc.freeze) by the CLI."""
    young, middle, old = gc.get_count()
    if young >= (GC_IDLE if idle else GC_FORCE):
        gc.collect(2 if old >= 10 else 1 if middle >= 10 else 0)



