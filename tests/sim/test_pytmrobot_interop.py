"""The unmodified PyPI client pytmrobot 0.2.2 drives the simulator through its public API (real time,
simulator in a background thread, 20x). What pytmrobot does that the TMscript 2.24 manual does not
allow is listed in docs/simulator.md ("Third-party clients") and asserted here as the robot would answer."""
import threading

import pytest

pytmrobot = pytest.importorskip("pytmrobot")

from pytmrobot import TMRobot  # noqa: E402
from pytmrobot.exceptions import TMScriptError  # noqa: E402
from pytmrobot.types import CartPoint, JointPoint  # noqa: E402

from tmsim.net.server import SimServer  # noqa: E402
from tmsim.tmscript.profiles import Profile  # noqa: E402


def start(profile=None):
    srv = SimServer(port=0, speedup=20.0, profile=profile)
    srv.start_background()
    robot = TMRobot("127.0.0.1", srv.ports[0], timeout=10)
    robot.connect()
    return srv, robot


@pytest.fixture
def sim():
    srv, robot = start()
    yield srv, robot
    robot.disconnect()
    srv.close()


def finished_within(fn, seconds):
    """Run fn in a thread; True when it returned (or raised) within ``seconds`` of wall time."""
    done = threading.Event()

    def run():
        try:
            fn()
        finally:
            done.set()
    threading.Thread(target=run, daemon=True).start()
    return done.wait(seconds)


def test_motions_absolute_relative_and_circle_arrive_where_asked(sim):
    srv, robot = sim
    robot.move.ptp(JointPoint(0, 0, 90, 0, 90, 10), speed=50)
    assert robot.state.joint_angles[5] == pytest.approx(10, abs=1e-3)
    robot.move.line(CartPoint(400, -100, 350, 180, 0, 90), speed=200)           # Line("CDP", ...): 2.x format
    assert robot.state.tcp_position[:3] == pytest.approx((400, -100, 350), abs=1e-3)
    robot.move.line_relative(CartPoint(0, 0, -10, 0, 0, 0), speed=100)
    robot.move.ptp_relative(CartPoint(0, 0, 10, 0, 0, 0), speed=50)
    robot.move.circle(CartPoint(410, -90, 350, 180, 0, 90), CartPoint(420, -100, 350, 180, 0, 90), speed=100)
    assert robot.state.tcp_position[:3] == pytest.approx((420, -100, 350), abs=1e-3)


def test_state_reads_print_32_bit_floats_and_the_2x_robot_attributes(sim):
    srv, robot = sim
    robot.move.line(CartPoint(400, -100, 350, 180, 0, 90), speed=200)
    assert robot.state.tcp_position[:3] == (400.0, -100.0, 350.0)              # not 399.99999999999994
    assert robot.state.tcp_force == 0.0 and robot.state.tcp_speed == 0.0
    robot.change_load(1.5)
    snap = robot.state.snapshot()                                               # Robot[0].Payload: 2.x
    assert (snap.base_name, snap.tcp_name, snap.payload_kg) == ("RobotBase", "NOTOOL", 1.5)


def test_io_single_points_and_whole_arrays(sim):
    srv, robot = sim
    robot.io.set_do(3, True)
    robot.io.set_ao(0, 2.5)
    assert robot.io.get_do(3) is True and robot.io.get_di(0) is False and robot.io.get_ai(0) == 0.0
    io = robot.io.get_all_io()                                                  # IO["ControlBox"].DI: 2.x
    assert io.do[3] == 1 and len(io.di) == 16 and io.ao[0] == 2.5
    assert robot.io.get_all_io().do[3] == 1                                    # second call assigns, not declares


def test_sleep_settings_scripts_and_exit(sim):
    srv, robot = sim
    robot.sleep(200)                                                            # Sleep(): 2.x
    robot.change_base("RobotBase")
    robot.change_tcp("NOTOOL")
    assert robot.run_script(["int pytm = 1"]) is True
    assert robot.run_script(["int pytm2 = 2", "pytm2 = "]) is False              # ERROR;2
    robot.exit_listen()
    assert srv.robots[0].state()["in_listen_node"] is False


def test_stop_then_wait_motion_returns_when_dropped_tags_answer_reached():
    """pytmrobot's wait_motion polls TMSTA 01 until 'true' and ignores 'none' (its bug, docs/simulator.md):
    with stop_tags='reached' the simulator answers 'true' for a tag a stop dropped, so it returns."""
    srv, robot = start(Profile(stop_tags="reached"))
    try:
        robot.move.ptp(JointPoint(0, 0, 90, 0, 90, 90), speed=5, wait=False)
        robot.stop()
        assert finished_within(robot.move.wait_motion, 5)
    finally:
        robot.disconnect()
        srv.close()


def test_by_default_a_dropped_tag_is_not_existed_which_pytmrobot_does_not_understand(sim):
    srv, robot = sim
    robot.move.ptp(JointPoint(0, 0, 90, 0, 90, 90), speed=5, wait=False)
    robot.stop()
    tag = robot.move._last_tag
    assert srv.robots[0].session.robot.tag_status(tag) == "none"                 # what TMSTA 01 answers


def test_pvt_as_pytmrobot_sends_it_is_refused_as_the_manual_says(sim):
    srv, robot = sim
    with pytest.raises(TMScriptError):
        robot.move.pvt_enter("joint")                  # PVTEnter(2): §13.17 knows 0 (joint) and 1 (Cartesian)
    robot.move.pvt_exit()
    assert srv.robots[0].state()["in_listen_node"] is True
