"""Fixtures for the HMI server tests: a fake PLC scanning in a thread and the HMI server on an ephemeral port."""
from __future__ import annotations

import contextlib

import pytest
from browser import Browser
from fake_plc import FakePlc, command_program, scanning, serving
from hmi_http import Client
from selenium.common.exceptions import WebDriverException

from cbt_hmi.web.mapping import Mapping


@pytest.fixture
def mapping():
    return Mapping.load()


@pytest.fixture
def fake_plc(mapping):
    with scanning(FakePlc(mapping, command_program)) as plc:
        yield plc


@pytest.fixture
def server(fake_plc, mapping):
    with serving(fake_plc, mapping) as srv:
        yield srv


@pytest.fixture
def client(server):
    """Engineer access: may change every writable variable (the role tests use their own clients)."""
    return Client(f"http://127.0.0.1:{server.port}", server.access.keys["engineer"])


@pytest.fixture(scope="session")
def _chromium_process():
    started: list[Browser] = []
    yield started
    for browser in started:
        browser.close()


@pytest.fixture(scope="module")
def chromium(_chromium_process):
    """One Chromium per test process (a start costs seconds); each test module gets it with a fresh tab. If a
    module left it unusable, the next one starts a new Chromium. After the module the tab is left on a blank page:
    an HMI page polls its server 20 times a second for as long as it is open, and the worker goes on with other
    modules (other folders too) while this Chromium waits for the next HMI module."""
    browser = None
    if _chromium_process:
        try:
            browser = _chromium_process[0].fresh()
        except WebDriverException:
            broken = _chromium_process.pop()
            with contextlib.suppress(WebDriverException):   # already gone: close() removed its profile all the same
                broken.close()
    if browser is None:
        _chromium_process.append(Browser())
        browser = _chromium_process[0]
    yield browser
    with contextlib.suppress(WebDriverException):   # left unusable: the next module replaces it (above)
        browser.driver.get("about:blank")
