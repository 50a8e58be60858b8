"""CBT_MoveAbsolute: normal ends, completion semantics, timing-chart rules, every parameter ErrorID."""
import pytest
from rig import move_abs


def start(rig, fb="mover", exec_="MoveExec", param="MoveParam", **kw):
    rig.set_struct(param, move_abs(**kw))
    rig.write(exec_, True)


def test_non_blended_move_is_active_while_moving_and_done_when_arrived(rig):
    start(rig, TargetPosition=dict(X=10, Y=0, Z=90, RX=0, RY=90, RZ=0))
    assert rig.until(lambda: rig.read("mover.Active"), 1)
    assert rig.read("mover.Busy") and not rig.read("mover.Done")
    assert rig.until(lambda: rig.read("mover.Done"), 5)
    end = rig.events("motion_end")
    assert len(end) == 1 and end[0]["t"] <= rig.plc.now_ns / 1e9
    assert not (rig.read("mover.Busy") or rig.read("mover.Active") or rig.read("mover.Error"))
    assert rig.read("mover.CmdID_Ack") == int(rig.scripts_in()[0][0])


def test_script_carries_full_precision_numbers_and_queue_tag(rig):
    start(rig, MovementCommand=0, DataFormat=4, Speed=250,
          TargetPosition=dict(X=417.5, Y=-122.345, Z=343.9, RX=180, RY=0, RZ=90.25))
    assert rig.until(lambda: rig.read("mover.Done"), 5)
    ident, script = rig.scripts_in()[0]
    assert script.startswith('Line("CAR",417.5,-122.345,343.9,180,0,90.25,250,200,0,true)\r\nQueueTag(')
    assert "+" not in script


def test_blended_move_is_done_on_acceptance_before_motion_ends(rig):
    start(rig, BlendingEnable=True, BlendingValue=50, TargetPosition=dict(X=30, Y=0, Z=90, RX=0, RY=90, RZ=0))
    assert rig.until(lambda: rig.read("mover.Done"), 1)
    assert rig.events("motion_end") == []
    assert "QueueTag" not in rig.scripts_in()[0][1]


def test_blending_chain_of_twelve_moves_sends_each_once_in_order(rig):
    targets = [dict(X=5.0 * (k % 6), Y=0, Z=90, RX=0, RY=90, RZ=1.5 * k) for k in range(12)]
    for k, target in enumerate(targets):
        rig.set_struct("MoveParam", move_abs(BlendingEnable=True, BlendingValue=20, TargetPosition=target))
        rig.write("MoveExec", True)
        assert rig.until(lambda: rig.read("mover.Done"), 1), k
        rig.write("MoveExec", False)
        rig.scans(1)
    assert rig.until(lambda: len(rig.events("motion_end")) == 12, 20)
    ids = [i for i, _ in rig.scripts_in()]
    assert len(ids) == 12 and len(set(ids)) == 12
    assert [e["joints_to"][5] for e in rig.events("motion_start")] == [1.5 * k for k in range(12)]


def test_done_stays_visible_one_scan_when_execute_dropped_early(rig):
    start(rig)
    rig.scans(1)
    rig.write("MoveExec", False)
    seen = []
    rig.until(lambda: not rig.read("mover.Busy"), 5)
    seen.append(rig.read("mover.Done"))
    rig.scans(1)
    seen.append(rig.read("mover.Done"))
    assert seen == [True, False]


def test_done_stays_while_execute_held(rig):
    start(rig)
    assert rig.until(lambda: rig.read("mover.Done"), 5)
    rig.scans(20)
    assert rig.read("mover.Done")
    rig.write("MoveExec", False)
    rig.scans(1)
    assert not rig.read("mover.Done")


def test_inputs_are_latched_at_rising_edge(rig):
    start(rig, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=7))
    rig.scans(1)
    rig.write("MoveParam.TargetPosition.RZ", 55.0)
    assert rig.until(lambda: rig.read("mover.Done"), 5)
    assert rig.events("motion_start")[0]["joints_to"][5] == 7.0


def test_several_fbs_busy_at_once_each_gets_its_own_reply(rig):
    for k in range(1, 5):
        rig.set_struct(f"MParam[{k}]", move_abs(TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=10.0 * k)))
        rig.write(f"MExec[{k}]", True)
    rig.scans(3)
    assert all(rig.read(f"movers[{k}].Busy") for k in range(1, 5))
    assert rig.until(lambda: all(rig.read(f"movers[{k}].Done") for k in range(1, 5)), 10)
    acks = {rig.read(f"movers[{k}].CmdID_Ack") for k in range(1, 5)}
    assert len(acks) == 4 and len(rig.events("motion_end")) == 4


PARAM_ERRORS = [
    (dict(MovementCommand=1, DataFormat=2), 0x1011),
    (dict(MovementCommand=0, DataFormat=0), 0x1012),
    (dict(Speed=0), 0x1013),
    (dict(Speed=101), 0x1013),
    (dict(MovementCommand=0, DataFormat=3, Speed=4501), 0x1014),
    (dict(AccelTime=10000), 0x1015),
    (dict(BlendingEnable=True, BlendingValue=101), 0x1016),
    (dict(MovementCommand=0, DataFormat=2, BlendingEnable=True, BlendingValue=1001), 0x1017),
    (dict(RobotPoseEnable=True), 0x1018),
    (dict(TargetPosition=dict(X=float("nan"), Y=0, Z=0, RX=0, RY=0, RZ=0)), 0x101A),
    (dict(TargetPosition=dict(X=0, Y=2e5, Z=0, RX=0, RY=0, RZ=0)), 0x101A),
]


@pytest.mark.parametrize("override,error_id", PARAM_ERRORS)
def test_invalid_parameter_ends_in_error_and_sends_nothing(rig, override, error_id):
    before = len(rig.events("frame_in"))
    start(rig, **override)
    rig.scans(2)
    assert rig.read("mover.Error") and rig.read("mover.ErrorID") == error_id
    assert rig.read("mover.ErrorDescrip") and not rig.read("mover.Busy")
    assert [e for e in rig.events("frame_in")[before:] if e.get("header") == "TMSCT"] == []


def test_command_without_connection_ends_with_not_connected():
    from rig import Rig
    r = Rig(connect=False)
    try:
        start(r)
        r.scans(2)
        assert r.read("mover.ErrorID") == 0x2001
    finally:
        r.close()


def test_pose_is_sent_for_cartesian_ptp(rig):
    start(rig, DataFormat=1, RobotPoseEnable=True, RobotPose=dict(Pose1=0, Pose2=0, Pose3=0),
          TargetPosition=dict(X=417.5, Y=-122.3, Z=300, RX=180, RY=0, RZ=90))
    assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 5)
    assert rig.scripts_in()[0][1].startswith('PTP("CPP",417.5,-122.3,300,180,0,90,50,200,0,true,0,2,4)')
    assert rig.read("mover.Done")


def test_retrigger_while_busy_starts_new_command_and_old_gives_no_feedback(rig):
    start(rig, Speed=20, TargetPosition=dict(X=40, Y=0, Z=90, RX=0, RY=90, RZ=0))
    assert rig.until(lambda: rig.read("mover.Active"), 1)
    first = rig.read("mover.CmdID_Ack")
    rig.write("MoveExec", False)
    rig.scans(1)
    rig.set_struct("MoveParam", move_abs(BlendingEnable=True, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    rig.write("MoveExec", True)
    assert rig.until(lambda: rig.read("mover.Done"), 2)
    assert rig.read("mover.CmdID_Ack") != first
    rig.write("MoveExec", False)
    assert rig.until(lambda: len(rig.events("motion_end")) == 2, 10)
    rig.scans(5)
    assert not rig.read("mover.Done") and rig.read("Cobot.QueueDepth") == 0


def test_queue_depth_counts_pending_commands(rig):
    for k in range(1, 4):
        target = dict(X=10.0 * k, Y=0, Z=90, RX=0, RY=90, RZ=0)
        rig.set_struct(f"MParam[{k}]", move_abs(Speed=30, TargetPosition=target))
        rig.write(f"MExec[{k}]", True)
    rig.scans(1)
    assert rig.read("Cobot.QueueDepth") == 3
    assert rig.until(lambda: rig.read("Cobot.QueueDepth") == 0, 10)


def test_exit_node_leaves_listen_node_after_the_motion(rig):
    start(rig, ExitNode=True)
    assert rig.until(lambda: rig.read("mover.Done"), 5)
    assert rig.scripts_in()[0][1].endswith("\r\nScriptExit()")
    assert rig.until(lambda: not rig.read("Cobot.InListenNode"), 2)


def test_reply_timeout_is_configurable_per_connection(rig):
    rig.write("Cobot.ReplyTimeout", 300_000_000)  # TIME in ns
    rig.robot.inject("reply_delay", seconds=0.6, count=1)
    start(rig, BlendingEnable=True)
    assert rig.until(lambda: not rig.read("mover.Busy"), 1)
    assert rig.read("mover.ErrorID") == 0x3001
