"""CBT_SetOverride (issue 26 item 2) on the virtual PLC against the simulator's Ethernet Slave over loopback:
Project_Speed written in mode 2 (TMflow 2.24 Appendix D: R/W M/A, multiples of five, 5..100), Done once the data
table shows it, the motion time following it (the simulator's event log), every value outside the range of
ranges.tsv refused in the scan of the rising edge with nothing sent, and each refusal of the robot (TMscript 2.24
§17.4.1) its own ErrorID with the text of errors.tsv."""

import importlib.util
import sys

import pytest
from cell import svr  # noqa: F401 - the fixture
from rig import ROOT, SEC, Rig, move_abs

from docs.library import make_error_tables as tables

TEXTS = {int(code[3:], 16): row["text"] for code, row in tables.load().items()}


def range_row():
    spec = importlib.util.spec_from_file_location("make_types", ROOT / "docs" / "library" / "make_types.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_types"] = module
    spec.loader.exec_module(module)
    (row,) = [r for r in module.read_ranges() if r.struct == "CBT_SetOverride" and r.member == "Override"]
    return row


def override(rig, value, seconds=3):
    """A rising edge with ``value``; runs until Done or Error, then Execute falls. Seconds it took."""
    rig.write("OvrValue", value)
    rig.write("OvrExec", True)
    start = rig.plc.now_ns
    assert rig.until(lambda: rig.read("ovr.Done") or rig.read("ovr.Error"), seconds), "no Done or Error"
    took = (rig.plc.now_ns - start) / SEC
    return took


def release(rig):
    rig.write("OvrExec", False)
    rig.scans(1)
    assert not (rig.read("ovr.Done") or rig.read("ovr.Error") or rig.read("ovr.Busy"))


def assert_refused(rig, error_id):
    assert rig.read("ovr.Error") and not rig.read("ovr.Done") and not rig.read("ovr.Busy")
    assert rig.read("ovr.ErrorID") == error_id, hex(rig.read("ovr.ErrorID"))
    assert rig.read("ovr.ErrorDescrip") == TEXTS[error_id]


def svr_writes(rig):
    return [e["items"] for e in rig.events("svr_write")]


def test_override_50_is_done_when_the_robot_shows_it_and_sends_nothing_to_the_listen_node(svr):
    took = override(svr, 50)
    assert svr.read("ovr.Done"), svr.read("ovr.ErrorDescrip")
    assert svr_writes(svr) == [{"Project_Speed": 50}]
    assert svr.robot.session.robot.project_speed == 50
    assert svr.read("status.Status.ProjectSpeed") == 50 and svr.read("Cobot.Status.ProjectSpeed") == 50
    assert took <= 0.11                                   # the reply at once, then the next data table (0.1 s)
    assert svr.scripts_in() == []
    svr.scans(5)
    assert svr.read("ovr.Done")                           # R3: Done stays while Execute is TRUE
    release(svr)
    override(svr, 100)
    assert svr.read("ovr.Done") and svr.read("status.Status.ProjectSpeed") == 100


def motion_seconds(rig, exec_var, done_var):
    """Virtual seconds the simulator's robot took for the motion started by ``exec_var`` (its event log)."""
    rig.write(exec_var, True)
    assert rig.until(lambda: rig.read(done_var), 30)
    rig.write(exec_var, False)
    rig.scans(1)
    start = [e for e in rig.robot.events if e["kind"] == "motion_start"][-1]
    end = [e for e in rig.robot.events if e["kind"] == "motion_end"][-1]
    return end["t"] - start["t"]


def test_override_50_doubles_the_time_of_a_motion_in_percent(svr):
    """PTP at 50 % there and back: the robot's own log times the motions; at a project speed of 50 % the same
    motion takes twice as long (the motion FB's speed is unchanged)."""
    svr.set_struct("MoveParam", move_abs(TargetPosition=dict(X=40, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    full = motion_seconds(svr, "MoveExec", "mover.Done")
    override(svr, 50)
    release(svr)
    svr.set_struct("MoveParam", move_abs())
    half = motion_seconds(svr, "MoveExec", "mover.Done")
    assert half == pytest.approx(2 * full, rel=0.02), (full, half)


def test_every_value_outside_the_range_table_is_refused_at_the_edge_and_nothing_is_written(svr):
    """Every USINT value against ranges.tsv's row (5..100) and the manual's multiples of five: a refused value
    ends with 16#1040 in the scan of its rising edge, no write reaches the robot; every allowed value runs."""
    row = range_row()
    assert (row.low, row.high, row.error) == (5, 100, "16#1040")
    for value in range(256):
        allowed = row.low <= value <= row.high and value % 5 == 0
        writes = len(svr_writes(svr))
        svr.write("OvrValue", value)
        svr.write("OvrExec", True)
        svr.scans(1)
        if allowed:
            assert svr.read("ovr.Busy") and not svr.read("ovr.Error"), value
            assert svr.until(lambda: svr.read("ovr.Done"), 1), (value, svr.read("ovr.ErrorDescrip"))
            assert svr.robot.session.robot.project_speed == value
        else:
            assert_refused(svr, 0x1040)
            assert len(svr_writes(svr)) == writes, value
        release(svr)


def test_no_write_permission_is_16_4020_and_the_speed_stays(svr):
    """§17.4.1 status 02 WritePermission (the robot's IP filter does not let the PLC write)."""
    svr.robot.svr.configure(write_permission=False)
    override(svr, 30)
    assert_refused(svr, 0x4020)
    assert svr.robot.session.robot.project_speed == 100
    assert [e["code"] for e in svr.events("svr_status")] == ["02"]


@pytest.mark.parametrize("status,error_id", [(6, 0x4021), (7, 0x4022), (1, 0x4023), (3, 0x4023), (4, 0x4023),
                                             (5, 0x4023)],
                         ids=["06-ModeError", "07-ValueError", "01", "03", "04", "05"])
def test_each_refusal_of_the_ethernet_slave_is_its_own_error_id(svr, status, error_id):
    """06 ModeError: Project_Speed is M/A in TMflow's table, so no setting of the simulator produces it; its
    fault refuse_writes does (docs/simulator.md), as it does the others."""
    svr.srv.svr.inject(svr.robot, "refuse_writes", status=status)
    override(svr, 30)
    assert_refused(svr, error_id)
    assert svr.robot.session.robot.project_speed == 100
    release(svr)
    svr.srv.svr.clear_faults(svr.robot)
    override(svr, 30)                                     # the next command after a refusal works
    assert svr.read("ovr.Done")


def test_no_reply_within_2_s_is_16_3007(svr):
    svr.srv.svr.inject(svr.robot, "stall")
    took = override(svr, 30, seconds=4)
    assert_refused(svr, 0x3007)
    assert 2.0 < took <= 2.1, took


def test_a_silent_ethernet_slave_is_16_2020_at_once_and_nothing_is_sent(svr):
    svr.srv.svr.inject(svr.robot, "stall")
    assert svr.until(lambda: not svr.read("Cobot.Status.SlaveLink"), 2)
    stalled = sum(e["kind"] == "svr_stalled" for e in svr.robot.events)
    svr.write("OvrValue", 30)
    svr.write("OvrExec", True)
    svr.scans(1)
    assert_refused(svr, 0x2020)
    svr.until(lambda: False, 0.3)
    assert sum(e["kind"] == "svr_stalled" for e in svr.robot.events) == stalled


def test_accepted_but_not_shown_within_2_s_is_16_4024(svr):
    """The data table without Project_Speed: the robot takes the value, the PLC cannot see it in force."""
    svr.robot.svr.configure(items=["Project_Run", "Robot_Error"])
    took = override(svr, 30)
    assert_refused(svr, 0x4024)
    assert svr.robot.session.robot.project_speed == 30
    assert 2.0 < took <= 2.12, took


def test_without_an_ethernet_slave_it_is_16_2010():
    r = Rig(program="Main_Cell.st")
    try:
        r.write("OvrValue", 50)
        r.write("OvrExec", True)
        r.scans(1)
        assert_refused(r, 0x2010)
    finally:
        r.close()


def test_a_project_command_pending_on_the_one_write_channel_is_waited_for(svr):
    """CBT_ProjectControl and CBT_SetOverride started in the same scan share the connection's one Ethernet Slave
    write: both end Done, one after the other, each with its own write (in the order the program calls them:
    ovr before proj in Main_Cell.st)."""
    svr.write("ProjCmd", "ProjectPause")
    svr.write("ProjExec", True)
    svr.write("OvrValue", 25)
    svr.write("OvrExec", True)
    assert svr.until(lambda: svr.read("ovr.Done") and svr.read("proj.Done"), 3), \
        (svr.read("ovr.ErrorDescrip"), svr.read("proj.ErrorDescrip"))
    assert svr_writes(svr) == [{"Project_Speed": 25}, {"Stick_Pause": 1}]
    assert svr.read("Cobot.Status.ProjectPaused") and svr.read("status.Status.ProjectSpeed") == 25


def test_a_rising_edge_while_busy_is_ignored_and_the_first_value_ends(svr):
    """Execute pulsed twice while the first write waits for its data table: one write, the first value."""
    svr.write("OvrValue", 40)
    svr.write("OvrExec", True)
    svr.scans(2)
    svr.write("OvrExec", False)
    svr.scans(1)
    assert svr.read("ovr.Busy")
    svr.write("OvrValue", 60)
    svr.write("OvrExec", True)
    assert svr.until(lambda: svr.read("ovr.Done") or svr.read("ovr.Error"), 1)
    assert svr.read("ovr.Done") and svr_writes(svr) == [{"Project_Speed": 40}]
    assert svr.read("status.Status.ProjectSpeed") == 40
