"""The robot view and the reach check in headless Chromium at 800x480 and 1280x800 against a fake PLC: the TM5-700
arm data the browser uses is the simulator's (tm5_700.json against src/tmsim/robot/kinematics.py), the arm is drawn from
the joint angles read, a target the TM5-700 cannot reach is previewed in red and refused with its reason, angles and
joints have their own limits, the scale is fixed (zoom buttons, labelled grid) and every page shows the same axes."""
from __future__ import annotations

import json
import random

import pytest
from browser import ROOT
from fake_plc import FakePlc, command_program, scanning, serving
from panel_metrics import check_controls
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

from cbt_hmi.web.mapping import Mapping
from tmsim.robot import kinematics

ARM = json.loads((ROOT / "src" / "cbt_hmi" / "pages" / "tm5_700.json").read_text(encoding="utf-8"))
TCP = [400.0, 0.0, 400.0, 180.0, 0.0, 90.0]
JOINTS = kinematics.inverse_kinematics(kinematics.pose_to_matrix(TCP))
SIZES = [(800, 480), (1280, 800)]


def test_arm_data_is_the_simulators_kinematics():
    """One fact, one home: the browser's link lengths and joint ranges are those src/tmsim/robot/kinematics.py uses."""
    joints = ARM["joints"]
    assert [j["alpha"] for j in joints] == list(kinematics.ALPHA)
    assert [j["a"] for j in joints] == list(kinematics.A)
    assert [j["d"] for j in joints] == list(kinematics.D)
    assert [j["offset"] for j in joints] == list(kinematics.OFFSET)
    assert [j["limit"] for j in joints] == list(kinematics.LIMITS)
    assert ARM["home_joints"] == [0, 0, 90, 0, 90, 0]
    assert "kinematics.py" in ARM["source"] and ARM["reach_mm"] == 700


@pytest.fixture(scope="module")
def stack(chromium):
    mapping = Mapping.load()
    with scanning(FakePlc(mapping, command_program)) as plc, serving(plc, mapping) as server:
        yield plc, server, chromium
    chromium.fit()


@pytest.fixture
def page(stack):
    plc, server, browser = stack
    with plc.lock:
        plc.writes.clear()
        plc.vars["ReadPos_Valid"] = True
        plc.vars["ReadPos_Position"]["TCP"].update(dict(zip(("X", "Y", "Z", "RX", "RY", "RZ"), TCP, strict=False)))
        plc.vars["ReadPos_Position"]["Joints"] = list(JOINTS)

    def open_page(name: str, size=(800, 480)):
        browser.size(*size)
        browser.open(server.page_url(name, "engineer"))
        browser.wait_for(lambda _d: _d.execute_script("return ARM.data !== null"), "the arm data")
        return browser
    yield plc, server, open_page
    browser.fit()


def js(b, script, *args):
    return b.driver.execute_script(script, *args)


def test_the_browser_forward_model_is_the_simulators(page):
    _, _, open_page = page
    b = open_page("moveabs")
    rng = random.Random(7)
    for _ in range(20):
        q = [rng.uniform(-lim, lim) for lim in kinematics.LIMITS]
        flange = js(b, "return armFrames(arguments[0])[6]", q)
        expected = kinematics.forward(q)
        assert [v for row in flange for v in row] == pytest.approx([v for row in expected for v in row], abs=1e-6)


@pytest.mark.slow
def test_the_browser_reach_check_agrees_with_the_simulator(page):
    """Poses the simulator's inverse kinematics solves are accepted, the ones it refuses are refused (tool: none)."""
    plc, _, open_page = page
    b = open_page("moveabs")
    with plc.lock:
        plc.vars["ReadPos_Valid"] = False
    b.wait_for(lambda _d: js(b, "return live.values.ReadPos_Valid") is False, "the position invalid")
    rng = random.Random(11)
    poses = [[2000, 0, 300, 180, 0, 90], [0, 0, 1200, 180, 0, 0], [30, 20, 400, 180, 0, 90]]
    poses += [[rng.uniform(-950, 950), rng.uniform(-950, 950), rng.uniform(-600, 1100),
               rng.uniform(-180, 180), rng.uniform(-90, 90), rng.uniform(-180, 180)] for _ in range(150)]
    # every pose checked by the page in one round trip
    results = js(b, "return arguments[0].map((p) => reachCheck({X: p[0], Y: p[1], Z: p[2], RX: p[3], RY: p[4], "
                    "RZ: p[5]}))", poses)
    agree = 0
    for pose, result in zip(poses, results, strict=True):
        try:
            kinematics.inverse_kinematics(kinematics.pose_to_matrix(pose))
            reachable = True
        except kinematics.KinematicsError:
            reachable = False
        assert ("reason" not in result) == reachable, (pose, result)
        agree += 1
    assert agree == len(poses)
    assert sum(1 for result in results if "reason" in result) > 10


def red_pixels(b, canvas_id):
    return js(b, """const c = document.getElementById(arguments[0]), d = c.getContext('2d')
        .getImageData(0, 0, c.width, c.height).data; let n = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] > 170 && d[i + 1] < 70 && d[i + 2] < 60) n++;
        return n;""", canvas_id)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_an_unreachable_target_is_previewed_in_red_and_refused_with_its_reason(page, size):
    plc, _, open_page = page
    b = open_page("moveabs", size)
    Select(b.field("MoveAbs_Param.MovementCommand")).select_by_visible_text("PTP")
    Select(b.field("MoveAbs_Param.DataFormat")).select_by_visible_text("CPP_Abs")
    b.type_into("MoveAbs_Param.Speed", "10")
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (2000, 0, 300, 180, 0, 90), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    b.wait_for(lambda _d: js(b, "return !!(VIEW.preview && VIEW.preview.refused)"), "the refused preview")
    refused_red = red_pixels(b, "view-top")
    note = b.driver.find_element(By.ID, "view-note")
    assert "out of reach" in note.text and "refused" in note.get_attribute("class")
    assert red_pixels(b, "view-top") > 30 and red_pixels(b, "view-side") > 30, "the target is drawn red"
    b.screenshot(f"reach_refused_moveabs_{size[0]}x{size[1]}")
    b.click("btn-execute")
    b.wait_for(lambda _d: "nothing was sent" in b.message(), "the refusal")
    assert b.message().startswith("Target Position: X 2000 Y 0 Z 300 is out of reach: the wrist would be")
    assert "the TM5-700 reaches 869 mm (rated reach 700 mm) — nothing was sent." in b.message()
    assert "invalid" in b.field("MoveAbs_Param.TargetPosition.X").get_attribute("class")
    assert plc.writes == []
    b.type_into("MoveAbs_Param.TargetPosition.X", "350")          # reachable: violet, the arm where it will be
    b.wait_for(lambda _d: js(b, "return !VIEW.preview.refused && !!VIEW.preview.arm"), "the reachable preview")
    assert red_pixels(b, "view-top") < refused_red - 30, "no red target any more (the red left is the X axes)"
    b.click("btn-execute")
    b.wait_for(lambda _d: ("MoveAbs_Execute", True) in plc.writes, "the command to be sent")
    assert ("MoveAbs_Param.TargetPosition.X", 350) in plc.writes


def test_joints_and_angles_have_their_own_limits(page):
    plc, _, open_page = page
    b = open_page("moveabs")
    Select(b.field("MoveAbs_Param.MovementCommand")).select_by_visible_text("PTP")
    Select(b.field("MoveAbs_Param.DataFormat")).select_by_visible_text("JPP_Abs")
    b.type_into("MoveAbs_Param.Speed", "10")
    labels = [e.text for e in
              b.driver.find_elements(By.CSS_SELECTOR, 'fieldset.pose[data-member="TargetPosition"] label')]
    assert labels == ["J1", "J2", "J3", "J4", "J5", "J6"]
    legend = b.driver.find_element(By.CSS_SELECTOR, 'fieldset.pose[data-member="TargetPosition"] legend').text
    assert "±270 ±180 ±155 ±180 ±180 ±270" in legend
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (0, 0, 170, 0, 90, 0), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    b.click("btn-execute")
    b.wait_for(lambda _d: "nothing was sent" in b.message(), "the refusal")
    assert b.message() == "Target Position J3: 170° is out of range -155..155° for the TM5-700 — nothing was sent."
    Select(b.field("MoveAbs_Param.DataFormat")).select_by_visible_text("CPP_Abs")
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (350, 0, 300, 400, 0, 90), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    legend = b.driver.find_element(By.CSS_SELECTOR, 'fieldset.pose[data-member="TargetPosition"] legend')
    assert "RX RY RZ ±360°" in legend.text
    b.click("btn-execute")
    b.wait_for(lambda _d: "RX: 400° is out of range" in b.message(), "the angle refusal")
    assert plc.writes == []


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_fixed_scale_zoom_buttons_labelled_grid_and_the_arm(page, size):
    _, _, open_page = page
    b = open_page("moveabs", size)
    scale = lambda: float(b.driver.find_element(By.ID, "view-top").get_attribute("data-scale"))  # noqa: E731
    span = lambda: js(b, "const c = document.getElementById('view-top'); "          # noqa: E731
                         "return Math.min(c.width, c.height) / Number(c.dataset.scale)")
    assert span() == pytest.approx(1800)                        # mm across the narrower side at 1x
    Select(b.field("MoveAbs_Param.MovementCommand")).select_by_visible_text("PTP")
    Select(b.field("MoveAbs_Param.DataFormat")).select_by_visible_text("CPP_Abs")
    for axis, value in zip(("Y", "Z", "RX", "RY", "RZ"), (0, 300, 180, 0, 90), strict=False):
        b.type_into(f"MoveAbs_Param.TargetPosition.{axis}", str(value))
    b.type_into("MoveAbs_Param.TargetPosition.X", "650")        # typing does not re-zoom the view
    b.wait_for(lambda _d: js(b, "return !!VIEW.preview && !!VIEW.preview.path"), "the preview")
    assert span() == pytest.approx(1800)
    before = scale()
    for button in ("zoom-in", "zoom-out"):
        r = b.driver.find_element(By.ID, button).rect
        assert r["width"] >= 34 and r["height"] >= 34, (button, r)
    b.click("zoom-in")
    assert scale() == pytest.approx(2 * before)
    assert b.driver.find_element(By.ID, "zoom-level").text == "2×"
    b.click("zoom-out")
    assert scale() == pytest.approx(before)
    grid = float(b.driver.find_element(By.ID, "view-top").get_attribute("data-grid"))
    assert grid in (100, 200, 500)
    arm = json.loads(b.driver.find_element(By.ID, "view-side").get_attribute("data-arm"))
    assert len(arm) == 8, "base, six joint frames and the TCP"
    frames = kinematics.link_frames(JOINTS)
    side = b.driver.find_element(By.ID, "view-side")
    s, w, h = scale(), side.get_attribute("width"), side.get_attribute("height")
    for (px, py), f in zip(arm[1:7], frames[1:], strict=False):   # drawn where the simulator puts the joints (Y-Z)
        assert px == pytest.approx(int(w) / 2 + f[1][3] * s, abs=1)
        assert py == pytest.approx(int(h) / 2 - (f[2][3] - 350) * s, abs=1)
    font = js(b, "return parseFloat(getComputedStyle(document.querySelector('.viewfoot')).fontSize)")
    assert font >= 14
    b.screenshot(f"robotview_arm_{size[0]}x{size[1]}")


def axes(b, name):
    if name == "pnp":
        b.wait_for(lambda _d: b.driver.find_element(By.ID, "pnp-svg").get_attribute("data-axes"), "the PnP drawing")
        return [b.driver.find_element(By.ID, "pnp-svg").get_attribute("data-axes")]
    b.wait_for(lambda _d: js(b, "return !!document.querySelector('.views canvas[data-axes]')"), "the view drawn")
    return [c.get_attribute("data-axes") for c in b.driver.find_elements(By.CSS_SELECTOR, ".views canvas")]


def pnp_example_cycle(plc):
    """The PnP example's cycle: pick and place 400 mm apart along Y; Line, CPP_Abs, 30 %."""
    with plc.lock:
        for i, (y, z) in enumerate([(-200, 400), (-200, 250), (-200, 400), (200, 400), (200, 250), (200, 400)]):
            plc.vars["PnP_MoveParameters"][i].update(MovementCommand=0, DataFormat=1, Speed=30)
            plc.vars["PnP_MoveParameters"][i]["TargetPosition"].update(X=350.0, Y=float(y), Z=float(z), RX=180.0,
                                                                       RZ=90.0)


PAGES_WITH_VIEWS = ["index", "connect", "changebase", "moverel", "moveabs", "movecircle", "setoutput", "stop", "pnp"]


@pytest.mark.slow
def test_every_page_shows_the_same_axes_and_a_switch_holds_for_every_page(page):
    """Top X-Y and side Y-Z everywhere, the PnP drawing included; X-Z chosen on one page is X-Z on all of them."""
    plc, _, open_page = page
    pnp_example_cycle(plc)
    for name in PAGES_WITH_VIEWS:
        b = open_page(name)
        assert axes(b, name) == (["Y-Z"] if name == "pnp" else ["X-Y", "Y-Z"]), name
    r = b.driver.find_element(By.ID, "pnp-side").rect
    assert r["width"] >= 34 and r["height"] >= 34
    b.click("pnp-side")
    b.wait_for(lambda _d: axes(b, "pnp") == ["X-Z"], "the PnP drawing in X-Z")
    assert "press Y–Z view" in b.driver.find_element(By.ID, "pnp-note").text     # the cycle is seen edge-on
    b.screenshot("pnp_side_xz")
    try:
        for name in PAGES_WITH_VIEWS:
            b = open_page(name)
            assert axes(b, name) == (["X-Z"] if name == "pnp" else ["X-Y", "X-Z"]), name
        b = open_page("moveabs")
        b.click("side-axis")
        assert axes(b, "moveabs") == ["X-Y", "Y-Z"]
    finally:
        js(b, "sessionStorage.removeItem('hmi.side')")


def test_move_relative_and_a_pnp_segment_are_refused_out_of_reach(page):
    plc, _, open_page = page
    b = open_page("moverel")
    Select(b.field("MoveRel_Param.MovementCommand")).select_by_visible_text("Line")
    Select(b.field("MoveRel_Param.DataFormat")).select_by_visible_text("CPP_Rel")
    b.type_into("MoveRel_Param.Speed", "10")
    # 400 + 900 mm along X
    for axis, value in zip(("X", "Y", "Z", "RX", "RY", "RZ"), (900, 0, 0, 0, 0, 0), strict=False):
        b.type_into(f"MoveRel_Param.TargetPosition.{axis}", str(value))
    b.wait_for(lambda _d: js(b, "return !!(VIEW.preview && VIEW.preview.refused)"), "the refused preview")
    b.click("btn-execute")
    b.wait_for(lambda _d: "nothing was sent" in b.message(), "the refusal")
    assert b.message().startswith("Target Position: X 1300 Y 0 Z 400 is out of reach")
    assert plc.writes == []
    b.screenshot("reach_refused_moverel")
    pnp_example_cycle(plc)
    b = open_page("pnp")
    b.wait_for(lambda _d: b.driver.find_elements(By.ID, "edit-1"), "the segments")
    b.click("edit-1")
    b.type_into("PnP_MoveParameters[1].TargetPosition.X", "1500")
    b.click("seg-apply")
    b.wait_for(lambda _d: "nothing was sent" in b.message(), "the refusal")
    assert b.message().startswith("Target Position: X 1500")
    assert "out of reach" in b.message() and plc.writes == []
    js(b, "document.getElementById('seg-dialog').close()")



@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_view_controls_fit_a_finger_and_read_on_the_panel(page, size):
    _, _, open_page = page
    b = open_page("moveabs", size)
    check_controls(b, ["zoom-in", "zoom-out", "side-axis"])
    texts = b.driver.execute_script("return ['tcp-pos', 'view-note', 'zoom-level'].map((id) => "
                                    "parseFloat(getComputedStyle(document.getElementById(id)).fontSize))")
    assert min(texts) >= 14
    b = open_page("pnp", size)
    b.wait_for(lambda _d: b.text("pnp-side"), "the PnP drawing")
    check_controls(b, ["pnp-side"])
