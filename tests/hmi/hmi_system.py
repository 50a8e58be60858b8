"""The whole system for the HMI's end-to-end tests: the example programs and the real library on the virtual PLC in
real time, the robot simulator over loopback, the HMI server, and a Chromium page on it."""
from __future__ import annotations

import contextlib
import pathlib
import threading
import time
from collections.abc import Iterator

import fake_plc
from browser import Browser

from cbt_hmi.web.mapping import Mapping
from cbt_hmi.web.pagedesc import load_pages, program_table
from cbt_hmi.web.server import HmiServer
from tmsim.net.server import SimServer
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = [str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")]
MOVE_WAIT_S = 30
SIM_SPEEDUP = 4.0     # the robot model runs 4x faster than the wall clock; PLC timers stay real time
DWELL_NS = 250_000_000  # PnP_DwellTime for the cycle tests (T#250ms)


@contextlib.contextmanager
def serving(plc, mapping: Mapping) -> Iterator[HmiServer]:
    """``plc`` scanning in real time on a thread of its own and an HMI server on it with ``mapping``; afterwards the
    server stopped, the scans ended and the PLC closed. The task sleeps to each due time, as in the demo (no busy
    wait before each scan: 30 % of a core for a 1 ms task)."""
    stop = threading.Event()
    thread = threading.Thread(target=plc.run_realtime, args=(stop,), kwargs={"spin_ns": 0}, daemon=True)
    thread.start()
    try:
        with fake_plc.serving(plc, mapping) as server:
            yield server
    finally:
        stop.set()
        thread.join(timeout=5)
        plc.close()


@contextlib.contextmanager
def serving_user_program(folder: pathlib.Path, source: str, program: str) -> Iterator[tuple]:
    """A user's own program (``folder/source``, PROGRAM ``program`` every 10 ms) with the page descriptions of its
    folder and the variable table generated from its globals, served as by ``serving``: yields (plc, server)."""
    plc = load_plc([str(folder / source)], task="Main@10ms", programs=[program])
    pages, errors = load_pages(folder, plc)
    assert errors == [], errors
    mapping = Mapping(program_table(plc, pages), f"generated from {source}")
    mapping.check_against_plc(plc)
    with serving(plc, mapping) as server:
        yield plc, server


class System:
    """The robot simulator, the examples on the virtual PLC in real time and the HMI server, for one browser;
    ``speedup``: the robot model's speed against the wall clock."""

    def __init__(self, browser: Browser, speedup: float = SIM_SPEEDUP):
        self.mapping = Mapping.load()
        self.sim = SimServer(port=0, robots=1, speedup=speedup, svr_port=0)
        self.sim.start_background()
        self.robot = self.sim.robots[0]
        self.plc = load_plc(SOURCES)
        self.mapping.check_against_plc(self.plc)
        with self.plc.lock:
            self.plc.write("Connect_AddressIP", "127.0.0.1")
            self.plc.write("Connect_Dest_PortIP", self.sim.ports[0])
            self.plc.write("Connect_SvrPort", self.robot.svr_port)
        self.stop_event = threading.Event()
        self.plc_thread = threading.Thread(target=self.plc.run_realtime, args=(self.stop_event,),
                                           kwargs={"spin_ns": 0}, daemon=True)
        self.plc_thread.start()
        self.hmi = HmiServer(self.plc, self.mapping, port=0)
        self.hmi.start()
        self.browser = browser

    def close(self):
        self.hmi.stop()
        self.stop_event.set()
        self.plc_thread.join(timeout=5)
        self.plc.close()
        self.sim.close()

    def read(self, name):
        with self.plc.lock:
            return self.plc.read(name)

    def state(self) -> dict:
        """The simulated robot's state (pose, motion, queue)."""
        with self.sim.lock:
            return self.robot.state()

    def events(self, kind: str, since: float = -1.0) -> list[dict]:
        """Events of one kind logged after the robot-clock time ``since`` (the in-memory log is capped, so
        positions in it shift; times do not)."""
        with self.sim.lock:
            return [e for e in self.robot.events if e["kind"] == kind and e["t"] > since]

    def event_count(self) -> float:
        """A mark for events(): the robot clock of the newest event."""
        with self.sim.lock:
            return self.robot.events[-1]["t"] if self.robot.events else -1.0

    def wait(self, predicate, what: str, timeout: float = MOVE_WAIT_S):
        done = threading.Event()
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out after {timeout} s waiting for {what}\n{self.snapshot()}")
            done.wait(0.02)

    def snapshot(self) -> str:
        """What the robot and the PLC were doing, for the message of a failed wait."""
        with self.sim.lock:
            tail = [{k: v for k, v in e.items() if k != "pose"} for e in self.robot.events[-25:]]
            state = self.robot.state()
        names = ("PnP_Segment", "PnP_MoveBusy", "ProgramControl_Execute", "ProgramControl_Busy",
                 "ProgramControl_Done", "ProgramControl_Error", "ProgramControl_ErrorDescrip",
                 "ProgramControl_Param.Command", "Cobot.QueueDepth", "Cobot.Connected")
        with self.plc.lock:
            plc = {n: self.plc.read(n) for n in names}
        lines = [f"robot state: {state}", f"PLC: {plc}", "last robot events:"] + [f"  {e}" for e in tail]
        return "\n".join(lines)

    def open(self, page: str) -> Browser:
        self.browser.open(self.hmi.page_url(page, "engineer"))
        return self.browser

    def robot_state(self) -> dict:
        with self.sim.lock:
            return self.robot.state()
