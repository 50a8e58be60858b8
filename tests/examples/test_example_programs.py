"""The example programs on the virtual PLC against the robot simulator, scan by scan on virtual time
(Contract D): they check clean, connect, run every command rung, and run the PnP cycle with its dwell,
Pause/Resume and clean end (stop, fault and recovery of the PnP cycle: test_pnp_states.py)."""
from __future__ import annotations

import pytest
from pnp_plant import SECOND, SOURCES, Plant

from cbt_hmi.web.mapping import Mapping
from vplc.project import load_project


@pytest.fixture
def rig():
    r = Plant()
    yield r
    r.close()


def test_examples_check_clean_with_the_library():
    project = load_project(SOURCES)
    assert not project.has_errors, project.render_diagnostics()


def test_hmi_variable_table_matches_the_example_globals(rig):
    Mapping.load().check_against_plc(rig.plc)


def test_connect_rung_connects_and_reports_the_time(rig):
    rig.connect()
    assert rig.read("Connect_Error") is False
    assert rig.read("Connect_LastConnTime") != rig.read("Connect_LastLostTime")
    rig.until(lambda: rig.read("ReadPos_Valid"), "a valid actual position")
    position = rig.read("ReadPos_Position")
    tcp = rig.robot.state()["tcp"]
    assert [position["TCP"][k] for k in ("X", "Y", "Z")] == pytest.approx(tcp[:3], abs=0.5)


def motion(script: list[str]) -> str:
    """The motion line of a non-blended move; the library follows it with its own QueueTag(n)."""
    assert len(script) == 2 and script[1].startswith("QueueTag("), script
    return script[0]


def test_every_command_rung_sends_the_exact_script(rig):
    rig.connect()
    rig.plc.write("MoveAbs_Param.TargetPosition.X", 380.0)
    assert motion(rig.command("MoveAbs")) == 'PTP("CPP",380,0,400,180,0,90,30,200,0,true)'
    assert rig.read("MoveAbs_CmdID_Ack") > 0
    assert motion(rig.command("MoveRel")) == 'Move_Line("CPP",0,0,50,0,0,0,20,200,0,true)'
    assert motion(rig.command("MoveCircle")) == \
        'Circle("CPP",450,50,400,180,0,90,400,100,400,180,0,90,30,200,0,0,true)'
    assert rig.command("ChangeBase") == ["ChangeBase(0,0,0,0,0,0)"]
    assert rig.command("ChangeTCP") == ["ChangeTCP(0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0)"]
    rig.plc.write("ProgramControl_Param.Command", "Pause")
    assert rig.command("ProgramControl") == ["Pause()"]
    rig.plc.write("ProgramControl_Param.Command", "Resume")
    assert rig.command("ProgramControl") == ["Resume()"]


def test_pnp_runs_two_cycles_with_dwell_pause_resume_and_stops_cleanly(rig):
    rig.connect()
    since = len(rig.robot.events)
    rig.plc.write("PnP_Example_Execute", True)
    rig.until(lambda: rig.read("PnP_Waiting"), "the dwell after pick", 30)
    assert rig.read("PnP_Segment") == 1
    dwell_start = rig.plc.now_ns
    rig.until(lambda: not rig.read("PnP_Waiting"), "the end of the dwell", 5)
    assert rig.plc.now_ns - dwell_start == pytest.approx(2 * SECOND, abs=0.01 * SECOND)   # T#2s as shipped
    rig.plc.write("PnP_DwellTime", SECOND // 2)                # a new dwell time applies from the next dwell

    rig.until(lambda: rig.read("PnP_Segment") == 4 and rig.read("PnP_MoveBusy"), "the place move", 30)
    rig.run_for(0.2)
    rig.plc.write("ProgramControl_Param.Command", 0)
    rig.command("ProgramControl")
    assert rig.robot.state()["paused"]
    rig.run_for(3)
    assert rig.read("PnP_Segment") == 4, "the sequence must wait while the robot is paused"
    rig.plc.write("ProgramControl_Param.Command", 1)
    rig.command("ProgramControl")
    rig.until(lambda: rig.read("PnP_Waiting"), "the dwell after place", 30)
    dwell_start = rig.plc.now_ns
    rig.until(lambda: not rig.read("PnP_Waiting"), "the end of the dwell", 5)
    assert rig.plc.now_ns - dwell_start == pytest.approx(SECOND // 2, abs=0.01 * SECOND)

    rig.until(lambda: rig.read("PnP_CycleCount") >= 2, "two complete cycles", 120)
    rig.plc.write("PnP_Example_Execute", False)
    # the segment in progress ends, then the cycle is Idle; PnP_Segment shows where the next start goes on
    rig.until(lambda: rig.read("PnP_State") == "Idle" and not rig.read("PnP_MoveBusy"), "a clean end", 30)
    moves_after_stop = len([e for e in rig.robot.events if e["kind"] == "motion_start"])
    rig.run_for(3)
    assert len([e for e in rig.robot.events if e["kind"] == "motion_start"]) == moves_after_stop

    targets = [[p["TargetPosition"][k] for k in ("X", "Y", "Z")] for p in rig.read("PnP_MoveParameters")]
    ends = [e["pose"][:3] for e in rig.robot.events[since:] if e["kind"] == "motion_end"]
    for segment, target in enumerate(targets):
        reached = [end for end in ends if end == pytest.approx(target, abs=0.5)]
        assert len(reached) >= 2, f"segment {segment} reached {len(reached)} times"
    assert rig.read("PnP_MoveError") is False
    # the gripper closed at every pick and opened at every place, each after the robot had arrived there
    gripper = [e for e in rig.robot.events[since:] if e["kind"] == "io" and e["point"] == "EndModule.DO[0]"]
    assert len(gripper) >= 4 and [e["value"] for e in gripper] == [1, 0] * (len(gripper) // 2)
    for event in gripper:
        arrived = [e for e in rig.robot.events[since:] if e["kind"] == "motion_end" and e["t"] <= event["t"]][-1]
        assert arrived["pose"][:3] == pytest.approx(targets[1 if event["value"] else 4], abs=0.5)
    assert rig.read("PnP_GripperClosed") is False
