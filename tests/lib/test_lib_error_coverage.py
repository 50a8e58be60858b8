"""ErrorIDs that need a value no checked write can produce, raised through the real FBs against the simulator:
an enumeration input holding an undefined integer (16#1010, 16#1019, 16#101C, 16#1022, 16#1023, 16#1024; put
there with a raw write, as an HMI or a memory copy can on the controller). A position reply whose data cannot be
read (the simulator's corrupt_checksum fault makes the library drop one of the two ListenSend frames) is not an
error: it is dropped and counted."""
import pytest
from rig import move_abs

TEXT = {
    0x1010: "MovementCommand invalid: Line or PTP",
    0x1019: "RobotPose invalid: Pose1 Righty/Lefty, Pose2 Above/Below, Pose3 NoFlip/Flip",
    0x101C: "DataFormat invalid for Circle: CPP_Circle, CAP_Circle or CDP_Circle",
    0x1022: "Command invalid: Pause or Resume",
    0x1023: "Mode invalid: StopNormal/StopImmediate/StopAbortScript/StopDiscardAll",
    0x1024: "Module invalid: ControlBox or EndModule",
}

REL = dict(MovementCommand=0, DataFormat=1, TargetPosition=dict(X=0, Y=0, Z=-20, RX=0, RY=0, RZ=0), Speed=50,
           AccelTime=200)
CIRC = dict(DataFormat=1, ArcPoint=dict(X=417.5, Y=-72.3, Z=359.7, RX=180, RY=0, RZ=90),
            EndPoint=dict(X=467.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90), Speed=100, AccelTime=200)
POSE = dict(MovementCommand=1, DataFormat=1, TargetPosition=dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90),
            RobotPoseEnable=True, RobotPose=dict(Pose1=0, Pose2=0, Pose3=0))

# (FB, Execute, Parameters, valid parameters, enumeration member, undefined value, ErrorID)
CASES = [
    ("mover", "MoveExec", "MoveParam", move_abs(), "MovementCommand", 2, 0x1010),
    ("mover", "MoveExec", "MoveParam", move_abs(), "MovementCommand", -1, 0x1010),
    ("rel", "RelExec", "RelParam", REL, "MovementCommand", 7, 0x1010),
    ("mover", "MoveExec", "MoveParam", move_abs(**POSE), "RobotPose.Pose1", 2, 0x1019),
    ("mover", "MoveExec", "MoveParam", move_abs(**POSE), "RobotPose.Pose2", 5, 0x1019),
    ("mover", "MoveExec", "MoveParam", move_abs(**POSE), "RobotPose.Pose3", 32767, 0x1019),
    ("circ", "CircExec", "CircParam", CIRC, "DataFormat", 3, 0x101C),
    ("prg", "PrgExec", "PrgParam", dict(Command=0), "Command", 2, 0x1022),
    ("stop", "StopExec", "StopParam", dict(Mode=0), "Mode", 4, 0x1023),
    ("stop", "StopExec", "StopParam", dict(Mode=0), "Mode", -32768, 0x1023),
    ("dout", "OutExec", "OutParam", dict(Module=0, Channel=1), "Module", 2, 0x1024),
]


@pytest.mark.parametrize("fb,exec_,param,values,member,raw,error_id", CASES,
                         ids=[f"{c[0]}.{c[4]}={c[5]}" for c in CASES])
def test_undefined_enumeration_value_is_a_parameter_error(rig, fb, exec_, param, values, member, raw, error_id):
    rig.set_struct(param, values)
    rig.write(f"{param}.{member}", raw, raw=True)
    assert rig.read(f"{param}.{member}") == raw                    # the variable really holds the number
    frames_out = rig.read("Cobot.FramesOut")
    rig.write(exec_, True)
    rig.scans(1)                                                   # the scan of the rising edge
    assert rig.read(f"{fb}.Error") and rig.read(f"{fb}.ErrorID") == error_id
    assert rig.read(f"{fb}.ErrorDescrip") == TEXT[error_id]
    assert not (rig.read(f"{fb}.Busy") or rig.read(f"{fb}.Done") or rig.read(f"{fb}.CommandAborted"))
    assert rig.read(f"{fb}.CmdID_Ack") == 0
    assert rig.read("Cobot.LastErrorID") == error_id and rig.read("Cobot.QueueDepth") == 0
    rig.scans(20)                                                  # Error stays while Execute is TRUE
    assert rig.read(f"{fb}.Error") and rig.read(f"{fb}.ErrorID") == error_id
    rig.write(exec_, False)
    rig.scans(1)                                                   # R3: one more scan, then cleared
    assert not rig.read(f"{fb}.Error") and rig.read(f"{fb}.ErrorID") == 0 and rig.read(f"{fb}.ErrorDescrip") == ""
    # nothing reached the robot: no script frame sent, none received, no motion
    assert rig.read("Cobot.FramesOut") == frames_out
    assert rig.scripts_in() == [] and rig.events("motion_start") == []
    assert rig.read("conn.Connected") and not rig.read("conn.Error")


def test_a_corrected_value_runs_after_the_error(rig):
    rig.set_struct("PrgParam", dict(Command=0))
    rig.write("PrgParam.Command", 3, raw=True)
    rig.write("PrgExec", True)
    rig.scans(1)
    assert rig.read("prg.ErrorID") == 0x1022
    rig.write("PrgExec", False)
    rig.write("PrgParam.Command", "Resume")
    rig.scans(1)
    rig.write("PrgExec", True)
    assert rig.until(lambda: rig.read("prg.Done") or rig.read("prg.Error"), 1)
    assert rig.read("prg.Done") and rig.scripts_in() == [(rig.scripts_in()[0][0], "Resume()")]


def read_scripts(rig):
    return [s for _, s in rig.scripts_in() if s.startswith("ListenSend(90,")]


@pytest.mark.parametrize("lost", [1, 2], ids=["TMSTA-90-lost", "TMSTA-90-and-91-lost"])
def test_unreadable_position_reply_is_dropped_and_reading_goes_on(rig, lost):
    """The robot answers the read with two ListenSend frames (90 = TCP, 91 = joints) and OK. A corrupted
    90 frame is dropped by the library, so the reply data lacks the TCP part: the reading is dropped and
    counted (Dropped), never an Error; the next Period reads again and Valid comes back by itself."""
    frames_out = rig.read("Cobot.FramesOut")
    rig.write("ReadEnable", True)
    assert rig.until(lambda: rig.read("Cobot.FramesOut") > frames_out, 1)
    assert read_scripts(rig) == []                                 # the read is on its way, not yet at the robot
    rig.robot.inject("corrupt_checksum", count=lost)
    assert rig.until(lambda: rig.read("rd.Dropped") == 1, 1)
    assert not rig.read("rd.Error") and rig.read("rd.ErrorID") == 0 and rig.read("rd.Busy")
    assert rig.read("Cobot.BadFrames") == lost
    assert rig.until(lambda: rig.read("rd.Valid"), 1)              # the next Period succeeds
    assert not rig.read("rd.Error") and rig.read("rd.Dropped") == 1 and len(read_scripts(rig)) >= 2
    assert rig.events("motion_start") == []
