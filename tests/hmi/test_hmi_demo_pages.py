"""make demo --pages: a page described for the user's cell shows on Main under "Your cell" next to the shipped
pages, opens from its tile at 800x480 and keeps the header's Stop key in its place (the examples on the virtual
PLC, no robot needed). Screenshots: artifacts/screenshots/demo_pages_*.png."""
from __future__ import annotations

import pathlib

import pytest
from hmi_system import serving
from selenium.webdriver.common.by import By

from cbt_hmi.demo import with_user_pages
from cbt_hmi.web.mapping import Mapping
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGE = """{
  "title": "Gripper Cell",
  "status": [
    {"variable": "PnP_GripperClosed", "label": "Gripper closed"},
    {"variable": "PnP_CycleCount", "label": "Cycles done"}
  ]
}
"""


@pytest.fixture(scope="module")
def served(chromium, tmp_path_factory):
    folder = tmp_path_factory.mktemp("cell_pages")
    (folder / "gripper.json").write_text(PAGE)
    plc = load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")])
    mapping, errors = with_user_pages(Mapping.load(), plc, str(folder))
    assert errors == []
    mapping.check_against_plc(plc)
    with serving(plc, mapping) as server:
        yield server, chromium


def test_the_users_page_shows_beside_the_shipped_pages_and_opens_from_main(served):
    server, browser = served
    browser.open(server.page_url("index", "operator"))
    tile = browser.driver.find_element(By.ID, "nav-gripper")
    assert tile.text == "Gripper Cell"
    assert browser.driver.find_element(By.ID, "nav-pnp").is_displayed()           # the shipped tiles stay
    assert browser.viewport_overflow() == []
    stop_at = browser.driver.find_element(By.ID, "hdr-stop").rect
    browser.screenshot("demo_pages_main_operator_800x480")
    tile.click()
    browser.wait_for(lambda d: d.find_element(By.CSS_SELECTOR, "header h1").text == "Gripper Cell", "the user's page")
    browser.wait_for(lambda d: browser.status("PnP_CycleCount") == "0", "the live cycle count")
    assert browser.driver.find_element(By.ID, "hdr-stop").rect == stop_at
    browser.screenshot("demo_pages_gripper_operator_800x480")
