"""CBT_ReadIO (issue 26 item 1) on the virtual PLC against the simulator's Ethernet Slave over loopback: the
robot's control-box and end-module inputs and outputs as the data table brings them (TMflow 2.24 Appendix D
item names), Valid falling when the data stop and returning with them, no Listen-node traffic, Error 16#2010
without an Ethernet Slave, and the outputs cleared when Enable falls."""

from cell import svr  # noqa: F401 - the fixture
from rig import SEC, Rig


def tmsct_count(rig):
    return len(rig.scripts_in())


def test_part_present_sensor_and_gripper_output_read_back(svr):
    """The use case: the end module's DI0 (part present) and DO0 (gripper) as the robot reports them, within one
    data table period (0.1 s) of the change on the robot."""
    source = svr.robot.svr_source
    assert not svr.read("io.IO.End_DI[0]") and not svr.read("io.IO.End_DO[0]")
    source.set_input("End_DI0", 1)
    svr.robot.session.robot.io["EndModule.DO[0]"] = 1                 # the gripper output, set by the robot
    start = svr.plc.now_ns
    assert svr.until(lambda: svr.read("io.IO.End_DI[0]") and svr.read("io.IO.End_DO[0]"), 0.2)
    assert (svr.plc.now_ns - start) / SEC <= 0.11
    assert svr.read("io.Valid") and svr.read("io.Busy") and not svr.read("io.Error")
    source.set_input("End_DI0", 0)
    assert svr.until(lambda: not svr.read("io.IO.End_DI[0]"), 0.2)
    assert svr.read("io.IO.End_DO[0]")


def test_every_point_of_both_modules_lands_in_its_member(svr):
    """Each item of the table in its own member: control box DI/DO 0..15, AO/AI 0..1, end module DI/DO 0..3,
    AO/AI 0..1 (the data table configured with all of them)."""
    items = ([f"Ctrl_{k}{i}" for k in ("DO", "DI") for i in range(16)] + [f"End_{k}{i}" for k in ("DO", "DI")
             for i in range(4)] + [f"{m}_{k}{i}" for m in ("Ctrl", "End") for k in ("AO", "AI") for i in range(2)])
    svr.robot.svr.configure(items=items)
    io = svr.robot.session.robot.io
    for i in (0, 7, 15):
        io[f"ControlBox.DO[{i}]"] = 1
        svr.robot.svr_source.set_input(f"Ctrl_DI{i}", 1)
    io["EndModule.DO[3]"] = 1
    svr.robot.svr_source.set_input("End_DI2", 1)
    io["ControlBox.AO[1]"] = 7.5
    svr.robot.svr_source.set_input("Ctrl_AI0", -3.25)
    io["EndModule.AO[0]"] = 1.5
    svr.robot.svr_source.set_input("End_AI1", 9.0)
    svr.until(lambda: False, 0.25)
    assert [i for i in range(16) if svr.read(f"io.IO.Ctrl_DO[{i}]")] == [0, 7, 15]
    assert [i for i in range(16) if svr.read(f"io.IO.Ctrl_DI[{i}]")] == [0, 7, 15]
    assert [i for i in range(4) if svr.read(f"io.IO.End_DO[{i}]")] == [3]
    assert [i for i in range(4) if svr.read(f"io.IO.End_DI[{i}]")] == [2]
    assert [svr.read(f"io.IO.Ctrl_AO[{i}]") for i in range(2)] == [0.0, 7.5]
    assert [svr.read(f"io.IO.Ctrl_AI[{i}]") for i in range(2)] == [-3.25, 0.0]
    assert [svr.read(f"io.IO.End_AO[{i}]") for i in range(2)] == [1.5, 0.0]
    assert [svr.read(f"io.IO.End_AI[{i}]") for i in range(2)] == [0.0, 9.0]
    assert svr.read("status.Status.IO.End_DI[2]") and svr.read("Cobot.Status.IO.End_DI[2]")   # the same values


def test_valid_falls_when_the_data_stop_and_returns_with_them(svr):
    """No data table for 1 s (the Ethernet Slave stalls): Valid falls, IO keeps its last values, Busy stays;
    the data return: Valid again at the next data table, without touching Enable."""
    svr.robot.svr_source.set_input("End_DI1", 1)
    assert svr.until(lambda: svr.read("io.IO.End_DI[1]"), 0.2)
    svr.srv.svr.inject(svr.robot, "stall")
    start = svr.plc.now_ns
    assert svr.until(lambda: not svr.read("io.Valid"), 2)
    assert 1.0 <= (svr.plc.now_ns - start) / SEC <= 1.15
    assert svr.read("io.Busy") and not svr.read("io.Error") and svr.read("io.IO.End_DI[1]")
    svr.robot.svr_source.set_input("End_DI1", 0)
    svr.until(lambda: False, 0.3)
    assert svr.read("io.IO.End_DI[1]")                                 # the last value, Valid FALSE
    svr.srv.svr.clear_faults(svr.robot)
    assert svr.until(lambda: svr.read("io.Valid"), 0.5)
    assert not svr.read("io.IO.End_DI[1]")


def test_a_point_missing_from_the_data_table_stays_false(svr):
    svr.robot.svr.configure(items=["Project_Run", "End_DI0"])
    svr.robot.svr_source.set_input("End_DI0", 1)
    svr.robot.svr_source.set_input("End_DI1", 1)
    svr.until(lambda: False, 0.25)
    assert svr.read("io.Valid") and svr.read("io.IO.End_DI[0]") and not svr.read("io.IO.End_DI[1]")


def test_reading_io_sends_nothing_to_the_listen_node(svr):
    before = tmsct_count(svr)
    svr.until(lambda: False, 1.0)
    assert tmsct_count(svr) == before == 0
    assert not any(e["kind"] == "svr_read" or e["kind"] == "svr_write" for e in svr.robot.events)


def test_enable_false_clears_the_outputs_in_the_same_scan(svr):
    svr.write("IOEnable", False)
    svr.scans(1)
    assert not (svr.read("io.Valid") or svr.read("io.Busy") or svr.read("io.Error"))
    svr.write("IOEnable", True)
    svr.scans(1)
    assert svr.read("io.Valid") and svr.read("io.Busy")


def test_without_an_ethernet_slave_it_is_error_16_2010_until_enable_falls():
    r = Rig(program="Main_Cell.st")                                     # SvrPort 0
    try:
        r.write("IOEnable", True)
        r.scans(1)
        assert r.read("io.Error") and r.read("io.ErrorID") == 0x2010 and not r.read("io.Valid")
        assert r.read("io.ErrorDescrip") == "Ethernet Slave not configured: set SvrPort of CBT_Connect"
        assert not r.read("io.Busy")
        r.write("IOEnable", False)
        r.scans(1)
        assert not r.read("io.Error") and r.read("io.ErrorID") == 0 and r.read("io.ErrorDescrip") == ""
    finally:
        r.close()
