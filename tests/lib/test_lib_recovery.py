"""Recovery without a PLC restart (issue 14): with CBT_Connect's Execute held TRUE, every kind of loss is shown as
Error with its own ErrorID for at least one scan and then repaired by automatic reconnect attempts with the
documented back-off (100 ms, 1 s, 2 s, then every 5 s); a command sent but not confirmed before the loss ends
with 16#200B (outcome unknown), never as "failed". The simulator's event log is the witness."""
import pytest
from rig import SEC, Rig, move_abs


def go(rig, k, rz, speed=50):
    rig.set_struct(f"MParam[{k}]", move_abs(Speed=speed, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=rz)))
    rig.write(f"MExec[{k}]", True)


def connects(rig):
    return [e for e in rig.events("connect")]


def watch_error_scans(rig):
    """on_scan hook counting the scans in which CBT_Connect showed Error, and the ErrorIDs it showed."""
    seen = {"scans": 0, "ids": []}

    def hook(_now):
        if rig.read("conn.Error"):
            seen["scans"] += 1
            if rig.read("conn.ErrorID") not in seen["ids"]:
                seen["ids"].append(rig.read("conn.ErrorID"))
    return seen, hook


@pytest.mark.parametrize("fault,error_id", [("disconnect", 0x2008), ("stop_project", 0x2008),
                                            ("close_mid_frame", 0x2008)])
def test_robot_closing_the_connection_is_shown_then_repaired_by_itself(rig, fault, error_id):
    seen, hook = watch_error_scans(rig)
    rig.robot.inject(fault)
    if fault == "close_mid_frame":
        go(rig, 1, rz=15)
    assert rig.until(lambda: rig.read("conn.Reconnecting"), 2, on_scan=hook)
    if fault == "stop_project":
        rig.robot.start_project()
    assert rig.until(lambda: rig.read("conn.Connected"), 3, on_scan=hook), rig.read("conn.ErrorDescrip")
    assert seen["ids"] == [error_id] and seen["scans"] >= 1
    assert rig.read("conn.RetryCount") >= 1 and not rig.read("conn.Reconnecting") and not rig.read("conn.Error")
    assert rig.read("conn.LastLostTime") >= rig.read("conn.LastConnTime") or rig.read("conn.Connected")
    # the machine carries on: a new motion runs on the new connection
    rig.write("MExec[2]", False)
    go(rig, 2, rz=30)
    assert rig.until(lambda: rig.read("movers[2].Done"), 5), rig.read("movers[2].ErrorDescrip")


def test_black_hole_then_restore_reconnects_with_the_documented_back_off(rig):
    """The first attempt follows the loss after 100 ms, the next ones 1 s, 2 s and 5 s apart (bounded)."""
    rig.robot.inject("black_hole")
    assert rig.until(lambda: rig.read("conn.Error"), 2)
    assert rig.read("conn.ErrorID") == 0x2006
    lost_at = rig.plc.now_ns
    attempts_before = len(connects(rig))
    assert rig.until(lambda: rig.read("conn.RetryCount") >= 1, 1)
    assert rig.plc.now_ns - lost_at <= 150_000_000                 # first retry fast (100 ms)
    assert rig.read("conn.Reconnecting") and rig.read("conn.Busy") and not rig.read("conn.Error")
    rig.robot.clear_faults()                                        # network repaired
    assert rig.until(lambda: rig.read("conn.Connected"), 15), rig.read("conn.ErrorDescrip")
    assert len(connects(rig)) > attempts_before
    assert not rig.read("conn.Reconnecting") and rig.read("Cobot.InListenNode")


def test_a_reconnect_attempt_into_a_black_hole_ends_at_time_out_with_3004_then_the_next_follows(rig):
    """A robot that accepts the connection but never answers: each attempt keeps trying quietly (Busy, no Error)
    until Time_Out, then shows 16#3004 during the back-off wait, and the next attempt starts 1 s later."""
    seen, hook = watch_error_scans(rig)
    rig.robot.inject("black_hole")
    assert rig.until(lambda: rig.read("conn.RetryCount") >= 1, 3, on_scan=hook)
    assert seen["ids"] == [0x2006]                                  # the loss, shown for a while, then attempt 1
    started = rig.plc.now_ns
    assert rig.until(lambda: rig.read("conn.Error"), 15, on_scan=hook)
    timeout_s = rig.read("TimeOut")
    assert (rig.plc.now_ns - started) / SEC == pytest.approx(timeout_s, abs=0.2)
    assert rig.read("conn.ErrorID") == 0x3004 and rig.read("conn.Reconnecting")
    failed = rig.plc.now_ns
    assert rig.until(lambda: rig.read("conn.RetryCount") >= 2, 3, on_scan=hook)
    assert (rig.plc.now_ns - failed) / SEC == pytest.approx(1.0, abs=0.05)
    assert rig.read("conn.Busy") and not rig.read("conn.Error")
    rig.robot.clear_faults()
    assert rig.until(lambda: rig.read("conn.Connected"), 15), rig.read("conn.ErrorDescrip")
    assert seen["ids"] == [0x2006, 0x3004]


def test_back_off_between_refused_attempts_is_100ms_1s_2s_then_5s():
    r = Rig()
    try:
        r.robot.inject("refuse_connections")
        r.robot.inject("disconnect")
        lost = r.plc.now_ns
        times = []

        def hook(now):
            if r.read("conn.RetryCount") > len(times):
                times.append((now - lost) / SEC)
        assert r.until(lambda: len(times) >= 5, 20, on_scan=hook)
        gaps = [round(b - a, 1) for a, b in zip(times, times[1:], strict=False)]
        assert round(times[0], 1) == 0.1 and gaps == [1.0, 2.0, 5.0, 5.0], (times, gaps)
        assert r.read("conn.Error") or r.read("conn.Busy")
        assert r.read("conn.ErrorID") in (0, 0x2004)
        r.robot.clear_faults()
        assert r.until(lambda: r.read("conn.Connected"), 6)
        assert r.read("conn.RetryCount") >= 5                       # kept once connected, for the HMI
    finally:
        r.close()


def test_execute_falling_while_reconnecting_ends_quietly_and_a_manual_trigger_connects(rig):
    rig.robot.inject("refuse_connections")
    rig.robot.inject("disconnect")
    assert rig.until(lambda: rig.read("conn.RetryCount") >= 1, 2)
    rig.write("ConnExec", False)
    rig.scans(2)
    assert not (rig.read("conn.Error") or rig.read("conn.Busy") or rig.read("conn.Reconnecting"))
    assert rig.read("conn.ErrorID") == 0
    rig.robot.clear_faults()
    rig.write("ConnExec", True)
    assert rig.until(lambda: rig.read("conn.Connected"), 3)
    assert rig.read("conn.RetryCount") == 0


def test_robot_stalled_after_a_motion_frame_reports_outcome_unknown_and_the_motion_ran_once(rig):
    go(rig, 1, rz=40, speed=20)
    assert rig.until(lambda: any(e.get("header") == "TMSCT" for e in rig.events("frame_in")), 1)
    rig.robot.inject("black_hole")                                  # the robot goes silent after the frame
    assert rig.until(lambda: rig.read("movers[1].Error"), 2)
    assert rig.read("movers[1].ErrorID") == 0x200B
    assert rig.read("movers[1].ErrorDescrip") == "Outcome unknown: may have executed; check position before repeating"
    assert rig.read("conn.ErrorID") == 0x2006
    rig.robot.clear_faults()
    assert rig.until(lambda: rig.read("conn.Connected"), 3)
    # the witness: the robot did start the motion, exactly once
    assert len(rig.events("motion_start")) == 1


def test_commands_waiting_at_a_loss_end_with_outcome_unknown(rig):
    """Sent and not yet confirmed: each waiting FB ends with an Error (PLCopen) saying it may have run."""
    for k in (1, 2, 3):
        go(rig, k, rz=10.0 * k, speed=10)
    assert rig.until(lambda: all(rig.read(f"movers[{k}].Busy") for k in (1, 2, 3)), 1)
    rig.scans(3)
    rig.robot.inject("disconnect")
    assert rig.until(lambda: not any(rig.read(f"movers[{k}].Busy") for k in (1, 2, 3)), 2)
    assert [rig.read(f"movers[{k}].ErrorID") for k in (1, 2, 3)] == [0x200B] * 3
    assert rig.read("Cobot.LastErrorID") == 0x2008


def test_a_damaged_status_reply_is_not_a_lost_link(rig):
    """One TMSTA 00 reply with a wrong checksum is dropped and counted; the next supervision query answers, so
    the link stays up (it used to end in 16#2006 and a reconnect)."""
    rig.scans(600)
    rig.robot.inject("corrupt_checksum", count=1)
    assert not rig.until(lambda: rig.read("conn.Error") or not rig.read("Cobot.Connected"), 3)
    assert rig.read("Cobot.BadFrames") == 1 and rig.read("conn.RetryCount") == 0
    assert rig.events("disconnect") == [] and len(rig.events("connect")) == 1


def test_a_motion_whose_ok_reply_is_lost_completes_by_its_queue_tag(rig):
    """The reply to a non-blended motion is damaged and dropped: its own queue tag reached proves the script was
    accepted, so the motion ends Done when it arrives (not 16#3001 after the 5 s reply timeout)."""
    rig.set_struct("MParam[1]", move_abs(Speed=20, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=30)))
    sent = rig.read("Cobot.FramesOut")
    rig.write("MExec[1]", True)
    assert rig.until(lambda: rig.read("Cobot.FramesOut") > sent, 1)
    rig.robot.inject("corrupt_checksum", count=1)                  # the next frame out: the OK of the motion
    start = rig.plc.now_ns
    assert rig.until(lambda: rig.read("movers[1].Done") or rig.read("movers[1].Error"), 8)
    assert rig.read("movers[1].Done") and rig.read("Cobot.BadFrames") == 1
    assert rig.plc.now_ns - start < 2 * SEC and len(rig.events("motion_start")) == 1


def test_a_first_connect_to_a_closed_port_ends_not_reachable_after_time_out_and_is_then_retried():
    """A PLC that boots before its robot: the first connect ends in Error 16#2004 at Time_Out (PLCopen), then,
    Execute still held, CBT_Connect keeps trying on the back-off like after a loss and connects by itself when the
    robot is up.
    A command started meanwhile is refused with 16#200C (retrying), not 'execute CBT_Connect first'."""
    r = Rig(connect=False)
    try:
        r.robot.inject("refuse_connections")
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Error"), 15)
        assert r.read("conn.ErrorID") == 0x2004
        assert r.until(lambda: r.read("conn.Reconnecting") and r.read("conn.RetryCount") >= 1, 3)
        assert r.read("Cobot.LinkErrorID") == 0x2004
        go(r, 1, rz=10)
        assert r.until(lambda: r.read("movers[1].Error"), 1)
        assert r.read("movers[1].ErrorID") == 0x200C and r.events("motion_start") == []
        assert r.read("movers[1].ErrorDescrip").startswith("Robot not connected: CBT_Connect is retrying")
        r.robot.clear_faults()
        assert r.until(lambda: r.read("conn.Connected"), 7)
        assert not r.read("conn.Error") and not r.read("conn.Reconnecting") and r.read("Cobot.LinkErrorID") == 0
    finally:
        r.close()


def test_a_command_started_while_the_link_is_down_says_why(rig):
    """After a loss CBT_Connect retries; a command refused meanwhile names that state (16#200C) and what is
    behind it is in stCBT_Connection.LinkErrorID (here 16#2006, the link fell silent)."""
    rig.robot.inject("black_hole")
    assert rig.until(lambda: rig.read("conn.Reconnecting"), 3)
    assert rig.read("Cobot.LinkErrorID") == 0x2006
    go(rig, 1, rz=10)
    assert rig.until(lambda: rig.read("movers[1].Error"), 1)
    assert rig.read("movers[1].ErrorID") == 0x200C
    rig.write("ConnExec", False)                      # Execute falling: nothing is retried, nothing to say
    rig.scans(2)
    assert rig.read("Cobot.LinkErrorID") == 0
    rig.write("MExec[1]", False)
    rig.scans(1)
    go(rig, 1, rz=10)
    assert rig.until(lambda: rig.read("movers[1].Error"), 1)
    assert rig.read("movers[1].ErrorID") == 0x2001


def test_a_link_status_query_running_at_a_quick_reconnect_neither_ends_the_new_link_nor_delays_the_next():
    """A status query (SktGetTCPStatus, every 100 ms) still running when the link closes ends in the first calls
    of the next link, about the closed socket: it is cleared at once and not taken as a loss of the new link,
    and the next query of the new link starts on time."""
    r = Rig(load_args=dict(socket_latency_ns=3_000_000))
    try:
        r.scans(50)
        while r.read("Cobot.Now") + r.plc.period_ns - r.read("conn.Sock.StatusAt") < 100_000_000:
            r.scans(1)                                   # the next scan starts a status query ...
        r.write("ConnExec", False)
        r.scans(1)                                       # ... and closes the link
        assert r.read("conn.Sock.FbStatus.Busy")
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Connected"), 2), r.read("conn.ErrorDescrip")
        reconnected = r.plc.now_ns
        queries = []

        def hook(now):
            if r.read("conn.Sock.FbStatus.Busy") and not queries:
                queries.append(now - reconnected)
        assert not r.until(lambda: not r.read("conn.Connected") or r.read("conn.Sock.Lost"), 0.5, on_scan=hook)
        assert queries and queries[0] <= 150_000_000, queries
    finally:
        r.close()
