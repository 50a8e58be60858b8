"""The HMI's Program page: the running ladder example (examples/Commands_Example.xml) drawn and coloured live
in headless Chromium at 800x480 (and 1280x800), against the virtual PLC in real time and the robot simulator: rung
list and jump, zoom, whole comments, 16# values, no text over another, boxes apart, coils at the right rail."""
from __future__ import annotations

import pathlib

import pytest
from browser import chromium_paths
from hmi_http import Client
from hmi_system import serving
from panel_metrics import check_controls
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

from cbt_hmi.web.mapping import Mapping
from tmsim.net.server import SimServer
from vplc.api import load_plc

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
    with serving(plc, Mapping.load()) as hmi:
        yield plc, hmi, chromium
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


def text_overlaps(browser) -> list:
    """Pairs of drawn texts whose boxes overlap, measured in the browser (values included)."""
    return browser.driver.execute_script("""
        const boxes = [...document.querySelectorAll('#ladder text')].filter(t => t.textContent.trim())
          .map(t => [t.textContent, t.getBoundingClientRect()]);
        const out = [];
        for (let i = 0; i < boxes.length; i++) for (let j = i + 1; j < boxes.length; j++) {
          const [a, r] = boxes[i], [b, s] = boxes[j];
          if (r.left < s.right - 1 && s.left < r.right - 1 && r.top < s.bottom - 1 && s.top < r.bottom - 1)
            out.push([a, b]);
        }
        return out;""")


@pytest.mark.parametrize("size", [(800, 480), (1280, 800)], ids=["800x480", "1280x800"])
def test_ladder_monitor_rung_list_zoom_whole_comments_hex_values_and_no_overlap(system, size):
    plc, hmi, browser = system
    d = browser.driver
    browser.size(*size)
    try:
        browser.open(f"{hmi.url}program.html")
        browser.wait_for(lambda _d: int(d.find_element(By.CSS_SELECTOR, "section[data-pou]").get_attribute("data-polls")
                                        or 0) > 2, "the ladder to be polled")
        with plc.lock:
            plc.write("Connect_Execute", True)
        browser.wait_for(lambda _d: any(t.startswith("16#") for t in d.execute_script(
            "return [...document.querySelectorAll('text.val')].map(t => t.textContent)")), "a WORD value")
        values = d.execute_script("return Object.fromEntries([...document.querySelectorAll('text.val')]"
                                  ".filter(t => t.textContent).map(t => [t.dataset.var, t.dataset.full]))")
        words = {k: v for k, v in values.items() if k.endswith("ErrorID")}
        assert words and all(v.startswith("16#") and len(v) == 7 for v in words.values()), words
        # every rung in the list; choosing one scrolls it to the top of the view
        options = d.execute_script("return [...document.querySelectorAll('#rung-jump option')].map(o => o.text)")
        assert len(options) == 11 and options[0].startswith("Commands_Example 1") is False
        assert options[0].startswith("1")
        Select(d.find_element(By.ID, "rung-jump")).select_by_index(7)
        top = d.execute_script("""const h = document.getElementById('ladder').getBoundingClientRect().top;
            return document.querySelector('g.rung[data-rung="8"]').getBoundingClientRect().top - h;""")
        assert 0 <= top <= 60
        # the whole comments, wrapped (the drawing alone cuts them with an ellipsis)
        api = Client(f"http://127.0.0.1:{hmi.port}").json("/api/program")[1]
        comments = [r["comment"] for r in api["programs"][0]["rungs"]]
        drawn = d.execute_script("return [...document.querySelectorAll('g.rung')].map(g => { const c = g.querySelector("
                                 "'text.cmt'); return c ? [...c.querySelectorAll('tspan')].map(t => t.textContent)"
                                 ".join(' ') : ''; })")
        assert drawn == [" ".join(c.split()) for c in comments]
        assert not any("…" in t for t in drawn)
        assert text_overlaps(browser) == [], "no text covers another"
        check_controls(browser, ["rung-jump", "ladder-in", "ladder-out"])
        width = float(d.find_element(By.CSS_SELECTOR, "svg.ld").get_attribute("width"))
        d.find_element(By.ID, "ladder-in").click()
        zoomed = float(d.find_element(By.CSS_SELECTOR, "svg.ld").get_attribute("width"))
        assert zoomed == pytest.approx(width * 1.3, abs=1)
        small = d.execute_script("return Math.min(...[...document.querySelectorAll('#ladder text')].filter(t => "
                                 "t.textContent.trim()).map(t => parseFloat(getComputedStyle(t).fontSize) * "
                                 "t.getScreenCTM().a))")
        assert small >= 14, "at 130 % every text of the drawing reads at 14 px or more"
        browser.wait_for(lambda _d: text_overlaps(browser) == [], "the values refitted")
        browser.screenshot(f"program_zoomed_{size[0]}x{size[1]}")
        d.find_element(By.ID, "ladder-out").click()
        browser.screenshot(f"program_rung8_{size[0]}x{size[1]}")
    finally:
        with plc.lock:
            plc.write("Connect_Execute", False)
        browser.fit()


def test_the_coils_stand_in_one_column_at_the_right_rail_in_every_rung(system):
    _plc, hmi, browser = system
    browser.open(f"{hmi.url}program.html")
    gaps = browser.driver.execute_script("""
        const out = [];
        for (const g of document.querySelectorAll('g.rung')) {
          const rails = [...g.querySelectorAll('path.rail')].map(p => p.getBoundingClientRect().left);
          const right = Math.max(...rails);
          const row = [];
          for (const c of g.querySelectorAll('g.el.coil')) {
            const sym = [...c.querySelectorAll('path.sym')].map(p => p.getBoundingClientRect());
            row.push(Math.round(right - Math.max(...sym.map(r => r.right))));
          }
          if (row.length) out.push(row);
        }
        return out;""")
    every = [g for row in gaps for g in row]
    assert len(gaps) >= 9 and max(every) - min(every) < 2, gaps     # one column, in every rung, at the rail
    assert max(every) < 30


def test_no_two_boxes_touch(system):
    """Two MOVE blocks stacked in rung 11 used to share an edge; every box keeps clear of the others and of texts."""
    _plc, hmi, browser = system
    browser.open(f"{hmi.url}program.html")
    touching = browser.driver.execute_script("""
        const out = [];
        for (const g of document.querySelectorAll('g.rung')) {
          const boxes = [...g.querySelectorAll('rect.box')].map(r => r.getBoundingClientRect());
          const texts = [...g.querySelectorAll('text')].filter(t => t.textContent.trim() &&
            !t.closest('g.el.block')).map(t => [t.textContent, t.getBoundingClientRect()]);
          boxes.forEach((a, i) => boxes.slice(i + 1).forEach(b => {
            if (a.left < b.right + 4 && b.left < a.right + 4 && a.top < b.bottom + 4 && b.top < a.bottom + 4)
              out.push([g.dataset.rung, 'box', 'box']);
          }));
          for (const b of boxes) for (const [t, r] of texts)
            if (r.left < b.right && b.left < r.right && r.top < b.bottom && b.top < r.bottom)
              out.push([g.dataset.rung, 'box', t]);
        }
        return out;""")
    assert touching == []
