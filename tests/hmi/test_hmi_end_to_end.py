"""The whole system from the operator's seat: headless Chromium at 800x480 -> HMI server -> the example programs
and the real library on the virtual PLC in real time -> the robot simulator over loopback.

Each test drives the pages like an operator and checks the robot side in the simulator's event log.
"""
from __future__ import annotations

import time

import pytest
from browser import Browser
from hmi_system import DWELL_NS, MOVE_WAIT_S, System
from selenium.webdriver.common.by import By


@pytest.fixture(scope="module")
def system(chromium):
    stack = System(chromium)
    yield stack
    stack.close()


@pytest.fixture(scope="module")
def connected(system):
    browser = system.open("connect")
    browser.type_into("Connect_AddressIP", "127.0.0.1")
    browser.type_into("Connect_Dest_PortIP", str(system.sim.ports[0]))
    browser.type_into("Connect_Time_Out", "10")
    browser.click("btn-execute")
    browser.wait_status("Connect_Connected", "true")
    browser.wait_for(lambda d: "DT#" in browser.status("Connect_LastConnTime")
                     or browser.status("Connect_LastConnTime") != "", "LastConnTime")
    browser.screenshot("e2e_connect")
    return system


def script_texts(system, since: float) -> list[str]:
    """Script lines the robot executed, without the position polling of CBT_ReadActualPosition (ListenSend)."""
    return [e["text"] for e in system.events("script_line", since) if not e["text"].startswith("ListenSend(")]


def commands(system, since: float) -> list[str]:
    """Script lines without the QueueTag(n) the library appends to every non-blended move."""
    return [t for t in script_texts(system, since) if not t.startswith("QueueTag(")]


ANSWERS = (": Done", ": done", ": Error", ": aborted")     # the message line's words for the FB's answer


def execute_and_wait_done(system, browser, group: str) -> None:
    """Execute and wait for this command's answer: the click replaces the message line at once ("Sending …"),
    and the page writes the answer only from values read after the command, so a Done still shown from the
    previous command of the same page does not count."""
    browser.click("btn-execute")
    browser.wait_for(lambda d: any(word in browser.message() for word in ANSWERS), f"the answer of {group}",
                     timeout=MOVE_WAIT_S)
    browser.wait_status(f"{group}_Done", "true", timeout=MOVE_WAIT_S)
    assert browser.status(f"{group}_Error") == "false"


def test_main_page_shows_the_live_tcp_position(connected):
    browser = connected.open("index")
    browser.wait_for(lambda d: browser.text("tcp-pos").startswith("TCP X "), "the TCP position")
    x = float(browser.text("tcp-pos").split()[2])
    assert abs(x - connected.robot_state()["tcp"][0]) < 1.0
    browser.wait_status("Robot_InListenNode", "true")                     # the robot status strip
    assert browser.status("Robot_Stopping") == "false" and browser.status("Robot_LastErrorID").startswith("16#")
    browser.screenshot("e2e_main")


def test_move_absolute_page_moves_the_robot_to_the_entered_target(connected):
    browser = connected.open("moveabs")
    browser.click("btn-preset")
    for axis, value in zip(("X", "Y", "Z"), ("380", "-50", "420"), strict=False):
        browser.type_into(f"MoveAbs_Param.TargetPosition.{axis}", value)
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "MoveAbs")
    assert commands(connected, since) == ['PTP("CPP",380,-50,420,180,0,90,50,200,0,true)']
    assert connected.robot_state()["tcp"][:3] == pytest.approx([380, -50, 420], abs=0.5)
    browser.screenshot("e2e_moveabs_done")


def test_move_relative_page_moves_by_the_offset(connected):
    browser = connected.open("moverel")
    browser.click("btn-preset")
    browser.type_into("MoveRel_Param.TargetPosition.Z", "-30")
    start = connected.robot_state()["tcp"][2]
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "MoveRel")
    assert commands(connected, since) == ['Move_Line("CPP",0,0,-30,0,0,0,20,200,0,true)']
    connected.wait(lambda: not connected.robot_state()["moving"], "the relative move to end")
    assert connected.robot_state()["tcp"][2] == pytest.approx(start - 30, abs=0.5)
    browser.screenshot("e2e_moverel_done")


def test_move_circle_page_sends_a_circle(connected):
    browser = connected.open("movecircle")
    browser.click("btn-preset")
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "MoveCircle")
    assert commands(connected, since) == [
        'Circle("CPP",450,50,400,180,0,90,400,100,400,180,0,90,30,200,0,0,true)']
    browser.screenshot("e2e_movecircle_done")


def test_change_base_page_sets_the_robot_base(connected):
    browser = connected.open("changebase")
    browser.click("btn-preset")
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "ChangeBase")
    assert commands(connected, since) == ["ChangeBase(0,0,0,0,0,0)"]
    browser.screenshot("e2e_changebase_done")


def test_change_tcp_page_sets_the_tool(connected):
    browser = connected.open("changetcp")
    browser.click("btn-preset")
    browser.type_into("ChangeTCP_Param.TCPOffset.Z", "100")
    browser.type_into("ChangeTCP_Param.Weight", "1.5")
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "ChangeTCP")
    assert commands(connected, since) == ["ChangeTCP(0,0,100,0,0,0,1.5,0,0,0,0,0,0,0,0,0)"]
    browser.click("btn-preset")      # back to no tool for the following tests
    execute_and_wait_done(connected, browser, "ChangeTCP")
    browser.screenshot("e2e_changetcp_done")


def test_digital_output_page_switches_the_gripper_output(connected):
    browser = connected.open("setoutput")
    browser.click("btn-preset")                                  # Gripper Close: End Module DO0 on, wait
    since = connected.event_count()
    execute_and_wait_done(connected, browser, "SetOutput")
    assert commands(connected, since) == ['IO["EndModule"].DO[0]=1']
    assert connected.robot_state()["io"]["EndModule.DO[0]"] == 1
    browser.screenshot("e2e_setoutput_done")
    browser.click("btn-preset-2")                                # Gripper Open
    execute_and_wait_done(connected, browser, "SetOutput")
    assert connected.robot_state()["io"]["EndModule.DO[0]"] == 0


def test_stop_page_stops_a_running_move_and_aborts_it(connected):
    browser = connected.open("moveabs")
    browser.click("btn-preset")       # 1 %: the move still runs when the stop arrives, even on a loaded machine
    for axis, value in zip(("X", "Y", "Z", "Speed"), ("300", "250", "300", "1"), strict=False):
        browser.type_into(f"MoveAbs_Param.{'' if axis == 'Speed' else 'TargetPosition.'}{axis}", value)
    browser.click("btn-execute")
    connected.wait(lambda: connected.robot_state()["moving"], "the slow move to start")
    browser = connected.open("stop")
    since = connected.event_count()
    browser.click("btn-preset")                                  # Stop Immediately: sends the stop at once
    browser.wait_for(lambda d: any(word in browser.message() for word in ANSWERS), "the answer of Stop",
                     timeout=MOVE_WAIT_S)
    browser.wait_status("Stop_Done", "true", timeout=MOVE_WAIT_S)
    assert browser.status("Stop_Error") == "false"
    browser.wait_for(lambda d: "Done – the robot stopped" in browser.message(), "Done on the message line")
    assert browser.status("Stop_Done") == "true"                 # held long enough to be seen
    assert [e["command"] for e in connected.events("priority", since)] == ["StopAndClearBuffer(0)"]
    released = "Stop Immediately: Done – the robot stopped and its queue is cleared."
    browser.wait_for(lambda d: browser.message() == released, "the push button to release")
    assert connected.read("Stop_Execute") is False and connected.read("Cobot.Stopping") is False
    browser.screenshot("e2e_stop_done")
    connected.wait(lambda: connected.read("MoveAbs_CommandAborted"), "the move to be aborted")
    browser = connected.open("moveabs")
    browser.wait_status("MoveAbs_CommandAborted", "true")        # the operator sees why the move ended
    state = connected.robot_state()
    assert not state["moving"] and state["queue_length"] == 0
    assert state["tcp"][:3] != pytest.approx([300, 250, 300], abs=1.0)       # stopped on the way
    browser.screenshot("e2e_stop_aborted_move")


def test_out_of_range_entry_shows_the_error_and_nothing_reaches_the_robot(connected):
    browser = connected.open("moveabs")
    browser.type_into("MoveAbs_Param.AccelTime", "10000")
    since = connected.event_count()
    browser.click("btn-execute")
    browser.wait_for(lambda d: "out of range" in browser.message(), "the range error")
    assert "Accel Time: 10000 is out of range 0..9999 ms" in browser.message()
    assert connected.read("MoveAbs_Param.AccelTime") != 10000
    moves = [t for t in script_texts(connected, since) if t.startswith(("PTP(", "Line(", "Move_", "Circle("))]
    assert moves == [] and connected.events("motion_start", since) == []
    browser.screenshot("e2e_moveabs_range_error")


def edit_place_speed(system, browser, speed: int) -> None:
    """Segment 5 (place) through its dialog on the PnP page, as the operator does; returns once the PLC has it."""
    browser.driver.find_element(By.ID, "edit-4").click()
    browser.wait_for(lambda d: d.find_element(By.ID, "seg-dialog").get_attribute("open") is not None, "the dialog")
    browser.type_into("PnP_MoveParameters[4].Speed", str(speed))
    browser.click("seg-apply")
    browser.wait_for(lambda d: d.find_element(By.ID, "seg-dialog").get_attribute("open") is None
                     and "Segment 5 updated" in browser.message(), "the segment update")
    system.wait(lambda: system.read("PnP_MoveParameters")[4]["Speed"] == speed, "the new place speed in the PLC")


@pytest.mark.slow
def test_two_pnp_cycles_with_pause_and_resume(connected):
    browser = connected.open("pnp")
    browser.click("btn-preset")
    browser.wait_for(lambda d: "Preset PnP cycle written" in browser.message(), "the preset")
    preset_speed = connected.read("PnP_MoveParameters")[4]["Speed"]
    edit_place_speed(connected, browser, 2)                     # slow "place" move: a sure window to pause in
    targets = [[p["TargetPosition"][k] for k in ("X", "Y", "Z")] for p in connected.read("PnP_MoveParameters")]
    cycles = connected.read("PnP_CycleCount")
    with connected.plc.lock:                                   # the gripper's settle time, T#2s as shipped
        connected.plc.write("PnP_DwellTime", DWELL_NS)
    since = connected.event_count()
    browser.click("btn-execute")
    connected.wait(lambda: connected.read("PnP_Segment") == 4 and connected.robot_state()["moving"]
                   and connected.robot_state()["tcp"][2] < targets[3][2] - 5, "the place move in progress")
    browser.click("btn-pause")
    connected.wait(lambda: connected.robot_state()["paused"], "the robot to pause")
    browser.screenshot("e2e_pnp_paused")
    paused_mark = connected.event_count()
    assert connected.robot.wait_event("motion_end", timeout=0.5, since=len(connected.robot.events)) is None
    assert connected.read("PnP_Segment") == 4, "the sequence must wait while the robot is paused"
    assert connected.robot_state()["tcp"][2] > targets[4][2] + 1, "paused before reaching the place point"
    edit_place_speed(connected, browser, preset_speed)           # the paused move keeps speed 1 (latched at its
    browser.click("btn-resume")                                  # start); the next cycle places at the preset speed
    connected.wait(lambda: not connected.robot_state()["paused"], "the robot to resume")
    connected.wait(lambda: connected.read("PnP_CycleCount") >= cycles + 2, "two complete cycles", timeout=90)
    browser.wait_for(lambda d: int(browser.status("PnP_CycleCount") or 0) >= cycles + 2, "the cycle count")
    browser.screenshot("e2e_pnp_running")
    browser.click("btn-stop")                                    # End Cycle: after the current segment
    connected.wait(lambda: connected.read("PnP_State") == "Idle" and not connected.read("PnP_MoveBusy"),
                   "the cycle to end")
    browser.wait_for(lambda d: browser.status("PnP_State") == "Idle", "Idle on the page")
    ends = [e["pose"][:3] for e in connected.events("motion_end", since)]
    for segment in range(6):
        reached = [end for end in ends if end == pytest.approx(targets[segment], abs=0.5)]
        assert len(reached) >= 2, f"segment {segment + 1} reached {len(reached)} times"
    assert connected.events("motion_end", paused_mark)[0]["pose"][:3] == pytest.approx(targets[4], abs=0.5)
    sent = commands(connected, since)
    assert sent.count("Pause()") == 1 and sent.count("Resume()") == 1
    assert sent.index("Pause()") < sent.index("Resume()")
    assert connected.read("PnP_MoveError") is False


def press_stop_motion(system) -> Browser:
    """The Stop Motion page as the operator uses it: Stop Immediately sends the stop; the page holds Stop until
    Done, shows Done for 1.5 s, then releases it. Returns once the page has released Stop."""
    browser = system.open("stop")
    browser.click("btn-preset")                                  # Stop Immediately
    system.wait(lambda: system.read("Stop_Done"), "the stop to be done")
    system.wait(lambda: not system.read("Stop_Execute"), "the page to release Stop")
    system.wait(lambda: not system.read("Cobot.Stopping"), "the robot released")
    return browser


def pnp_page_offers(browser) -> dict:
    """Which of the PnP page's Execute, Stop and Reset keys are enabled (not :disabled, as WebDriver's is_enabled
    tells), read in one round trip."""
    return browser.driver.execute_script(
        "return Object.fromEntries(arguments[0].map((name) => "
        "[name, !document.getElementById(`btn-${name}`).matches(':disabled')]))", ["execute", "stop", "reset"])


def long_dwell_at_pick(system) -> bool:
    """A long dwell (20 s: the stop surely hits it) for the dwell at the pick point only, written on the way to
    pick before that dwell starts; False until then. The cycle goes on from where the test before left it: the
    long dwell written at once was first waited out at the place point (22 s). Looked and written under the PLC's
    lock, so no scan comes in between."""
    with system.plc.lock:
        if system.plc.read("PnP_Segment") != 1 or system.plc.read("PnP_Waiting"):
            return False
        system.plc.write("PnP_DwellTime", 20 * 1_000_000_000)
        return True


@pytest.mark.slow
def test_pnp_stop_stays_stopped_while_dwelling_and_mid_move_until_a_new_start(connected):
    """Issue 25 item 1: Stop on the Stop Motion page while the cycle dwells at the pick point, and again while a
    move runs. The page releases Stop 1.5 s later; the robot must not move again by itself, and the PnP page
    shows Stopped and offers Start (not Reset, not End Cycle); Start moves the robot again."""
    browser = connected.open("pnp")
    browser.click("btn-preset")
    browser.wait_for(lambda d: "Preset PnP cycle written" in browser.message(), "the preset")
    with connected.plc.lock:
        connected.plc.write("PnP_DwellTime", DWELL_NS)
        connected.plc.write("PnP_MoveParameters[4].Speed", 2)      # a slow place move: a sure window for a stop
    cycles = connected.read("PnP_CycleCount")
    browser.wait_for(lambda d: pnp_page_offers(browser) == {"execute": True, "stop": False, "reset": False},
                     "Start offered while Idle")
    browser.click("btn-execute")
    connected.wait(lambda: long_dwell_at_pick(connected), "the way to pick")
    connected.wait(lambda: connected.read("PnP_Waiting") and connected.read("PnP_Segment") == 1, "the dwell at pick")

    press_stop_motion(connected)                                 # 1) while dwelling
    connected.wait(lambda: connected.read("PnP_State") == "Stopped", "the latched stop")
    with connected.plc.lock:
        connected.plc.write("PnP_DwellTime", DWELL_NS)           # the next dwell is short again
    mark = connected.event_count()
    time.sleep(2.0)                                              # 8 s of robot time after the release
    assert connected.events("motion_start", mark) == [], "the robot moved again by itself"
    assert connected.read("PnP_State") == "Stopped" and connected.read("PnP_Example_Execute") is True
    browser = connected.open("pnp")
    browser.wait_for(lambda d: "Cycle: Stopped" in browser.text("pnp-state"), "Stopped on the page")
    assert "Nothing moves until you press Start" in browser.text("pnp-state")
    assert pnp_page_offers(browser) == {"execute": True, "stop": False, "reset": False}
    assert browser.viewport_overflow() == []
    browser.screenshot("e2e_pnp_stopped_dwelling")
    browser.click("btn-execute")                                 # the deliberate start
    browser.wait_for(lambda d: "Start: the cycle is Running" in browser.message(), "the start taken")
    connected.wait(lambda: connected.events("motion_start", mark), "the robot to move after Start")

    target = connected.read("PnP_MoveParameters")[4]["TargetPosition"]["Z"]
    connected.wait(lambda: connected.read("PnP_Segment") == 4 and connected.robot_state()["moving"]
                   and connected.robot_state()["tcp"][2] < target + 100, "the slow place move")
    press_stop_motion(connected)                                 # 2) while moving
    assert connected.read("PnP_State") == "Stopped" and connected.read("PnP_MoveError") is False
    mark = connected.event_count()
    time.sleep(2.0)
    assert connected.events("motion_start", mark) == [], "the robot moved again by itself"
    assert not connected.robot_state()["moving"] and connected.read("PnP_State") == "Stopped"
    browser = connected.open("pnp")
    browser.wait_for(lambda d: "Cycle: Stopped" in browser.text("pnp-state"), "Stopped on the page")
    assert pnp_page_offers(browser) == {"execute": True, "stop": False, "reset": False}
    browser.screenshot("e2e_pnp_stopped_mid_move")
    with connected.plc.lock:
        connected.plc.write("PnP_MoveParameters[4].Speed", 30)
    browser.click("btn-execute")
    browser.wait_for(lambda d: "Start: the cycle is Running" in browser.message(), "the start taken")
    browser.wait_for(lambda d: pnp_page_offers(browser) == {"execute": False, "stop": True, "reset": False},
                     "End Cycle offered while Running")
    connected.wait(lambda: connected.read("PnP_CycleCount") > cycles, "the cycle to complete", timeout=60)
    browser.click("btn-stop")
    connected.wait(lambda: connected.read("PnP_State") == "Idle", "the cycle to end")
    assert connected.read("PnP_MoveError") is False


def test_pnp_fault_with_an_unknown_outcome_is_reset_on_the_page_and_the_move_is_not_repeated(connected):
    """The link is cut while the place move runs: the move's outcome is unknown (16#200B), the cycle is Faulted
    and the page offers Reset only; after Reset, Start checks where the robot is: it finished the place move on
    its own, so the move is not sent again and the cycle goes on with the gripper."""
    browser = connected.open("pnp")
    browser.click("btn-preset")
    browser.wait_for(lambda d: "Preset PnP cycle written" in browser.message(), "the preset")
    with connected.plc.lock:
        connected.plc.write("PnP_DwellTime", DWELL_NS)
        connected.plc.write("PnP_MoveParameters[4].Speed", 5)      # a slow place move: a sure window for the cut
    place = connected.read("PnP_MoveParameters")[4]["TargetPosition"]
    place = [place[k] for k in ("X", "Y", "Z")]
    browser.click("btn-execute")
    # the place move accepted by the robot (Active) and running: its outcome is then unknown after the cut (a cut
    # before its frame left would be 16#200C, nothing sent: under load the blended approach can still be moving)
    connected.wait(lambda: connected.read("PnP_Segment") == 4 and connected.read("PnP_MoveActive")
                   and connected.robot_state()["moving"] and connected.robot_state()["tcp"][2] < place[2] + 100,
                   "the place move")
    with connected.sim.lock:
        connected.robot.inject("disconnect")
    cut = connected.event_count()
    connected.wait(lambda: connected.read("PnP_State") == "Faulted", "the fault")
    assert connected.read("PnP_MoveErrorID") == 0x200B and connected.read("PnP_OutcomeUnknown") is True
    browser.wait_for(lambda d: "Cycle: Faulted" in browser.text("pnp-state"), "Faulted on the page")
    text = browser.text("pnp-state")
    assert "16#200B" in text and "Press Reset, then Start" in text and "may have run" in text
    assert pnp_page_offers(browser) == {"execute": False, "stop": False, "reset": True}
    browser.screenshot("e2e_pnp_faulted_outcome_unknown")
    connected.wait(lambda: connected.read("Connect_Connected"), "the reconnect")
    browser.click("btn-reset")
    browser.wait_for(lambda d: "Reset: the cycle is Idle" in browser.message(), "the reset taken")
    browser.wait_for(lambda d: pnp_page_offers(browser) == {"execute": True, "stop": False, "reset": False},
                     "Start offered after Reset")
    with connected.plc.lock:
        connected.plc.write("PnP_MoveParameters[4].Speed", 30)
    cycles = connected.read("PnP_CycleCount")
    browser.click("btn-execute")
    connected.wait(lambda: connected.read("PnP_CycleCount") > cycles, "the cycle to complete", timeout=60)
    sent = commands(connected, cut)                              # what the robot received after the cut
    place_line = 'Line("CPP",{:g},{:g},{:g},'.format(*place)
    assert sent and not sent[0].startswith(place_line), "the place move was sent again although the robot had arrived"
    assert sent[0] == 'IO["EndModule"].DO[0]=0', "the gripper opens at the place point before the cycle moves on"
    browser.click("btn-stop")
    connected.wait(lambda: connected.read("PnP_State") == "Idle", "the cycle to end")


def test_connection_loss_shows_on_the_connect_page(connected):
    browser = connected.open("connect")
    browser.wait_status("Connect_Connected", "true")
    lost_before = browser.status("Connect_LastLostTime")
    with connected.sim.lock:
        connected.robot.inject("refuse_connections")           # the robot stays away: the loss stays visible
        connected.robot.inject("disconnect")
    browser.wait_status("Connect_Connected", "false")
    browser.wait_status("Connect_Reconnecting", "true")
    browser.wait_for(lambda d: browser.status("Connect_LastLostTime") != lost_before, "LastLostTime to change")
    browser.wait_for(lambda d: browser.text("pill-robot") == "Robot not connected", "the pill")
    browser.screenshot("e2e_connect_lost")
    with connected.sim.lock:
        connected.robot.clear_faults()                          # back: CBT_Connect reconnects by itself
    browser.wait_status("Connect_Connected", "true")
    browser.wait_status("Connect_Reconnecting", "false")


def test_message_line_shows_the_fb_error_of_a_motion_the_robot_refuses(connected):
    """A move the page accepts but the robot refuses (its script answered ERROR, injected in the simulator; an
    unreachable target no longer serves: the page refuses it before sending): the message line shows the FB's
    Error, ErrorID and ErrorDescrip."""
    browser = connected.open("moveabs")
    browser.click("btn-preset")
    connected.robot.inject("reply_error", count=1)
    browser.click("btn-execute")
    browser.wait_for(lambda d: "Move Absolute: Error 16#" in browser.message(), "the FB's error on the message line")
    error_id = connected.read("MoveAbs_ErrorID")
    assert f"Error 16#{error_id:04X} – {connected.read('MoveAbs_ErrorDescrip')}" in browser.message()
    browser.screenshot("e2e_moveabs_robot_error")
