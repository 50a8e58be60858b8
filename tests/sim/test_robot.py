"""Robot model on virtual time: durations from the parameters, frames, kinematics, failures."""
import math
import random

import pytest

from tmsim.robot import kinematics as kin
from tmsim.robot.model import RobotModel
from tmsim.robot.motion import SETTLE_S, MotionRequest, rotation_angle, trapezoid_fraction, trapezoid_time


def req(function, fmt, target, speed=100, accel=200, blend=0, precise=False, **kw):
    return MotionRequest(function, fmt, list(target), speed, accel, blend, precise, **kw)


def run_until_idle(robot, dt=0.001, limit=60.0):
    t, events = 0.0, []
    while not robot.idle and t < limit:
        t += dt
        events.extend(dict(e, t=t) for e in robot.tick(dt))
    return t, events


def end_time(events, function):
    return next(e["t"] for e in events if e["kind"] == "motion_end" and e["function"] == function)


def test_ptp_duration_follows_the_trapezoid_of_the_slowest_joint_plus_settling():
    robot = RobotModel()
    robot.enqueue_motion(req("PTP", "JPP", [90, 0, 90, 0, 90, 0], speed=10, accel=200, precise=True))
    _, events = run_until_idle(robot)
    expected = 90 / 18.0 + 0.2 + SETTLE_S
    assert end_time(events, "PTP") == pytest.approx(expected, abs=0.002)


def test_short_move_uses_a_triangular_profile():
    assert trapezoid_time(1.0, 100.0, 0.2) == pytest.approx(2 * math.sqrt(1.0 * 0.2 / 100.0))
    assert trapezoid_time(100.0, 100.0, 0.2) == pytest.approx(1.2)


def test_profile_fraction_is_monotonic_and_ends_at_one():
    values = [trapezoid_fraction(t / 100, 1.2, 0.2) for t in range(0, 121)]
    assert values[0] == 0 and values[-1] == pytest.approx(1.0)
    assert all(b >= a for a, b in zip(values, values[1:], strict=False))


def test_line_in_mm_per_second_takes_distance_over_speed():
    robot = RobotModel()
    start = robot.tcp_pose()
    robot.enqueue_motion(req("Line", "CAP", [start[0], start[1] + 200, start[2]] + start[3:], speed=100, accel=100))
    _, events = run_until_idle(robot)
    assert end_time(events, "Line") == pytest.approx(200 / 100 + 0.1, abs=0.002)
    assert robot.tcp_pose()[1] == pytest.approx(start[1] + 200, abs=0.01)


def test_line_in_percent_uses_the_tcp_speed_limit():
    robot = RobotModel()
    start = robot.tcp_pose()
    robot.enqueue_motion(req("Line", "CPP", [start[0], start[1] + 110, start[2]] + start[3:], speed=10, accel=0))
    _, events = run_until_idle(robot)
    assert end_time(events, "Line") == pytest.approx(110 / 110.0, abs=0.002)


def test_blending_shortens_and_precise_positioning_lengthens_the_motion():
    def duration(blend, precise):
        robot = RobotModel()
        robot.enqueue_motion(req("PTP", "JPP", [30, 0, 90, 0, 90, 0], speed=50, accel=300, blend=blend,
                                 precise=precise))
        _, events = run_until_idle(robot)
        return end_time(events, "PTP")
    plain = duration(0, False)
    assert duration(100, False) == pytest.approx(plain - 0.3, abs=0.002)
    assert duration(50, False) == pytest.approx(plain - 0.15, abs=0.002)
    assert duration(0, True) == pytest.approx(plain + SETTLE_S, abs=0.002)


def test_pause_freezes_the_arm_mid_motion_and_resume_continues():
    robot = RobotModel()
    robot.enqueue_motion(req("PTP", "JPP", [90, 0, 90, 0, 90, 0], speed=10, accel=200))
    robot.tick(2.0)
    robot.pause()
    frozen = robot.current_joints()
    robot.tick(10.0)
    assert robot.current_joints() == frozen and 0 < frozen[0] < 90
    robot.resume()
    robot.tick(3.19)
    assert not robot.idle
    robot.tick(0.02)
    assert robot.idle and robot.joints[0] == pytest.approx(90)


def test_stop_and_clear_stops_where_the_arm_is_and_forgets_queued_tags():
    robot = RobotModel()
    robot.enqueue_motion(req("PTP", "JPP", [90, 0, 90, 0, 90, 0], speed=10, accel=200))
    robot.enqueue_tag(1)
    robot.tick(2.0)
    dropped = robot.stop_and_clear()
    assert dropped == [1] and robot.tag_status(1) == "none"
    assert 0 < robot.joints[0] < 90 and robot.idle


def test_tags_are_reached_in_order_and_history_keeps_the_last_four():
    robot = RobotModel(tag_history=4)
    for tag in range(1, 7):
        robot.enqueue_tag(tag)
    assert robot.tag_status(6) == "false"
    events = robot.tick(0.0)
    assert [e["tag"] for e in events] == [1, 2, 3, 4, 5, 6]
    assert [robot.tag_status(t) for t in range(1, 7)] == ["none", "none", "true", "true", "true", "true"]


def test_relative_moves_in_base_tool_and_joint_frames():
    robot = RobotModel()
    start = robot.tcp_pose()
    robot.enqueue_motion(req("Move_Line", "CAP", [0, 0, 50, 0, 0, 0]))
    run_until_idle(robot)
    assert robot.tcp_pose()[2] == pytest.approx(start[2] + 50, abs=0.01)
    robot.enqueue_motion(req("Move_Line", "TAP", [0, 0, 50, 0, 0, 0]))    # tool Z points down (Rx = 180)
    run_until_idle(robot)
    assert robot.tcp_pose()[2] == pytest.approx(start[2], abs=0.01)
    robot.enqueue_motion(req("Move_PTP", "JPP", [10, 0, 0, 0, 0, 0]))
    run_until_idle(robot)
    assert robot.joints[0] == pytest.approx(10)
    robot.enqueue_motion(req("Move_PTP", "CPP", [0, 0, 0, 0, 0, 30]))
    run_until_idle(robot)
    assert robot.tcp_pose()[5] == pytest.approx(kin.matrix_to_pose(kin.pose_to_matrix(
        [0, 0, 0, 180, 0, 100 + 30]))[5], abs=0.01)


def test_targets_are_interpreted_in_the_current_base_and_tool():
    robot = RobotModel()
    robot.enqueue_setting("base", [100, 0, 0, 0, 0, 0])
    robot.enqueue_setting("tcp", ([0, 0, 50, 0, 0, 0], 1.0))
    robot.enqueue_motion(req("Line", "CAP", [300, -100, 300, 180, 0, 90]))
    run_until_idle(robot)
    assert robot.tcp_pose() == pytest.approx([300, -100, 300, 180, 0, 90], abs=0.01)
    assert robot.tcp_pose_robot()[:3] == pytest.approx([400, -100, 300], abs=0.01)
    flange = kin.matrix_to_pose(kin.forward(robot.joints))
    assert flange[2] == pytest.approx(350, abs=0.01)          # tool 50 mm along flange Z, Z points down


def test_circle_through_via_point_to_end_point():
    robot = RobotModel()
    robot.enqueue_motion(req("Line", "CAP", [400, -100, 350, 180, 0, 90]))
    run_until_idle(robot)
    robot.enqueue_motion(req("Circle", "CAP", [450, -50, 350, 180, 0, 90, 500, -100, 350, 180, 0, 90], speed=100))
    robot.tick(0.0)
    plan = robot.active
    closest = min(math.dist(kin.matrix_to_pose(plan.cartesian(s / 200))[:3], [450, -50, 350]) for s in range(201))
    assert closest < 0.5
    _, events = run_until_idle(robot)
    assert robot.tcp_pose()[:3] == pytest.approx([500, -100, 350], abs=0.01)
    arc = math.pi * 50
    assert events[-1]["t"] == pytest.approx(arc / 100 + 0.2, abs=0.01)


def test_circle_with_arc_angle_keeps_orientation_and_travels_that_angle():
    robot = RobotModel()
    robot.enqueue_motion(req("Line", "CAP", [400, -100, 350, 180, 0, 90]))
    run_until_idle(robot)
    robot.enqueue_motion(req("Circle", "CAP", [450, -50, 350, 180, 0, 90, 500, -100, 350, 180, 0, 90], arc_angle=90))
    run_until_idle(robot)
    assert robot.tcp_pose()[:3] == pytest.approx([450, -50, 350], abs=0.01)
    assert robot.tcp_pose()[3:] == pytest.approx([180, 0, 90], abs=0.01)


def test_wrist_singularity_falls_back_to_the_numerical_solver():
    joints = [10, -20, 100, 10, 0, 30]                       # joint 5 = 0: joints 4 and 6 aligned
    solution = kin.inverse_kinematics(kin.forward(joints), reference=[12, -18, 98, 5, 5, 30])
    assert [kin.forward(solution)[i][3] for i in range(3)] == pytest.approx(
        [kin.forward(joints)[i][3] for i in range(3)], abs=0.01)


def test_forward_model_home_pose():
    assert kin.matrix_to_pose(kin.forward([0, 0, 90, 0, 90, 0])) == pytest.approx([417.5, -122.3, 359.7, 180, 0, 90],
                                                                                abs=1e-6)


def test_inverse_kinematics_round_trip_for_random_poses():
    rng = random.Random(7)
    for _ in range(20):
        joints = [rng.uniform(-120, 120), rng.uniform(-60, 60), rng.uniform(30, 140),
                  rng.uniform(-90, 90), rng.uniform(30, 150), rng.uniform(-170, 170)]
        target = kin.forward(joints)
        solution = kin.inverse_kinematics(target, reference=joints)
        assert kin.matrix_to_pose(kin.forward(solution)) == pytest.approx(kin.matrix_to_pose(target), abs=0.01)


def test_each_requested_arm_configuration_is_honoured():
    target = kin.pose_to_matrix([400, -100, 350, 180, 0, 90])
    found = {}
    for shoulder in (0, 1):
        for elbow in (2, 3):
            for wrist in (4, 5):
                try:
                    q = kin.inverse_kinematics(target, config=(shoulder, elbow, wrist))
                except kin.KinematicsError:
                    continue
                assert kin.configuration(q) == (shoulder, elbow, wrist)
                reached = kin.forward(q)
                assert [reached[i][3] for i in range(3)] == pytest.approx([400, -100, 350], abs=0.01)
                assert rotation_angle(reached, target) < 0.01
                found[(shoulder, elbow, wrist)] = q
    assert len(found) == 8
    assert len({tuple(round(v, 1) for v in q) for q in found.values()}) == len(found)


def test_ptp_with_arm_configuration_reaches_that_configuration():
    robot = RobotModel()
    robot.enqueue_motion(req("PTP", "CPP", [400, -100, 350, 180, 0, 90], speed=100, config=(1, 2, 4)))
    run_until_idle(robot)
    assert kin.configuration(robot.joints) == (1, 2, 4)


@pytest.mark.parametrize("motion, reason", [
    (req("Line", "CPP", [2000, 0, 0, 180, 0, 0]), "out of reach"),
    (req("PTP", "JPP", [0, 0, 170, 0, 90, 0]), "joint limits"),
    (req("PTP", "JPP", [0, 0, 90, 0, 90, 0], speed=150), "speed"),
    (req("PTP", "JPP", [0, 0, 90, 0, 90, 0], accel=-1), "acceleration"),
    (req("Line", "CAP", [417.5, -122.3, 359.7, 180, 0, 90], speed=0), "speed"),
])
def test_impossible_motion_fails_and_clears_the_queue(motion, reason):
    robot = RobotModel()
    robot.enqueue_motion(motion)
    robot.enqueue_tag(3)
    events = robot.tick(0.01)
    assert events[0]["kind"] == "motion_failed" and reason in events[0]["reason"]
    assert robot.fault and robot.idle and robot.tag_status(3) == "none"


def test_unknown_named_base_is_a_fault_but_defined_names_work():
    robot = RobotModel(bases={"Table": (100, 0, 0, 0, 0, 0)})
    robot.enqueue_setting("base", "Table")
    robot.tick(0)
    assert robot.base_name == "Table"
    robot.enqueue_setting("base", "Nowhere")
    robot.tick(0)
    assert "Nowhere" in robot.fault
