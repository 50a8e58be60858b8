"""Fixtures for the HMI server tests: a fake PLC scanning in a thread and the HMI server on an ephemeral port."""
from __future__ import annotations

import pathlib
import sys
import threading

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from fake_plc import FakePlc, command_program  # noqa: E402
from hmi_http import Client  # noqa: E402
from vplc.hmi.server import HmiServer, Mapping  # noqa: E402


@pytest.fixture
def mapping():
    return Mapping.load()


@pytest.fixture
def fake_plc(mapping):
    plc = FakePlc(mapping, command_program)
    stop = threading.Event()

    def scanning():
        while not stop.wait(0.001):
            plc.scan()

    thread = threading.Thread(target=scanning, daemon=True)
    thread.start()
    yield plc
    stop.set()
    thread.join(timeout=5)


@pytest.fixture
def server(fake_plc, mapping):
    srv = HmiServer(fake_plc, mapping, port=0)
    srv.start()
    yield srv
    srv.stop()


@pytest.fixture
def client(server):
    """Engineer access: may change every writable variable (the role tests use their own clients)."""
    return Client(f"http://127.0.0.1:{server.port}", server.access.keys["engineer"])
