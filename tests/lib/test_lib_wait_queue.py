"""CBT_WaitQueue and the motion status of CBT_RobotStatus (issue 26 item 3) on the virtual PLC against the
simulator over loopback: the mark 'QueueTag(n)' alone (TMscript 2.24 §13.1), Done only once every motion sent
before it has ended on the robot (the simulator's event log), blended motions of several FB instances included;
a stop ends it CommandAborted; Moving / Standstill from TCP_Speed3D and Joint_Speed (TMflow 2.24 Appendix D)
and MotionsQueued following what the robot still has to do."""

from cell import svr  # noqa: F401 - the fixture
from rig import SEC, Rig, move_abs

TARGETS = [dict(X=30, Y=0, Z=90, RX=0, RY=90, RZ=0), dict(X=30, Y=20, Z=90, RX=0, RY=90, RZ=0),
           dict(X=0, Y=20, Z=90, RX=0, RY=90, RZ=0), dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=0)]


def motion_ends(rig):
    return [e["t"] for e in rig.robot.events if e["kind"] == "motion_end"]


def now_s(rig):
    return rig.plc.now_ns / SEC


def start_blended_path(rig):
    """Four blended PTPs from four FB instances, each Done when the robot accepted it."""
    for k, target in enumerate(TARGETS, start=1):
        rig.set_struct(f"MParam[{k}]", move_abs(TargetPosition=target, BlendingEnable=True, BlendingValue=50))
        rig.write(f"MExec[{k}]", True)
    assert rig.until(lambda: all(rig.read(f"movers[{k}].Done") for k in range(1, 5)), 1)
    assert motion_ends(rig) == []                        # all accepted, none finished


def test_done_when_every_motion_sent_before_it_has_ended(svr):
    start_blended_path(svr)
    svr.write("WaitExec", True)
    assert svr.until(lambda: svr.read("wait.Active"), 0.1)
    assert svr.read("wait.Busy") and not svr.read("wait.Done")
    active_at = now_s(svr)
    assert svr.until(lambda: svr.read("wait.Done") or svr.read("wait.Error"), 20), svr.read("wait.ErrorDescrip")
    done_at = now_s(svr)
    ends = motion_ends(svr)
    assert svr.read("wait.Done") and len(ends) == 4
    assert ends[-1] <= done_at <= ends[-1] + 0.01, (ends, done_at)     # pushed as the last motion ends
    assert active_at < ends[0]
    scripts = [s for _, s in svr.scripts_in()]
    assert scripts[-1] == "QueueTag(1)" and svr.read("wait.CmdID_Ack") == int(svr.scripts_in()[-1][0])
    svr.write("WaitExec", False)
    svr.scans(1)
    assert not (svr.read("wait.Done") or svr.read("wait.Busy"))


def test_nothing_queued_is_done_at_once(svr):
    svr.write("WaitExec", True)
    assert svr.until(lambda: svr.read("wait.Done"), 0.05)
    assert [s for _, s in svr.scripts_in()] == ["QueueTag(1)"]
    assert motion_ends(svr) == []


def test_a_motion_sent_after_it_is_not_waited_for(svr):
    """The mark goes into the queue behind what was sent before its edge: a motion sent in the next scan comes
    after it, so Done arrives when the first motion ends, before the second one."""
    svr.set_struct("MParam[1]", move_abs(TargetPosition=TARGETS[0], BlendingEnable=True))
    svr.write("MExec[1]", True)
    assert svr.until(lambda: svr.read("movers[1].Done"), 1)
    svr.write("WaitExec", True)
    svr.scans(1)
    svr.set_struct("MParam[2]", move_abs(TargetPosition=TARGETS[1], BlendingEnable=True))
    svr.write("MExec[2]", True)
    assert svr.until(lambda: svr.read("wait.Done"), 20)
    done_at = now_s(svr)
    assert svr.until(lambda: len(motion_ends(svr)) == 2, 20)
    first, second = motion_ends(svr)
    assert first <= done_at < second


def test_a_stop_ends_it_command_aborted_and_the_robot_stands(svr):
    start_blended_path(svr)
    svr.write("WaitExec", True)
    assert svr.until(lambda: svr.read("wait.Active"), 0.1)
    svr.until(lambda: False, 0.2)
    svr.write("StopExec", True)
    assert svr.until(lambda: svr.read("wait.CommandAborted") or svr.read("wait.Done") or svr.read("wait.Error"), 2)
    assert svr.read("wait.CommandAborted") and not svr.read("wait.Done") and not svr.read("wait.Error")
    assert svr.until(lambda: svr.read("stop.Done"), 1)
    assert svr.until(lambda: svr.read("status.Status.Standstill"), 1)
    assert svr.read("status.Status.MotionsQueued") == 0


def test_without_a_connection_it_is_16_2001_and_nothing_is_sent():
    r = Rig(program="Main_Cell.st", connect=False)
    try:
        r.write("WaitExec", True)
        r.scans(1)
        assert r.read("wait.Error") and r.read("wait.ErrorID") == 0x2001
    finally:
        r.close()


def test_moving_and_standstill_follow_the_robot(svr):
    """Standing: Standstill, speeds 0. During a PTP: Moving within one data table (0.1 s) of the motion's start
    on the robot, TCP speed and a joint speed above the thresholds; after it: Standstill within one data table
    of its end."""
    assert svr.read("status.Status.Standstill") and not svr.read("status.Status.Moving")
    assert svr.read("status.Status.TCPSpeed") == 0.0
    svr.set_struct("MoveParam", move_abs(TargetPosition=TARGETS[0]))
    svr.write("MoveExec", True)
    assert svr.until(lambda: svr.read("status.Status.Moving"), 0.5)
    started = [e["t"] for e in svr.robot.events if e["kind"] == "motion_start"][0]
    assert now_s(svr) - started <= 0.11
    assert not svr.read("status.Status.Standstill")
    assert svr.read("status.Status.TCPSpeed") >= 1.0
    assert abs(svr.read("status.Status.JointSpeed[1]")) >= 0.5                # J1 turns 0 -> 30 deg
    assert svr.until(lambda: svr.read("status.Status.Standstill"), 20)
    (ended,) = motion_ends(svr)
    assert 0 <= now_s(svr) - ended <= 0.11
    assert not svr.read("status.Status.Moving")


def test_motions_queued_counts_the_non_blended_motions_the_robot_still_has(svr):
    for k in (1, 2, 3):
        svr.set_struct(f"MParam[{k}]", move_abs(TargetPosition=TARGETS[k - 1]))
        svr.write(f"MExec[{k}]", True)
    assert svr.until(lambda: svr.read("status.Status.MotionsQueued") == 3, 0.1)
    assert svr.until(lambda: svr.read("status.Status.MotionsQueued") == 2, 20)
    assert len(motion_ends(svr)) == 1
    assert svr.until(lambda: svr.read("status.Status.MotionsQueued") == 0, 20)
    assert len(motion_ends(svr)) == 3 and all(svr.read(f"movers[{k}].Done") for k in (1, 2, 3))


def test_moving_and_standstill_stay_false_without_the_speed_items(svr):
    svr.robot.svr.configure(items=["Project_Run", "Project_Speed", "Joint_Angle"])
    svr.until(lambda: False, 0.25)
    assert svr.read("status.Valid")
    assert not svr.read("status.Status.Moving") and not svr.read("status.Status.Standstill")


def test_the_status_follows_a_dropped_frame_and_the_listen_link_between_data_tables(svr):
    """CBT_RobotStatus copies only when something changed: a damaged data table (counted, no new values) and the
    Listen-node link (the project stops: the robot closes the Listen node, the Ethernet Slave goes on) still show
    in the next call."""
    bad = svr.read("status.Status.BadFrames")
    svr.srv.svr.inject(svr.robot, "corrupt_checksum", count=1)
    assert svr.until(lambda: svr.read("status.Status.BadFrames") == bad + 1, 0.2)
    assert svr.read("status.Valid")
    assert svr.read("status.Status.ListenLink")
    svr.robot.stop_project()
    assert svr.until(lambda: not svr.read("status.Status.ListenLink"), 2)
    assert svr.read("status.Valid")
    assert svr.until(lambda: svr.read("status.Status.ProjectStopped"), 0.2)          # the next data table


def test_while_a_stop_is_held_it_is_done_at_once(svr):
    """A CBT_Stop with Execute held clears the queue and refuses motions (16#4005); the mark is no motion: it is
    sent and reached at once, the queue being empty."""
    svr.write("StopExec", True)
    assert svr.until(lambda: svr.read("stop.Done"), 1)
    svr.write("WaitExec", True)
    assert svr.until(lambda: svr.read("wait.Done") or svr.read("wait.Error"), 0.1)
    assert svr.read("wait.Done")
