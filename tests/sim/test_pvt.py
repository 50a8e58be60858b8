"""PVT mode (PVTEnter / PVTPoint / PVTExit) as the official TM ROS drivers send it: one packet per trajectory,
Hermite curves between the points, speed and reach checked, PVT mode ending on PVTExit or a stop."""
import pytest
from session_rig import S, sct

from tmsim.robot.motion import hermite

ROS_TRAJECTORY = ("PVTEnter(0)\r\n"
                  "PVTPoint(10,0,90,0,90,0,20,0,0,0,0,0,1)\r\n"
                  "PVTPoint({30,0,90,0,90,0},{0,0,0,0,0,0},1.5)\r\n"
                  "PVTExit()")


def kinds(node, *wanted):
    return [(kind, f) for kind, f in node.events if kind in wanted]


def test_joint_trajectory_follows_the_hermite_curves_and_ends_at_the_last_point():
    node = S()
    node.connect()
    assert node.send(1, sct("PvtTraj", ROS_TRAJECTORY)) == ["$TMSCT,10,PvtTraj,OK,*27\r\n"]
    node.advance(0.5)
    assert node.s.snapshot()["pvt"] == "joint"
    assert node.s.robot.current_joints()[0] == pytest.approx(2.5, abs=0.05)    # Hermite 0,0 -> 10,20 at s=0.5
    node.advance(1.0)                                                          # 1.5 s: 0.5 s into point 2
    expected, _ = hermite((10.0,), (20.0,), (30.0,), (0.0,), 1.5, 0.5)
    assert node.s.robot.current_joints()[0] == pytest.approx(expected[0], abs=0.3)
    node.advance(1.5)
    snap = node.s.snapshot()
    assert snap["joints"][:3] == pytest.approx([30, 0, 90]) and snap["pvt"] is None and not snap["moving"]
    starts = [f["duration_s"] for _, f in kinds(node, "motion_start")]
    assert starts == [1.0, 1.5]
    assert [f["value"] for _, f in kinds(node, "setting")] == ["joint", "exit"]


def test_hermite_velocity_matches_the_given_end_velocities():
    pos, vel = hermite((0.0, 5.0), (0.0, 1.0), (10.0, 5.0), (20.0, -1.0), 2.0, 2.0)
    assert pos == pytest.approx([10.0, 5.0]) and vel == pytest.approx([20.0, -1.0])
    _, vel0 = hermite((0.0,), (3.0,), (10.0,), (20.0,), 2.0, 0.0)
    assert vel0 == pytest.approx([3.0])


def test_pvt_point_outside_pvt_mode_fails_the_motion():
    node = S()
    node.connect()
    assert node.send(1, sct("1", "PVTPoint({10,0,90,0,90,0},{0,0,0,0,0,0},1)")) == ["$TMSCT,4,1,OK,*5C\r\n"]
    node.advance(1.0)
    (failed,) = [f for _, f in kinds(node, "motion_failed")]
    assert failed["reason"] == "PVTPoint outside PVTEnter() ... PVTExit()"
    assert node.s.robot.current_joints()[0] == 0


def test_cartesian_mode_reaches_the_pose_and_refuses_a_too_fast_point():
    node = S()
    node.connect()
    node.send(1, sct("1", "PVTEnter(1)\r\nPVTPoint({417.5,-122.3,300,180,0,90},{0,0,0,0,0,0},1)\r\nPVTExit()"))
    node.advance(2.0)
    assert node.s.snapshot()["tcp"] == pytest.approx([417.5, -122.3, 300, 180, 0, 90], abs=1e-3)
    node.send(1, sct("2", "PVTEnter(1)\r\nPVTPoint(417.5,-22.3,300,-180,0,90,0,0,0,0,0,0,0.01)\r\nPVTExit()"))
    node.advance(1.0)
    (failed,) = [f for _, f in kinds(node, "motion_failed")]
    assert failed["reason"].startswith("PVTPoint: joint 1 would move at") and "limit of 180 deg/s" in failed["reason"]
    assert node.s.snapshot()["pvt"] is None                                   # the fault stopped PVT mode


def test_regular_motion_inside_pvt_mode_fails_and_a_stop_ends_pvt_mode():
    node = S()
    node.connect()
    node.send(1, sct("1", 'PVTEnter()\r\nPTP("JPP",10,0,90,0,90,0,50,200,0,false)'))
    node.advance(0.5)
    (failed,) = [f for _, f in kinds(node, "motion_failed")]
    assert failed["reason"] == "PTP inside PVT mode; call PVTExit() first"
    node = S()                                                 # (a robot fault ends the project: a fresh robot)
    node.connect()
    node.send(1, sct("2", "PVTEnter(0)\r\nPVTPoint({5,0,90,0,90,0},{0,0,0,0,0,0},10)"))
    node.advance(0.5)
    assert node.s.snapshot()["pvt"] == "joint"
    node.send(1, sct("3", "StopAndClearBuffer(0)"))
    assert node.s.snapshot()["pvt"] is None and not node.s.snapshot()["moving"]


@pytest.mark.parametrize("line", ["PVTPoint({1,2,3,4,5,6},{0,0,0,0,0,0})", "PVTPoint(1,2,3)", 'PVTEnter("joint")'])
def test_malformed_pvt_lines_are_rejected_before_anything_runs(line):
    node = S()
    node.connect()
    assert node.send(1, sct("7", f"PVTEnter(0)\r\n{line}")) == [sct("7", "ERROR;2").decode()]
    node.advance(0.5)
    assert node.s.snapshot()["pvt"] is None
