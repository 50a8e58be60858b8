"""The shipped examples on the virtual PLC (virtual time) and a simulator robot with its Ethernet Slave, in one
thread: the plant of the example tests (test_example_programs.py) and of the PnP end-to-end tests
(test_pnp_states.py, test_recovery_e2e.py)."""
from __future__ import annotations

import pathlib

import pytest

from tmsim.net.server import SimServer
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = [str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")]
SECOND = 1_000_000_000
GRIPPER = "EndModule.DO[0]"
HMI_STOP_HOLD_S = 1.5            # the HMI's Stop Motion page releases Stop 1.5 s after Done (hmi.js HOLD_DONE_MS)


class Plant:
    """The examples on the virtual PLC and a simulator robot with its Ethernet Slave, one thread."""

    def __init__(self, **sim_args):
        self.sim = SimServer(port=0, robots=1, svr_port=0, **sim_args)
        self.sim.start()
        self.robot = self.sim.robots[0]
        self.plc = load_plc(SOURCES)
        self.plc.write("Connect_AddressIP", "127.0.0.1")
        self.plc.write("Connect_Dest_PortIP", self.sim.ports[0])
        self.plc.write("Connect_SvrPort", self.robot.svr_port)

    def close(self):
        self.plc.close()
        self.sim.close()

    def read(self, name):
        return self.plc.read(name)

    def until(self, predicate, what, seconds=10.0):
        ok = self.plc.run_until(predicate, timeout_ns=int(seconds * SECOND),
                                on_scan=lambda now_ns: self.sim.poll(now_ns / 1e9))
        assert ok, f"{what} did not happen within {seconds} s of PLC time (state {self.read('PnP_State')})"

    def run_for(self, seconds):
        end = self.plc.now_ns + int(seconds * SECOND)
        self.until(lambda: self.plc.now_ns >= end, f"{seconds} s to pass", seconds + 1)

    def scripts(self, since: int = 0) -> list[str]:
        """Script lines the robot executed, without the position polling of CBT_ReadActualPosition."""
        return [e["text"] for e in self.robot.events[since:]
                if e["kind"] == "script_line" and not e["text"].startswith("ListenSend(")]

    def connect(self):
        self.plc.write("Connect_Execute", True)
        self.until(lambda: self.read("Connect_Connected"), "the connection")

    def command(self, group: str, seconds: float = 15) -> list[str]:
        """Rising edge on <group>_Execute, wait for Done (or fail on Error); return the scripts it sent."""
        since = len(self.robot.events)
        self.plc.write(f"{group}_Execute", False)
        self.run_for(0.002)
        self.plc.write(f"{group}_Execute", True)
        self.until(lambda: self.read(f"{group}_Done") or self.read(f"{group}_Error"), f"{group} to finish",
                   seconds)
        assert not self.read(f"{group}_Error"), self.read(f"{group}_ErrorDescrip")
        self.plc.write(f"{group}_Execute", False)
        return self.scripts(since)

    def pulse(self, name, done, what):
        """A rising edge of ``name``, held until ``done``, then released."""
        self.plc.write(name, False)
        self.until(lambda: True, "one scan")
        self.plc.write(name, True)
        self.until(lambda: self.read(done), what)
        self.plc.write(name, False)

    def start(self):
        """The operator's deliberate start: a rising edge of PnP_Example_Execute, held TRUE afterwards."""
        self.plc.write("PnP_Example_Execute", False)
        self.run_for(0.002)
        self.plc.write("PnP_Example_Execute", True)

    def reset(self):
        self.plc.write("PnP_Reset", True)
        self.until(lambda: self.read("PnP_State") != "Faulted", "the reset")
        self.plc.write("PnP_Reset", False)

    def press_stop_like_the_hmi(self):
        """Stop Motion page: Execute until Done, Done shown for 1.5 s, then Execute released."""
        self.plc.write("Stop_Execute", True)
        self.until(lambda: self.read("Stop_Done"), "the stop", 2)
        self.run_for(HMI_STOP_HOLD_S)
        self.plc.write("Stop_Execute", False)

    def events(self, kind, since=0):
        return [e for e in self.robot.events[since:] if e["kind"] == kind]

    def mark(self):
        return len(self.robot.events)

    def target(self, segment):
        return [self.read(f"PnP_MoveParameters[{segment}].TargetPosition.{a}") for a in ("X", "Y", "Z")]

    def arrivals(self, segment, since=0):
        """motion_end events at the target of a segment."""
        return [e for e in self.events("motion_end", since)
                if e["pose"][:3] == pytest.approx(self.target(segment), abs=0.5)]

    def gripper(self, since=0):
        return [e for e in self.events("io", since) if e["point"] == GRIPPER]
