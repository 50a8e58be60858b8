"""CBT_MoveRelative, CBT_MoveCircle, CBT_ChangeBase, CBT_ChangeTCP, CBT_ProgramControl, CBT_Stop,
CBT_ReadActualPosition: normal end, script sent, parameter errors."""
import pytest
from rig import circ, move_abs, rel, run


def test_move_relative_line_in_base_arrives(rig):
    script = run(rig, "rel", "RelExec", "RelParam", rel())
    assert rig.read("rel.Done")
    assert script.startswith('Move_Line("CPP",0,0,-20.5,0,0,0,50,200,0,false)\r\nQueueTag(')
    assert len(rig.events("motion_end")) == 1


@pytest.mark.parametrize("override,error_id", [
    (dict(MovementCommand=1, DataFormat=2), 0x1011),
    (dict(MovementCommand=0, DataFormat=0), 0x1012),
    (dict(DataFormat=7, Speed=0), 0x1014),
    (dict(AccelTime=20000), 0x1015),
    (dict(TargetPosition=dict(X=float("inf"), Y=0, Z=0, RX=0, RY=0, RZ=0)), 0x101A),
])
def test_move_relative_parameter_errors(rig, override, error_id):
    run(rig, "rel", "RelExec", "RelParam", rel(**override))
    assert rig.read("rel.ErrorID") == error_id and rig.scripts_in() == []


def test_move_circle_arrives_and_sends_arc_angle(rig):
    script = run(rig, "circ", "CircExec", "CircParam", circ(), seconds=10)
    assert rig.read("circ.Done"), rig.read("circ.ErrorDescrip")
    assert script.startswith('Circle("CAP",417.5,-72.3,359.7,180,0,90,467.5,-122.3,359.7,180,0,90,100,200,0,0,true)')


@pytest.mark.parametrize("override,error_id", [
    (dict(ArcAngle=361), 0x101B),
    (dict(DataFormat=0, Speed=150), 0x1013),
    (dict(EndPoint=dict(X=float("nan"), Y=0, Z=0, RX=0, RY=0, RZ=0)), 0x101D),
])
def test_move_circle_parameter_errors(rig, override, error_id):
    run(rig, "circ", "CircExec", "CircParam", circ(**override))
    assert rig.read("circ.ErrorID") == error_id and rig.scripts_in() == []


def test_change_base_is_done_on_acceptance(rig):
    script = run(rig, "base", "BaseExec", "BaseParam",
                 dict(Transformation=dict(X=100.25, Y=-50, Z=0, RX=0, RY=0, RZ=45), ExitNode=False))
    assert rig.read("base.Done") and script == "ChangeBase(100.25,-50,0,0,0,45)"


def test_change_base_rejects_non_finite_frame(rig):
    run(rig, "base", "BaseExec", "BaseParam",
        dict(Transformation=dict(X=float("nan"), Y=0, Z=0, RX=0, RY=0, RZ=0), ExitNode=False))
    assert rig.read("base.ErrorID") == 0x101E


def tcp(**kw):
    p = dict(TCPOffset=dict(X=0, Y=0, Z=150.5, RX=0, RY=0, RZ=0), Weight=1.25,
             MomentOfInertia=dict(Ixx=10, Iyy=10, Izz=5.5), MassCenter=dict(X=0, Y=0, Z=60, RX=0, RY=0, RZ=0),
             ExitNode=False)
    p.update(kw)
    return p


def test_change_tcp_sends_offset_mass_and_inertia(rig):
    script = run(rig, "tcp", "TcpExec", "TcpParam", tcp())
    assert rig.read("tcp.Done")
    assert script == "ChangeTCP(0,0,150.5,0,0,0,1.25,10,10,5.5,0,0,60,0,0,0)"


@pytest.mark.parametrize("override,error_id", [
    (dict(Weight=14.5), 0x1020),
    (dict(MomentOfInertia=dict(Ixx=-1, Iyy=0, Izz=0)), 0x1021),
    (dict(MassCenter=dict(X=0, Y=0, Z=1e6, RX=0, RY=0, RZ=0)), 0x101F),
])
def test_change_tcp_parameter_errors(rig, override, error_id):
    run(rig, "tcp", "TcpExec", "TcpParam", tcp(**override))
    assert rig.read("tcp.ErrorID") == error_id and rig.scripts_in() == []


def test_pause_mid_motion_holds_the_move_busy_until_resume(rig):
    rig.set_struct("MoveParam", move_abs(Speed=20, TargetPosition=dict(X=60, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    rig.write("MoveExec", True)
    assert rig.until(lambda: rig.read("mover.Active"), 1)
    rig.until(lambda: False, 0.2)
    run(rig, "prg", "PrgExec", "PrgParam", dict(Command=0))
    assert rig.read("prg.Done")
    assert not rig.until(lambda: rig.read("mover.Done"), 5)
    assert rig.read("mover.Busy") and rig.read("mover.Active") and rig.read("Cobot.Connected")
    rig.write("PrgExec", False)
    rig.scans(2)
    run(rig, "prg", "PrgExec", "PrgParam", dict(Command=1))
    assert rig.until(lambda: rig.read("mover.Done"), 10)


@pytest.mark.parametrize("mode,script", [(0, "StopAndClearBuffer()"), (1, "StopAndClearBuffer(0)"),
                                         (2, "StopAndClearBuffer(1)"), (3, "StopAndClearBuffer(2)")])
def test_stop_aborts_every_waiting_motion(rig, mode, script):
    for k in range(1, 4):
        target = dict(X=20.0 * k, Y=0, Z=90, RX=0, RY=90, RZ=0)
        rig.set_struct(f"MParam[{k}]", move_abs(Speed=20, TargetPosition=target))
        rig.write(f"MExec[{k}]", True)
    assert rig.until(lambda: rig.read("movers[3].Active"), 1)
    sent = run(rig, "stop", "StopExec", "StopParam", dict(Mode=mode))
    assert rig.read("stop.Done") and sent == script
    assert rig.until(lambda: all(rig.read(f"movers[{k}].CommandAborted") for k in range(1, 4)), 1)
    assert not any(rig.read(f"movers[{k}].Busy") or rig.read(f"movers[{k}].Done") for k in range(1, 4))
    assert rig.read("Cobot.QueueDepth") == 0


def test_read_actual_position_reports_tcp_and_joints(rig):
    rig.write("ReadEnable", True)
    assert rig.until(lambda: rig.read("rd.Valid"), 1)
    pos = rig.read("rd.Position")
    state = rig.robot.state()
    assert pos["Joints"] == pytest.approx(list(state["joints"]), abs=1e-3)
    assert pos["TCP"]["X"] == pytest.approx(417.5, abs=1e-3)
    rig.write("ReadEnable", False)
    rig.scans(2)
    assert not rig.read("rd.Valid") and not rig.read("rd.Busy")


def test_stop_holds_the_stopping_state_while_execute_is_true(rig):
    """PLCopen MC_GroupStop: while CBT_Stop's Execute stays TRUE the robot is Stopping and motion FBs are refused
    (16#4005, nothing sent); other commands still run; releasing Execute allows motions again."""
    run(rig, "stop", "StopExec", "StopParam", dict(Mode=1))
    assert rig.read("stop.Done") and rig.read("Cobot.Stopping")
    frames_out = rig.read("Cobot.FramesOut")
    rig.set_struct("MoveParam", move_abs())
    rig.write("MoveExec", True)
    rig.scans(1)
    assert rig.read("mover.Error") and rig.read("mover.ErrorID") == 0x4005
    assert rig.read("mover.ErrorDescrip") == "Robot stopping: a CBT_Stop Execute is TRUE, motion rejected"
    rig.set_struct("RelParam", rel())
    rig.write("RelExec", True)
    rig.scans(1)
    assert rig.read("rel.ErrorID") == 0x4005
    assert rig.read("Cobot.FramesOut") == frames_out                   # nothing reached the robot
    script = run(rig, "dout", "OutExec", "OutParam", dict(Module=0, Channel=2, Value=True))
    assert rig.read("dout.Done") and script == 'IO["ControlBox"].DO[2]=1'   # not a motion: allowed
    rig.write("StopExec", False)
    rig.write("MoveExec", False)
    rig.scans(2)
    assert not rig.read("Cobot.Stopping")
    rig.write("MoveExec", True)
    assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 5)
    assert rig.read("mover.Done")


def test_a_stop_that_could_not_be_sent_does_not_hold_the_robot(rig):
    rig.write("StopParam.Mode", 9, raw=True)                           # undefined mode: 16#1023
    rig.write("StopExec", True)
    rig.scans(2)
    assert rig.read("stop.ErrorID") == 0x1023 and not rig.read("Cobot.Stopping")
