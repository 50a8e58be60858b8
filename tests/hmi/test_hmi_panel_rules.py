"""Every HMI page in headless Chromium at 800x480 (the 9-inch panel) and 1280x800 (a 12-inch panel), as engineer and
as operator, against a fake PLC: controls at least 34x34 px, text at least 14 px, contrast at least 4.5:1
(STYLE.md, HMI), the panel filling the screen without black bands, and grey for every normal state (ISA-101).
The screenshots go to artifacts/screenshots/panel_<page>_<role>_<size>.png."""
from __future__ import annotations

import pytest
from browser import SHOWN_TEXT
from fake_plc import FakePlc, command_program, scanning, serving
from panel_metrics import cut_texts, page_metrics

from cbt_hmi.web.mapping import Mapping

PAGES = ["index", "connect", "changebase", "changetcp", "moverel", "moveabs", "movecircle", "setoutput", "stop",
         "pnp", "jog"]
SIZES = [(800, 480), (1280, 800)]

# the chroma (max - min of R, G, B) above which a background counts as coloured rather than grey
GREY_CHROMA = 40
NORMAL_STATE_ELEMENTS = ("#pill-role, #pill-robot, #pill-plc, #message, header a.menu, .area .tiles a, "
                         "button:not(#hdr-stop), .lamp, .led")

COLOURS = """
    const rgba = (c) => (c.match(/[\\d.]+/g) || []).map(Number);
    const out = [];
    for (const el of document.querySelectorAll(arguments[0])) {
      if (!el.getClientRects().length) continue;
      const c = rgba(getComputedStyle(el).backgroundColor);
      if (c.length > 3 && c[3] === 0) continue;
      const chroma = Math.max(c[0], c[1], c[2]) - Math.min(c[0], c[1], c[2]);
      if (chroma > arguments[1]) out.push([el.id || el.className || el.tagName, el.textContent.trim().slice(0, 30),
        getComputedStyle(el).backgroundColor]);
    }
    return out;"""


@pytest.fixture(scope="module")
def stack(chromium):
    mapping = Mapping.load()
    with scanning(FakePlc(mapping, command_program)) as plc, serving(plc, mapping) as server:
        with plc.lock:                 # a robot in its normal state: connected, in its Listen node, project running
            plc.vars["Connect_Execute"] = True
            plc.vars["Robot_InListenNode"] = True
            plc.vars["ReadPos_Valid"] = True
            plc.vars["RobotStatus_Valid"] = True
            plc.vars["RobotStatus"]["ProjectRunning"] = True
        yield plc, server, chromium
    chromium.fit()


def open_sized(stack, name: str, role: str, size):
    """``name`` loaded afresh (Browser.open) as ``role`` in a viewport of ``size``."""
    _, server, browser = stack
    d = browser.driver
    browser.size(*size)
    browser.open(server.page_url(name, role))
    role_shown, *viewport = d.execute_script(SHOWN_TEXT + "return [shown(document.getElementById('pill-role')), "
                                                          "innerWidth, innerHeight]")
    assert role_shown == role.capitalize(), role_shown
    assert viewport == list(size)
    return browser


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
@pytest.mark.parametrize("role", ["engineer", "operator"])
@pytest.mark.parametrize("name", PAGES)
def test_every_page_meets_the_panel_rules(stack, name, role, size):
    browser = open_sized(stack, name, role, size)
    browser.wait_for(lambda d: d.execute_script("return document.querySelectorAll('[data-status]').length > 0"),
                     "the page's status values")
    browser.screenshot(f"panel_{name}_{role}_{size[0]}x{size[1]}")
    found = page_metrics(browser)
    assert found["small"] == [], f"controls under 34x34 px: {found['small']}"
    assert found["text"] == [], f"text under 14 px: {found['text']}"
    assert found["contrast"] == [], f"contrast under 4.5:1: {found['contrast']}"
    assert browser.viewport_overflow() == []


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
def test_the_panel_fills_the_screen_and_its_text_grows_with_it(stack, size):
    browser = open_sized(stack, "moveabs", "engineer", size)
    panel, body_px = browser.driver.execute_script(
        "const r = document.querySelector('.panel').getBoundingClientRect();"
        "return [[r.left, r.top, r.width, r.height], parseFloat(getComputedStyle(document.querySelector("
        "'.field label')).fontSize) * (parseFloat(getComputedStyle(document.querySelector('.panel')).zoom) || 1)]")
    assert [round(v) for v in panel] == [0, 0, size[0], size[1]]          # no black bands
    # 9-inch 800x480: 4.1 px/mm; 12.1-inch 1280x800: 4.9 px/mm. The same text in mm is 1.2 times the pixels.
    assert body_px >= (14 if size[0] == 800 else 16.8)


@pytest.mark.parametrize("name", ["index", "connect", "moveabs", "pnp"])
def test_normal_states_are_grey(stack, name):
    """Robot connected and in its Listen node, PLC online, operator logged in, a command done: nothing is coloured
    (ISA-101). Only the header's Stop key keeps its red."""
    browser = open_sized(stack, name, "operator", (800, 480))
    browser.wait_for(lambda d: browser.text("pill-robot") == "Robot ready", "the robot state")
    browser.driver.execute_script("message('Move Absolute: Done – the robot arrived at the target.', 'ok')")
    assert browser.driver.execute_script(COLOURS, NORMAL_STATE_ELEMENTS, GREY_CHROMA) == []


@pytest.fixture(scope="module")
def ladder_stack(chromium):
    """The Program page needs the real ladder example: the examples on the virtual PLC (no robot needed)."""
    import pathlib

    from hmi_system import serving

    from vplc.api import load_plc
    root = pathlib.Path(__file__).resolve().parents[2]
    plc = load_plc([str(root / "lib" / "CBT_Commands_Lib"), str(root / "examples")])
    with serving(plc, Mapping.load()) as server:
        yield plc, server, chromium
    chromium.fit()


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
def test_the_program_page_meets_the_panel_rules(ladder_stack, size):
    """The rung bar, the zoom keys and the rung headings; the ladder drawing's own text has the zoom keys."""
    browser = open_sized(ladder_stack, "program", "operator", size)
    browser.wait_for(lambda d: d.execute_script("return document.querySelector('.ladder svg') !== null"),
                     "the ladder drawing")
    browser.screenshot(f"panel_program_operator_{size[0]}x{size[1]}")
    found = page_metrics(browser, zoomable=".ladder svg")
    assert found == {"small": [], "text": [], "contrast": []}, found


def test_disabled_fields_and_keys_look_disabled(stack):
    """Fields, check boxes and keys the operator may not use: flat grey with a dashed border (a check box: a dashed
    outline and a grey label), text still readable (the issue: disabled fields looked editable)."""
    browser = open_sized(stack, "setoutput", "operator", (800, 480))
    looks = browser.driver.execute_script("""
        const look = (el) => { const s = getComputedStyle(el);
          return [el.disabled, s.backgroundColor, s.borderTopStyle]; };
        const box = document.querySelector('[data-path="SetOutput_Param.ExitNode"]');
        return [[look(document.querySelector('[data-path="SetOutput_Param.Module"]')),
                 look(document.getElementById('btn-execute'))],
                [box.disabled, getComputedStyle(box).outlineStyle, getComputedStyle(box.nextElementSibling).color]];""")
    for disabled, background, border in looks[0]:
        assert disabled and background == "rgb(227, 231, 235)" and border == "dashed", (disabled, background, border)
    assert looks[1] == [True, "dashed", "rgb(80, 91, 102)"]             # a check box: dashed outline, grey label
    browser = open_sized(stack, "setoutput", "engineer", (800, 480))
    disabled, background, border = browser.driver.execute_script(
        "const el = document.querySelector('[data-path=\"SetOutput_Param.Module\"]'), s = getComputedStyle(el);"
        "return [el.disabled, s.backgroundColor, s.borderTopStyle];")
    assert not disabled and background == "rgb(255, 255, 255)" and border == "solid"


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
@pytest.mark.parametrize("name", PAGES)
def test_no_label_or_value_is_cut(stack, name, size):
    """Every label and value an operator needs reads whole: nothing cut with "…" or hidden past its box ("Motion
    Comma…", "Safety / mo…", "CBT Commands – …" were); the alarm banner's line shows the whole alarm when tapped."""
    browser = open_sized(stack, name, "engineer", size)
    browser.wait_for(lambda d: d.execute_script("return document.querySelectorAll('[data-status]').length > 0"),
                     "the page's status values")
    browser.wait_for(lambda d: cut_texts(browser) == [], f"every text whole: {cut_texts(browser)}")


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
def test_the_ladder_drawing_reads_at_the_panels_body_text_size(ladder_stack, size):
    """At the Program page's 100 % every text of the ladder drawing (names, pins, values, comments) is at least
    14 px: 100 % is the panel's reading size; 60 % and 80 % are the operator's overview."""
    browser = open_sized(ladder_stack, "program", "operator", size)
    browser.driver.execute_script("sessionStorage.removeItem('hmi.ladderZoom')")
    browser.driver.refresh()
    browser.wait_for(lambda d: d.execute_script("return document.querySelector('.ladder svg') !== null"),
                     "the ladder drawing")
    assert browser.text("ladder-zoom") == "100 %"
    browser.screenshot(f"panel_program_100_{size[0]}x{size[1]}")
    found = page_metrics(browser)
    assert found == {"small": [], "text": [], "contrast": []}, found
    assert cut_texts(browser) == []                   # the title beside "Robot not connected" too


@pytest.mark.parametrize("size", SIZES, ids=["800x480", "1280x800"])
def test_the_pnp_segment_dialog_cuts_no_label(stack, size):
    """The segment dialog (a CBT_MoveAbsolute parameter structure, laid out only when it opens) keeps its labels whole
    and its controls at panel size."""
    browser = open_sized(stack, "pnp", "engineer", size)
    browser.wait_for(lambda d: d.execute_script("return document.getElementById('edit-0') !== null"), "the drawing")
    browser.driver.execute_script("document.getElementById('edit-0').onclick()")
    browser.wait_for(lambda d: d.execute_script("return document.getElementById('seg-dialog').open"), "the dialog")
    browser.wait_for(lambda d: cut_texts(browser) == [], f"every text whole: {cut_texts(browser)}")
    browser.screenshot(f"panel_pnp_segment_{size[0]}x{size[1]}")
    found = page_metrics(browser)
    assert found == {"small": [], "text": [], "contrast": []}, found
