"""The HMI's alarm banner and history and its Robot tile (issue 14) in headless Chromium, against the examples on
the virtual PLC in real time and the simulator with its Ethernet Slave: a robot error raises the alarms (robot
code and text, CBT_Connect's 16#4006), Acknowledge clears the banner, Play on the Robot tile restarts the
project through CBT_ProjectControl and the message line reports the FB's answer; a link outage is one alarm
from the loss until connected again, however many reconnect attempts it takes."""
import pytest
from selenium.webdriver.common.by import By

from test_hmi_end_to_end import System


@pytest.fixture(scope="module")
def system(chromium):
    stack = System(chromium)
    with stack.plc.lock:
        stack.plc.write("Connect_Execute", True)
    stack.wait(lambda: stack.read("Connect_Connected") and stack.read("RobotStatus_Valid"), "connected", 15)
    yield stack
    stack.close()


def text(browser, element_id):
    return browser.driver.find_element(By.ID, element_id).text


def banner(browser):
    element = browser.driver.find_element(By.ID, "alarm-banner")
    return element.text if element.is_displayed() else ""


def acknowledge_until_quiet(browser):
    """A robot error raises its alarms over several scans (the robot's code, CBT_Connect's 16#4006, then the FBs
    that were busy), so one more may come after a click: Acknowledge all until the banner stays hidden, then every
    alarm in the history must read acknowledged."""
    def clicked_and_clear(_):
        if banner(browser) == "":
            return True
        browser.click("btn-alarm-ack-all")
        return False
    browser.wait_for(clicked_and_clear, "the banner to clear")
    rows = browser.driver.find_element(By.ID, "alarm-history").text.splitlines()[1:]
    assert rows and all("acknowledged" in row for row in rows), rows


def connection_rows(browser):
    rows = browser.driver.find_element(By.ID, "alarm-history").text.splitlines()[1:]
    return [row for row in rows if "Connection" in row]


def running_project(system, browser):
    """Start from a running project whatever the test before left (a failed test must not fail the next)."""
    with system.sim.lock:
        system.robot.svr_source.model.estop = False
        if system.robot.session.state == "project_stopped":
            system.robot.svr_source.model.error_active = False
            system.robot.start_project()
    browser.wait_for(lambda d: text(browser, "robot-project").startswith("running"), "the project running")


def test_robot_error_raises_alarms_acknowledge_clears_the_banner_and_play_restarts(system):
    browser = system.open("index")
    browser.wait_for(lambda d: text(browser, "robot-project").startswith("running"), "the project running")
    assert text(browser, "robot-error") == "none" and banner(browser) == ""
    with system.sim.lock:
        system.robot.session.fire("robot_fault", reason="Line: target pose is out of reach")
    browser.wait_for(lambda d: "out of reach" in text(browser, "robot-error"), "the robot error on the tile")
    assert text(browser, "robot-project") == "stopped"
    browser.wait_for(lambda d: "16#4006" in browser.driver.find_element(By.ID, "alarm-history").text,
                     "CBT_Connect's robot error alarm")
    history = browser.driver.find_element(By.ID, "alarm-history").text
    assert "Robot code 16#00010001: Line: target pose is out of reach" in history
    assert banner(browser) != ""
    acknowledge_until_quiet(browser)
    browser.click("btn-project-play")
    browser.wait_for(lambda d: "Project Play: done" in browser.message(), "Play's answer on the message line")
    browser.wait_for(lambda d: text(browser, "robot-project").startswith("running"), "the project running again")
    system.wait(lambda: system.read("Connect_Connected"), "the automatic reconnect", 15)
    browser.wait_for(lambda d: text(browser, "robot-link") == "Listen node connected", "the link on the tile")
    browser.wait_for(lambda d: "gone" in browser.driver.find_element(By.ID, "alarm-history").text, "alarms gone")
    browser.screenshot("e2e_robot_tile")


def test_a_refused_project_command_is_reported_as_an_error_not_as_sent(system):
    browser = system.open("index")
    running_project(system, browser)
    with system.sim.lock:
        system.robot.svr_source.model.estop = True
    browser.wait_for(lambda d: text(browser, "robot-safety").startswith("E-STOP"), "the E-stop on the tile")
    browser.click("btn-project-play")
    browser.wait_for(lambda d: "Error 16#400A" in browser.message(), "the refusal on the message line")
    assert "error" in browser.driver.find_element(By.ID, "message").get_attribute("class")
    with system.sim.lock:
        system.robot.svr_source.model.estop = False


def test_a_link_outage_is_one_alarm_through_every_reconnect_attempt_until_connected(system):
    """CBT_Connect shows Error only during its back-off waits (docs/library/CBT_Connect.md, "Reconnect"): the HMI
    must not raise a new alarm for every attempt. Black hole: the loss (16#2006) raises one connection alarm;
    acknowledged, it stays active and the banner stays hidden while attempt 1 runs (Busy, no Error); the robot
    then goes away (connects refused), attempt 1 fails and attempt 2 follows after the back-off, still in the same
    row; once the fault is cleared and the link is up again the same alarm is gone. (An attempt into the black
    hole ends at Time_Out with 16#3004: tests/lib/test_lib_recovery.py, in virtual time.)"""
    browser = system.open("index")
    running_project(system, browser)
    system.wait(lambda: system.read("Connect_Connected"), "the connection", 15)
    # this test's own history: what is active now comes back at the next poll, what is gone is forgotten
    browser.driver.execute_script("alarms.list.length = 0; alarms.active = {}; saveAlarms(); drawAlarms();")
    browser.wait_for(lambda d: text(browser, "robot-link") == "Listen node connected", "the link on the tile")
    assert connection_rows(browser) == []
    with system.sim.lock:
        system.robot.inject("black_hole")
    try:
        browser.wait_for(lambda d: any("Connection lost, reconnecting" in row for row in connection_rows(browser)),
                         "the connection alarm")
        acknowledge_until_quiet(browser)
        browser.wait_for(lambda d: any("(attempt 1)" in row for row in connection_rows(browser)), "attempt 1")
        assert system.read("Connect_Busy") and not system.read("Connect_Error"), "attempt 1 runs quietly"
        rows = connection_rows(browser)
        assert len(rows) == 1 and rows[0].endswith("active, acknowledged"), rows
        assert banner(browser) == ""
        with system.sim.lock:                                  # the robot goes away while attempt 1 runs
            system.robot.inject("refuse_connections")
            system.robot.inject("disconnect")
        browser.wait_for(lambda d: any("(attempt 2)" in row and "16#" in row for row in connection_rows(browser)),
                         "the second reconnect attempt after the first failed", timeout=15)
        rows = connection_rows(browser)
        assert len(rows) == 1 and rows[0].endswith("active, acknowledged"), rows
        assert banner(browser) == ""
    finally:
        with system.sim.lock:
            system.robot.clear_faults()
    system.wait(lambda: system.read("Connect_Connected"), "the reconnect after the fault was cleared", 30)
    browser.wait_for(lambda d: text(browser, "robot-link") == "Listen node connected", "the link on the tile")
    browser.wait_for(lambda d: any(row.endswith("gone, acknowledged") for row in connection_rows(browser)),
                     "the connection alarm gone")
    rows = connection_rows(browser)
    assert len(rows) == 1 and "Connection lost, reconnecting" in rows[0], rows
    assert banner(browser) == ""
