"""CBT_SetOutput: queued and immediate digital outputs, completion on acceptance or when set, ordering with
motions, parameter errors, abort by CBT_Stop."""
import pytest
from rig import move_abs, run

LONG_MOVE = move_abs(BlendingEnable=True, BlendingValue=0, Speed=20,
                     TargetPosition=dict(X=90, Y=0, Z=90, RX=0, RY=90, RZ=0))      # J1 turns 90 deg: > 1 s


def out(**kw):
    p = dict(Module=0, Channel=3, Value=True, Immediate=False, WaitUntilSet=False, ExitNode=False)
    p.update(kw)
    return p


def test_queued_output_is_sent_and_done_on_acceptance(rig):
    script = run(rig, "dout", "OutExec", "OutParam", out())
    assert rig.read("dout.Done") and not rig.read("dout.Error")
    assert script == 'IO["ControlBox"].DO[3]=1'
    rig.scans(5)
    assert rig.robot.state()["io"]["ControlBox.DO[3]"] == 1
    assert [e["point"] for e in rig.events("io")] == ["ControlBox.DO[3]"]


def test_end_module_output_off(rig):
    script = run(rig, "dout", "OutExec", "OutParam", out(Module=1, Channel=0, Value=False))
    assert rig.read("dout.Done") and script == 'IO["EndModule"].DO[0]=0'


def test_queued_output_waits_for_the_motion_before_it(rig):
    """Gripper closes when the pick motion has arrived: the robot runs the DO after the motion queued before it;
    with WaitUntilSet, Done comes only then."""
    rig.set_struct("MoveParam", LONG_MOVE)
    rig.write("MoveExec", True)
    rig.scans(3)
    rig.set_struct("OutParam", out(Channel=5, WaitUntilSet=True))
    rig.write("OutExec", True)
    rig.scans(20)
    assert rig.read("dout.Busy") and not rig.read("dout.Done")            # the motion is still running
    assert rig.robot.state()["io"].get("ControlBox.DO[5]", 0) == 0
    assert rig.until(lambda: rig.read("dout.Done") or rig.read("dout.Error"), 10)
    assert rig.read("dout.Done") and rig.robot.state()["io"]["ControlBox.DO[5]"] == 1
    ends = [e["t"] for e in rig.events("motion_end")]
    (io,) = rig.events("io")
    assert len(ends) == 1 and io["t"] >= ends[0]
    assert rig.scripts_in()[-1][1].startswith('IO["ControlBox"].DO[5]=1\r\nQueueTag(')


def test_immediate_output_is_set_while_a_motion_runs(rig):
    rig.set_struct("MoveParam", LONG_MOVE)
    rig.write("MoveExec", True)
    rig.scans(3)
    rig.set_struct("OutParam", out(Channel=15, Immediate=True, WaitUntilSet=True))     # WaitUntilSet ignored
    rig.write("OutExec", True)
    assert rig.until(lambda: rig.read("dout.Done") or rig.read("dout.Error"), 2)
    assert rig.read("dout.Done") and rig.robot.state()["io"]["ControlBox.DO[15]"] == 1
    assert rig.robot.state()["moving"]                                           # the motion still runs
    assert rig.scripts_in()[-1][1] == 'IO["ControlBox"].InstantDO[15]=1'


@pytest.mark.parametrize("override,error_id,text", [
    (dict(Channel=16), 0x1025, "Channel out of range: 0..15 (ControlBox), 0..3 (EndModule)"),
    (dict(Module=1, Channel=4), 0x1025, "Channel out of range: 0..15 (ControlBox), 0..3 (EndModule)"),
])
def test_channel_out_of_range_is_a_parameter_error(rig, override, error_id, text):
    run(rig, "dout", "OutExec", "OutParam", out(**override))
    assert rig.read("dout.ErrorID") == error_id and rig.read("dout.ErrorDescrip") == text
    assert rig.scripts_in() == []


def test_stop_aborts_an_output_waiting_behind_a_motion(rig):
    rig.set_struct("MoveParam", LONG_MOVE)
    rig.write("MoveExec", True)
    rig.scans(3)
    rig.set_struct("OutParam", out(WaitUntilSet=True))
    rig.write("OutExec", True)
    rig.scans(20)
    rig.set_struct("StopParam", dict(Mode=1))
    rig.write("StopExec", True)
    assert rig.until(lambda: rig.read("dout.CommandAborted") or rig.read("dout.Done"), 3)
    assert rig.read("dout.CommandAborted") and rig.robot.state()["io"].get("ControlBox.DO[3]", 0) == 0
    rig.scans(200)
    assert rig.events("io") == []
