"""CBT_Connect: connection, identification, retries, supervision and loss."""
import pytest
from rig import Rig


def test_connect_identifies_robot_and_reports_connection_time():
    r = Rig()
    try:
        assert r.read("Cobot.Connected") and r.read("Cobot.InListenNode")
        assert r.read("conn.Busy") and not r.read("conn.Error")
        assert r.read("conn.LastConnTime") != r.read("conn.LastLostTime")
        assert r.events("frame_in")[0]["raw"] == "$TMSTA,2,00,*41\r\n"
    finally:
        r.close()


def test_connect_rejects_time_out_outside_10_to_300_s_without_connecting():
    r = Rig(connect=False)
    try:
        r.write("TimeOut", 5)
        r.write("ConnExec", True)
        r.scans(2)
        assert r.read("conn.Error") and r.read("conn.ErrorID") == 0x1001
        assert "10..300" in r.read("conn.ErrorDescrip")
        assert r.events("connect") == []
    finally:
        r.close()


def test_connect_rejects_empty_ip_address():
    r = Rig(connect=False)
    try:
        r.write("Ip", "")
        r.write("ConnExec", True)
        r.scans(2)
        assert r.read("conn.ErrorID") == 0x1002
    finally:
        r.close()


def test_connect_keeps_retrying_until_robot_enters_listen_node():
    r = Rig(connect=False, auto_enter=False)
    try:
        r.write("ConnExec", True)
        assert not r.until(lambda: r.read("conn.Connected"), 3)
        assert r.read("conn.Busy") and not r.read("conn.Error")
        r.robot.enter_listen_node()
        assert r.until(lambda: r.read("conn.Connected"), 3)
    finally:
        r.close()


def test_connect_ends_with_not_in_listen_node_after_time_out():
    r = Rig(connect=False, auto_enter=False)
    try:
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Error"), 15)
        assert r.read("conn.ErrorID") == 0x2005
        assert r.plc.now_ns >= 10 * 10**9
        assert not r.read("conn.Busy") and not r.read("conn.Connected")
    finally:
        r.close()


def test_execute_falling_closes_connection_without_error(rig):
    rig.write("ConnExec", False)
    assert rig.until(lambda: not rig.read("conn.Busy"), 1)
    assert not rig.read("conn.Error") and not rig.read("Cobot.Connected")
    assert rig.until(lambda: rig.events("disconnect") or rig.events("peer_closed"), 1)


@pytest.mark.parametrize("delay_ms", [0, 250, 499])
def test_black_hole_is_detected_by_link_supervision_1_0_to_1_5_s_after_the_link_fell_silent(rig, delay_ms):
    """The figure of CBT_Connect.md: TMSTA 00 every 500 ms, each unanswered after 1 s is a loss; wherever in the
    500 ms cycle the link falls silent, the loss is seen 1.0 to 1.5 s later (plus the scan that sees it)."""
    rig.until(lambda: rig.read("Cobot.StaPending") == 1, 1)          # a query just went out
    rig.until(lambda: rig.read("Cobot.StaPending") == 0, 1)          # ... and was answered
    rig.scans(delay_ms)
    rig.robot.inject("black_hole")
    start = rig.plc.now_ns
    assert rig.until(lambda: rig.read("conn.Error"), 3)
    assert rig.read("conn.ErrorID") == 0x2006
    assert 1_000_000_000 <= rig.plc.now_ns - start <= 1_502_000_000
    assert not rig.read("Cobot.Connected")


def test_robot_closing_the_connection_is_reported_with_lost_time(rig):
    rig.robot.inject("disconnect")
    assert rig.until(lambda: rig.read("conn.Error"), 1.5)
    assert rig.read("conn.ErrorID") in (0x2008, 0x2006)
    assert not rig.read("conn.Connected")
    assert rig.read("conn.LastLostTime") >= rig.read("conn.LastConnTime")


def test_connect_rejects_port_zero():
    r = Rig(connect=False)
    try:
        r.write("Port", 0)
        r.write("ConnExec", True)
        r.scans(2)
        assert r.read("conn.ErrorID") == 0x1003 and r.events("connect") == []
    finally:
        r.close()
