"""`make demo` keeps the simulator and the web HMI up after a major fault of the PLC (issue 23, item 7).

A major fault used to stop everything, HMI included; now the PLC alone stops, the console says so once, and
the HMI shows the fault until Ctrl-C.
"""
from __future__ import annotations

from hmi_http import Client

from cbt_hmi.demo import Demo
from vplc.api import PlcFault


def test_a_major_fault_stops_the_plc_alone_and_the_hmi_shows_it(free_port):
    demo = Demo("127.0.0.1", free_port(), free_port(), free_port(), free_port())
    demo.start()
    try:
        client = Client(demo.hmi.url.rstrip("/"), demo.hmi.access.keys["operator"])
        assert client.json("/api/read?names=Connect_Connected")[1]["plc"] == "run"
        with demo.plc.lock:                     # the engine's own fault path: the next scan raises it
            demo.plc.engine.fault = PlcFault("examples/PnP_Example.st:57: major fault in PnP_Example: "
                                             "integer division by zero (100 / 0)")
        demo.plc_thread.join(timeout=10)
        assert not demo.plc_thread.is_alive() and not demo.stop_event.is_set()
        status, answer = client.json("/api/read?names=Connect_Connected")
        assert status == 200 and answer["plc"] == "fault"
        assert answer["fault"]["what"] == "integer division by zero (100 / 0)"
        status, page, _ = client.request("/")
        assert status == 200 and b"hmi.js" in page
        lines = demo.console_lines()
        assert lines[-1].startswith("PLC major fault - the virtual PLC stopped:\nexamples/PnP_Example.st:57: ")
        assert "The web HMI stays up and shows the fault" in lines[-1]
        assert not any("PLC major fault" in line for line in demo.console_lines())      # printed once
    finally:
        demo.stop()
