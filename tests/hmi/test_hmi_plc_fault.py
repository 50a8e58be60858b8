"""After a major fault of the PLC the HMI stays up and says so (issue 23, item 7).

The header said "PLC online" and "Robot connected" after a major fault (the PLC had stopped and closed its
socket to the robot). Now /api/read reports the fault with the values, marked no longer valid, writes are
refused, and the pages show "PLC fault — <what>".
"""
from __future__ import annotations

import types

import pytest
from fake_plc import FakePlc, command_program, scanning, serving
from hmi_http import Client

from cbt_hmi.web.mapping import Mapping
from cbt_hmi.web.server import HmiServer
from vplc.api import PlcFault, load_plc

FAULT = "examples/PnP_Example.st:57: major fault in PnP_Example: integer division by zero (100 / 0)"


@pytest.fixture
def faulted(mapping):
    """A fake PLC scanning, then faulted the way vplc's Plc keeps a fault (engine.fault), with its HMI server."""
    with scanning(FakePlc(mapping, command_program)) as plc, serving(plc, mapping) as server:
        yield plc, server, Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"])


def fault(plc) -> None:
    with plc.lock:
        plc.engine = types.SimpleNamespace(fault=PlcFault(FAULT))


def test_a_running_plc_is_reported_running(faulted):
    _, _, client = faulted
    status, answer = client.json("/api/read?names=Connect_Connected")
    assert status == 200 and answer["plc"] == "run" and "fault" not in answer


def test_after_a_major_fault_a_read_reports_it_with_the_last_values(faulted):
    plc, _, client = faulted
    plc.vars["MoveAbs_ErrorID"] = 0x3012
    fault(plc)
    status, answer = client.json("/api/read?names=MoveAbs_ErrorID")
    assert status == 200 and answer["plc"] == "fault"
    assert answer["fault"] == {"message": FAULT, "what": "integer division by zero (100 / 0)"}
    assert answer["values"] == {"MoveAbs_ErrorID": 0x3012}


@pytest.mark.parametrize("path, body", [("/api/write", {"values": {"MoveAbs_Param.Speed": 40}}),
                                        ("/api/execute", {"execute": "Stop_Execute"})])
def test_after_a_major_fault_writes_are_refused_and_nothing_is_written(faulted, path, body):
    plc, _, client = faulted
    fault(plc)
    plc.writes.clear()
    status, answer = client.json(path, body)
    assert status == 503 and answer["error"] == ("the PLC has stopped with a major fault (integer division by zero "
                                                 "(100 / 0)): nothing was written; restart the PLC")
    assert plc.writes == []


def test_a_fault_of_the_real_plc_is_reported(tmp_path):
    """The vplc runtime's own fault, not a stand-in: a division by zero the HMI itself provokes."""
    (tmp_path / "main.st").write_text("VAR_GLOBAL Divisor : INT := 1; Quotient : INT; END_VAR\n"
                                      "PROGRAM Main VAR_EXTERNAL Divisor : INT; Quotient : INT; END_VAR\n"
                                      "Quotient := 100 / Divisor;\nEND_PROGRAM\n")
    plc = load_plc([str(tmp_path)])
    mapping = Mapping({"types": {}, "variables": {"Divisor": {"type": "INT", "access": "rw"},
                                                  "Quotient": {"type": "INT", "access": "r"}}})
    server = HmiServer(plc, mapping, port=0)
    server.start()
    try:
        client = Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"])
        plc.scan(0)
        assert client.json("/api/read?names=Quotient")[1]["plc"] == "run"
        assert client.json("/api/write", {"values": {"Divisor": 0}})[0] == 200
        with pytest.raises(PlcFault):
            plc.scan(plc.period_ns)
        status, answer = client.json("/api/read?names=Quotient,Divisor")
    finally:
        server.stop()
    assert status == 200 and answer["plc"] == "fault" and answer["values"] == {"Quotient": 100, "Divisor": 0}
    assert answer["fault"]["what"] == "integer division by zero (100 / 0)"
    assert answer["fault"]["message"].endswith("main.st:3: major fault in Main: integer division by zero (100 / 0)")


def test_the_page_header_shows_the_fault_and_no_robot_link(chromium, mapping):
    with scanning(FakePlc(mapping)) as plc, serving(plc, mapping) as server:      # no program: the link stays up
        plc.vars["Connect_Connected"] = True
        chromium.open(server.page_url("stop", "operator"))
        chromium.wait_for(lambda d: chromium.text("pill-robot") == "Robot connected", "the robot link")
        fault(plc)
        chromium.wait_for(lambda d: chromium.text("pill-plc").startswith("PLC fault — "), "the fault")
        driver = chromium.driver
        assert driver.find_element("id", "pill-plc").text == "PLC fault — integer division by zero (100 / 0)"
        assert driver.find_element("id", "pill-plc").get_attribute("title") == FAULT
        assert driver.find_element("id", "pill-robot").text == "Robot link closed"
        assert driver.execute_script("return document.querySelector('.panel').classList.contains('plc-fault')")
        assert chromium.message().startswith(f"PLC major fault: {FAULT}. The PLC has stopped")
        chromium.screenshot("fake_stop_plc_fault")
