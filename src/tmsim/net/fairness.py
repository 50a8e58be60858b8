"""Fair processing of the robots' client input (mixed into ``server.SimServer``).

The server only schedules: which client's input is processed next and how much of it. One turn lets the
robot's session (``ListenSession.process``) handle at most SERVE_ITEMS items of one client's input and
decode at most SERVE_SCAN, and do at most TURN_WORK units of work (tmsim/tmscript/work.py: checking and running
scripts, logging; a script that is not done goes on in the robot's next turn, ``SimServer._advance``);
what is left waits in that client's receive buffer in the session
(``_backlog``), which is not read further meanwhile, while the other clients get their turn, round
robin. A client whose last read filled the receive size or who has input left over is "greedy":
``SimServer._serve`` serves it after the others. The session limits the CPERR answers to bad packets
(CPERR_BURST, CPERR_PER_S per client). Bounds: tmsim/limits.py.
"""
from __future__ import annotations

import time

from tmsim.limits import (
    FRAME_DATA_MAX,
    IO_SLICE_S,
    PENDING_SCRIPTS_MAX,
    POLL_BUDGET_S,
    SERVE_ITEMS,
    SERVE_SCAN,
    TURN_WORK,
)
from tmsim.protocol.listen_session import FRAME_LIMIT, INPUT_DONE


class FairInput:
    def _process(self, robot, conn):
        """One turn of ``conn``'s input: at most SERVE_ITEMS items handled, SERVE_SCAN decoded. What is left
        waits for the next turn (``_backlog``), after the other clients' turns. The fault ``close_after``
        closes the connection right after the frame that reaches its count (its replies are sent first)."""
        key = (robot.index, conn.id)
        robot.session.meter.begin(TURN_WORK)
        _, outcome = robot.session.process(conn.id, SERVE_ITEMS, SERVE_SCAN, max_waiting=PENDING_SCRIPTS_MAX,
                                           frame_limit=robot.faults.close_after)
        if outcome == INPUT_DONE:
            self._backlog.pop(key, None)
        elif outcome == FRAME_LIMIT:
            robot.faults.close_after = None
            self._flush(robot)
            self.drop(robot, conn, "fault: close_after")
        else:
            self._backlog[key] = (robot, conn)
            conn.greedy = True

    def _buffer_full(self, robot, fraction=1.0) -> bool:
        """The robot's buffered scripts reach PENDING_SCRIPTS_MAX or its share of PENDING_BYTES_MAX (times
        ``fraction``). Checked once a turn: one turn may add SERVE_ITEMS frames more."""
        waiting = robot.session.waiting_scripts
        if waiting >= PENDING_SCRIPTS_MAX * fraction:
            return True
        limit = self.pending_bytes_limit * fraction
        return waiting * FRAME_DATA_MAX >= limit and robot.session.waiting_script_bytes() >= limit

    def _serve_backlog(self):
        """Turns for the clients with input left over, round robin, until none is left or POLL_BUDGET_S has
        passed; every IO_SLICE_S the sockets are polled, so fresh requests of other clients go first."""
        served = start = time.perf_counter()
        while self._backlog and time.perf_counter() - start < POLL_BUDGET_S:
            served = self._backlog_round(served)

    def _backlog_round(self, served):
        for key, (robot, conn) in list(self._backlog.items()):
            if time.perf_counter() - served > IO_SLICE_S:
                self._serve(0.0, quick_only=True)
                served = time.perf_counter()
            if conn.id not in robot.conns:
                self._backlog.pop(key, None)
                continue
            if self._buffer_full(robot):
                self._backlog.pop(key, None)      # the script buffer is full: _set_reading resumes it
                if not robot.reading_paused:
                    self._set_reading(robot, False)
                continue
            self._process(robot, conn)
            if robot not in self._touched:
                self._touched.append(robot)
            if not robot.faults.active:
                self._flush(robot, conn)
        return served


def is_greedy(ready_item) -> bool:
    """Whether a ready selector item is a greedy robot client (see the module docstring)."""
    conn = ready_item[0].data[2]
    return hasattr(conn, "greedy") and conn.greedy
