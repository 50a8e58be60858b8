"""Fair processing of the robots' client input: the scheduler the server owns (``SimServer.fair``).

The scheduler only decides which client's input is processed next and how much of it; the bytes and
their meaning belong to the robot's Listen-node session, which takes one bounded turn at a time through
``turn(conn, budget)`` (a ``TurnBudget`` of tmsim/limits.py): at most SERVE_ITEMS items of one client's
input handled and SERVE_SCAN decoded, and at most TURN_WORK units of work (tmsim/tmscript/work.py: checking
and running scripts, logging; a script that is not done goes on in the robot's next turn). What is left
waits in that client's receive buffer in the session (the scheduler's backlog), which is not read further
meanwhile, while the other clients get their turn, round robin. A client whose last read filled the receive
size or who has input left over is "greedy": the server serves it after the others. The session limits the
CPERR answers to bad packets (CPERR_BURST, CPERR_PER_S per client). Bounds: tmsim/limits.py.

The scheduler reaches the sockets only through its host's public calls (``TurnHost``): the server flushes
and drops connections, polls its sockets and pauses reading.
"""
from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

from tmsim.limits import FRAME_DATA_MAX, IO_SLICE_S, PENDING_SCRIPTS_MAX, POLL_BUDGET_S, SERVE_TURN
from tmsim.protocol.listen_protocol import FRAME_LIMIT, INPUT_DONE

if TYPE_CHECKING:
    from tmsim.net.robot_ports import Conn, Robot


class TurnHost(Protocol):
    """What the scheduler needs of the server that owns it."""

    def serve_ready(self, quick_only: bool = False) -> int:
        """Serve the sockets that are ready now (``quick_only``: only clients that are not greedy)."""
        ...

    def flush(self, robot: Robot, only: Conn | None = None) -> None:
        """Write what the robot's session produced (``only``: that client's output)."""
        ...

    def drop(self, robot: Robot, conn: Conn, reason: str) -> None:
        """Close a client connection of the robot."""
        ...

    def touch(self, robot: Robot) -> None:
        """The robot received input: it advances with dt = 0 before the poll ends."""
        ...

    def pause_reading(self, robot: Robot) -> None:
        """Back-pressure: stop reading the robot's clients until its script buffer is half empty."""
        ...


class FairScheduler:
    """Bounded, round-robin turns of the robots' client input (see the module docstring)."""

    def __init__(self, host: TurnHost, pending_bytes_limit: int):
        self._host = host
        self.pending_bytes_limit = pending_bytes_limit      # a robot's share of PENDING_BYTES_MAX
        self._backlog: dict[tuple[int, int], tuple[Robot, Conn]] = {}   # clients with input left over

    @property
    def has_backlog(self) -> bool:
        """Some client has input left over from its last turn."""
        return bool(self._backlog)

    def waits(self, robot: Robot, conn: Conn) -> bool:
        """``conn`` has input left over and waits for its turn in ``serve_backlog``."""
        return (robot.index, conn.id) in self._backlog

    def requeue(self, robot: Robot, conn: Conn) -> None:
        """``conn`` has input buffered (read before a pause): it gets a turn in ``serve_backlog``."""
        self._backlog[(robot.index, conn.id)] = (robot, conn)

    def forget(self, robot: Robot, conn: Conn) -> None:
        """``conn`` is gone."""
        self._backlog.pop((robot.index, conn.id), None)

    def turn(self, robot: Robot, conn: Conn) -> None:
        """One turn of ``conn``'s input within SERVE_TURN. What is left waits for the next turn (the backlog),
        after the other clients' turns. The fault ``close_after`` closes the connection right after the frame
        that reaches its count (its replies are sent first)."""
        key = (robot.index, conn.id)
        close_after = robot.faults.close_after
        budget = SERVE_TURN if close_after is None else replace(SERVE_TURN, frame_limit=close_after)
        _, outcome = robot.session.turn(conn.id, budget)
        if outcome == INPUT_DONE:
            self._backlog.pop(key, None)
        elif outcome == FRAME_LIMIT:
            robot.faults.close_after_reached()
            self._host.flush(robot)
            self._host.drop(robot, conn, "fault: close_after")
        else:
            self._backlog[key] = (robot, conn)
            conn.greedy = True

    def buffer_full(self, robot: Robot, fraction: float = 1.0) -> bool:
        """The robot's buffered scripts reach PENDING_SCRIPTS_MAX or its share of PENDING_BYTES_MAX (times
        ``fraction``). Checked once a turn: one turn may add SERVE_ITEMS frames more."""
        waiting = robot.session.waiting_scripts
        if waiting >= PENDING_SCRIPTS_MAX * fraction:
            return True
        limit = self.pending_bytes_limit * fraction
        return waiting * FRAME_DATA_MAX >= limit and robot.session.waiting_script_bytes() >= limit

    def serve_backlog(self) -> None:
        """Turns for the clients with input left over, round robin, until none is left or POLL_BUDGET_S has
        passed; every IO_SLICE_S the sockets are polled, so fresh requests of other clients go first."""
        served = start = time.perf_counter()
        while self._backlog and time.perf_counter() - start < POLL_BUDGET_S:
            served = self._round(served)

    def _round(self, served: float) -> float:
        host = self._host
        for key, (robot, conn) in list(self._backlog.items()):
            if time.perf_counter() - served > IO_SLICE_S:
                host.serve_ready(quick_only=True)
                served = time.perf_counter()
            if conn.id not in robot.conns:
                self._backlog.pop(key, None)
                continue
            if self.buffer_full(robot):
                self._backlog.pop(key, None)      # the script buffer is full: the server resumes reading later
                if not robot.reading_paused:
                    host.pause_reading(robot)
                continue
            self.turn(robot, conn)
            host.touch(robot)
            if not robot.faults.active:
                host.flush(robot, conn)
        return served


def is_greedy(ready_item: tuple) -> bool:
    """Whether a ready selector item is a greedy robot client (see the module docstring)."""
    conn = ready_item[0].data[2]
    return hasattr(conn, "greedy") and conn.greedy
