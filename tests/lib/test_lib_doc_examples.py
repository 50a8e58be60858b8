"""The FB pages in docs/library/ are what a PLC engineer copies: every "## Example" program must check clean with
the library, run on the virtual PLC against the simulator, end without error, and send exactly the script the
page says it sends."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from doc_steps import STEPS
from rig import LIB, ROOT, SEC
from tmsim.robot.camera import camera_of
from tmsim.net.server import SimServer
from tmsim.protocol.svr_table import parse_variable
from vplc.api import load_plc

DOCS = ROOT / "docs" / "library"
EXAMPLE = re.compile(r"^## Example\n```\n(.*?)```\n(.*?)(?=^## |\Z)", re.S | re.M)
SCRIPT = re.compile(r"^- `(.*)`$", re.M)

# the global variables of the robot's project that the pages' examples read and write (simulator: --svr-var)
SVR_VARIABLES = ("g_PartCount:int=17", "g_Recipe:string=\"Flange\"", "g_Offset:float[3]={0.5,-1.25,0}")


# the vision job of the robot's project (simulator: --vision-job) and the one part its camera finds
VISION_JOB, VISION_OBJECT = "job1", [417.5, -122.3, 300, 0, 0, 0]


def simulator() -> SimServer:
    """The robot the examples run against: Listen node, Ethernet Slave, the variables and the vision job above."""
    srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, svr_port=0,
                    svr_options={"variables": [parse_variable(spec) for spec in SVR_VARIABLES]})
    camera_of(srv.robots[0].session.robot).define(VISION_JOB, objects=[VISION_OBJECT])
    return srv


def example_of(page: str) -> tuple[str, list[str]]:
    text = (DOCS / f"{page}.md").read_text(encoding="utf-8")
    m = EXAMPLE.search(text)
    assert m, f"{page}.md has no '## Example' section with a code block"
    return m.group(1), SCRIPT.findall(m.group(2))


def test_every_fb_page_has_a_runnable_example():
    pages = {p.stem for p in DOCS.glob("CBT_*.md")}
    assert pages == set(STEPS), "a page was added or removed: give its example steps in STEPS"


def on_simulator(code: str, srv) -> str:
    """The example as the page shows it, pointed at the simulator's robot and Ethernet Slave on loopback."""
    return (code.replace("'192.168.1.10'", "'127.0.0.1'").replace("IPPort := 5890", f"IPPort := {srv.ports[0]}")
            .replace("SvrPort := 5891", f"SvrPort := {srv.robots[0].svr_port}"))


@pytest.mark.parametrize("page", sorted(STEPS))
def test_page_example_runs_against_the_simulator(page, tmp_path):
    code, promised = example_of(page)
    program = re.search(r"^PROGRAM (\w+)", code, re.M).group(1)
    srv = simulator()
    srv.start()
    try:
        source = tmp_path / f"{page}_example.st"
        source.write_text(on_simulator(code, srv), encoding="utf-8")
        plc = load_plc([str(LIB), str(source)], task="Main@1ms")
        read = lambda name: plc.read(f"{program}.{name}")  # noqa: E731
        pump = lambda now_ns: srv.poll(now_ns / 1e9)  # noqa: E731
        if page != "CBT_Connect":
            assert plc.run_until(lambda: read("fbConnect.Connected"), 5 * SEC, on_scan=pump), \
                read("fbConnect.ErrorDescrip")
        for trigger, done in STEPS[page]:
            if trigger:
                plc.write(f"{program}.{trigger}", True)
            fb = done.rpartition(".")[0] or "fbConnect"
            ended = plc.run_until(lambda: read(done) or read(f"{fb}.Error"), 20 * SEC, on_scan=pump)
            assert ended and not read(f"{fb}.Error"), f"{page}: {read(f'{fb}.ErrorDescrip')}"
        sent = [e["data"].partition(",")[2] for e in srv.robots[0].events
                if e["kind"] == "frame_in" and e.get("header") == "TMSCT"]
        polls = [s for s in sent if s.startswith("ListenSend(")]          # cyclic: stated once
        sent = [s for s in sent if not s.startswith("ListenSend(")] + sorted(set(polls))
        sent = [s.replace("\r\n", "\\r\\n") for s in sent]
        assert sent == promised, f"{page}.md must state every script its example sends"
        plc.close()
    finally:
        srv.close()

