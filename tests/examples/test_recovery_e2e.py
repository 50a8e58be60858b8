"""Done-when scenarios of issue 14 on the examples as shipped (Commands_Example + PnP_Example on the virtual PLC,
virtual time) against the simulator with its Ethernet Slave over real loopback sockets; the simulator's event
log is the witness that nothing ran twice."""
from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest
from pnp_plant import SECOND, SOURCES, Plant

from vplc.api import load_plc

UNREACHABLE = dict(X=1900.0, Y=0.0, Z=300.0, RX=180.0, RY=0.0, RZ=90.0)


@pytest.fixture
def plant():
    p = Plant()
    p.plc.write("Connect_Execute", True)
    p.until(lambda: p.read("Connect_Connected") and p.read("RobotStatus_Valid"), "connected with status")
    yield p
    p.close()


def set_target(plant, segment, pose):
    for axis, value in pose.items():
        plant.plc.write(f"PnP_MoveParameters[{segment}].TargetPosition.{axis}", value)


def test_out_of_reach_mid_pnp_is_a_robot_error_acknowledged_and_resumed_without_repeats(plant):
    original = {a: plant.read(f"PnP_MoveParameters[3].TargetPosition.{a}") for a in UNREACHABLE}
    set_target(plant, 3, UNREACHABLE)                 # an operator typo: the place approach out of reach
    plant.plc.write("PnP_Example_Execute", True)
    plant.until(lambda: plant.read("PnP_MoveError"), "the failed move", 30)
    # segment 3 is blended (Done when accepted): the robot stops on it while segment 4 is either sent (ended
    # by the robot error, or outcome unknown) or refused because the link is already gone - then the refusal
    # says why: the robot error from the Ethernet Slave, or "retrying" in the moment before its data table
    # shows the stop; never "execute CBT_Connect first" (16#2001) while CBT_Connect is executing
    assert plant.read("PnP_MoveErrorID") in (0x4006, 0x200B, 0x200C)
    plant.until(lambda: plant.read("Connect_ErrorID") == 0x4006, "robot error on CBT_Connect", 2)
    plant.until(lambda: plant.read("RobotStatus.RobotError"), "robot error in CBT_RobotStatus", 1)
    assert plant.read("RobotStatus.ErrorCode") != 0 and "reach" in plant.read("RobotStatus.ErrorText")
    assert plant.read("PnP_GripperClosed") and plant.read("PnP_Segment") in (3, 4)
    picks = len([e for e in plant.events("io") if e.get("value") in (1, True)])
    # operator: correct the target, acknowledge and play the project, restart the cycle
    set_target(plant, 3, original)
    plant.plc.write("PnP_Example_Execute", False)
    plant.plc.write("Project_Command", "ProjectPlay")
    plant.pulse("Project_Execute", "Project_Done", "project play")
    plant.until(lambda: plant.read("Connect_Connected"), "automatic reconnect", 8)
    assert not plant.read("RobotStatus.RobotError") and plant.read("RobotStatus.ProjectRunning")
    plant.plc.write("PnP_Reset", True)                 # the cycle is Faulted: Reset, then a new start
    plant.until(lambda: plant.read("PnP_State") == "Idle", "the reset", 1)
    plant.plc.write("PnP_Reset", False)
    starts_before = len(plant.events("motion_start"))
    plant.plc.write("PnP_Example_Execute", True)
    plant.until(lambda: plant.read("PnP_MoveBusy"), "the first move after the start", 2)
    assert plant.read("PnP_Segment") == 3                # with the part: on to the place approach
    plant.until(lambda: plant.read("PnP_CycleCount") >= 1, "the cycle to complete", 40)
    # resumed at the place approach with the part: no second pick, the part placed once
    lines = [e["line"] for e in plant.events("motion_start")[starts_before:]]
    assert lines and plant.read("PnP_CycleCount") == 1
    closes = [e for e in plant.events("io") if e.get("value") in (1, True)]
    assert len(closes) == picks                       # the gripper did not close again


@pytest.mark.slow
def test_simulator_killed_mid_pnp_and_started_again_is_reconnected_by_itself(tmp_path, free_port):
    """SIGKILL: no FIN, no RST from a process that is gone — the kernel answers for it. CBT_Connect (Execute held)
    reports the loss and reconnects by itself once the simulator is back; the cycle resumes with an operator
    start where the part is and completes. The simulator runs as its own process in real time, so this test runs the
    PLC in real time too."""
    port = free_port()
    cmd = [sys.executable, "-m", "tmsim", "--port", str(port), "--no-svr", "--control-port", "0", "--speedup", "4"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    plc = load_plc(SOURCES)
    try:
        plc.write("Connect_AddressIP", "127.0.0.1")
        plc.write("Connect_Dest_PortIP", port)
        plc.write("Connect_SvrPort", 0)
        plc.write("PnP_DwellTime", SECOND // 4)       # real time: a short settle time keeps the test short
        plc.write("Connect_Execute", True)

        def run(pred, seconds):
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                now = plc.now_ns + plc.period_ns
                plc.scan(now)
                if pred():
                    return True
                time.sleep(0.001)
            return False
        assert run(lambda: plc.read("Connect_Connected"), 15), plc.read("Connect_ErrorDescrip")
        plc.write("PnP_Example_Execute", True)
        assert run(lambda: plc.read("PnP_Segment") >= 1, 30)
        proc.send_signal(signal.SIGKILL)
        proc.wait(5)
        assert run(lambda: plc.read("PnP_MoveError") or plc.read("Connect_Reconnecting"), 5)
        assert run(lambda: plc.read("Connect_Reconnecting") and not plc.read("Connect_Connected"), 5)
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        assert run(lambda: plc.read("Connect_Connected"), 15), plc.read("Connect_ErrorDescrip")
        assert plc.read("Connect_RetryCount") >= 1
        cycles = plc.read("PnP_CycleCount")
        plc.write("PnP_Example_Execute", False)
        assert run(lambda: not plc.read("PnP_MoveBusy"), 10)
        plc.write("PnP_Reset", True)                      # the cycle is Faulted by the loss: Reset ...
        assert run(lambda: plc.read("PnP_State") == "Idle", 2)
        plc.write("PnP_Reset", False)
        plc.write("PnP_Example_Execute", True)            # ... and an operator start (the robot's position
        assert run(lambda: plc.read("PnP_MoveBusy"), 5)   # decides where the cycle goes on)
        assert run(lambda: plc.read("PnP_CycleCount") > cycles, 40), plc.read("PnP_MoveErrorDescrip")
        assert not plc.read("PnP_MoveError") and plc.read("Connect_Connected")
    finally:
        plc.close()
        proc.kill()
        proc.wait(5)
