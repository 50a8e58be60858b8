"""The vision pick example (examples/vision_pick/) on the virtual PLC against the simulator, scan by scan on virtual
time: the camera finds 3 parts at poses set here, the PLC picks each through the vision base CBT_VisionJob reports
(CBT_ChangeBase, an approach point in it, a relative move down), the gripper's part-present input read with
CBT_ReadIO confirms every grip, and the cell ends when the camera finds no part. The test plays the part on the
table: the sensor turns on only when the gripper closes with the TCP at a part that is still there (the simulator's
event log and its robot model are the witnesses); a picked part leaves the camera's next image. The rest of issue 26's
"Done when" on the same program: the project speed at 50 % (CBT_SetOverride) doubles every motion's time in the
simulator's log, the drop bin filling while the robot carries a part replaces the drop move mid-way by an aborting
move to the spare bin (the drop move ends CommandAborted, the robot never reaches the drop point), and a jog of the
commissioning part stops within 100 ms of its release (PLC scan time against the simulator's stop event), after
which the jogged position taught as the drop point is where the cell puts the parts."""
from __future__ import annotations

import math
import pathlib

import pytest

from tmsim.net.server import SimServer
from tmsim.robot import kinematics as kin
from tmsim.robot.camera import camera_of
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
SEC = 1_000_000_000
PARTS = [[417.5, -122.3, 300.0, 0.0, 0.0, 0.0], [467.5, -62.3, 300.0, 0.0, 0.0, 30.0],
         [377.5, -182.3, 310.0, 0.0, 0.0, -45.0]]
GRIP = [0.0, 0.0, 0.0, 180.0, 0.0, 90.0]          # the TCP at a part, in its vision base: its origin, tool down
DROP = [417.5, 100.0, 359.7]                      # VisionPick.DropParam's target, mm
SPARE = [330.0, 20.0, 400.0]                      # VisionPick.SpareParam's target, mm
SCAN_S = 0.001


class Cell:
    """Simulator (Listen node, Ethernet Slave, camera) + examples/vision_pick on the virtual PLC, and the table."""

    def __init__(self, parts, count_statements=False):
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
                            task="Main@1ms", count_statements=count_statements)
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
                if all(math.isclose(a, b, abs_tol=0.5) for row_a, row_b in zip(tcp, at_part, strict=False)
                       for a, b in zip(row_a, row_b, strict=False)):
                    self.holding = part
                    self.table.remove(part)
                    self.gripped.append(part)
                    self.robot.svr_source.set_input("End_DI0", 1)
                    self.show_parts()               # the next image shows the parts left
                    break
        elif not closed and self.holding is not None:
            self.holding = None
            self.robot.svr_source.set_input("End_DI0", 0)

    def run_until(self, pred, seconds, on_scan=None):
        def hook(now_ns):
            self.scan_hook(now_ns)
            if on_scan is not None:
                on_scan(now_ns)
        return self.plc.run_until(pred, timeout_ns=int(seconds * SEC), on_scan=hook)

    def now_s(self):
        return self.plc.now_ns / SEC

    def log(self, kind):
        return [e for e in self.robot.events if e["kind"] == kind]

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


def distance(a, b):
    return math.dist(a[:3], b[:3])


def motion_times(robot):
    """(target, seconds) of each motion in the simulator's log, from its start to its end."""
    times, started = [], None
    for e in robot.events:
        if e["kind"] == "motion_start":
            started = e
        elif e["kind"] == "motion_end" and started is not None:
            times.append((started["to"], e["t"] - started["t"]))
            started = None
    return times


def run_at(override):
    cell = Cell(PARTS)
    try:
        assert cell.run_until(lambda: cell.read("fbConnect.Connected") and cell.read("fbIO.Valid"), 5)
        cell.plc.write("VisionPick.Override", override)
        start(cell)
        assert cell.run_until(lambda: not cell.read("Busy"), 120), cell.read("Step")
        assert cell.read("Done") and cell.read("Picked") == 3, cell.read("ErrorText")
        assert cell.model.project_speed == override                  # the robot's project speed in force
        return motion_times(cell.robot)
    finally:
        cell.close()


def test_override_50_doubles_the_time_of_every_motion_in_the_simulators_log():
    full, half = run_at(100), run_at(50)
    assert len(full) == len(half) == 3 * 4                          # approach, down, up, drop per part
    for (target, seconds), (target_half, seconds_half) in zip(full, half, strict=False):
        assert list(target) == pytest.approx(list(target_half), abs=1e-6)       # the same path
        assert seconds_half == pytest.approx(2 * seconds, abs=2 * SCAN_S), (target, seconds, seconds_half)


def test_the_bin_filling_mid_move_replaces_the_drop_move_and_the_robot_never_reaches_the_drop_point(cell):
    """The drop bin's sensor rises half-way along the second part's drop move: an aborting move to the spare bin
    replaces it; the third part goes to the spare bin directly."""
    seen = {"aborted": False}

    def bin_fills_half_way(now_ns):
        drops = [e for e in cell.log("motion_start") if distance(e["to"], DROP) < 1e-3]
        if len(drops) == 2 and now_ns / SEC >= drops[1]["t"] + drops[1]["duration_s"] / 2:
            cell.plc.write("VisionPick.DropFull", True)
        seen["aborted"] |= cell.read("fbDrop.CommandAborted")
        assert not cell.read("fbDrop.Error")

    start(cell)
    assert cell.run_until(lambda: not cell.read("Busy"), 120, on_scan=bin_fills_half_way), cell.read("Step")
    assert cell.read("Done") and not cell.read("Error"), cell.read("ErrorText")
    assert cell.read("Picked") == 3 and cell.read("Diverted") == 2 and cell.read("DropsReplaced") == 1
    assert seen["aborted"]                                          # the replaced drop move ended CommandAborted
    assert cell.gripped == PARTS
    starts = cell.log("motion_start")
    replaced = [e for e in starts if distance(e["to"], DROP) < 1e-3][1]
    after = [e for e in cell.robot.events if e["t"] >= replaced["t"] and e is not replaced]
    ends = [e for e in after if e["kind"] == "motion_end"]
    assert all(distance(e["pose"], DROP) > 1.0 for e in ends)       # never at the drop point after the replaced move
    spare = next(e for e in after if e["kind"] == "motion_start")   # the aborting move, from where the robot was
    assert spare["t"] < replaced["t"] + replaced["duration_s"]      # before the drop move could have ended
    assert distance(spare["to"], SPARE) < 1e-3
    assert distance(spare["from"], DROP) > 20 and distance(spare["from"], replaced["from"]) > 20   # mid-way
    assert sum(1 for e in ends if distance(e["pose"], SPARE) < 1e-3) == 2


def test_a_jog_stops_within_100_ms_of_release_and_the_jogged_position_taught_becomes_the_drop_point(cell):
    before = cell.robot.state()["tcp"]
    cell.plc.write("VisionPick.JogForward", True)                   # base Z up at 10 %, the example's defaults
    assert cell.run_until(lambda: cell.read("fbJog.Active"), 0.05)
    cell.run_until(lambda: False, 0.3)
    cell.plc.write("VisionPick.JogForward", False)
    cell.run_until(lambda: False, SCAN_S)                           # the scan that sees the release
    released = cell.now_s()
    assert cell.run_until(lambda: not cell.read("fbJog.Busy"), 1)
    (stop,) = cell.log("stop")
    assert 0 <= stop["t"] - released <= 0.1, (stop["t"], released)
    moved = [e["t"] for e in cell.log("motion_start")]
    cell.run_until(lambda: False, 0.3)
    assert [e["t"] for e in cell.log("motion_start")] == moved and moved[-1] <= released   # nothing ran on
    jogged = cell.robot.state()["tcp"]
    assert jogged[2] - before[2] > 20 and jogged[:2] == pytest.approx(before[:2], abs=1e-3)

    cell.plc.write("VisionPick.TeachDrop", True)
    assert cell.run_until(lambda: cell.read("fbTeach.Done"), 2)
    cell.plc.write("VisionPick.TeachDrop", False)
    taught = [cell.read(f"DropParam.TargetPosition.{k}") for k in ("X", "Y", "Z", "RX", "RY", "RZ")]
    assert taught == pytest.approx(jogged, abs=1e-3)
    start(cell)
    assert cell.run_until(lambda: not cell.read("Busy"), 120), cell.read("Step")
    assert cell.read("Done") and cell.read("Picked") == 3, cell.read("ErrorText")
    opens = [e for e in cell.robot.events if e["kind"] == "io" and e.get("point") == "EndModule.DO[0]"
             and e.get("value") == 0]
    drops = [e for e in cell.log("motion_end") if distance(e["pose"], jogged) < 1e-2]
    assert len(opens) == len(drops) == 3                            # every part put down at the taught point
