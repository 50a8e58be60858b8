"""The unmodified PyPI client techmanpy 1.2 drives the simulator (real time, background thread).

techmanpy's clients take the robot port from a class attribute (PORT = 5890); the tests subclass
them with the simulator's ephemeral port instead of patching the library.
"""
import asyncio

import pytest

techmanpy = pytest.importorskip("techmanpy")

from tmsim.net.server import SimServer  # noqa: E402


@pytest.fixture
def sim():
    srv = SimServer(port=0, speedup=20.0)      # 20x: a 1 s motion takes 50 ms of wall time
    srv.start_background()
    yield srv
    srv.close()


def clients(port):
    class STA(techmanpy.TMSTA_client):
        PORT = port

    class SCT(techmanpy.TMSCT_client):
        PORT = port

    return STA, SCT


def run(coro, timeout=20):
    return asyncio.run(asyncio.wait_for(coro, timeout))


def test_listen_node_query_true_then_false_after_exit(sim):
    STA, SCT = clients(sim.ports[0])

    async def scenario():
        async with STA(robot_ip="127.0.0.1") as sta:
            before = await sta.is_listen_node_active()
        async with SCT(robot_ip="127.0.0.1") as sct:
            await sct.exit_listen()
        async with STA(robot_ip="127.0.0.1") as sta:
            after = await sta.is_listen_node_active()
        return before, after

    assert run(scenario()) == (True, False)


def test_ptp_and_line_with_queue_tags_wait_for_completion(sim):
    STA, SCT = clients(sim.ports[0])

    async def scenario():
        async with SCT(robot_ip="127.0.0.1") as sct:
            await sct.set_base("RobotBase")
            await sct.move_to_joint_angles_ptp([10, -10, 100, -10, 80, -10], 0.5, 200)
            await sct.set_queue_tag(1, wait_for_completion=True)
            await sct.move_to_point_line([400, -100, 350, 180, 0, 90], 200, 200,
                                         speed_is_velocity=True, blending_is_radius=True, blending=5)
            await sct.set_queue_tag(2)
            await sct.wait_for_queue_tag(2)
        async with STA(robot_ip="127.0.0.1") as sta:
            tag1 = await sta.get_queue_tag_status(1)
            tag9 = await sta.get_queue_tag_status(9)
        return tag1, tag9

    tag1, tag9 = run(scenario())
    assert (tag1, tag9) == (True, None)
    robot = sim.robots[0]
    ends = [e for e in robot.events if e["kind"] == "motion_end"]
    assert [e["function"] for e in ends] == ["PTP", "Line"]
    assert ends[-1]["pose"][:3] == pytest.approx([400, -100, 350], abs=0.01)
    waited = [e for e in robot.events if e["kind"] == "frame_out" and ",OK" in e["raw"]]
    assert waited, "every script was answered"


def test_transaction_pause_resume_and_stop(sim):
    _STA, SCT = clients(sim.ports[0])
    robot = sim.robots[0]

    async def scenario():
        async with SCT(robot_ip="127.0.0.1") as sct:
            trsct = sct.start_transaction()
            trsct.move_to_joint_angles_ptp([90, 0, 90, 0, 90, 0], 0.1, 200)
            trsct.set_queue_tag(5)
            await trsct.submit()
            await sct.pause_project()
            paused = robot.state()["paused"]
            await sct.resume_project()
            await sct.stop_motion()
            return paused, robot.state()

    paused, state = run(scenario())
    assert paused is True
    assert state["paused"] is False and state["queue_length"] == 0
    kinds = [e["kind"] for e in robot.events]
    assert "motion_start" in kinds and "motion_end" not in kinds


def test_script_error_raises_tmsct_error_naming_the_line(sim):
    _STA, SCT = clients(sim.ports[0])

    async def scenario():
        async with SCT(robot_ip="127.0.0.1") as sct:
            await sct.move_to_point_ptp([400, -100, 350, 180, 0, 90], 0.5, 200, pose_goal=[0, 2, 4])
            with pytest.raises(techmanpy.TMSCTError, match="XYZ"):
                # the public helpers never build a bad data format; _execute is how they all send
                await sct._execute(("Line", ["XYZ", [1, 2, 3, 4, 5, 6], 1, 2, 3, True]))
            return True

    assert run(scenario())


def test_command_outside_node_raises_protocol_error(sim):
    _STA, SCT = clients(sim.ports[0])
    sim.robots[0].leave_listen_node()

    async def scenario():
        async with SCT(robot_ip="127.0.0.1") as sct:
            with pytest.raises(techmanpy.TMProtocolError):
                await sct.set_base("RobotBase")
            return True

    assert run(scenario())


def test_relative_moves_path_moves_and_tool_settings(sim):
    _STA, SCT = clients(sim.ports[0])
    robot = sim.robots[0]

    async def scenario():
        async with SCT(robot_ip="127.0.0.1") as sct:
            await sct.set_tcp([0, 0, 50, 0, 0, 0], weight=1.2)
            await sct.set_load_weight(2.0)
            await sct.move_to_point_path([400, -100, 300, 180, 0, 90], 500, 100)
            await sct.move_to_relative_point_ptp([0, 0, 20, 0, 0, 0], 0.5, 100)
            await sct.move_to_relative_point_line([0, 10, 0, 0, 0, 0], 0.5, 100, relative_to_tcp=True)
            await sct.move_to_relative_joint_angles_ptp([5, 0, 0, 0, 0, 0], 0.5, 100)
            await sct.set_queue_tag(3, wait_for_completion=True)

    run(scenario())
    state = robot.state()
    assert state["tool"]["pose"][2] == 50 and state["tool"]["mass"] == 1.2 and state["load"] == 2.0
    functions = [e["function"] for e in robot.events if e["kind"] == "motion_end"]
    assert functions == ["PLine", "Move_PTP", "Move_Line", "Move_PTP"]
    assert not any(e["kind"] in ("script_error", "runtime_error", "motion_failed") for e in robot.events)


def test_enter_message_reaches_the_broadcast_callback(sim):
    _STA, SCT = clients(sim.ports[0])
    robot = sim.robots[0]
    robot.leave_listen_node()
    received = []

    async def scenario():
        arrived = asyncio.Event()

        def on_broadcast(packet):
            received.append(packet)
            arrived.set()

        async with SCT(robot_ip="127.0.0.1") as sct:
            sct.add_broadcast_callback(on_broadcast)
            assert robot.wait_event("connect", timeout=5) is not None
            robot.enter_listen_node()
            await asyncio.wait_for(arrived.wait(), 5)
            sct.quit()
        return received

    packets = run(scenario())
    assert packets and packets[0].handle_id == "0"
