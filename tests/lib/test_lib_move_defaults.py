"""Issue 26 item 8: the defaults of stCBT_MovAbsParam are a command that runs. Before, they were Line with
JPP_Abs and Speed 0, which CBT_MoveAbsolute refuses (16#1012). A stCBT_MovAbsParam never written by the program
now moves the robot: PTP in joints at 10 %, not blended, to the joints 0 deg (AccelTime keeps its default 0, so
programs that set everything but AccelTime move as before)."""

from rig import Rig


def test_a_never_written_parameter_structure_moves_the_robot_to_joint_zero():
    r = Rig(program="Main_Cell.st")
    try:
        assert r.read("DefaultParam.MovementCommand") == "PTP"
        assert r.read("DefaultParam.DataFormat") == "JPP_Abs"
        assert (r.read("DefaultParam.Speed"), r.read("DefaultParam.AccelTime")) == (10, 0)
        r.write("DefaultExec", True)
        assert r.until(lambda: r.read("dflt.Done") or r.read("dflt.Error"), 30)
        assert r.read("dflt.Done"), r.read("dflt.ErrorDescrip")
        assert [s for _, s in r.scripts_in()] == ['PTP("JPP",0,0,0,0,0,0,10,0,0,true)\r\nQueueTag(1)']
        assert all(abs(j) < 1e-6 for j in r.robot.session.robot.current_joints())
    finally:
        r.close()
