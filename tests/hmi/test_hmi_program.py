"""The HMI's Program page: the running ladder example (examples/Commands_Example.xml) drawn and coloured live
in headless Chromium at 800x480, against the virtual PLC in real time and the robot simulator."""
from __future__ import annotations

import pathlib
import threading

import pytest
from selenium.webdriver.common.by import By

from browser import chromium_paths
from hmi_http import Client
from tmsim.server import SimServer
from vplc.api import load_plc
from vplc.hmi.mapping import Mapping
from vplc.hmi.server import HmiServer

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = [str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")]

pytestmark = pytest.mark.skipif(chromium_paths() is None, reason="chromium/chromedriver: run `make browser`")


@pytest.fixture(scope="module")
def system(chromium):
    sim = SimServer(port=0, robots=1)
    sim.start_background()
    plc = load_plc(SOURCES)
    with plc.lock:
        plc.write("Connect_AddressIP", "127.0.0.1")
        plc.write("Connect_Dest_PortIP", sim.ports[0])
    stop = threading.Event()
    thread = threading.Thread(target=plc.run_realtime, args=(stop,), daemon=True)
    thread.start()
    hmi = HmiServer(plc, Mapping.load(), port=0)
    hmi.start()
    yield plc, hmi, chromium
    hmi.stop()
    stop.set()
    thread.join(timeout=5)
    plc.close()
    sim.close()


def on(browser, selector: str) -> bool:
    return browser.driver.execute_script(
        "const el = document.querySelector(arguments[0]); return !!el && el.classList.contains('on');", selector)


def element_id(browser, kind: str, var: str) -> str:
    return browser.driver.execute_script("""
        for (const g of document.querySelectorAll('g.el.' + arguments[0]))
          for (const t of g.querySelectorAll('text')) if (t.textContent === arguments[1]) return g.dataset.id;
        return null;""", kind, var)


def test_program_page_shows_the_ladder_live_and_scrolls_at_800x480(system):
    plc, hmi, browser = system
    browser.open(f"{hmi.url}program.html")
    d = browser.driver
    browser.wait_for(lambda _d: int(d.find_element(By.CSS_SELECTOR, "section[data-pou]").get_attribute("data-polls")
                                    or 0) > 2, "the ladder to be polled")
    assert len(d.find_elements(By.CSS_SELECTOR, "g.rung")) == 11, "one rung per command, Connect and status"
    holder = d.find_element(By.ID, "ladder")
    box = d.execute_script("const r = arguments[0].getBoundingClientRect(); return [r.right, r.bottom, "
                           "arguments[0].scrollHeight, arguments[0].clientHeight];", holder)
    assert box[0] <= 800 and box[1] <= 480 and box[2] > box[3], "the ladder scrolls inside the 800x480 panel"
    assert browser.viewport_overflow() in ([], ["ld"]) or all(x == "ld" for x in browser.viewport_overflow())
    browser.screenshot("program_idle")

    execute = element_id(browser, "contact", "Connect_Execute")
    connected = element_id(browser, "coil", "Connect_Connected")
    assert execute and connected
    assert not on(browser, f'[data-id="{execute}"]')
    with plc.lock:
        plc.write("Connect_Execute", True)
    browser.wait_for(lambda _d: on(browser, f'g[data-id="{execute}"]'), "the Execute contact to be energised")
    browser.wait_for(lambda _d: on(browser, f'g[data-id="{connected}"]'), "the Connected coil to be energised", 20)
    values = d.execute_script("return [...document.querySelectorAll('text.val')].filter(t => t.textContent)"
                              ".map(t => t.dataset.var + '=' + t.textContent)")
    assert "Connect_Execute=TRUE" in values and "Connect_Connected=TRUE" in values
    assert "Connect_Dest_PortIP=" + str(plc.read("Connect_Dest_PortIP")) in values
    d.execute_script("document.querySelector('g.rung[data-rung=\"10\"]').scrollIntoView()")
    browser.wait_for(lambda _d: True, "scroll")
    browser.screenshot("program_connected")


def test_program_api_refuses_an_unknown_program(system):
    _plc, hmi, _browser = system
    client = Client(f"http://127.0.0.1:{hmi.port}")
    status, body = client.json("/api/program/state?pou=Nope")
    assert status == 404 and "no ladder program named `Nope`" in body["error"]
