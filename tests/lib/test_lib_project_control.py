"""CBT_ProjectControl's refusals (issue 14): every ErrorID it documents besides 16#400A (E-stop) and 16#2010 (no
Ethernet Slave configured, both in test_lib_ethernet_slave.py), produced by the simulator's Ethernet Slave on
virtual time over loopback — the robot's status codes of TMscript 2.24 §17.4.1, a silent Ethernet Slave — with
the FB's ErrorID and ErrorDescrip (the text of docs/library/errors.tsv) and nothing done to the project."""

import pytest
from rig import SEC, Rig

from docs.library import make_error_tables as tables

TEXTS = {int(code[3:], 16): row["text"] for code, row in tables.load().items()}


@pytest.fixture
def svr():
    r = Rig(svr_port=0)
    r.write("StatusEnable", True)
    assert r.until(lambda: r.read("status.Valid"), 1)
    yield r
    r.close()


def command(rig, cmd, seconds):
    """A rising edge of Execute with ``cmd``; runs until Done or Error. Returns the virtual seconds it took."""
    rig.write("ProjCmd", cmd)
    rig.write("ProjExec", True)
    start = rig.plc.now_ns
    assert rig.until(lambda: rig.read("proj.Done") or rig.read("proj.Error"), seconds), "no Done or Error"
    return (rig.plc.now_ns - start) / SEC


def assert_refused(rig, error_id):
    assert rig.read("proj.Error") and not rig.read("proj.Done") and not rig.read("proj.Busy")
    assert rig.read("proj.ErrorID") == error_id, hex(rig.read("proj.ErrorID"))
    assert rig.read("proj.ErrorDescrip") == TEXTS[error_id]


def statuses(rig):
    return [e["code"] for e in rig.events("svr_status")]


def test_no_write_permission_is_16_4008_and_the_project_keeps_running(svr):
    """§17.4.1 status 02 WritePermission: the robot's Ethernet Slave settings do not let the PLC's address write."""
    svr.robot.svr.configure(write_permission=False)
    command(svr, "ProjectPause", 3)
    assert_refused(svr, 0x4008)
    assert statuses(svr) == ["02"] and svr.events("stick") == []
    svr.until(lambda: False, 0.3)                       # a newer data table: the project did not pause
    assert svr.read("Cobot.Status.ProjectRunning") and not svr.read("Cobot.Status.ProjectPaused")


def test_mode_error_is_16_4009(svr):
    """§17.4.1 status 06 ModeError (the item may not be written in this manual/auto mode). TMflow's tables make
    the stick items M/A, so the simulator's fault refuse_writes produces it (docs/simulator.md, Ethernet Slave)."""
    svr.srv.svr.inject(svr.robot, "refuse_writes", status=6)
    command(svr, "ProjectStop", 3)
    assert_refused(svr, 0x4009)
    assert statuses(svr) == ["06"] and svr.events("stick") == []
    assert svr.read("Cobot.Status.ProjectRunning")


@pytest.mark.parametrize("status", [1, 3, 4, 5, 7],
                         ids=["01-NotSupport", "03-InvalidData", "04-NotExist", "05-ReadOnly", "07-ValueError"])
def test_any_other_refusal_of_the_ethernet_slave_is_16_400B(svr, status):
    svr.srv.svr.inject(svr.robot, "refuse_writes", status=status)
    command(svr, "ProjectPause", 3)
    assert_refused(svr, 0x400B)
    assert statuses(svr) == [f"{status:02d}"] and svr.events("stick") == []
    svr.write("ProjExec", False)                        # the next command after a refusal works
    svr.scans(1)
    svr.srv.svr.clear_faults(svr.robot)
    command(svr, "ProjectPause", 3)
    assert svr.read("proj.Done") and svr.read("Cobot.Status.ProjectPaused")


def test_no_reply_from_the_ethernet_slave_within_2_s_is_16_3007(svr):
    """The write is sent, the Ethernet Slave reads it and answers nothing (fault stall: it stops its data table
    too): Error 16#3007 once 2 s passed since the write left, not before."""
    svr.srv.svr.inject(svr.robot, "stall")
    took = command(svr, "ProjectPause", 4)
    assert_refused(svr, 0x3007)
    assert 2.0 < took <= 2.1, took
    assert any(e["kind"] == "svr_stalled" for e in svr.robot.events)      # the write did arrive
    assert svr.events("stick") == []


def test_a_silent_ethernet_slave_is_16_2011_at_once_and_nothing_is_sent(svr):
    """No data table for more than 1 s (stall): the connection's SlaveLink is FALSE, so the command is refused in
    the scan of its rising edge, before anything is sent."""
    svr.srv.svr.inject(svr.robot, "stall")
    assert svr.until(lambda: not svr.read("Cobot.Status.SlaveLink"), 2)
    stalled = sum(e["kind"] == "svr_stalled" for e in svr.robot.events)
    svr.write("ProjCmd", "ProjectStop")
    svr.write("ProjExec", True)
    svr.scans(1)
    assert_refused(svr, 0x2011)
    svr.until(lambda: False, 0.5)
    assert sum(e["kind"] == "svr_stalled" for e in svr.robot.events) == stalled
    svr.srv.svr.clear_faults(svr.robot)
    assert svr.until(lambda: svr.read("Cobot.Status.SlaveLink"), 2)
    assert svr.read("Cobot.Status.ProjectRunning") and svr.events("stick") == []
