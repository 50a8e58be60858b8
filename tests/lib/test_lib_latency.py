"""Latency in scans (issue 6) in both call orders, and the fast order (CBT_Connect before and after the
command FBs) working like the documented one. Figures and their proof: docs/library/design.md, "Latency"."""
import latency as L
import pytest
from rig import Rig, move_abs


@pytest.fixture
def documented():
    r = Rig(program=L.ORDERS["documented"])
    yield r
    r.close()


@pytest.fixture
def twice():
    r = Rig(program=L.ORDERS["twice"])
    yield r
    r.close()


def test_documented_order_figures(documented):
    r = documented
    assert L.execute_to_socket(r) == 0                   # frame out in the scan of the edge
    assert L.reply_to_done(r) == 1                       # CBT_Connect routes after the FBs ran
    assert L.sustained(r, 1, pulse=False, count=20) == pytest.approx(4.0)
    assert L.sustained(r, 1, pulse=True, count=20) == pytest.approx(3.0)
    assert L.sustained(r, 4, pulse=True, count=80) == pytest.approx(0.75, abs=0.02)


def test_fast_order_figures(twice):
    r = twice
    assert L.execute_to_socket(r) == 0
    assert L.reply_to_done(r) == 0                       # routed by the first call, Done in the same scan
    assert L.sustained(r, 1, pulse=False, count=20) == pytest.approx(3.0)
    assert L.sustained(r, 1, pulse=True, count=20) == pytest.approx(2.0)   # issue 6 target per FB instance
    assert L.sustained(r, 4, pulse=True, count=80) == pytest.approx(0.5, abs=0.02)


def test_fast_order_runs_motions_supervision_and_settings_like_the_documented_one(twice):
    r = twice
    sta_before = sum(1 for e in r.events("frame_in") if e.get("header") == "TMSTA")
    r.set_struct("MParam[1]", move_abs(TargetPosition=dict(X=30, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    r.write("MExec[1]", True)
    assert r.until(lambda: r.read("movers[1].Active"), 1)
    assert r.until(lambda: r.read("movers[1].Done") or r.read("movers[1].Error"), 10)
    assert r.read("movers[1].Done") and len(r.events("motion_end")) == 1
    r.write("MExec[1]", False)
    r.write("BaseExec", True)                           # base frame = RobotBase (all zero)
    assert r.until(lambda: r.read("base.Done") or r.read("base.Error"), 1) and r.read("base.Done")
    r.write("BaseExec", False)
    t0 = r.plc.now_ns
    r.scans(3000)
    assert r.read("conn.Connected") and not r.read("conn.Error") and r.read("Cobot.QueueDepth") == 0
    # supervision is time based: two calls per scan do not double the TMSTA 00 traffic (one per 500 ms)
    sta = [e for e in r.events("frame_in") if e.get("header") == "TMSTA" and e["data"] == "00"]
    span_s = (r.plc.now_ns - t0) / 1e9
    assert len(sta) - sta_before <= span_s / 0.5 + 30 and len(sta) >= span_s / 0.5 - 1


def test_fast_order_reports_a_lost_link(twice):
    r = twice
    r.set_struct("MParam[1]", move_abs(Speed=5, TargetPosition=dict(X=60, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    r.write("MExec[1]", True)
    assert r.until(lambda: r.read("movers[1].Active"), 1)
    r.robot.inject("disconnect")
    assert r.until(lambda: r.read("conn.Error"), 1)
    assert r.read("conn.ErrorID") == 0x2008 and not r.read("conn.Connected")
    assert r.until(lambda: r.read("movers[1].Error"), 1) and r.read("movers[1].ErrorID") == 0x200B   # outcome unknown
