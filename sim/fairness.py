"""Fair processing of the robots' client input (mixed into ``server.SimServer``).

One turn processes at most SERVE_ITEMS items of one client's input (and decodes at most SERVE_SCAN);
what is left waits in the client's receive buffer (``_backlog``), which is not read further meanwhile,
while the other clients get their turn, round robin. A client whose last read filled the receive size
or who has input left over is "greedy": ``SimServer._serve`` serves it after the others. Bad packets are
answered with CPERR at most CPERR_BURST at once, then CPERR_PER_S per second of robot clock per client;
the others are counted (event ``cperr_suppressed``). Bounds: sim/limits.py.
"""
from __future__ import annotations

import time

from . import codec
from .eventlog import text as _text
from .limits import CPERR_BURST, CPERR_PER_S, SERVE_ITEMS, SERVE_SCAN

MAX_PENDING = 1000          # buffered scripts per robot (TCP back-pressure beyond, see server.py)
POLL_BUDGET_S = 0.004       # backlog turns of one poll stop after this long
IO_SLICE_S = 0.0003         # between two turns, the sockets are polled for new requests this often


class FairInput:
    def _process(self, robot, conn):
        """One turn of ``conn``'s input: at most SERVE_ITEMS items handled, SERVE_SCAN decoded. What is left
        waits for the next turn (``_backlog``), after the other clients' turns."""
        handled, key = 0, (robot.index, conn.id)
        for _ in range(SERVE_SCAN):
            if conn.rbuf[:2] == b"$$" and self._cperr_tokens(conn) < 1.0:
                # a '$' followed by another '$' is always a bad packet (header missing, CPERR 01): a run of
                # them that gets no answer anyway is skipped at once
                run = len(conn.rbuf) - len(conn.rbuf.lstrip(b"$")) - 1
                del conn.rbuf[:run]
                conn.suppressed += run
                continue
            item, used = codec.decode(conn.rbuf)
            if not used:
                self._backlog.pop(key, None)
                break
            del conn.rbuf[:used]
            if type(item) is codec.BadFrame and not self._may_answer_bad(conn):
                conn.suppressed += 1
                continue
            if conn.suppressed:
                robot._log("cperr_suppressed", conn=conn.id, count=conn.suppressed)
                conn.suppressed = 0
            if type(item) is codec.Frame:
                conn.frames_in += 1
                robot._log("frame_in", conn=conn.id, raw=_text(item.raw), header=item.header,
                           data=_text(item.data))
            robot.session.handle(conn.id, item)
            if robot.faults.close_after is not None and conn.frames_in >= robot.faults.close_after:
                robot.faults.close_after = None
                self._flush(robot)
                self._drop(robot, conn, "fault: close_after")
                return
            handled += 1
            if handled >= SERVE_ITEMS or robot.session.waiting_scripts >= MAX_PENDING:
                self._backlog[key] = (robot, conn)
                conn.greedy = True
                break
        else:
            self._backlog[key] = (robot, conn)
            conn.greedy = True

    def _buffer_full(self, robot, fraction=1.0) -> bool:
        """The robot's buffered scripts reach MAX_PENDING or its share of PENDING_BYTES_MAX (times
        ``fraction``). Checked once a turn: one turn may add SERVE_ITEMS frames more."""
        waiting = robot.session.waiting_scripts
        if waiting >= MAX_PENDING * fraction:
            return True
        limit = self.pending_bytes_limit * fraction
        return waiting * codec.MAX_DATA >= limit and robot.session.waiting_script_bytes() >= limit

    def _cperr_tokens(self, conn) -> float:
        """Token bucket of CPERR answers to bad packets: CPERR_BURST at once, CPERR_PER_S per second."""
        conn.cperr_tokens = min(CPERR_BURST, conn.cperr_tokens + (self._now - conn.cperr_at) * CPERR_PER_S)
        conn.cperr_at = self._now
        return conn.cperr_tokens

    def _may_answer_bad(self, conn) -> bool:
        if self._cperr_tokens(conn) < 1.0:
            return False
        conn.cperr_tokens -= 1.0
        return True

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
