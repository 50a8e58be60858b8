"""The robot's Ethernet Slave as the library's second channel (issue 14): status, project control and the actual
position from the streamed data table, on the virtual PLC against the simulator's Ethernet Slave over loopback."""
import pytest
from rig import Rig, move_abs

UNREACHABLE = dict(X=1900.0, Y=0.0, Z=300.0, RX=180.0, RY=0.0, RZ=90.0)


@pytest.fixture
def svr():
    r = Rig(svr_port=0)
    yield r
    r.close()


def listen_scripts(rig):
    return [e for e in rig.events("frame_in") if e.get("header") == "TMSCT"]


def test_robot_status_reports_project_mode_and_links(svr):
    svr.write("StatusEnable", True)
    assert svr.until(lambda: svr.read("status.Valid"), 1)
    s = lambda m: svr.read("status.Status." + m)  # noqa: E731
    assert s("ProjectRunning") and not s("ProjectPaused") and not s("ProjectStopped")
    assert not s("RobotError") and s("ErrorCode") == 0 and not s("EStop")
    assert s("SlaveLink") and s("ListenLink") and s("ProjectSpeed") == 100
    assert not svr.read("status.Error") and svr.read("Cobot.Status.Updates") > 0


def test_robot_status_without_a_configured_ethernet_slave_is_an_error(rig):
    rig.write("StatusEnable", True)
    rig.scans(1)
    assert rig.read("status.Error") and rig.read("status.ErrorID") == 0x2010
    assert rig.read("status.ErrorDescrip") == "Ethernet Slave not configured: set SvrPort of CBT_Connect"
    rig.write("StatusEnable", False)
    rig.scans(1)
    assert not rig.read("status.Error")


def test_read_position_from_the_data_table_sends_nothing_to_the_listen_node(svr):
    before = len(listen_scripts(svr))
    svr.write("ReadPeriod", 50_000_000)
    svr.write("ReadEnable", True)
    assert svr.until(lambda: svr.read("rd.Valid"), 1)
    svr.until(lambda: False, 2)
    joints = [svr.read(f"rd.Position.Joints[{i}]") for i in range(1, 7)]
    assert joints == pytest.approx([0, 0, 90, 0, 90, 0], abs=0.01)
    assert svr.read("rd.Valid") and len(listen_scripts(svr)) == before


def test_read_position_without_ethernet_slave_is_rate_limited_by_period(rig):
    rig.write("ReadPeriod", 250_000_000)
    rig.write("ReadEnable", True)
    assert rig.until(lambda: rig.read("rd.Valid"), 1)
    start, first = rig.plc.now_ns, len(listen_scripts(rig))
    rig.until(lambda: False, 5)
    rate = (len(listen_scripts(rig)) - first) / ((rig.plc.now_ns - start) / 1e9)
    # at most one script per 250 ms (fewer when replies are slow: loopback delivery is real time)
    assert 1.0 <= rate <= 4.0 + 1e-9, rate
    assert rig.read("rd.Valid")


def test_damaged_position_reply_is_dropped_counted_and_valid_returns(rig):
    rig.write("ReadPeriod", 100_000_000)
    rig.write("ReadEnable", True)
    assert rig.until(lambda: rig.read("rd.Valid"), 1)
    rig.robot.inject("corrupt_checksum", count=1)
    assert rig.until(lambda: rig.read("rd.Dropped") >= 1, 2)
    assert not rig.read("rd.Error")
    rig.until(lambda: False, 1)
    assert rig.read("rd.Valid") and not rig.read("rd.Error") and rig.read("rd.Dropped") == 1


def test_read_position_period_out_of_range_is_a_parameter_error(rig):
    rig.write("ReadPeriod", 1_000_000)
    rig.write("ReadEnable", True)
    rig.scans(1)
    assert rig.read("rd.Error") and rig.read("rd.ErrorID") == 0x1004 and not rig.read("rd.Valid")


def test_robot_error_is_told_apart_and_project_control_restarts_the_project(svr):
    """Out of reach: the robot's project stops with a robot error. CBT_Connect says so (16#4006), CBT_RobotStatus
    gives the robot's code and text, CBT_ProjectControl Play acknowledges and restarts, CBT_Connect reconnects."""
    svr.write("StatusEnable", True)
    assert svr.until(lambda: svr.read("status.Valid"), 1)
    svr.set_struct("MoveParam", move_abs(MovementCommand=0, DataFormat=2, TargetPosition=UNREACHABLE))
    svr.write("MoveExec", True)
    assert svr.until(lambda: svr.read("mover.Error"), 3)
    assert svr.read("mover.ErrorID") == 0x4006                      # stopped by the robot error
    assert svr.until(lambda: svr.read("conn.ErrorID") == 0x4006, 2), hex(svr.read("conn.ErrorID"))
    assert svr.read("conn.Error") and svr.read("conn.ErrorDescrip").startswith("Robot error stopped the project")
    svr.scans(1)                                                  # CBT_RobotStatus runs before CBT_Connect
    assert svr.read("status.Status.RobotError") and svr.read("status.Status.ProjectStopped")
    assert svr.read("status.Status.ErrorCode") != 0 and "reach" in svr.read("status.Status.ErrorText")
    svr.write("ProjCmd", "ProjectPlay")
    svr.write("ProjExec", True)
    assert svr.until(lambda: svr.read("proj.Done") or svr.read("proj.Error"), 6)
    assert svr.read("proj.Done"), svr.read("proj.ErrorDescrip")
    assert svr.until(lambda: svr.read("conn.Connected"), 7), svr.read("conn.ErrorDescrip")
    assert not svr.read("status.Status.RobotError") and svr.read("status.Status.ProjectRunning")
    assert [e["button"] for e in svr.events("stick")] == ["Play"]


def test_project_stopped_at_the_robot_is_not_a_robot_error(svr):
    svr.robot.inject("stop_project")
    assert svr.until(lambda: svr.read("conn.ErrorID") == 0x4007, 2), hex(svr.read("conn.ErrorID"))
    assert svr.read("conn.ErrorDescrip") == "Robot project stopped without a robot error (operator or program)"


def test_pause_then_play_through_the_stick(svr):
    svr.write("ProjCmd", "ProjectPause")
    svr.write("ProjExec", True)
    assert svr.until(lambda: svr.read("proj.Done") or svr.read("proj.Error"), 3)
    assert svr.read("proj.Done") and svr.read("Cobot.Status.ProjectPaused")
    svr.write("ProjExec", False)
    svr.scans(1)
    svr.write("ProjCmd", "ProjectPlay")
    svr.write("ProjExec", True)
    assert svr.until(lambda: svr.read("proj.Done") or svr.read("proj.Error"), 3)
    assert svr.read("proj.Done") and not svr.read("Cobot.Status.ProjectPaused")


def test_play_with_the_emergency_stop_pressed_is_refused(svr):
    svr.robot.svr_source.model.estop = True
    assert svr.until(lambda: svr.read("Cobot.Status.EStop"), 1)
    svr.write("ProjCmd", "ProjectPlay")
    svr.write("ProjExec", True)
    svr.scans(1)
    assert svr.read("proj.Error") and svr.read("proj.ErrorID") == 0x400A


def test_project_control_without_ethernet_slave_is_an_error(rig):
    rig.write("ProjExec", True)
    rig.scans(1)
    assert rig.read("proj.Error") and rig.read("proj.ErrorID") == 0x2010


def svr_frame(data: bytes, checksum=None) -> bytes:
    body = b"TMSVR," + str(len(data)).encode() + b"," + data + b","
    cs = 0
    for b in body:
        cs ^= b
    return b"$" + body + b"*%02X\r\n" % (cs if checksum is None else checksum)


@pytest.mark.parametrize("raw", [
    svr_frame(b"0,1,\x0b\x00Project_Run\x01\x00\x01", checksum=0x00),     # wrong checksum
    svr_frame(b"0,1,\x05\x00ab"),                                           # name length past the end
    svr_frame(b"0,1,\x0b\x00Project_Run\x09\x00\x01"),                     # value length past the end
], ids=["checksum", "name-length", "value-length"])
def test_damaged_data_table_frame_is_dropped_and_counted(svr, raw):
    svr.write("StatusEnable", True)
    assert svr.until(lambda: svr.read("status.Valid"), 1)
    n = svr.read("Cobot.SvrRxLen")
    for i, b in enumerate(raw):
        svr.write(f"Cobot.SvrRxBuf.Bytes[{n + i}]", b)
    svr.write("Cobot.SvrRxLen", n + len(raw))
    bad, updates = svr.read("Cobot.Status.BadFrames"), svr.read("Cobot.Status.Updates")
    svr.scans(1)
    assert svr.read("Cobot.Status.BadFrames") == bad + 1 and svr.read("Cobot.Status.Updates") == updates
    assert svr.read("Cobot.Status.ProjectRunning")                # nothing of the damaged table was taken
    assert svr.until(lambda: svr.read("Cobot.Status.Updates") > updates, 1)
    assert svr.read("status.Valid") and not svr.read("status.Error")


@pytest.mark.parametrize("stop,error_id", [("robot error", 0x4006), ("project stopped", 0x4007)])
def test_a_command_refused_while_the_project_is_stopped_says_why(svr, stop, error_id):
    """With the Ethernet Slave, a command started while the robot's project is stopped is refused with what the
    operator must fix: 16#4006 after a robot error, 16#4007 when the project was stopped without one."""
    if stop == "robot error":
        svr.robot.session.robot_error("Line: target pose is out of reach")
    else:
        svr.robot.inject("stop_project")
    assert svr.until(lambda: svr.read("conn.ErrorID") == error_id, 2), hex(svr.read("conn.ErrorID"))
    svr.set_struct("MoveParam", move_abs())
    svr.write("MoveExec", True)
    assert svr.until(lambda: svr.read("mover.Error"), 1)
    assert svr.read("mover.ErrorID") == error_id and svr.events("motion_start") == []
