"""A Sysmac program written the way the manuals show (TmClient.st: Omron socket and text instructions called
directly, no library) checks clean and moves the simulated robot (issue 13, first "Done when" item).

The program relies on: SktTCPRcv TimeOut 0 = no timeout (W506 9-2 and Sysmac field code; W502 2-1149 is not
in the search corpus), RealToFormatString formal and positional (W502 2-259, 2-269), AryToString(In, Size)
positional, INT_TO_STRING(LEN(...)) with LEN's UINT result (W501 6-107), UINT x 100000000 as a DINT
expression into NanoSecToTime (W501 6-106, 6-32)."""
from __future__ import annotations

import subprocess
import sys
from functools import reduce
from pathlib import Path

import pytest

from tmsim.net.server import SimServer
from vplc.api import load_plc

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
PROGRAM = HERE / "TmClient.st"
SEC = 1_000_000_000
SCRIPT = 'PTP("JPP",+90,-30,+110,+10,+90,+45,10,200,0,false)\r\nQueueTag(1)'


class Client:
    """TmClient on a 1 ms task against one simulated robot; the simulator is polled once per PLC scan."""

    def __init__(self, **sim_args):
        self.srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, **sim_args).start()
        self.robot = self.srv.robots[0]
        self.plc = load_plc([str(PROGRAM)], task="TmClient@1ms")
        self.plc.write("TmClient.RobotPort", self.srv.ports[0])

    def read(self, name):
        return self.plc.read("TmClient." + name)

    def run(self, seconds, on_scan=None):
        """Start the sequence and scan until Done or Error (False when neither within ``seconds``)."""
        def hook(now_ns):
            self.srv.poll(now_ns / 1e9)
            if on_scan:
                on_scan(now_ns)
        self.plc.write("TmClient.Start", True)
        return self.plc.run_until(lambda: self.read("Done") or self.read("Error"), timeout_ns=int(seconds * SEC),
                                  on_scan=hook)

    def scripts_in(self):
        return [e["data"] for e in self.robot.events if e["kind"] == "frame_in" and e["header"] == "TMSCT"]

    def close(self):
        self.plc.close()
        self.srv.close()


@pytest.fixture
def client():
    made = []

    def make(**sim_args):
        made.append(Client(**sim_args))
        return made[-1]
    yield make
    for c in made:
        c.close()


def test_program_written_for_sysmac_studio_checks_clean_in_the_sysmac_dialect():
    r = subprocess.run([sys.executable, "-m", "vplc", "check", "--dialect", "sysmac", "--warnings-as-errors",
                        str(PROGRAM)], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.strip().endswith("1 file(s) checked: 0 error(s), 0 warning(s)")


def test_receive_with_timeout_zero_waits_through_the_motion_for_the_queue_tag_w506_9_2(client):
    c = client()
    waiting = []          # (scan time, receive busy) between the OK reply and the end of the motion

    def watch(now_ns):
        if c.read("OkSeen") and not c.read("MotionEnded"):
            waiting.append((now_ns, c.read("FbRcv.Busy"), c.read("FbRcv.Done")))
            assert c.read("Stage") in (30, 31) and not c.read("FbRcv.Error")
    assert c.run(15, on_scan=watch), c.read("ErrorText")
    assert c.read("Done") and not c.read("Error") and c.read("Stage") == 50
    # the reply was parsed: the OK of script M1, then the QueueTag push of tag 1
    assert (c.read("ReplyId"), c.read("ReplyStatus")) == ("M1", "OK")
    assert (c.read("TagNo"), c.read("TagState")) == ("01", "true") and c.read("FramesIn") == 2
    # it waited for seconds, longer than the 2.0 s reply supervision (ReplyLimit x 0.1 s)
    assert waiting[-1][0] - waiting[0][0] >= 5 * SEC
    # one receive, started right after the OK, stayed Busy all that time (no timeout with TimeOut 0) and
    # ended Done when the robot's message came
    busy = [b for _, b, _ in waiting]
    assert busy[0] is False and all(busy[1:-1]) and waiting[-1][1:] == (False, True)
    # the robot got the script exactly once, in a frame with the correct length and checksum
    assert c.scripts_in() == ["M1," + SCRIPT]
    data = ("M1," + SCRIPT).encode()
    body = b"TMSCT,%d,%s," % (len(data), data)
    raw = [e["raw"] for e in c.robot.events if e["kind"] == "frame_in"]
    assert raw == [f"${body.decode()}*{reduce(lambda a, b: a ^ b, body):02X}\r\n"]
    # the motion completed where the program asked, then the program closed its socket
    ends = [e for e in c.robot.events if e["kind"] == "motion_end"]
    assert len(ends) == 1 and ends[0]["joints"] == (90.0, -30.0, 110.0, 10.0, 90.0, 45.0)
    assert [e["tag"] for e in c.robot.events if e["kind"] == "tag_reached"] == [1]
    assert any(e["kind"] == "peer_closed" for e in c.robot.events)
    assert not c.plc.engine.sockets.conns


def test_replies_arriving_byte_by_byte_are_put_together_by_repeated_receives(client):
    c = client()
    c.robot.inject("split_replies", size=1)
    assert c.run(15), c.read("ErrorText")
    assert (c.read("ReplyStatus"), c.read("TagState"), c.read("FramesIn")) == ("OK", "true", 2)
    assert c.scripts_in() == ["M1," + SCRIPT]


def test_missing_reply_ends_after_reply_limit_tenths_uint_times_literal_w501_6_106(client):
    """ReplyLimit (UINT 20) x 100000000 = 2,000,000,000 ns, a DINT expression, through NanoSecToTime."""
    c = client()
    c.robot.inject("black_hole")
    start = c.plc.now_ns
    assert c.run(5)
    assert c.read("Error") and c.read("ErrorText") == "no reply to the motion script"
    assert 2 * SEC <= c.plc.now_ns - start < 2 * SEC + 50_000_000
    assert c.plc.run_until(lambda: not c.plc.engine.sockets.conns, timeout_ns=SEC,
                           on_scan=lambda t: c.srv.poll(t / 1e9))
    assert not c.scripts_in()             # the black hole swallowed the frame: nothing ran on the robot
