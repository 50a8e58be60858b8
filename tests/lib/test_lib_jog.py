"""CBT_Jog and CBT_Teach (issue 26 item 5) on the virtual PLC against the simulator over loopback, on virtual time:
the robot moves only while a jog input is held (increments of 50 ms of motion, never more than two on the robot),
the release sends StopAndClearBuffer(2) (TMscript 2.24 §15.8) in the scan that sees it, a cut link leaves the robot
at most 100 ms of motion, bad parameters (the rows of docs/library/ranges.tsv) are refused before anything is sent,
and CBT_Teach stores the robot's actual position (CBT_ReadActualPosition) into a teach-table entry that a motion FB
then goes back to. Times come from the simulator's event log against the PLC's scan time."""
from __future__ import annotations

import importlib.util
import math
import sys

import pytest
from rig import ROOT, SEC, Rig, move_abs

DOCS = ROOT / "docs" / "library"
INCREMENT_S = 0.05                       # CBT_Jog: an increment is 50 ms of motion at the rated speed
SCAN_S = 0.001


def ranges():
    spec = importlib.util.spec_from_file_location("make_types", DOCS / "make_types.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_types"] = module
    spec.loader.exec_module(module)
    return [r for r in module.read_ranges() if r.struct == "CBT_Jog"]


@pytest.fixture
def rig():
    r = Rig(program="Main_Jog.st")
    yield r
    r.close()


def now_s(rig):
    return rig.plc.now_ns / SEC


def log(rig, kind):
    return [e for e in rig.robot.events if e["kind"] == kind]


def tcp(rig):
    return rig.robot.state()["tcp"]


def jog(rig, frame="JogBase", axis=3, velocity=10, direction="JogFwd"):
    rig.write("JogFrame", frame)
    rig.write("JogAxis", axis)
    rig.write("JogVelocity", velocity)
    rig.write(direction, True)


def release_and_wait(rig, direction="JogFwd"):
    """Release in one scan; returns the scan time of the release."""
    rig.write(direction, False)
    rig.scans(1)
    released = now_s(rig)
    assert rig.until(lambda: not rig.read("jog.Busy"), 1), "the jog did not end after its release"
    return released


def test_moves_only_while_held_and_stops_in_the_release_scan(rig):
    start = tcp(rig)
    jog(rig)
    pressed = now_s(rig)
    assert rig.until(lambda: rig.read("jog.Active"), 0.02)
    assert rig.read("jog.Busy") and not rig.read("jog.Done")
    rig.until(lambda: False, 0.4)
    assert rig.read("jog.Active") and not rig.read("jog.Error")
    rig.write("JogFwd", False)
    rig.scans(1)
    released = now_s(rig)
    assert rig.until(lambda: rig.read("jog.Done"), 0.1)
    assert not rig.read("jog.Busy") and not rig.read("jog.Active")
    rig.scans(1)
    assert not rig.read("jog.Done")                                # released: Done for one scan
    (stop,) = log(rig, "stop")
    assert stop["t"] - released <= 0.1 and stop["t"] - released <= 2 * SCAN_S, (stop["t"], released)
    starts = [e["t"] for e in log(rig, "motion_start")]
    assert starts and pressed <= starts[0] and starts[-1] <= released
    rig.until(lambda: False, 0.3)
    assert [e["t"] for e in log(rig, "motion_start")] == starts    # nothing ran after the release
    end = tcp(rig)
    assert end[:2] == pytest.approx(start[:2], abs=1e-3) and end[3:] == pytest.approx(start[3:], abs=1e-3)
    expected = 1100 * 0.10 * (released - pressed)                   # 10 % of the rated 1100 mm/s, while held
    assert abs((end[2] - start[2]) - expected) <= 1100 * 0.10 * 2 * INCREMENT_S
    scripts = [s for _, s in rig.scripts_in()]
    assert scripts[-1] == "StopAndClearBuffer(2)"
    assert all(s.startswith('Move_Line("CPP",0,0,5.5,0,0,0,10,0,0,true)\r\nQueueTag(') for s in scripts[:-1])


def test_never_more_than_two_increments_on_the_robot(rig):
    jog(rig)
    rig.until(lambda: False, 0.5)
    release_and_wait(rig)
    sent = [e["t"] for e in log(rig, "frame_in") if e.get("header") == "TMSCT" and "Move_Line" in e["data"]]
    ends = [e["t"] for e in log(rig, "motion_end")]
    for t in sent:
        assert sum(1 for s in sent if s <= t) - sum(1 for e in ends if e <= t) <= 2, t


@pytest.mark.parametrize("frame, axis, direction, script", [
    ("JogJoint", 1, "JogFwd", 'Move_PTP("JPP",0.9,0,0,0,0,0,10,0,0,true)'),            # 10 % of 180 deg/s, 50 ms
    ("JogJoint", 5, "JogBwd", 'Move_PTP("JPP",0,0,0,0,-1.125,0,10,0,0,true)'),         # 10 % of 225 deg/s
    ("JogBase", 1, "JogBwd", 'Move_Line("CPP",-5.5,0,0,0,0,0,10,0,0,true)'),           # 10 % of 1100 mm/s
    ("JogTool", 3, "JogFwd", 'Move_Line("TPP",0,0,5.5,0,0,0,10,0,0,true)'),
    ("JogTool", 6, "JogFwd", 'Move_Line("TPP",0,0,0,0,0,1.125,10,0,0,true)'),          # 10 % of 225 deg/s
])
def test_each_frame_and_axis_sends_its_increment(rig, frame, axis, direction, script):
    jog(rig, frame=frame, axis=axis, direction=direction)
    assert rig.until(lambda: rig.read("jog.Active"), 0.02), rig.read("jog.ErrorDescrip")
    release_and_wait(rig, direction)
    assert rig.read("jog.Done") or not rig.read("jog.Error")
    scripts = [s for _, s in rig.scripts_in()]
    assert scripts[0] == script + "\r\nQueueTag(1)" and scripts[-1] == "StopAndClearBuffer(2)"
    assert not log(rig, "motion_failed")


def test_a_cut_link_leaves_the_robot_at_most_100_ms_of_motion(rig):
    """Nothing reaches the robot any more (the simulator's black_hole): it runs out the increments it has, at
    most two, then stands; the jog input stays held. The library sees the loss by its supervision and ends the
    jog with the increments' ErrorID."""
    jog(rig)
    rig.until(lambda: False, 0.23)
    rig.robot.inject("black_hole")
    cut = now_s(rig)
    assert rig.until(lambda: rig.read("jog.Error"), 2)
    assert rig.read("jog.ErrorID") in (0x200B, 0x2003), hex(rig.read("jog.ErrorID"))
    assert rig.read("JogFwd") and not rig.read("jog.Busy")
    moving = [e["t"] for e in log(rig, "motion_start") + log(rig, "motion_end")]
    assert max(moving) - cut <= 2 * INCREMENT_S + SCAN_S, (max(moving), cut)
    state = rig.robot.state()
    assert not state["moving"] and state["queue_length"] == 0           # and it stands
    rig.write("JogFwd", False)
    rig.scans(1)
    assert not rig.read("jog.Error")                                    # shown while held


def test_another_stop_ends_the_jog_command_aborted(rig):
    jog(rig)
    rig.until(lambda: False, 0.2)
    rig.write("StopParam.Mode", "StopImmediate")
    rig.write("StopExec", True)
    assert rig.until(lambda: rig.read("jog.CommandAborted") or rig.read("jog.Error"), 0.2)
    assert rig.read("jog.CommandAborted") and not rig.read("jog.Busy")
    rig.write("StopExec", False)
    rig.until(lambda: False, 0.2)
    starts = log(rig, "motion_start")
    assert starts[-1]["t"] <= log(rig, "stop")[0]["t"]                  # the held input sends nothing more
    rig.write("JogFwd", False)
    rig.scans(1)
    assert not rig.read("jog.CommandAborted")


def test_both_inputs_held_is_no_direction(rig):
    rig.write("JogFwd", True)
    rig.write("JogBwd", True)
    rig.scans(20)
    assert not rig.read("jog.Busy") and rig.scripts_in() == []


def test_reversing_stops_and_needs_a_new_press(rig):
    jog(rig)
    rig.until(lambda: False, 0.1)
    rig.write("JogFwd", False)
    rig.write("JogBwd", True)
    assert rig.until(lambda: rig.read("jog.Done"), 0.1)
    rig.scans(5)
    assert rig.read("jog.Done") and not rig.read("jog.Busy")            # shown while an input is held
    rig.write("JogBwd", False)
    rig.scans(1)
    rig.write("JogBwd", True)
    assert rig.until(lambda: rig.read("jog.Active"), 0.02)
    release_and_wait(rig, "JogBwd")
    assert '-5.5' in rig.scripts_in()[-2][1]


@pytest.mark.parametrize("row", ranges(), ids=lambda r: r.member)
def test_range_rows_are_refused_before_anything_is_sent(rig, row):
    """Every row of ranges.tsv for CBT_Jog: both limits (every enumeration value) jog, one step outside (an
    undefined enumeration value, written as an HMI could) is refused with the row's ErrorID and sends nothing."""
    path = {"Frame": "JogFrame", "Axis": "JogAxis", "Velocity": "JogVelocity"}[row.member]
    error = int(row.error[3:], 16)
    good = row.allowed if row.allowed else [row.low, row.high]
    bad = [3, -1] if row.allowed else [row.low - 1, row.high + 1]
    for value in good:
        rig.write(path, value)
        rig.write("JogFwd", True)
        assert rig.until(lambda: rig.read("jog.Active") or rig.read("jog.Error"), 0.05)
        assert not rig.read("jog.Error"), (value, rig.read("jog.ErrorDescrip"))
        release_and_wait(rig)
        rig.scans(1)
    for value in bad:
        sent = len(rig.scripts_in())
        rig.write(path, value, raw=bool(row.allowed))
        rig.write("JogFwd", True)
        rig.scans(1)
        assert rig.read("jog.Error") and rig.read("jog.ErrorID") == error, (value, rig.read("jog.ErrorDescrip"))
        assert not rig.read("jog.Busy") and rig.read("jog.ErrorDescrip")
        rig.scans(5)
        assert len(rig.scripts_in()) == sent
        rig.write("JogFwd", False)
        rig.scans(1)
        assert not rig.read("jog.Error")
        rig.write(path, good[0])


def teach(rig, index, name):
    rig.write("TeachIndex", index)
    rig.write("TeachName", name)
    rig.write("TeachExec", True)
    assert rig.until(lambda: rig.read("teach.Done") or rig.read("teach.Error"), 2)
    done = rig.read("teach.Done")
    rig.write("TeachExec", False)
    rig.scans(1)
    assert not (rig.read("teach.Done") or rig.read("teach.Busy"))
    return done


def point(rig, index):
    base = f"Table[{index}]"
    pose = [rig.read(f"{base}.Pose.{m}") for m in ("X", "Y", "Z", "RX", "RY", "RZ")]
    joints = [rig.read(f"{base}.Joints.{m}") for m in ("X", "Y", "Z", "RX", "RY", "RZ")]
    return rig.read(f"{base}.Name"), pose, joints, rig.read(f"{base}.Taught")


@pytest.mark.parametrize("svr", [False, True], ids=["listen_node", "ethernet_slave"])
def test_teach_stores_the_actual_position_and_a_move_goes_back_to_it(svr):
    rig = Rig(program="Main_Jog.st", **({"svr_port": 0} if svr else {}))
    try:
        if svr:
            assert rig.until(lambda: rig.read("Cobot.Status.SlaveLink"), 1)
        jog(rig, axis=1)
        rig.until(lambda: False, 0.3)
        release_and_wait(rig)
        rig.until(lambda: False, 0.25)                   # a data table after the stop
        assert teach(rig, 2, "Pick")
        name, pose, joints, taught = point(rig, 2)
        state = rig.robot.state()
        assert name == "Pick" and taught
        assert pose == pytest.approx(state["tcp"], abs=2e-3)
        assert joints == pytest.approx(state["joints"], abs=2e-3)
        assert point(rig, 1)[3] is False                 # only the chosen entry is written
        jog(rig, axis=2, velocity=20)
        rig.until(lambda: False, 0.2)
        release_and_wait(rig)
        assert tcp(rig)[1] != pytest.approx(pose[1], abs=1.0)
        target = dict(zip(("X", "Y", "Z", "RX", "RY", "RZ"), pose, strict=False))
        rig.set_struct("MoveParam", move_abs(MovementCommand=0, DataFormat=1, TargetPosition=target))
        rig.write("MoveExec", True)
        assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 5)
        assert rig.read("mover.Done"), rig.read("mover.ErrorDescrip")
        assert tcp(rig) == pytest.approx(pose, abs=2e-3)
    finally:
        rig.close()


def test_teach_refuses_an_empty_name_and_keeps_the_entry(rig):
    assert teach(rig, 1, "Home")
    before = point(rig, 1)
    rig.write("TeachName", "")
    rig.write("TeachExec", True)
    rig.scans(1)
    assert rig.read("teach.Error") and rig.read("teach.ErrorID") == 0x1073
    rig.write("TeachExec", False)
    rig.scans(1)
    assert point(rig, 1) == before


def test_teach_without_a_robot_ends_with_no_position_after_1_s():
    rig = Rig(program="Main_Jog.st", connect=False)
    try:
        rig.write("TeachExec", True)
        rig.scans(1)
        started = now_s(rig)
        assert rig.read("teach.Busy")
        assert rig.until(lambda: rig.read("teach.Error"), 2)
        assert rig.read("teach.ErrorID") == 0x2030 and math.isclose(now_s(rig) - started, 1.0, abs_tol=0.005)
        assert not point(rig, 1)[3]
    finally:
        rig.close()


def test_a_jog_without_a_connection_ends_with_16_2001_and_sends_nothing():
    rig = Rig(program="Main_Jog.st", connect=False)
    try:
        rig.write("JogFwd", True)
        assert rig.until(lambda: rig.read("jog.Error"), 0.05)
        assert rig.read("jog.ErrorID") == 0x2001 and not rig.read("jog.Busy")
        assert rig.scripts_in() == [] and not rig.read("Cobot.Stopping")
    finally:
        rig.close()
