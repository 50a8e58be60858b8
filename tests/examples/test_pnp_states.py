"""PnP_Example's operating states on the virtual PLC (virtual time) against the simulator with its Ethernet Slave:
a stop latches (issue 25 item 1) and an unknown outcome is resolved from the robot's position and outputs before
the cycle moves again (issue 23 item 3). The simulator's event log is the witness of what the robot did."""
from __future__ import annotations

import pytest
from pnp_plant import ROOT, SECOND, Plant


@pytest.fixture
def plant():
    p = Plant()
    p.plc.write("PnP_DwellTime", SECOND // 4)
    p.plc.write("Connect_Execute", True)
    p.until(lambda: p.read("Connect_Connected") and p.read("RobotStatus_Valid"), "connected with status")
    yield p
    p.close()


@pytest.fixture
def plant_without_ethernet_slave():
    """The robot's Ethernet Slave not used (Connect_SvrPort 0): positions come from the Listen node, the robot's
    outputs are not known to the PLC."""
    p = Plant()
    p.plc.write("PnP_DwellTime", SECOND // 4)
    p.plc.write("Connect_SvrPort", 0)
    p.plc.write("Connect_Execute", True)
    p.until(lambda: p.read("Connect_Connected"), "connected")
    yield p
    p.close()


def switched(values):
    """The gripper's switching: consecutive equal values collapsed (setting an output to the value it has is no
    switching)."""
    out = []
    for v in values:
        if not out or out[-1] != v:
            out.append(v)
    return out


def test_stop_while_dwelling_at_the_pick_point_stays_stopped_after_the_stop_is_released(plant):
    plant.plc.write("PnP_DwellTime", 2 * SECOND)               # as shipped: the stop hits during the dwell
    plant.start()
    plant.until(lambda: plant.read("PnP_Waiting"), "the dwell after pick", 30)
    assert plant.read("PnP_Segment") == 1 and plant.read("PnP_State") == "Running"
    plant.press_stop_like_the_hmi()
    assert plant.read("PnP_State") == "Stopped"
    mark = plant.mark()
    plant.run_for(5)                                           # PnP_Example_Execute is still TRUE
    assert plant.events("motion_start", mark) == [], "the robot moved again after the stop was released"
    assert plant.read("PnP_State") == "Stopped" and plant.read("PnP_Example_Execute") is True
    assert not plant.read("PnP_Waiting") and plant.read("PnP_MoveError") is False
    plant.plc.write("PnP_Example_Execute", True)                # TRUE again is no start
    plant.run_for(1)
    assert plant.events("motion_start", mark) == []
    plant.start()                                              # the deliberate start
    plant.until(lambda: plant.read("PnP_State") == "Running", "the start", 1)
    plant.until(lambda: plant.read("PnP_CycleCount") == 1, "the cycle to complete", 40)
    assert len(plant.arrivals(1)) == 1                         # picked once: the cycle went on from the dwell
    assert switched([e["value"] for e in plant.gripper()]) == [1, 0]


def test_stop_during_a_move_stays_stopped_until_a_new_start_then_the_cycle_completes(plant):
    plant.start()
    plant.until(lambda: plant.read("PnP_Segment") == 1 and plant.robot.state()["moving"], "the pick move", 30)
    plant.press_stop_like_the_hmi()
    assert not plant.robot.state()["moving"]
    assert plant.read("PnP_State") == "Stopped" and plant.read("PnP_MoveError") is False
    mark = plant.mark()
    plant.run_for(5)
    assert plant.events("motion_start", mark) == [] and plant.read("PnP_Example_Execute") is True
    assert plant.arrivals(1) == [] and plant.gripper() == []
    plant.plc.write("PnP_Example_Execute", True)                # the HMI's old Execute: no edge, nothing moves
    plant.run_for(1)
    assert plant.events("motion_start", mark) == [] and plant.read("PnP_State") == "Stopped"
    plant.start()
    plant.until(lambda: plant.read("PnP_CycleCount") == 1, "the cycle to complete", 40)
    assert len(plant.arrivals(1)) == 1 and len(plant.arrivals(4)) == 1
    assert switched([e["value"] for e in plant.gripper()]) == [1, 0]
    assert plant.read("PnP_MoveError") is False


def test_a_start_while_a_stop_is_held_is_refused_and_the_release_does_not_start(plant):
    plant.plc.write("Stop_Execute", True)
    plant.until(lambda: plant.read("Stop_Done"), "the stop", 2)
    plant.start()
    plant.run_for(1)
    assert plant.read("PnP_State") == "Idle" and plant.events("motion_start") == []
    plant.plc.write("Stop_Execute", False)
    plant.run_for(1)
    assert plant.read("PnP_State") == "Idle" and plant.events("motion_start") == []
    plant.start()
    plant.until(lambda: plant.read("PnP_Segment") == 1, "a new cycle", 30)


def lose_the_answer_of_the_next(plant, what, predicate):
    """When ``predicate`` turns TRUE after a scan the command has just been sent: every frame the robot sends is
    held back, the robot executes the command, then the link is cut, so the answer never arrives."""
    plant.until(predicate, what, 30)
    mark = plant.mark()
    plant.robot.inject("reply_delay", seconds=60)
    return mark


def lose_the_gripper_close_answer_then_restart(plant):
    """The gripper closes at the pick point, its answer is lost (16#200B); the link comes back; the operator
    resets and starts again. Returns the event index before the close."""
    plant.start()
    mark = lose_the_answer_of_the_next(plant, "the gripper close", lambda: plant.read("PnP.GripperExecute"))
    plant.until(lambda: plant.gripper(mark), "the robot to close the gripper", 2)
    plant.robot.inject("disconnect")
    plant.robot.clear_faults()
    plant.until(lambda: plant.read("PnP_State") == "Faulted", "the fault", 10)
    assert plant.read("PnP_MoveErrorID") == 0x200B and plant.read("PnP_OutcomeUnknown") is True
    assert plant.read("PnP_GripperClosed") is False             # not confirmed by the robot
    plant.until(lambda: plant.read("Connect_Connected"), "the reconnect", 10)
    plant.start()                                              # a start without Reset is refused
    plant.run_for(1)
    assert plant.read("PnP_State") == "Faulted"
    plant.reset()
    assert plant.read("PnP_State") == "Idle" and plant.read("PnP_MoveError") is False
    plant.start()
    plant.until(lambda: plant.read("PnP_CycleCount") == 1, "the cycle to complete", 40)
    assert len(plant.arrivals(1)) == 1, "the part was carried back to the pick point"
    assert plant.read("PnP_OutcomeUnknown") is False and plant.read("PnP_GripperClosed") is False
    return mark


def test_gripper_close_with_a_lost_answer_is_resolved_from_the_robots_output_and_the_part_is_picked_once(plant):
    """Issue 23 item 3: the gripper closed, its answer was lost (16#200B). The next start must not carry the part
    back to the pick point and close again: the robot is at rest at the pick point and its Ethernet Slave data
    table shows End_DO0 = 1, so the close had run; the cycle goes on with the dwell and the retreat."""
    mark = lose_the_gripper_close_answer_then_restart(plant)
    assert [e["value"] for e in plant.gripper(mark)] == [1, 0]  # closed once (answer lost), opened at place
    assert [e["value"] for e in plant.gripper()] == [1, 0]


def test_without_the_robots_output_the_gripper_close_is_sent_again_at_the_pick_point(plant_without_ethernet_slave):
    """No Ethernet Slave, so no output reading: the robot is still at the pick point, so the close is sent again
    there (the output already is 1: no switching) before anything moves."""
    plant = plant_without_ethernet_slave
    mark = lose_the_gripper_close_answer_then_restart(plant)
    gripper = plant.gripper(mark)
    assert [e["value"] for e in gripper] == [1, 1, 0]           # sent again at the pick point, opened at place
    assert [e for e in plant.events("motion_start", mark) if e["t"] < gripper[1]["t"]] == [], \
        "the robot moved before the gripper state was known"
    assert switched([e["value"] for e in plant.gripper()]) == [1, 0]


def test_move_with_a_lost_answer_is_not_sent_again_when_the_robot_has_arrived(plant):
    """The pick move's answer is lost (16#200B) but the robot finishes it on its own: at the next start the
    position says it has arrived, so the cycle closes the gripper without sending the move again."""
    plant.start()
    mark = lose_the_answer_of_the_next(plant, "the pick move",
                                       lambda: plant.read("PnP_Segment") == 1 and plant.read("PnP_MoveBusy"))
    plant.until(lambda: plant.arrivals(1, mark), "the robot to reach the pick point", 10)
    plant.robot.inject("disconnect")
    plant.robot.clear_faults()
    plant.until(lambda: plant.read("PnP_State") == "Faulted", "the fault", 10)
    assert plant.read("PnP_MoveErrorID") == 0x200B and plant.read("PnP_OutcomeUnknown") is True
    plant.until(lambda: plant.read("Connect_Connected"), "the reconnect", 10)
    plant.reset()
    plant.start()
    plant.until(lambda: plant.read("PnP_CycleCount") == 1, "the cycle to complete", 40)
    picks = [e for e in plant.events("motion_start") if e["to"][:3] == pytest.approx(plant.target(1), abs=0.5)]
    assert len(picks) == 1 and len(plant.arrivals(1)) == 1
    assert switched([e["value"] for e in plant.gripper()]) == [1, 0]


def test_the_recovery_page_shows_the_code_the_example_runs():
    """docs/library/recovering_unknown_outcome.md quotes PnP_Example's Resolve step: every quoted line (``...``
    marks a gap) is in the example, in the same order."""
    page = (ROOT / "docs" / "library" / "recovering_unknown_outcome.md").read_text(encoding="utf-8")
    quoted = page.split("```\n")[1]
    example = [line.strip() for line in (ROOT / "examples" / "PnP_Example.st").read_text(encoding="utf-8").splitlines()]
    at = 0
    for line in (q.strip() for q in quoted.splitlines()):
        if line in ("", "..."):
            continue
        assert line in example[at:], f"not in PnP_Example.st (after line {at}): {line}"
        at = example.index(line, at) + 1
