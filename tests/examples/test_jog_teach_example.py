"""examples/JogTeach_Example.st (run by the examples' configuration) on the virtual PLC against the simulator, on
virtual time: the panel's hold-to-run jog moves the robot while the panel keeps its beat, stops on the release and
by itself when the beat stops (a browser or network that died with the button held), and Teach stores the robot's
position into the examples' TeachTable."""
from __future__ import annotations

import pytest
from pnp_plant import Plant

SEC = 1_000_000_000
BEAT_S = 0.05                       # the panel counts Jog_Beat up with every poll while a button is held
WATCHDOG_S = 0.3                    # JogTeach_Example: BeatAge PT


class Cell(Plant):
    """The examples' plant, the robot in its Listen node from the start, connected with a valid position."""

    def __init__(self):
        super().__init__(auto_enter=True)
        self.plc.write("Connect_Execute", True)
        assert self.run(lambda: self.plc.read("Connect_Connected") and self.plc.read("ReadPos_Valid"), 5)

    def now(self):
        return self.plc.now_ns / SEC

    def run(self, pred, seconds, beat=False):
        next_beat = [self.now()]

        def hook(now_ns):
            self.sim.poll(now_ns / 1e9)
            if beat and now_ns / SEC >= next_beat[0]:
                self.plc.write("Jog_Beat", self.plc.read("Jog_Beat") + 1)
                next_beat[0] += BEAT_S
        return self.plc.run_until(pred, timeout_ns=int(seconds * SEC), on_scan=hook)


@pytest.fixture
def cell():
    c = Cell()
    yield c
    c.close()


def test_panel_jog_moves_while_held_and_teach_stores_the_position(cell):
    start = cell.robot.state()["tcp"]
    cell.plc.write("Jog_Frame", "JogBase")
    cell.plc.write("Jog_Axis", 2)
    cell.plc.write("Jog_Forward", True)
    assert cell.run(lambda: False, 0.5, beat=True) is False
    assert cell.plc.read("Jog_Active") and not cell.plc.read("Jog_Dropped")
    cell.plc.write("Jog_Forward", False)
    assert cell.run(lambda: cell.plc.read("Jog_Done"), 0.1)
    moved = cell.robot.state()["tcp"][1] - start[1]
    assert moved == pytest.approx(110 * 0.5, abs=110 * 0.1)          # 10 % of 1100 mm/s for 0.5 s
    cell.run(lambda: False, 0.25)                                    # a data table after the stop
    cell.plc.write("Teach_Index", 3)
    cell.plc.write("Teach_Name", "Place")
    cell.plc.write("Teach_Execute", True)
    assert cell.run(lambda: cell.plc.read("Teach_Done") or cell.plc.read("Teach_Error"), 1)
    assert cell.plc.read("Teach_Done"), cell.plc.read("Teach_ErrorDescrip")
    entry = cell.plc.read("TeachTable[3]")
    pose = [entry["Pose"][k] for k in ("X", "Y", "Z", "RX", "RY", "RZ")]
    assert entry["Name"] == "Place" and entry["Taught"]
    assert pose == pytest.approx(cell.robot.state()["tcp"], abs=2e-3)
    assert not cell.plc.read("TeachTable[1]")["Taught"]


def test_a_silent_panel_releases_the_jog_and_the_robot_stops(cell):
    cell.plc.write("Jog_Frame", "JogJoint")
    cell.plc.write("Jog_Axis", 1)
    cell.plc.write("Jog_Forward", True)
    cell.run(lambda: False, 0.2, beat=True)
    last_beat = cell.now()
    assert cell.plc.read("Jog_Active")
    assert cell.run(lambda: cell.plc.read("Jog_Done"), 1)              # nobody released it: the watchdog did
    assert cell.plc.read("Jog_Dropped") and not cell.plc.read("Jog_Forward")
    (stop,) = cell.events("stop")
    assert stop["t"] - last_beat <= WATCHDOG_S + BEAT_S + 0.002
    cell.run(lambda: False, 0.3)
    assert cell.events("motion_start")[-1]["t"] <= stop["t"] and not cell.robot.state()["moving"]


class ListenNodeCell(Cell):
    """The same cell without the Ethernet Slave: a teach reads the position with a Listen-node request, Busy for a
    few scans (with the Ethernet Slave the newest data table completes it in the edge scan)."""

    def __init__(self):
        Plant.__init__(self, auto_enter=True)
        self.plc.write("Connect_SvrPort", 0)
        self.plc.write("Connect_Execute", True)
        assert self.run(lambda: self.plc.read("Connect_Connected") and self.plc.read("ReadPos_Valid"), 5)


def test_teach_stores_into_the_entry_selected_at_the_edge():
    """The panel selecting the next entry while Teach is Busy leaves it untouched: the example holds Teach_Index
    while Busy, as CBT_Teach.md asks (Point is written when the reading arrives, a few scans after the edge)."""
    cell = ListenNodeCell()
    try:
        cell.plc.write("Teach_Index", 5)
        cell.plc.write("Teach_Name", "Edge")
        cell.plc.write("Teach_Execute", True)
        assert cell.run(lambda: cell.plc.read("Teach_Busy"), 0.1)
        cell.plc.write("Teach_Index", 6)
        assert cell.run(lambda: cell.plc.read("Teach_Done") or cell.plc.read("Teach_Error"), 1)
        assert cell.plc.read("Teach_Done"), cell.plc.read("Teach_ErrorDescrip")
        assert cell.plc.read("TeachTable[5].Name") == "Edge" and cell.plc.read("TeachTable[5].Taught")
        assert not cell.plc.read("TeachTable[6].Taught")
    finally:
        cell.close()
