"""Headless Chromium for the HMI tests: Debian's chromium + chromedriver, an 800x480 viewport, screenshots."""
from __future__ import annotations

import itertools
import os
import pathlib
import shutil
import tempfile

from selenium import webdriver
from selenium.common.exceptions import NoSuchElementException, TimeoutException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCREENSHOTS = ROOT / "artifacts" / "screenshots"
# --incognito: history, cache and session state in memory, not written to the profile on disk; the pages keep their
# sessionStorage per tab all the same (about a sixth less CPU per page load, an eighth less while a page polls)
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--incognito"]
WAIT_S = 15
# The pages refresh their values every 50 ms: a wait polling faster finds nothing new, and each poll is a round trip
# through chromedriver and the browser (at 0.02 s Chromium and chromedriver burnt twice the CPU of a page left alone).
POLL_S = 0.05

# The text an element shows, as WebElement.text reads it (the same lines, spaces and "" for an element not displayed),
# computed in the page: a read costs one execute_script instead of find_element plus getElementText. A table row is
# its cells' texts joined by a space, one row a line, as WebDriver renders a table.
SHOWN_TEXT = """
    const lines = (s) => s.replace(/\\xa0/g, ' ').split('\\n').map((l) => l.trim()).join('\\n').trim();
    const shown = (el) => (el.getClientRects().length ? lines(el.innerText) : '');
    const rowText = (r) => [...r.cells].map(shown).filter((t) => t).join(' ');"""


# Debian's chromium-headless-shell: the same Blink, V8 and layout as `chromium` without the desktop browser around
# them. Measured on the 2-core machine, a PnP page open and idle: 3.5 % of a core against 8.2 %, a page load
# 0.10 against 0.19 CPU-s, a start 0.2 against 0.8 CPU-s. HMI_BROWSER=chromium runs the tests in the full browser.
HEADLESS_SHELL = "/usr/lib/chromium/chromium-headless-shell"


def chromium_paths() -> tuple[str, str] | None:
    """(browser, chromedriver): the headless shell when it is installed (unless HMI_BROWSER=chromium), else the
    full Chromium; None when there is no browser or no driver."""
    driver = shutil.which("chromedriver")
    shell = HEADLESS_SHELL if os.access(HEADLESS_SHELL, os.X_OK) else None
    full = shutil.which("chromium") or shutil.which("chromium-browser")
    browser = full if os.environ.get("HMI_BROWSER") == "chromium" else shell or full
    return (browser, driver) if browser and driver else None


def _shell_launcher(binary: str, folder: str) -> str:
    """A launcher for the headless shell in ``folder``: it opens no page unless given an address, chromedriver
    waits for a page and gives none (and puts "--" before every argument it is given), so the launcher adds one."""
    path = os.path.join(folder, "headless-shell")
    with open(path, "w", encoding="ascii") as fh:
        fh.write(f'#!/bin/sh\nexec "{binary}" "$@" about:blank\n')
    os.chmod(path, 0o700)
    return path


class Browser:
    """A Chrome session sized so the page viewport is exactly 800x480, like the touch panel."""

    def __init__(self):
        paths = chromium_paths()
        if paths is None:
            raise RuntimeError("chromium and chromedriver are needed: run `make browser` (Debian packages)")
        self.profile = tempfile.mkdtemp(prefix="hmi-chromium-")
        self.loads = itertools.count(1)
        options = webdriver.ChromeOptions()
        options.binary_location = paths[0]
        if paths[0] == HEADLESS_SHELL:          # the launcher in the profile folder, removed with it
            options.binary_location = _shell_launcher(paths[0], self.profile)
        for flag in FLAGS + [f"--user-data-dir={self.profile}", "--window-size=800,480"]:
            options.add_argument(flag)
        self.driver = webdriver.Chrome(options=options, service=Service(paths[1]))
        self.driver.set_window_size(800, 480)
        self.fit()

    def fit(self) -> None:
        """Size the window so that the page itself is 800 x 480 (the 9-inch panel), whatever the frame takes."""
        self.size(800, 480)

    def size(self, width: int, height: int) -> None:
        """Size the window so that the page's viewport is ``width`` x ``height``; a window already showing that
        viewport is left as it is (a resize lays the page shown out again)."""
        dw, dh, *viewport = self.driver.execute_script(
            "return [window.outerWidth - window.innerWidth, window.outerHeight - window.innerHeight, "
            "innerWidth, innerHeight]")
        if viewport != [width, height]:
            self.driver.set_window_size(width + dw, height + dh)

    def fresh(self) -> Browser:
        """The same Chromium with a new tab in place of the old one: no page, no sessionStorage (access key, alarm
        list) left by the tests that used it before."""
        old = self.driver.current_window_handle
        self.driver.switch_to.new_window("tab")
        new = self.driver.current_window_handle
        self.driver.switch_to.window(old)
        self.driver.close()
        self.driver.switch_to.window(new)
        self.fit()
        return self

    def close(self):
        try:
            self.driver.quit()
        finally:
            shutil.rmtree(self.profile, ignore_errors=True)

    def open(self, url: str):
        """Load ``url`` afresh. Our addresses carry the access key in the fragment, and going to the address the
        tab already shows only moves to the fragment: the old page would go on running, and a command it was
        still finishing (Play holding Done for 1.5 s, then releasing) would write into the next test's message
        line. Each open adds a query of its own (``?load=<n>``, which the HMI server ignores for a page), so the
        address differs before the fragment: a full load, which ends the old page's scripts (a blank page in
        between did the same for a third more CPU)."""
        address, hash_, fragment = url.partition("#")
        address += f"{'&' if '?' in address else '?'}load={next(self.loads)}"
        self.driver.get(address + hash_ + fragment)
        self.wait_for(lambda d: d.execute_script("return document.querySelector('#message') !== null "
                                                 "&& document.querySelector('#pill-plc').textContent "
                                                 "=== 'PLC online'"), "the page to load and go online")

    def wait_for(self, condition, what: str, timeout: float = WAIT_S):
        try:
            return WebDriverWait(self.driver, timeout, poll_frequency=POLL_S).until(condition)
        except TimeoutException:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}; "
                                 f"message line: {self.message()!r}") from None

    def field(self, path: str):
        return self.driver.find_element(By.CSS_SELECTOR, f'[data-path="{path}"]')

    def type_into(self, path: str, text: str):
        element = self.field(path)
        element.clear()
        element.send_keys(text)

    def click(self, element_id: str):
        self.driver.find_element(By.ID, element_id).click()

    def text(self, element_id: str) -> str:
        """The text of the element with id ``element_id`` (NoSuchElementException without one, like find_element)."""
        shown = self.driver.execute_script(SHOWN_TEXT + """
            const el = document.getElementById(arguments[0]);
            return el ? shown(el) : null;""", element_id)
        if shown is None:
            raise NoSuchElementException(f"no element with id {element_id!r}")
        return shown

    def status(self, variable: str) -> str:
        """A status cell's value: its data-value (a lamp), else its text."""
        value = self.driver.execute_script(SHOWN_TEXT + """
            const cell = document.querySelector(`[data-status="${arguments[0]}"]`);
            return cell ? cell.getAttribute('data-value') || shown(cell) : null;""", variable)
        if value is None:
            raise NoSuchElementException(f"no status cell for {variable!r}")
        return value

    def wait_status(self, variable: str, expected: str, timeout: float = WAIT_S):
        self.wait_for(lambda d: self.status(variable) == expected, f"{variable} = {expected}", timeout)

    def banner(self) -> str:
        """The alarm banner's text, "" while it is hidden."""
        return self.text("alarm-banner")

    def alarm_rows(self) -> list[str]:
        """The rows of the main page's alarm list, without its header ([] for "No alarms.")."""
        rows = self.driver.execute_script(SHOWN_TEXT + """
            const table = document.getElementById('alarm-history');
            return table && [...table.rows].slice(1).map(rowText).filter((t) => t);""")
        if rows is None:
            raise NoSuchElementException("no alarm list (#alarm-history)")
        return [] if rows == ["No alarms."] else rows

    def message(self) -> str:
        try:
            return self.text("message")
        except Exception:  # noqa: BLE001 - only used to enrich a failure message
            return ""

    def viewport_overflow(self) -> list[str]:
        """Ids/classes of visible elements that stick out of the 800x480 viewport (layout check)."""
        return self.driver.execute_script("""
            const out = [];
            for (const el of document.querySelectorAll('button, a, input, select, .status, canvas, svg')) {
              const r = el.getBoundingClientRect();
              if (r.width === 0 || el.closest('dialog:not([open])') || el.closest('.params')) continue;
              if (r.right > window.innerWidth + 1 || r.bottom > window.innerHeight + 1)
                out.push(el.id || el.className.baseVal || el.className || el.tagName);
            }
            return out;""")

    def screenshot(self, name: str) -> pathlib.Path:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        path = SCREENSHOTS / f"{name}.png"
        self.driver.save_screenshot(str(path))
        return path
