"""The FB pages in docs/library/ are what a PLC engineer copies: every "## Example" program must check clean with
the library, run on the virtual PLC against the simulator, end without error, and send exactly the script the
page says it sends."""
from __future__ import annotations

import re

import pytest
from doc_steps import DOCS, STEPS, Examples, example_of
from rig import SEC


def test_every_fb_page_has_a_runnable_example():
    pages = {p.stem for p in DOCS.glob("CBT_*.md")}
    assert pages == set(STEPS), "a page was added or removed: give its example steps in STEPS"


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """Every page's example with its own simulator, the library compiled once for all of them."""
    found = Examples(tmp_path_factory.mktemp("examples"))
    yield found
    found.close()


@pytest.mark.parametrize("page", sorted(STEPS))
def test_page_example_runs_against_the_simulator(page, examples):
    code, promised = example_of(page)
    program = re.search(r"^PROGRAM (\w+)", code, re.M).group(1)
    srv = examples.servers[page]
    try:
        plc = examples.plc(page)
        read = lambda name: plc.read(f"{program}.{name}")  # noqa: E731
        pump = lambda now_ns: srv.poll(now_ns / 1e9)  # noqa: E731
        if page != "CBT_Connect":
            assert plc.run_until(lambda: read("fbConnect.Connected"), 5 * SEC, on_scan=pump), \
                read("fbConnect.ErrorDescrip")
        for trigger, done in STEPS[page]:
            if trigger:
                plc.write(f"{program}.{trigger}", True)
            fb = done.rpartition(".")[0] or "fbConnect"
            ended = plc.run_until(lambda done=done, fb=fb: read(done) or read(f"{fb}.Error"), 20 * SEC, on_scan=pump)
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

