"""The alarm system and the Robot tile end to end, in headless Chromium at 800x480, against the examples on the
virtual PLC in real time and the simulator with its Ethernet Slave (issue 14, issue 25 items 2 and 4): a robot
error is one alarm with the robot's code and text, its consequences (CBT_Connect's 16#4006, the lost link) as
details; it returns to normal when Play has restarted the project; a link outage is one alarm from the loss until
connected again, however many reconnect attempts it takes; a robot that left its Listen node is an alarm, the
header says so, and Back to Listen Node on Main brings it back through CBT_ProjectControl."""
import pytest
from hmi_system import System
from selenium.webdriver.common.by import By


@pytest.fixture(scope="module")
def system(chromium):
    stack = System(chromium)
    with stack.plc.lock:
        stack.plc.write("Connect_Execute", True)
    stack.wait(lambda: stack.read("Connect_Connected") and stack.read("RobotStatus_Valid"), "connected", 15)
    yield stack
    stack.close()


def text(browser, element_id):
    return browser.text(element_id)




def alarms(system):
    return system.hmi.alarms.summary()["alarms"]


def running_project(system, browser):
    """Start from a running project, connected, with no alarm listed (a failed test must not fail the next)."""
    with system.sim.lock:
        system.robot.svr_source.model.estop = False
        if system.robot.session.state == "project_stopped":
            system.robot.svr_source.model.error_active = False
            system.robot.start_project()
    system.wait(lambda: system.read("Connect_Connected"), "the connection", 30)
    browser.wait_for(lambda d: text(browser, "robot-project").startswith("running"), "the project running")
    system.wait(lambda: all(a["state"] != "active-unacknowledged" and a["state"] != "active-acknowledged"
                            for a in alarms(system)), "every alarm returned", 15)
    system.hmi.alarms.acknowledge(None, "engineer")


def test_a_robot_error_is_one_alarm_that_returns_to_normal_after_play(system):
    browser = system.open("index")
    running_project(system, browser)
    assert browser.alarm_rows() == [] and browser.banner() == ""
    with system.sim.lock:
        system.robot.session.fire("robot_fault", reason="Line: target pose is out of reach")
    browser.wait_for(lambda d: "out of reach" in text(browser, "robot-error"), "the robot error on the tile")
    browser.wait_for(lambda d: "Robot error 16#00010001: Line: target pose is out of reach" in browser.banner(),
                     "the robot error in the banner")
    assert "press Play on the Main screen" in browser.banner()
    assert text(browser, "pill-robot") == "Robot error"
    system.wait(lambda: any("16#4006" in d["text"] for a in alarms(system) for d in a["details"]),
                "CBT_Connect's 16#4006 as a detail of the robot error", 10)
    listed = alarms(system)
    assert [a["key"] for a in listed] == ["robot"], listed          # one alarm for the cause
    browser.screenshot("e2e_robot_error_one_alarm")
    browser.click("btn-alarm-ack")
    browser.wait_for(lambda d: browser.banner() == "", "the banner clear")
    browser.click("btn-project-play")
    browser.wait_for(lambda d: "Play: Done – the robot project runs" in browser.message(), "Play's answer")
    browser.wait_for(lambda d: text(browser, "robot-project").startswith("running"), "the project running again")
    system.wait(lambda: system.read("Connect_Connected"), "the automatic reconnect", 15)
    browser.wait_for(lambda d: text(browser, "robot-link") == "Listen node connected", "the link on the tile")
    browser.wait_for(lambda d: browser.alarm_rows() == [], "the alarm normal: acknowledged and its cause gone")
    browser.wait_for(lambda d: text(browser, "pill-robot") == "Robot ready", "the robot ready in the header")
    browser.screenshot("e2e_robot_tile")


def test_a_refused_project_command_is_a_message_not_an_alarm(system):
    browser = system.open("index")
    running_project(system, browser)
    with system.sim.lock:
        system.robot.svr_source.model.estop = True
    try:
        browser.wait_for(lambda d: text(browser, "robot-safety").startswith("E-STOP"), "the E-stop on the tile")
        browser.wait_for(lambda d: "Emergency stop pressed" in browser.banner(), "the E-stop alarm")
        browser.click("btn-project-play")
        browser.wait_for(lambda d: "Error 16#400A" in browser.message(), "the refusal on the message line")
        assert "error" in browser.driver.find_element(By.ID, "message").get_attribute("class")
        assert "Release the emergency stop" in browser.message()
        assert [a["key"] for a in alarms(system)] == ["estop"], alarms(system)   # 16#400A: no alarm of its own
    finally:
        with system.sim.lock:
            system.robot.svr_source.model.estop = False


def test_leaving_the_listen_node_is_an_alarm_and_back_to_listen_node_brings_the_robot_back(system):
    browser = system.open("index")
    running_project(system, browser)
    with system.sim.lock:
        system.robot.inject("leave_node", path="Pass")
    browser.wait_for(lambda d: text(browser, "pill-robot") == "Robot left Listen node", "the header")
    browser.wait_for(lambda d: "The robot left the Listen node" in browser.banner(), "the alarm")
    button = browser.driver.find_element(By.ID, "btn-back-to-node")
    assert button.is_displayed()
    browser.screenshot("e2e_left_listen_node")
    browser.click("btn-back-to-node")
    browser.wait_for(lambda d: "Back to Listen Node: Done" in browser.message(), "the way back", timeout=30)
    system.wait(lambda: system.read("Connect_Connected") and system.read("Robot_InListenNode"),
                "the robot in its Listen node again", 30)
    browser.wait_for(lambda d: text(browser, "pill-robot") == "Robot ready", "the robot ready again", timeout=30)
    browser.wait_for(lambda d: all("returned" in r for r in browser.alarm_rows()), "the alarm returned")
    browser.click("btn-alarm-ack-all")
    browser.wait_for(lambda d: browser.alarm_rows() == [], "normal")


@pytest.mark.slow
def test_a_link_outage_is_one_alarm_through_every_reconnect_attempt_until_connected(system):
    """CBT_Connect shows Error only during its back-off waits (docs/library/CBT_Connect.md, "Reconnect"): one
    alarm for the outage. Black hole: the loss (16#2006) raises it; acknowledged, it stays active while attempt 1
    runs; the robot then goes away (connects refused), attempt 1 fails and attempt 2 follows after the back-off,
    still the same alarm; once the fault is cleared and the link is up again it returns to normal."""
    browser = system.open("index")
    running_project(system, browser)
    with system.sim.lock:
        system.robot.inject("black_hole")
    try:
        system.wait(lambda: any(a["key"] == "link" for a in alarms(system)), "the connection alarm", 15)
        number = next(a["number"] for a in alarms(system) if a["key"] == "link")
        browser.wait_for(lambda d: "Connection to the robot lost, reconnecting" in browser.banner(), "the banner")
        browser.click("btn-alarm-ack")
        system.wait(lambda: any("(attempt 1)" in a["text"] for a in alarms(system)), "attempt 1", 15)
        with system.sim.lock:                                  # the robot goes away while attempt 1 runs
            system.robot.inject("refuse_connections")
            system.robot.inject("disconnect")
        system.wait(lambda: any("(attempt 2)" in a["text"] for a in alarms(system)), "attempt 2", 30)
        listed = [a for a in alarms(system) if a["key"] == "link"]
        assert len(listed) == 1 and listed[0]["number"] == number and listed[0]["state"] == "active-acknowledged"
        assert browser.banner() == ""
    finally:
        with system.sim.lock:
            system.robot.clear_faults()
    system.wait(lambda: system.read("Connect_Connected"), "the reconnect after the fault was cleared", 30)
    browser.wait_for(lambda d: browser.alarm_rows() == [], "the connection alarm normal")
    link = [e for e in system.hmi.alarms.summary(history=200)["history"] if e["alarm"] == number]
    assert [e["event"] for e in link][:2] == ["normal", "returned"]
