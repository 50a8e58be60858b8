"""The HMI in headless Chromium at 800x480 against a fake PLC: limits that follow the data format and come from the
library's range table, refused format/command combinations, Active/Paused/Stopping lamps, the robot view with its
target preview, the trail kept by the server, and the message line following the FB's outcome."""
from __future__ import annotations

import json
import math

import pytest
from browser import ROOT, Browser
from fake_plc import FakePlc, command_program, scanning, serving
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

from cbt_hmi.web.mapping import Mapping

TCP = {"X": 400.0, "Y": 0.0, "Z": 400.0, "RX": 180.0, "RY": 0.0, "RZ": 90.0}


@pytest.fixture(scope="module")
def stack(chromium):
    mapping = Mapping.load()
    with scanning(FakePlc(mapping, command_program)) as plc, serving(plc, mapping) as server:
        yield plc, server, chromium


@pytest.fixture
def page(stack):
    plc, server, browser = stack
    with plc.lock:
        plc.writes.clear()
        plc.vars["ReadPos_Valid"] = True
        plc.vars["ReadPos_Position"]["TCP"].update(TCP)
        for name in ("MoveAbs_Active", "Robot_Paused", "Robot_Stopping"):
            plc.vars[name] = False

    def open_page(name: str) -> Browser:
        browser.open(server.page_url(name, "engineer"))
        return browser
    return plc, server, open_page


def hint(browser, path):
    return browser.field(path).find_element(By.XPATH, "..").find_element(By.CLASS_NAME, "hint").text


def select(browser, path, text):
    Select(browser.field(path)).select_by_visible_text(text)


def test_speed_and_blending_hints_follow_the_data_format(page):
    _, _, open_page = page
    b = open_page("moveabs")
    select(b, "MoveAbs_Param.MovementCommand", "Line")
    select(b, "MoveAbs_Param.DataFormat", "CPP_Abs")
    assert hint(b, "MoveAbs_Param.Speed") == "1..100 %"
    assert hint(b, "MoveAbs_Param.BlendingValue") == "blending off"
    b.field("MoveAbs_Param.BlendingEnable").click()
    assert hint(b, "MoveAbs_Param.BlendingValue") == "0..100 %"
    select(b, "MoveAbs_Param.DataFormat", "CAR_Abs")
    assert hint(b, "MoveAbs_Param.Speed") == "1..4500 mm/s"
    assert hint(b, "MoveAbs_Param.BlendingValue") == "0..1000 mm"
    b.screenshot("limits_moveabs_car")


def test_a_value_refused_for_one_format_is_sent_for_another(page):
    plc, _, open_page = page
    b = open_page("moveabs")
    select(b, "MoveAbs_Param.MovementCommand", "Line")
    select(b, "MoveAbs_Param.DataFormat", "CPP_Abs")
    b.type_into("MoveAbs_Param.Speed", "150")
    b.click("btn-execute")
    b.wait_for(lambda d: "out of range" in b.message(), "the range error")
    assert "Speed: 150 is out of range 1..100 % (the FB would refuse it with 16#1013)" in b.message()
    assert plc.writes == []
    select(b, "MoveAbs_Param.DataFormat", "CAP_Abs")
    # a target it can reach
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (350, 0, 300, 180, 0, 90), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    b.click("btn-execute")
    b.wait_for(lambda d: ("MoveAbs_Execute", True) in plc.writes, "the command to be sent")
    assert ("MoveAbs_Param.Speed", 150) in plc.writes


def test_page_limits_are_the_library_range_table(page):
    """Inertia above 100000 kg·mm² is refused on the page as by CBT_ChangeTCP (the page used to take 1e9)."""
    plc, server, open_page = page
    table = json.loads((ROOT / "src" / "cbt_hmi" / "pages" / "ranges.json").read_text(encoding="utf-8"))
    leaves = server.mapping.leaves
    assert (leaves["ChangeTCP_Param.MomentOfInertia.Ixx"].min, leaves["ChangeTCP_Param.MomentOfInertia.Ixx"].max) == \
        (table["stCBT_TCParam"]["MomentOfInertia"][0]["min"], table["stCBT_TCParam"]["MomentOfInertia"][0]["max"])
    assert leaves["Connect_Time_Out"].max == table["CBT_Connect"]["Time_Out"][0]["max"]
    b = open_page("changetcp")
    b.type_into("ChangeTCP_Param.MomentOfInertia.Ixx", "1e9")
    b.click("btn-execute")
    b.wait_for(lambda d: "out of range" in b.message(), "the range error")
    assert "1000000000 is out of range 0..100000 kg·mm² (the FB would refuse it with 16#1021)" in b.message()
    assert plc.writes == []


@pytest.mark.parametrize("command, fmt, code", [("Line", "JPP_Rel", "16#1012"), ("PTP", "CAR_Rel", "16#1011")])
def test_format_the_fb_refuses_for_the_motion_command_is_refused_on_the_page(page, command, fmt, code):
    plc, _, open_page = page
    b = open_page("moverel")
    select(b, "MoveRel_Param.MovementCommand", command)
    select(b, "MoveRel_Param.DataFormat", fmt)
    assert "invalid" in b.field("MoveRel_Param.DataFormat").get_attribute("class")
    assert hint(b, "MoveRel_Param.DataFormat") == f"not for {command}"
    assert code in b.field("MoveRel_Param.DataFormat").get_attribute("title")
    b.type_into("MoveRel_Param.Speed", "10")
    b.click("btn-execute")
    b.wait_for(lambda d: "cannot be used" in b.message(), "the refusal")
    assert f"Data Format: {fmt} cannot be used with Motion Command {command}" in b.message()
    assert f"the FB would refuse it with {code}) — nothing was sent." in b.message()
    assert plc.writes == []
    b.screenshot(f"limits_moverel_refused_{command.lower()}")


def test_active_paused_and_stopping_lamps_show_the_plc_state(page):
    plc, _, open_page = page
    b = open_page("moveabs")
    def lamps():        # the three lamps' data-value in one round trip
        return b.driver.execute_script(
            "return [...document.querySelectorAll('.indicators .lamp')].map((e) => e.getAttribute('data-value'))")
    b.wait_for(lambda d: lamps() == ["false"] * 3, "the lamps off")
    with plc.lock:
        plc.vars["MoveAbs_Active"] = True
        plc.vars["Robot_Paused"] = True
    b.wait_for(lambda d: lamps() == ["true", "true", "false"], "Active and Paused on")
    with plc.lock:
        plc.vars["Robot_Stopping"] = True
    b.wait_for(lambda d: lamps() == ["true", "true", "true"], "Stopping on")
    assert [e.text for e in b.driver.find_elements(By.CSS_SELECTOR, ".indicators .lamp")] == \
        ["Active", "Paused", "Stopping"]
    b.screenshot("indicators_moveabs")


def preview_path(b):
    b.wait_for(lambda d: d.execute_script("return VIEW.preview && VIEW.preview.path && VIEW.preview.path.length > 0"),
               "the target preview")
    return b.driver.execute_script("return VIEW.preview.path")


def test_move_absolute_previews_the_entered_target_before_execute(page):
    plc, _, open_page = page
    b = open_page("moveabs")
    select(b, "MoveAbs_Param.MovementCommand", "PTP")
    select(b, "MoveAbs_Param.DataFormat", "CPP_Abs")
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (350, -150, 250, 180, 0, 90), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    path = preview_path(b)
    assert path[0] == [400, 0, 400] and path[-1] == [350, -150, 250]
    assert plc.writes == []                                   # previewed, nothing sent
    b.screenshot("preview_moveabs")


def test_move_relative_in_the_tool_frame_is_previewed_along_the_tool_axes(page):
    """TPP offsets are in the tool frame: with the tool pointing down (RX 180), +50 mm tool Z is 50 mm lower."""
    _, _, open_page = page
    b = open_page("moverel")
    select(b, "MoveRel_Param.MovementCommand", "Line")
    select(b, "MoveRel_Param.DataFormat", "TPP_Rel")
    for axis in ("X", "Y", "RX", "RY", "RZ"):
        b.type_into(f"MoveRel_Param.TargetPosition.{axis}", "0")
    b.type_into("MoveRel_Param.TargetPosition.Z", "50")
    end = preview_path(b)[-1]
    assert end == pytest.approx([400, 0, 350], abs=1e-6)
    select(b, "MoveRel_Param.DataFormat", "CPP_Rel")              # base offsets: 50 mm up
    b.wait_for(lambda d: d.execute_script("return VIEW.preview.path[1][2]") == pytest.approx(450), "base offset")
    b.screenshot("preview_moverel")


def test_move_circle_preview_is_the_arc_through_the_arc_point(page):
    _, _, open_page = page
    b = open_page("movecircle")
    for prefix, (x, y) in (("ArcPoint", (450, 50)), ("EndPoint", (400, 100))):
        for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (x, y, 400, 180, 0, 90), strict=False):
            b.type_into(f"MoveCircle_Param.{prefix}.{axis}", str(value))
    path = preview_path(b)
    assert path[0] == pytest.approx([400, 0, 400]) and path[-1] == pytest.approx([400, 100, 400])
    assert min(math.dist(p, [450, 50, 400]) for p in path) < 4         # passes the arc point
    b.screenshot("preview_movecircle")


def test_trail_is_kept_by_the_server_and_shown_by_a_page_opened_later(page):
    plc, server, open_page = page
    for k in range(5):
        with plc.lock:
            plc.vars["ReadPos_Position"]["TCP"].update(X=300.0 + 20 * k, Y=-100.0 + 10 * k)
        server.trail.sample()
    expected = [p[1:] for p in list(server.trail.points)[-5:]]
    b = open_page("index")
    b.wait_for(lambda d: d.execute_script("return VIEW.trail.length") >= 5, "the trail from the server")
    trail = b.driver.execute_script("return VIEW.trail")
    assert [tuple(p) for p in trail[-5:]] == [tuple(round(v, 2) for v in p) for p in expected]
    b.screenshot("trail_main")


def test_message_line_follows_the_fb_to_done(page):
    _, _, open_page = page
    b = open_page("changebase")
    b.click("btn-preset")
    b.click("btn-execute")
    b.wait_for(lambda d: "Done" in b.message(), "the FB's Done on the message line")
    assert b.message() == "Change Base: Done – the robot accepted the base; it applies to the motions queued after it."


@pytest.mark.parametrize("name", ["index", "connect", "changebase", "changetcp", "moverel", "moveabs", "movecircle",
                                  "setoutput", "stop", "pnp"])
def test_every_page_uses_the_panel_without_dead_space(page, name):
    """The lowest visible element of the content area ends near the message line: no empty third of a page."""
    _, _, open_page = page
    b = open_page(name)
    if name == "pnp":
        b.click("btn-preset")
        b.wait_for(lambda d: "Preset PnP cycle written" in b.message(), "the preset")
    gap = b.driver.execute_script("""
        const main = document.getElementById('main').getBoundingClientRect();
        let lowest = main.top;
        for (const el of document.querySelectorAll('#main fieldset, #main canvas, #main svg, #main .status, ' +
                                                   '#main .area, #main .robotview, #main .robot-status'))
          { const r = el.getBoundingClientRect(); if (r.height > 0) lowest = Math.max(lowest, r.bottom); }
        return main.bottom - lowest;""")
    assert gap < 24, f"{name}: {gap:.0f} px unused below the content"
    assert b.viewport_overflow() == []
    b.screenshot(f"page_{name}")
