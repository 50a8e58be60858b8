"""An HMI page with nothing changing writes nothing into the page (docs/hmi.md, Performance): every poll (20 a second)
runs the page's listeners, and a write of the value an element already has still costs the panel's browser a new
frame (style, layout, paint). Against the whole system idle (robot connected, nothing moving), each page is watched by
a MutationObserver over about a second of polls, and no attribute, text or child list may be written with what it
already held. The count of such writes is compared, never a time."""
from __future__ import annotations

import time
from collections import Counter

import pytest
from browser import chromium_paths
from fake_plc import ConnectedStack
from hmi_system import System

pytestmark = pytest.mark.skipif(chromium_paths() is None, reason="chromium/chromedriver: run `make browser`")

WATCH_S = 1.2          # about 20 polls
MIN_POLLS = 5          # the window saw the page's listeners run, whatever the machine's load

# Records every change of the page in order. A record's new value is the old value of the next record of the same
# attribute (or text node), or the value at the end; a child list is written with what it had when the nodes it
# removed read the same as those it added (textContent = the same text).
OBSERVE = """
const seen = [];
window.__idle = { records: seen, ticks: 0 };
live.listeners.push(() => { window.__idle.ticks += 1; });     // every poll, answered or not
window.__idleObserver = new MutationObserver((list) => { for (const m of list) seen.push(m); });
window.__idleObserver.observe(document.body, { subtree: true, childList: true, attributes: true, characterData: true,
  attributeOldValue: true, characterDataOldValue: true });
"""
SAME_VALUE_WRITES = """
const idle = window.__idle, records = idle.records.concat(window.__idleObserver.takeRecords());
window.__idleObserver.disconnect();
const name = (n) => n.nodeType === 3 ? '#text in ' + name(n.parentNode || document.body) :
  n.nodeName + (n.id ? '#' + n.id : '') +
  (n.dataset && n.dataset.status ? '[data-status=' + n.dataset.status + ']' : '');
const markup = (nodes) => [...nodes].map((n) => n.nodeType === 1 ? n.outerHTML : n.textContent).join('');
const same = [];
records.forEach((m, i) => {
  let now;
  if (m.type === 'childList') {
    if (markup(m.removedNodes) === markup(m.addedNodes)) same.push('text of ' + name(m.target));
    return;
  }
  const next = records.slice(i + 1).find((r) => r.target === m.target && r.type === m.type &&
                                                 r.attributeName === m.attributeName);
  if (next) now = next.oldValue;
  else now = m.type === 'attributes' ? m.target.getAttribute(m.attributeName) : m.target.data;
  if (now === m.oldValue) same.push(m.type === 'attributes' ? name(m.target) + '@' + m.attributeName : name(m.target));
});
return { same, writes: records.length, polls: idle.ticks };
"""


@pytest.fixture(scope="module")
def system(chromium):
    stack = System(chromium)
    with stack.plc.lock:
        stack.plc.write("Connect_Execute", True)
    stack.open("index")
    chromium.wait_for(lambda d: chromium.text("pill-robot") == "Robot ready",
                      "the robot connected in its Listen node")
    yield stack
    stack.close()


def watch(browser) -> dict:
    """The same-value writes of about a second of polls on the open page."""
    browser.driver.execute_script(OBSERVE)
    time.sleep(WATCH_S)
    return browser.driver.execute_script(SAME_VALUE_WRITES)


def settle(browser) -> None:
    """The page's first answers are in: its one-off work (alarm list, trail, arm data, drawings) is done."""
    start = browser.driver.execute_script("return live.polls")
    browser.wait_for(lambda d: d.execute_script("return live.polls") >= start + 10, "ten polls")


def test_the_watch_sees_a_same_value_write(system):
    """The check itself: an attribute and a text written with their own values are counted, a real change is not."""
    browser = system.open("index")
    settle(browser)
    browser.driver.execute_script(OBSERVE)
    browser.driver.execute_script("""
        const pill = document.getElementById('pill-plc'), h1 = document.querySelector('header h1');
        pill.setAttribute('title', pill.getAttribute('title'));
        h1.textContent = h1.textContent;
        document.getElementById('message').dataset.probe = 'changed';""")
    result = browser.driver.execute_script(SAME_VALUE_WRITES)
    assert sorted(result["same"]) == ["SPAN#pill-plc@title", "text of H1"], result


@pytest.mark.parametrize("page", ["index", "moveabs", "moverel", "movecircle", "changebase", "changetcp", "connect",
                                  "setoutput", "stop", "pnp", "jog", "program"])
def test_an_idle_page_writes_no_value_it_already_shows(system, page):
    browser = system.open(page)
    settle(browser)
    result = watch(browser)
    assert result["polls"] >= MIN_POLLS, result
    assert result["same"] == [], f"{page}: written with the value already there (times): {Counter(result['same'])}"


@pytest.fixture(scope="module")
def stack(chromium):
    """The stand-in PLC with its robot connected: states the idle demo does not show, held still."""
    s = ConnectedStack()
    yield s
    s.close()


def test_a_page_with_an_alarm_and_the_robot_out_of_its_listen_node_writes_nothing_twice(stack, chromium):
    """The robot outside its Listen node: the banner shown (its priority and number), the header's alarm pill, the
    Robot tile's red link and Back to Listen Node, each held for a second of polls."""
    stack.set(Robot_InListenNode=False)
    try:
        chromium.open(stack.server.page_url("index", "operator"))
        chromium.wait_for(lambda d: "The robot left the Listen node" in chromium.banner(), "the alarm in the banner")
        chromium.wait_for(lambda d: d.find_element("id", "btn-back-to-node").is_displayed(), "Back to Listen Node")
        settle(chromium)
        result = watch(chromium)
        assert result["polls"] >= MIN_POLLS, result
        assert result["same"] == [], f"written with the value already there (times): {Counter(result['same'])}"
    finally:
        stack.set(Robot_InListenNode=True)
        stack.server.alarms.acknowledge(None, "engineer")


def test_a_page_without_its_plc_writes_nothing_twice(stack, chromium):
    """No answer from the HMI server: ####, grey lamps and the communication alarm, held while the polls fail."""
    chromium.open(stack.server.page_url("moveabs", "operator"))
    port = stack.server.port
    stack.server.stop()
    try:
        chromium.wait_for(lambda d: chromium.status("MoveAbs_ErrorID") == "####", "#### in place of the value")
        chromium.wait_for(lambda d: "PLC communication lost" in chromium.banner(), "the communication alarm")
        result = watch(chromium)
        assert result["polls"] >= MIN_POLLS, result
        assert result["same"] == [], f"written with the value already there (times): {Counter(result['same'])}"
    finally:
        stack.start_server(port)
        chromium.wait_for(lambda d: chromium.status("MoveAbs_ErrorID") == "16#0000", "valid values again")
