"""Issue 25 item 2: one Stop key in the same place on every page, the only red key, that sends the stop at once
through the PLC's CBT_Stop instance, for the operator too. Headless Chromium at 800x480 -> HMI server -> the
examples on the virtual PLC in real time -> the robot simulator; the simulator's event log is the witness.
Screenshots: artifacts/screenshots/stopkey_*.png."""
from __future__ import annotations

import time

import pytest
from hmi_system import DWELL_NS, MOVE_WAIT_S, System

PAGES = ["index", "connect", "changebase", "changetcp", "moverel", "moveabs", "movecircle", "setoutput", "stop",
         "pnp", "jog", "program"]
RED_KEYS = """
    const rgb = (c) => (c.match(/[\\d.]+/g) || []).map(Number);
    const out = [];
    for (const el of document.querySelectorAll("button, a")) {
      if (!el.getClientRects().length) continue;
      const [r, g, b] = rgb(getComputedStyle(el).backgroundColor);
      if (r - Math.max(g, b) > 60) out.push(el.id || el.textContent.trim());
    }
    return out;"""


@pytest.fixture(scope="module")
def connected(chromium):
    system = System(chromium)
    browser = system.open("connect")
    browser.type_into("Connect_Dest_PortIP", str(system.sim.ports[0]))
    browser.click("btn-execute")
    browser.wait_status("Connect_Connected", "true")
    yield system
    system.close()


def open_as_operator(system, page: str):
    system.browser.open(system.hmi.page_url(page, "operator"))
    return system.browser


def stop_key_rect(browser) -> dict:
    return browser.driver.execute_script(
        "const r = document.getElementById('hdr-stop').getBoundingClientRect();"
        "return {x: r.x, y: r.y, w: r.width, h: r.height};")


def test_the_stop_key_is_in_the_same_place_on_every_page_and_the_only_red_key(connected):
    places = {}
    for page in PAGES:
        browser = open_as_operator(connected, page)
        key = browser.driver.find_element("id", "hdr-stop")
        assert key.is_enabled() and "Stop" in key.text, page
        places[page] = stop_key_rect(browser)
        assert places[page]["w"] >= 34 and places[page]["h"] >= 34, (page, places[page])
        assert places[page]["x"] + places[page]["w"] <= 800 and places[page]["y"] >= 0, (page, places[page])
        assert browser.driver.execute_script(RED_KEYS) == ["hdr-stop"], page
        browser.screenshot(f"stopkey_{page}_operator_800x480")
    assert len({tuple(rect.values()) for rect in places.values()}) == 1, places


def start_slow_move(system):
    """A 1 % move as the engineer sets it up, so it still runs when the stop arrives."""
    browser = system.open("moveabs")
    browser.click("btn-preset")
    for axis, value in zip(("X", "Y", "Z", "Speed"), ("300", "250", "300", "1"), strict=False):
        browser.type_into(f"MoveAbs_Param.{'' if axis == 'Speed' else 'TargetPosition.'}{axis}", value)
    browser.click("btn-execute")
    system.wait(lambda: system.robot_state()["moving"], "the slow move to start")


def press_the_stop_key(system, page: str):
    browser = open_as_operator(system, page)
    since = system.event_count()
    browser.click("hdr-stop")
    browser.wait_for(lambda d: "Stop: Done" in browser.message(), "the stop's answer", timeout=MOVE_WAIT_S)
    assert [e["command"] for e in system.events("priority", since)] == ["StopAndClearBuffer(0)"]
    system.wait(lambda: not system.read("Stop_Execute"), "the page to release Stop")
    assert browser.message() == "Stop: Done – the robot stopped and its queue is cleared."
    return browser


def test_the_stop_key_stops_a_running_move_as_operator(connected):
    start_slow_move(connected)
    browser = press_the_stop_key(connected, "index")
    connected.wait(lambda: connected.read("MoveAbs_CommandAborted"), "the move to be aborted")
    browser.screenshot("stopkey_move_stopped_operator")
    state = connected.robot_state()
    assert not state["moving"] and state["queue_length"] == 0
    assert state["tcp"][:3] != pytest.approx([300, 250, 300], abs=1.0)       # the motion ended early
    mark = connected.event_count()
    time.sleep(1.0)                                                          # 4 s of robot time
    assert connected.events("motion_start", mark) == [], "a motion started after the stop"
    # the Stop page's "Stop and Discard All" acts as well: it sends the stop with its mode when pressed
    browser = open_as_operator(connected, "stop")
    since = connected.event_count()
    browser.click("btn-preset-2")
    browser.wait_for(lambda d: "Stop and Discard All: Done" in browser.message(), "the stop's answer",
                     timeout=MOVE_WAIT_S)
    assert connected.events("priority", since), "no stop reached the robot"
    assert connected.read("Stop_Param")["Mode"] == "StopDiscardAll"
    connected.wait(lambda: not connected.read("Stop_Execute"), "the page to release Stop")


def test_the_stop_key_latches_the_pnp_cycle(connected):
    browser = connected.open("pnp")
    browser.click("btn-preset")
    browser.wait_for(lambda d: "Preset PnP cycle written" in browser.message(), "the preset")
    with connected.plc.lock:
        connected.plc.write("PnP_DwellTime", DWELL_NS)
        connected.plc.write("PnP_MoveParameters[4].Speed", 2)      # a slow place move: a sure window for the stop
    browser.click("btn-execute")
    target = connected.read("PnP_MoveParameters")[4]["TargetPosition"]["Z"]
    connected.wait(lambda: connected.read("PnP_Segment") == 4 and connected.robot_state()["moving"]
                   and connected.robot_state()["tcp"][2] < target + 100, "the slow place move")
    browser = press_the_stop_key(connected, "pnp")
    connected.wait(lambda: connected.read("PnP_State") == "Stopped", "the latched stop")
    mark = connected.event_count()
    time.sleep(2.0)                                                          # 8 s of robot time after the release
    assert connected.events("motion_start", mark) == [], "the robot moved again by itself"
    assert not connected.robot_state()["moving"] and connected.read("PnP_State") == "Stopped"
    browser.wait_for(lambda d: "Cycle: Stopped" in browser.text("pnp-state"), "Stopped on the page")
    browser.screenshot("stopkey_pnp_stopped_operator")
    with connected.plc.lock:
        connected.plc.write("PnP_MoveParameters[4].Speed", 30)
    browser = connected.open("pnp")                                          # leave the cycle Idle
    browser.click("btn-execute")
    connected.wait(lambda: connected.events("motion_start", mark), "the robot to move after Start")
    browser.wait_for(lambda d: d.find_element("id", "btn-stop").is_enabled(), "End Cycle offered")
    browser.click("btn-stop")
    connected.wait(lambda: connected.read("PnP_State") == "Idle", "the cycle to end", timeout=60)
