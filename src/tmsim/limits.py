"""Every bound of the simulated controller and of its servers, in one place.

docs/simulator.md ("Limits") shows each of them with the error a client sees;
tests/sim/test_sim_limits_doc.py checks that the table and this file agree.
Values marked [MAN 2.24 §x] follow Techman's *Programming Language TMscript* 2.24 manual;
the others are the simulator's choice (a robot controller has such bounds, the manual does not
give their values).
"""
from __future__ import annotations

import errno
import sys
from dataclasses import dataclass

# ---- script values ------------------------------------------------------------------------------
INT_MIN, INT_MAX = -2 ** 31, 2 ** 31 - 1    # [MAN 2.24 §2.1] int: 32-bit signed; results wrap (§2.2)
BYTE_MAX = 255                              # [MAN 2.24 §2.1] byte: 8-bit unsigned; results wrap (§2.2)
FLOAT_MAX = 3.4028235e38                    # [MAN 2.24 §2.1] float: 32-bit; beyond it an Error (§2.5)
DOUBLE_MAX = sys.float_info.max             # [MAN 2.24 §2.1] double: 64-bit
ARRAY_MAX = 2048                            # [MAN 2.24 §2.3] "The maximum element number is 2048"
STRING_MAX = 65_536                         # characters in one string value (a frame's data is 64 KiB)
HEX_DIGITS_MAX = 8                          # a hexadecimal constant is at most 32 bits wide
IO_INDEX_MAX = 255                          # IO["module"].DO[n] and the like: n in 0..255

# ---- one script (TMSCT packet) -----------------------------------------------------------------
STATEMENTS_MAX = 5_000                      # non-empty lines of one packet
TOKENS_MAX = 10_000                         # tokens of one script (an array of 2048 numbers takes 4,097; a
                                            # call with constant arguments only, e.g. a motion, counts 1)
DEPTH_MAX = 100                             # nesting of one expression (operands of operands ...)
STEPS_MAX = 20_000                          # work of one script: statements + expression nodes + array
                                            # elements copied / 8 + string characters built or sent / 256

# ---- work of one turn of the scheduler (tmsim/tmscript/work.py): a unit is 1-5 us of the simulator's time ---
TURN_WORK = 500                             # units one turn of one robot may do; then its work goes on later
WORK_CHAR = 1                               # a character of a script line parsed and checked ...
WORK_LINE = 4                               # ... plus this per line
WORK_TOKEN = 1                              # a token of a line longer than 512 characters, parsed ...
PARSE_SLICE = 256                           # ... this many at a time between two checks of the turn's budget
WORK_STEP = 1                               # an interpreter step (STEPS_MAX; a ListenSend counts its bytes / 256)
WORK_PLAN = 120                             # planning one motion ...
WORK_PVT_CARTESIAN = 1_000                  # ... a Cartesian PVTPoint (13 inverse-kinematics solutions)
WORK_LOG_BYTES = 1_024                      # bytes of event text kept or written to the file per unit

# ---- one project (the flow's variables while it stays in the Listen node) ----------------------
VARIABLES_MAX = 1_000                       # declared variables
VARIABLE_BYTES_MAX = 8 << 20                # their memory: 8 bytes a number, 1 a character (as text)

# ---- control channel -----------------------------------------------------------------------------
CONTROL_LINE_MAX = 65_536                   # bytes of one request line
CONTROL_DEPTH_MAX = 8                       # JSON nesting of one request
CONTROL_OUTBOX_MAX = 4 << 20                # unsent answer bytes per client; beyond: the client is closed
CONTROL_EVENTS_MAX = 1_000                  # events in one "events" answer (page on with "next") ...
CONTROL_ANSWER_BYTES = 1 << 20              # ... and their bytes as the event log counts them (at least one)
CONTROL_CLIENTS_MAX = 16
CONTROL_TURN_REQUESTS = 4                   # requests of one client answered in one turn ...
CONTROL_TURN_BYTES = 64 << 10               # ... and no more once this turn's answers reach this many bytes
CONTROL_TURN_PIECES = 1_024                 # pieces (numbers, texts) of one large answer encoded in one turn

# ---- the command line ----------------------------------------------------------------------------
SPEEDUP_MAX = 1000.0                        # --speedup: the robot clock at most this many times the wall clock
NODE_TIMEOUT_MAX_S = 86_400.0               # --data-timeout / --connection-timeout of the Listen node

# ---- one frame ---------------------------------------------------------------------------------------
FRAME_DATA_MAX = 65_536                     # DATA of one Listen-node or Ethernet Slave frame; a longer declared
                                            # length is a packet error (CPERR 01)
SVR_STRING_MAX = 256                        # bytes of a text value written through the Ethernet Slave (status 07)
SVR_ARRAY_MAX = 1_024                       # elements of an array variable of the Ethernet Slave's data table

# ---- the virtual camera (per robot) ---------------------------------------------------------------
VISION_JOBS_MAX = 64                        # vision jobs of one project
VISION_OBJECTS_MAX = 64                     # objects one job finds
VISION_SECONDS_MAX = 60.0                   # the longest job
VISION_POSE_MAX = 100_000.0                 # mm / deg of a pose the camera reports, as the library's range

# ---- the robot model ------------------------------------------------------------------------------
FIFO_ITEMS_MAX = 1_000                      # queued items (motions, tags, settings); a script waits while full

# ---- robot servers (per robot unless noted) -----------------------------------------------------
LISTEN_CLIENTS_MAX = 256                    # Listen-node clients; more are accepted and closed at once
LISTEN_OUTBOX_MAX = 1 << 20                 # unsent bytes of one Listen-node client; beyond: it is disconnected
SVR_CLIENTS_MAX = 64                        # Ethernet Slave clients; more are accepted and closed at once
SVR_OUTBOX_MAX = 1 << 20                    # unsent bytes of one Ethernet Slave client; beyond: disconnected
PENDING_SCRIPTS_MAX = 1_000                 # buffered scripts (TCP back-pressure beyond, with PENDING_BYTES_MAX)
RECV_BYTES = 65_536                         # bytes taken from one connection per read
EVENTS_KEPT_MAX = 40_000                    # events kept in memory, all robots together (see also EVENT_BYTES_MAX)
POLL_BUDGET_S = 0.004                       # backlog turns of one poll stop after this long (wall clock)
IO_SLICE_S = 0.0003                         # between two turns the sockets are polled this often (wall clock)
LOOP_WAIT_MIN_S = 0.002                     # serve_forever waits at least this long between two polls (wall clock)
                                            # while something is due: an arm moving, a dense data table ...
LOOP_WAIT_MAX_S = 0.05                      # ... and at most this long when nothing is (a socket or a call from
                                            # another thread ends the wait at once)
EVENT_BYTES_MAX = 20 << 20                  # event log kept in memory, all robots together
LOG_FILE_BYTES_MAX = 64 << 20               # the --log file: then renamed to FILE.1 and begun anew
ACCEPT_BACKOFF_S = 0.1                      # out of descriptors: stop accepting for this long
OUT_OF_DESCRIPTORS = (errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM)   # accept() errors that pause it
SERVE_ITEMS = 8                             # items of one client's input processed in one turn ...
SERVE_SCAN = 256                            # ... and decoded (bad packets not answered count here only)
CPERR_BURST = 16                            # CPERR answers to bad packets a client gets at once ...
CPERR_PER_S = 100                           # ... then at most this many per second (robot clock)
CPERR_SETTING_MAX = 10_000                  # the largest burst / rate ``configure`` gives a Listen node's CPERR limit
PORT_EVENTS_MAX = 10_000                    # events a port protocol without a log callback keeps for events()
OUTBOX_TOTAL_MAX = 16 << 20                 # unsent bytes of all clients of one robot
PENDING_BYTES_MAX = 32 << 20                # bytes of buffered scripts, all robots together (each robot at
                                            # least 4 frames of 64 KiB)


@dataclass(frozen=True, slots=True)
class TurnBudget:
    """The bounds of one turn of one client's input, as the fair scheduler (tmsim/net/fairness.py) hands them to
    a protocol's ``turn(conn, budget)``: at most ``decoded`` items decoded and ``items`` of them handled, the turn
    ended once ``waiting`` scripts wait to start (None: no such bound) and its work metered from ``work`` units
    (None: the meter is left as it is); ``frame_limit`` (the fault ``close_after``) ends it right after the frame
    that brings the connection's received frames to that count."""
    items: int = SERVE_ITEMS
    decoded: int = SERVE_SCAN
    waiting: int | None = PENDING_SCRIPTS_MAX
    work: int | None = TURN_WORK
    frame_limit: int | None = None


SERVE_TURN = TurnBudget()                   # one scheduled turn of a Listen-node client's input
RECEIVE_TURN = TurnBudget(items=SERVE_SCAN, decoded=SERVE_SCAN, waiting=None, work=None)   # receive_data: all at once
