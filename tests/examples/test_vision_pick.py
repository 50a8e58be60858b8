"""The vision pick example (examples/vision_pick/) on the virtual PLC against the simulator, scan by scan on virtual
time: the camera finds 3 parts at poses set here, the PLC picks each through the vision base CBT_VisionJob reports
(CBT_ChangeBase, an approach point in it, a relative move down), the gripper's part-present input read with
CBT_ReadIO confirms every grip, and the cell ends when the camera finds no part. The test plays the part on the
table: the sensor turns on only when the gripper closes with the TCP at a part that is still there (the simulator's
event log and its robot model are the witnesses); a picked part leaves the camera's next image."""
from __future__ import annotations

import math
import pathlib

import pytest

from tmsim import kinematics as kin
from tmsim.camera import camera_of
from tmsim.server import SimServer
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
SEC = 1_000_000_000
PARTS = [[417.5, -122.3, 300.0, 0.0, 0.0, 0.0], [467.5, -62.3, 300.0, 0.0, 0.0, 30.0],
         [377.5, -182.3, 310.0, 0.0, 0.0, -45.0]]
GRIP = [0.0, 0.0, 0.0, 180.0, 0.0, 90.0]          # the TCP at a part, in its vision base: its origin, tool down


class Cell:
    """Simulator (Listen node, Ethernet Slave, camera) + examples/vision_pick on the virtual PLC, and the table."""

    def __init__(self, parts):
        self.srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, svr_port=0)
        self.srv.start()
        self.robot = self.srv.robots[0]
        self.model = self.robot.session.robot
        self.camera = camera_of(self.model)
        self.table = [list(p) for p in parts]       # parts still on the table
        self.gripped = []                           # the parts the gripper took, in order
        self.holding = None
        self.show_parts()
        self.plc = load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples" / "vision_pick")],
                            task="Main@1ms")
        self.plc.write("VisionPick.Port", self.srv.ports[0])
        self.plc.write("VisionPick.SvrPort", self.robot.svr_port)

    def show_parts(self):
        self.camera.define("parts", objects=self.table, seconds=0.3)

    def read(self, name):
        return self.plc.read(f"VisionPick.{name}")

    def scan_hook(self, now_ns):
        self.srv.poll(now_ns / 1e9)
        closed = self.model.io.get("EndModule.DO[0]", 0) == 1
        if closed and self.holding is None:
            tcp = kin.pose_to_matrix(self.model.tcp_pose_robot())
            for part in self.table:
                at_part = kin.matmul(kin.pose_to_matrix(part), kin.pose_to_matrix(GRIP))
                if all(math.isclose(a, b, abs_tol=0.5) for row_a, row_b in zip(tcp, at_part)
                       for a, b in zip(row_a, row_b)):
                    self.holding = part
                    self.table.remove(part)
                    self.gripped.append(part)
                    self.robot.svr_source.set_input("End_DI0", 1)
                    self.show_parts()               # the next image shows the parts left
                    break
        elif not closed and self.holding is not None:
            self.holding = None
            self.robot.svr_source.set_input("End_DI0", 0)

    def run_until(self, pred, seconds):
        return self.plc.run_until(pred, timeout_ns=int(seconds * SEC), on_scan=self.scan_hook)

    def close(self):
        self.plc.close()
        self.srv.close()


@pytest.fixture
def cell():
    c = Cell(PARTS)
    assert c.run_until(lambda: c.read("fbConnect.Connected") and c.read("fbIO.Valid"), 5)
    yield c
    c.close()


def start(cell):
    cell.plc.write("VisionPick.Start", True)
    assert cell.run_until(lambda: cell.read("Busy"), 0.1)
    cell.plc.write("VisionPick.Start", False)


def test_three_parts_found_by_the_camera_are_picked_through_the_vision_base_each_grip_confirmed(cell):
    start(cell)
    assert cell.run_until(lambda: not cell.read("Busy"), 120), cell.read("Step")
    assert cell.read("Done") and not cell.read("Error"), cell.read("ErrorText")
    assert cell.read("Picked") == 3
    assert cell.gripped == PARTS and cell.table == []            # each part once, where the camera saw it
    runs = [e for e in cell.robot.events if e["kind"] == "vision_job"]
    assert [r["objects"] for r in runs] == [3, 2, 1, 0]           # the last image: an empty table
    closes = [e for e in cell.robot.events if e["kind"] == "io" and e.get("point") == "EndModule.DO[0]"
              and e.get("value") == 1]
    assert len(closes) == 3


def test_a_grip_without_a_part_stops_the_cell_with_the_reason(cell):
    """The camera reports a part 20 mm off where it lies: the gripper closes on nothing, the sensor stays off."""
    cell.camera.define("parts", objects=[[417.5, -102.3, 300.0, 0.0, 0.0, 0.0]], seconds=0.3)
    cell.show_parts = lambda: None                  # the camera keeps reporting the wrong place
    start(cell)
    assert cell.run_until(lambda: not cell.read("Busy"), 60), cell.read("Step")
    assert cell.read("Error") and cell.read("Picked") == 0
    assert cell.read("ErrorText").startswith("No part in the gripper")
    assert cell.gripped == []


def test_an_unknown_vision_job_stops_the_cell_with_the_fb_text(cell):
    cell.camera.remove("parts")
    cell.show_parts = lambda: None
    start(cell)
    assert cell.run_until(lambda: not cell.read("Busy"), 10)
    assert cell.read("Error") and cell.read("ErrorText") == "Vision job not in the robot's project"     # 16#4050
    assert [e["result"] for e in cell.robot.events if e["kind"] == "vision_job"] == ["unknown"]    # nothing ran
