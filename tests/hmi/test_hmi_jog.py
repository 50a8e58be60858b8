"""The Jog/Teach page from the engineer's seat: headless Chromium at 800x480 -> HMI server -> the example programs
(JogTeach_Example) and the library on the virtual PLC in real time -> the robot simulator over loopback. Holding a
jog button moves the robot, releasing it stops the robot at once; a page that falls silent with the button held
is released by the PLC; Teach stores the robot's position into the table the page lists."""
from __future__ import annotations

import time

import pytest
from hmi_system import System
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

WAIT_S = 20


class Cell(System):
    """The engineer's jog cell: the robot model in real time (speedup 1), the connection made before the page opens."""

    def __init__(self, browser):
        super().__init__(browser, speedup=1.0)
        with self.plc.lock:
            self.plc.write("Connect_Execute", True)
        self.wait(lambda: self.read("Connect_Connected") and self.read("ReadPos_Valid"), "the connection", WAIT_S)

    def open(self):
        self.browser.open(self.hmi.page_url("jog", "engineer"))
        self.browser.wait_for(lambda d: d.find_elements(By.ID, "jog-3p"), "the jog buttons")
        self.browser.wait_for(lambda d: d.find_element(By.CSS_SELECTOR, "[data-jog-now='0']").text not in ("", "####"),
                              "the live position")
        return self.browser


@pytest.fixture(scope="module")
def cell(chromium):
    c = Cell(chromium)
    yield c
    c.close()


def test_holding_a_button_jogs_and_releasing_it_stops_the_robot(cell):
    browser = cell.open()
    browser.click("jog-frame-JogBase")
    start = cell.state()["tcp"]
    button = browser.driver.find_element(By.ID, "jog-3p")                     # Z+
    ActionChains(browser.driver).click_and_hold(button).perform()
    cell.wait(lambda: cell.read("Jog_Active"), "the jog to move the robot")
    time.sleep(0.3)
    assert cell.state()["moving"] and cell.read("Jog_Forward")
    stops = len(cell.events("stop"))
    ActionChains(browser.driver).release(button).perform()
    cell.wait(lambda: len(cell.events("stop")) > stops, "the release's stop")
    cell.wait(lambda: not cell.read("Jog_Busy"), "the jog to end")
    end = cell.state()
    assert not end["moving"] and end["tcp"][2] > start[2] + 5.0
    assert end["tcp"][:2] == pytest.approx(start[:2], abs=0.01)
    assert cell.read("Cobot.Stopping") is False and not cell.read("Jog_Error")
    browser.screenshot("jog_page")


def test_a_page_that_stops_answering_is_released_by_the_plc(cell):
    browser = cell.open()
    button = browser.driver.find_element(By.ID, "jog-1m")
    ActionChains(browser.driver).click_and_hold(button).perform()
    cell.wait(lambda: cell.read("Jog_Active"), "the jog to move the robot")
    browser.driver.execute_script("clearInterval(jog.timer)")                # the page's beat stops, button held
    cell.wait(lambda: cell.read("Jog_Dropped"), "the PLC to drop the jog", timeout=5)
    cell.wait(lambda: not cell.read("Jog_Busy") and not cell.state()["moving"], "the robot to stop", timeout=5)
    assert cell.read("Jog_Forward") is False and cell.read("Jog_Backward") is False
    browser.wait_for(lambda d: "stopped the jog because this page stopped answering" in browser.message(),
                     "the page to say why")
    ActionChains(browser.driver).release(button).perform()


def test_teach_stores_the_position_in_the_chosen_entry(cell):
    browser = cell.open()
    browser.driver.find_element(By.CSS_SELECTOR, "#teach-index option[value='5']").click()
    name = browser.driver.find_element(By.ID, "teach-name")
    name.clear()
    name.send_keys("Pick")
    browser.click("btn-teach")
    cell.wait(lambda: cell.read("TeachTable[5]")["Taught"], "the point to be taught")
    entry = cell.read("TeachTable[5]")
    tcp = cell.state()["tcp"]
    assert entry["Name"] == "Pick"
    assert [entry["Pose"][k] for k in ("X", "Y", "Z")] == pytest.approx(tcp[:3], abs=0.01)
    browser.wait_for(lambda d: d.find_elements(By.CSS_SELECTOR, "#teach-points tr")[4].text.startswith("5 Pick"),
                     "the table row to show the point")
    browser.wait_for(lambda d: "Teach: Done" in browser.message(), "Done on the message line")
    cell.wait(lambda: cell.read("Teach_Execute") is False, "the page to release Teach")
    browser.screenshot("jog_page_taught")


def test_a_taught_point_becomes_the_target_of_move_absolute_and_of_a_pnp_segment(cell):
    """Issue 26: the position table the Teach button fills is usable by the motion pages and the PnP segments —
    'Use as target' writes the point's TCP pose (or its joint angles where the target is in JPP_Abs)."""
    browser = cell.open()
    browser.driver.find_element(By.CSS_SELECTOR, "#teach-index option[value='6']").click()
    name = browser.driver.find_element(By.ID, "teach-name")
    name.clear()
    name.send_keys("Place")
    browser.click("btn-teach")
    cell.wait(lambda: cell.read("TeachTable[6]")["Taught"], "the point to be taught")
    cell.wait(lambda: cell.read("Teach_Execute") is False, "the page to release Teach")
    point = cell.read("TeachTable[6]")
    axes = ("X", "Y", "Z", "RX", "RY", "RZ")
    with cell.plc.lock:
        cell.plc.write("MoveAbs_Param.DataFormat", "CPP_Abs")
        cell.plc.write("PnP_MoveParameters[2].DataFormat", "JPP_Abs")
    for target, expected in (("MoveAbs_Param", point["Pose"]), ("PnP_MoveParameters[2]", point["Joints"])):
        browser.driver.find_element(By.CSS_SELECTOR, f"#teach-use-target option[value='{target}']").click()
        browser.click("btn-teach-use")
        browser.wait_for(lambda d: "Use point 6" in browser.message(), "the answer: " + browser.message())
        cell.wait(lambda target=target, expected=expected: [cell.read(f"{target}.TargetPosition")[k] for k in axes]
                  == pytest.approx([expected[k] for k in axes], abs=1e-3),
                  f"{target} to take the point: " + browser.message())
        browser.wait_for(lambda d: "Use point 6 'Place': now the target of" in browser.message(), "the message")
    browser.driver.find_element(By.CSS_SELECTOR, "#teach-index option[value='16']").click()
    browser.click("btn-teach-use")
    browser.wait_for(lambda d: "the point is not taught yet" in browser.message(), "the refusal of an empty point")
    browser.screenshot("jog_page_point_used")
