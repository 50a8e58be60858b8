"""The pages of the server's alarm system, the invalid values without the PLC and the robot's real state, in
headless Chromium at 800x480 against the stand-in PLC (issue 25, items 2 to 5): alarm states, an acknowledge shared
by two browser sessions, the controller's date and 24-hour time, the list and history across a reload and a server
restart, #### and grey lamps within a second of the PLC going away, the operator's Exit Listen Node, the header's
robot state with the way back to the Listen node, and Play that does not speak of a stop."""
from __future__ import annotations

import time

import pytest
from browser import Browser
from fake_plc import ConnectedStack
from panel_metrics import cut_texts, page_metrics
from selenium.webdriver.common.by import By

CONTROLLER_START = time.mktime((2031, 7, 4, 21, 15, 30, 0, 0, -1))   # the controller's clock: not the browser's


class ControllerClock:
    """The server's clock, set to 4 July 2031 21:15:30 and running from there."""

    def __init__(self):
        self.origin = time.monotonic()

    def __call__(self):
        return CONTROLLER_START + (time.monotonic() - self.origin)


class Stack(ConnectedStack):
    """The stand-in PLC with its robot connected, and an HMI server keeping its alarm history in ``log_path`` on the
    controller's clock (a new clock at each server start)."""

    def __init__(self, log_path, port=0):
        self.log_path = log_path
        super().__init__(port)

    def server_options(self):
        return {"alarm_log": self.log_path, "clock": ControllerClock()}


@pytest.fixture(scope="module")
def stack(tmp_path_factory):
    s = Stack(tmp_path_factory.mktemp("alarms") / "alarms.jsonl")
    yield s
    s.close()


@pytest.fixture
def browser(chromium, stack):
    yield chromium
    stack.set(RS_EStop=False, RS_RobotError=False, Robot_InListenNode=True)
    stack.server.alarms.acknowledge(None, "engineer")




def text(browser, element_id):
    return browser.text(element_id)


def test_an_alarm_goes_through_its_states_on_the_page(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    stack.set(RS_EStop=True)
    browser.wait_for(lambda d: "Emergency stop pressed" in browser.banner(), "the E-stop in the banner")
    assert browser.viewport_overflow() == []
    assert "High" in browser.banner()
    assert "release the emergency stop, then press Play on the Main screen" in browser.banner()
    browser.wait_for(lambda d: browser.alarm_rows() and browser.alarm_rows()[0].endswith("active, unack."), "the row")
    assert browser.driver.find_element(By.ID, "alarm-banner").get_attribute("data-priority") == "high"
    assert text(browser, "pill-robot") == "Robot E-stop"
    browser.screenshot("alarm_active_unacknowledged")
    browser.click("btn-alarm-ack")
    browser.wait_for(lambda d: browser.alarm_rows()[0].endswith("active, ack.") and browser.banner() == "",
                     "the acknowledged alarm")
    browser.screenshot("alarm_active_acknowledged")
    stack.set(RS_EStop=False)
    browser.wait_for(lambda d: browser.alarm_rows() == [], "the alarm normal (acknowledged and returned)")
    stack.set(RS_EStop=True)
    browser.wait_for(lambda d: browser.alarm_rows() and browser.alarm_rows()[0].endswith("active, unack."), "again")
    stack.set(RS_EStop=False)
    browser.wait_for(lambda d: browser.alarm_rows()[0].endswith("returned, unack."), "returned unacknowledged")
    assert "Emergency stop pressed" in browser.banner()
    browser.screenshot("alarm_returned_unacknowledged")
    browser.click("btn-alarm-ack")
    browser.wait_for(lambda d: browser.alarm_rows() == [] and browser.banner() == "", "normal")


def test_one_alarm_per_cause_with_its_consequences_and_priority(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    stack.set(MoveAbs_Error=True, MoveAbs_ErrorID=0x3001,
              MoveAbs_ErrorDescrip="No reply from robot within ReplyTimeout")
    browser.wait_for(lambda d: any("16#3001" in r for r in browser.alarm_rows()), "the command's alarm")
    stack.set(RS_EStop=True, RS_RobotError=True, RS_ErrorCode=0x10001,
              RS_ErrorText="Emergency stop: the robot stopped its motion and its project; release it to go on",
              Connect_Connected=False, Connect_Reconnecting=True, Connect_ErrorID=0x4006,
              MoveRel_Error=True, MoveRel_ErrorID=0x4006, MoveRel_ErrorDescrip="Robot error stopped the project")
    try:
        browser.wait_for(lambda d: browser.alarm_rows() and "Emergency stop pressed (+3)" in browser.alarm_rows()[0],
                         "the E-stop with its three consequences on top")
        listed = browser.alarm_rows()
        assert len(listed) == 2 and "High" in listed[0] and "Low ① Move Absolute 16#3001" in listed[1], listed
        assert browser.viewport_overflow() == [] and browser.driver.execute_script(   # a long robot error text
            "const d = document.documentElement; return d.scrollWidth <= innerWidth && d.scrollHeight <= innerHeight")
        browser.screenshot("alarm_one_per_cause")
        browser.driver.find_element(By.ID, "alarm-history").find_elements(By.TAG_NAME, "tr")[1].click()
        whole = browser.message()
        assert "Consequences: Robot: Robot error 16#00010001: Emergency stop: the robot stopped its motion and its " \
               "project; release it to go on; Connection 16#4006: Connection to the " \
               "robot lost, reconnecting" in whole and "Move Relative 16#4006" in whole
    finally:
        stack.set(MoveAbs_Error=False, MoveAbs_ErrorID=0, MoveRel_Error=False, MoveRel_ErrorID=0,
                  Connect_Connected=True, Connect_Reconnecting=False, Connect_ErrorID=0)


@pytest.mark.parametrize("size", [(800, 480), (1280, 800)], ids=["800x480", "1280x800"])
def test_alarm_rows_are_touch_targets_and_main_cuts_no_text_while_alarms_stand(browser, stack, size):
    """The alarm list's rows are tapped (the whole alarm on the message line): each is a control of at least 34 px
    (they were 18 px), and the robot tile's state and the list's texts read whole with an E-stop, a robot error, a
    lost link and a failed command standing."""
    d = browser.driver
    browser.size(*size)
    browser.open(stack.server.page_url("index", "operator"))
    stack.set(MoveAbs_Error=True, MoveAbs_ErrorID=0x3001,
              MoveAbs_ErrorDescrip="No reply from robot within ReplyTimeout")
    try:
        browser.wait_for(lambda d: any("16#3001" in r for r in browser.alarm_rows()), "the command's alarm")
        stack.set(RS_EStop=True, RS_RobotError=True, RS_ErrorCode=0x10001, RS_ErrorText="Emergency stop",
                  Robot_InListenNode=False)
        browser.wait_for(lambda d: len(browser.alarm_rows()) >= 2, "two alarms listed")
        browser.screenshot(f"alarm_rows_{size[0]}x{size[1]}")
        rows = d.execute_script("return [...document.querySelectorAll('#alarm-history tr')].slice(1)"
                                ".map(r => [r.getBoundingClientRect().height, r.onclick !== null])")
        assert rows and all(height >= 34 and tapped for height, tapped in rows), rows
        found = page_metrics(browser)
        assert found == {"small": [], "text": [], "contrast": []}, found
        assert cut_texts(browser) == []
        assert text(browser, "robot-safety") == "E-STOP pressed, auto mode"
        assert browser.viewport_overflow() == []
    finally:
        stack.set(MoveAbs_Error=False, MoveAbs_ErrorID=0, RS_EStop=False, RS_RobotError=False, RS_ErrorText="",
                  Robot_InListenNode=True)
        browser.fit()


def test_acknowledge_is_shared_by_two_browser_sessions(browser, stack):
    second = Browser()
    try:
        browser.open(stack.server.page_url("index", "operator"))
        second.open(stack.server.page_url("index", "operator"))
        stack.set(Robot_InListenNode=False)
        for b in (browser, second):
            b.wait_for(lambda d, b=b: "The robot left the Listen node" in b.banner(), "the alarm on both panels")
        second.screenshot("alarm_second_panel_before_acknowledge")
        browser.click("btn-alarm-ack")
        second.wait_for(lambda d: second.banner() == "", "the acknowledge seen by the other panel")
        browser.wait_for(lambda d: browser.alarm_rows()[0].endswith("active, ack."), "acknowledged on the first")
        second.screenshot("alarm_second_panel_after_acknowledge")
    finally:
        second.close()


def test_timestamps_are_the_controllers_date_and_24_hour_time(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    stack.set(RS_EStop=True)
    browser.wait_for(lambda d: "Emergency stop" in browser.banner(), "the alarm")
    assert browser.banner().startswith("2031-07-04 21:1"), browser.banner()      # not the browser's clock
    assert browser.alarm_rows()[0].startswith("21:1")                                     # 24-hour, no AM/PM
    browser.click("btn-alarm-history")
    log = browser.driver.find_element(By.ID, "alarm-log").text.splitlines()
    raised = [line for line in log if " raised " in line and "Emergency stop pressed" in line]
    assert raised and raised[0].startswith("2031-07-04 21:1"), log[:5]
    browser.screenshot("alarm_history_controller_time")
    browser.click("btn-alarm-history-close")


def test_the_list_the_acknowledge_and_the_history_survive_a_reload_and_a_server_restart(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    browser.wait_for(lambda d: browser.alarm_rows() == [], "no alarm left by the test before")
    stack.set(RS_EStop=True)
    browser.wait_for(lambda d: "Emergency stop" in browser.banner(), "the alarm")
    browser.click("btn-alarm-ack")
    browser.wait_for(lambda d: browser.alarm_rows()[0].endswith("active, ack."), "acknowledged")
    browser.driver.refresh()
    browser.wait_for(lambda d: browser.alarm_rows() and browser.alarm_rows()[0].endswith("active, ack."),
                     "after reload")
    assert browser.banner() == ""
    stack.set(RS_EStop=False)
    browser.wait_for(lambda d: browser.alarm_rows() == [], "normal")
    entries = stack.server.alarms.summary(history=500)["history"]
    port = stack.server.port
    stack.server.stop()                                   # a server restart on the same port, same history file
    stack.start_server(port)
    browser.open(stack.server.page_url("index", "operator"))
    browser.click("btn-alarm-history")
    browser.wait_for(lambda d: len(browser.driver.find_element(By.ID, "alarm-log").text.splitlines()) >= len(entries),
                     "the history read back")
    shown = browser.driver.find_element(By.ID, "alarm-log").text.splitlines()[1:]
    assert shown[0].startswith(entries[0]["time"]) and "normal" in shown[0], shown[:2]
    browser.screenshot("alarm_history_after_restart")
    browser.click("btn-alarm-history-close")


def test_without_the_plc_values_read_invalid_with_a_communication_alarm(browser, stack, capsys):
    browser.open(stack.server.page_url("moveabs", "operator"))
    browser.wait_for(lambda d: browser.status("MoveAbs_ErrorID") == "16#0000", "a valid value")
    port = stack.server.port
    stack.server.stop()
    gone = time.monotonic()
    browser.wait_for(lambda d: browser.status("MoveAbs_ErrorID") == "####", "#### in place of the value")
    took = time.monotonic() - gone
    with capsys.disabled():
        print(f"\n  values invalid {took * 1000:.0f} ms after the HMI server stopped")
    assert browser.status("MoveAbs_Busy") == "invalid" and browser.status("Robot_Stopping") == "invalid"
    assert text(browser, "pill-plc") == "PLC offline" and text(browser, "pill-robot") == "Robot ####"
    assert "PLC communication lost" in browser.banner()
    assert "not valid" in browser.message()
    assert "plc-offline" in browser.driver.find_element(By.CSS_SELECTOR, ".panel").get_attribute("class")
    browser.screenshot("offline_values_invalid")
    stack.start_server(port)
    browser.wait_for(lambda d: browser.status("MoveAbs_ErrorID") == "16#0000", "valid values again")
    assert browser.banner() == ""


def test_the_operator_sees_exit_listen_node_locked_and_the_engineer_may_change_it(browser, stack):
    browser.open(stack.server.page_url("moveabs", "operator"))
    box = browser.field("MoveAbs_Param.ExitNode")
    assert not box.is_enabled() and browser.field("MoveAbs_Param.Speed").is_enabled()
    assert "Engineering setting" in box.find_element(By.XPATH, "..").get_attribute("title")
    browser.screenshot("operator_exit_node_locked")
    browser.fresh().open(stack.server.page_url("moveabs", "engineer"))     # a new tab: the address's key counts
    assert browser.field("MoveAbs_Param.ExitNode").is_enabled()


def test_the_header_says_when_the_robot_left_its_listen_node_and_main_offers_the_way_back(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    browser.wait_for(lambda d: text(browser, "pill-robot") == "Robot ready", "the robot ready")
    assert not browser.driver.find_element(By.ID, "btn-back-to-node").is_displayed()
    stack.set(Robot_InListenNode=False)
    browser.wait_for(lambda d: text(browser, "pill-robot") == "Robot left Listen node", "the header")
    browser.wait_for(lambda d: "Press Back to Listen Node on the Main screen" in browser.banner(), "the alarm")
    button = browser.driver.find_element(By.ID, "btn-back-to-node")
    assert button.is_displayed() and button.is_enabled()
    assert text(browser, "robot-link") == "connected, robot outside its Listen node"
    browser.screenshot("robot_left_listen_node")


def test_play_reports_that_the_project_runs_and_not_a_stop(browser, stack):
    browser.open(stack.server.page_url("index", "operator"))
    browser.click("btn-project-play")
    browser.wait_for(lambda d: "Play: Done – the robot project runs" in browser.message(), "Play's answer")
    assert "stop" not in browser.message().lower()
