"""Fault matrix from the simulator's injection list: each ends in the documented state within its timeout,
no FB stays Busy, and the event log shows no script executed twice or lost."""
import pytest
from rig import move_abs


def go(rig, k, blend=False, rz=10.0):
    rig.set_struct(f"MParam[{k}]", move_abs(BlendingEnable=blend, BlendingValue=10,
                                            TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=rz)))
    rig.write(f"MExec[{k}]", True)


def settled(rig, k):
    return not rig.read(f"movers[{k}].Busy")


def executed_lines(rig):
    return [e["line"] for e in rig.events("motion_start")]


@pytest.mark.parametrize("fault,params", [("split_replies", dict(size=1)), ("split_replies", dict(size=3)),
                                          ("glue_replies", dict(count=3)), ("reply_delay", dict(seconds=0.3))])
def test_stream_faults_still_complete_every_command_once(rig, fault, params):
    rig.robot.inject(fault, **params)
    for k in range(1, 5):
        go(rig, k, blend=k % 2 == 0, rz=5.0 * k)
    done = rig.until(lambda: all(rig.read(f"movers[{k}].Done") for k in range(1, 5)), 10)
    state = {k: (rig.read(f"movers[{k}].Done"), rig.read(f"movers[{k}].ErrorID")) for k in range(1, 5)}
    lines = executed_lines(rig)
    detail = f"movers (Done, ErrorID): {state}; executed: {lines}; connection: " \
             f"{ {n: rig.read('Cobot.' + n) for n in ('Connected', 'LastErrorID', 'BadFrames', 'FramesIn')} }"
    assert done, detail
    assert len(lines) == 4 and len(set(lines)) == 4, detail
    assert rig.read("Cobot.BadFrames") == 0, detail


def test_blended_motion_whose_ok_is_damaged_ends_outcome_unknown_at_the_status_query_not_after_5_s(rig):
    """TMscript 2.24 §15.8: the Listen node works through its packets in order, so the answer to the status
    query asked at once after the damaged frame proves the OK was in it: 16#3005 (outcome unknown), not a
    16#3001 reply timeout 5 s later. The motion ran once and nothing is sent again."""
    go(rig, 1, blend=True)
    rig.robot.inject("corrupt_checksum", count=1, match=",OK")
    start = rig.plc.now_ns
    assert rig.until(lambda: settled(rig, 1), 7)
    assert rig.read("movers[1].Error") and rig.read("movers[1].ErrorID") == 0x3005
    assert rig.plc.now_ns - start < 200_000_000                   # the next status answer, not ReplyTimeout
    assert rig.read("Cobot.BadFrames") == 1 and rig.read("Cobot.Connected")
    rig.until(lambda: False, 2)
    assert len(executed_lines(rig)) == 1 and len(rig.scripts_in()) == 1


def test_non_blended_motion_whose_ok_is_damaged_ends_done_by_its_tag_even_after_the_reply_timeout(rig):
    """The same loss for a motion with a queue tag: found by the status query, it waits for its tag like an
    accepted motion, so a motion longer than ReplyTimeout (5 s) ends Done when it is finished, not 16#3001."""
    rig.set_struct("MParam[1]", move_abs(Speed=5, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=170)))
    rig.write("MExec[1]", True)
    rig.robot.inject("corrupt_checksum", count=1, match=",OK")
    start = rig.plc.now_ns
    assert rig.until(lambda: settled(rig, 1), 30)
    assert rig.read("movers[1].Done"), rig.read("movers[1].ErrorDescrip")
    assert rig.plc.now_ns - start > 5_000_000_000 and rig.read("Cobot.BadFrames") == 1
    assert len(executed_lines(rig)) == 1


def test_corrupted_tag_push_is_recovered_by_status_query(rig):
    go(rig, 1)
    assert rig.until(lambda: rig.read("movers[1].Active"), 1)
    rig.robot.inject("corrupt_checksum", count=1)
    assert rig.until(lambda: rig.read("movers[1].Done"), 5)


@pytest.mark.parametrize("fault,params", [("close_after", dict(frames=1)), ("close_mid_frame", {}),
                                          ("disconnect", {}), ("stop_project", {})])
def test_connection_drop_mid_command_ends_every_waiting_fb_with_error(rig, fault, params):
    for k in range(1, 4):
        go(rig, k, rz=20.0 * k)
    rig.scans(2)
    start = rig.plc.now_ns
    rig.robot.inject(fault, **params)
    assert rig.until(lambda: all(settled(rig, k) for k in range(1, 4)), 2)
    assert rig.plc.now_ns - start <= 1_600_000_000
    for k in range(1, 4):
        assert rig.read(f"movers[{k}].Done") or rig.read(f"movers[{k}].Error")
    assert rig.read("conn.Error") and not rig.read("Cobot.Connected")
    lines = executed_lines(rig)
    assert len(lines) == len(set(lines))


def test_black_hole_ends_waiting_commands_within_link_supervision(rig):
    rig.robot.inject("black_hole")
    go(rig, 1)
    assert rig.until(lambda: settled(rig, 1), 2)
    assert rig.read("movers[1].ErrorID") == 0x200B            # sent, never confirmed: outcome unknown
    assert rig.read("conn.ErrorID") == 0x2006


def test_script_rejected_by_robot_reports_error_lines(rig):
    rig.robot.inject("reply_error", count=1)
    go(rig, 1)
    assert rig.until(lambda: settled(rig, 1), 1)
    assert rig.read("movers[1].ErrorID") == 0x4001 and executed_lines(rig) == []


def test_robot_leaving_listen_node_ends_waiting_motion_and_refuses_new_ones(rig):
    go(rig, 1, rz=80.0)
    assert rig.until(lambda: rig.read("movers[1].Active"), 1)
    rig.robot.inject("leave_node")
    go(rig, 2, blend=True)
    assert rig.until(lambda: settled(rig, 1) and settled(rig, 2), 2)
    assert rig.read("movers[2].ErrorID") == 0x4002
    assert rig.read("movers[1].Done") or rig.read("movers[1].ErrorID") in (0x4003, 0x4004)
    assert rig.read("Cobot.Connected") and not rig.read("Cobot.InListenNode")


def frame(header, data):
    body = f"{header},{len(data.encode())},{data},".encode()
    cs = 0
    for b in body:
        cs ^= b
    return b"$" + body + b"*%02X\r\n" % cs


def feed(rig, raw: bytes):
    """Puts raw bytes into the receive stream as if the socket had delivered them."""
    n = rig.read("Cobot.RxLen")
    for i, b in enumerate(raw):
        rig.write(f"Cobot.RxBuf.Bytes[{n + i}]", b)
    rig.write("Cobot.RxLen", n + len(raw))


@pytest.mark.parametrize("code,error_id", [("01", 0x3011), ("02", 0x3012), ("03", 0x3013), ("04", 0x3014),
                                           ("F1", 0x4002)])
def test_cperr_code_maps_to_its_error_id(rig, code, error_id):
    """A CPERR frame arriving while a script is unanswered ends that script with the code's ErrorID."""
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    feed(rig, frame("CPERR", code))
    rig.scans(2)
    assert rig.read("movers[1].Error") and rig.read("movers[1].ErrorID") == error_id


def test_garbage_and_lower_case_checksum_are_handled_in_the_stream(rig):
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    ident = rig.read("movers[1].CmdID_Ack")
    good = frame("TMSCT", f"{ident},OK")
    lower = good[:-4] + good[-4:-2].lower() + b"\r\n"
    feed(rig, b"xx\r\n" + lower)
    rig.scans(2)
    assert rig.read("movers[1].Done")


def test_frame_fed_byte_by_byte_is_reassembled(rig):
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    raw = frame("TMSCT", f"{rig.read('movers[1].CmdID_Ack')},OK;2")
    for b in raw:
        assert not rig.read("movers[1].Done")
        feed(rig, bytes([b]))
        rig.scans(1)
    rig.scans(1)
    assert rig.read("movers[1].Done")


def test_wrong_checksum_frame_is_dropped_and_counted(rig):
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    raw = bytearray(frame("TMSCT", f"{rig.read('movers[1].CmdID_Ack')},OK"))
    raw[-3] = ord("0") if raw[-3] != ord("0") else ord("1")
    feed(rig, bytes(raw))
    rig.scans(2)
    assert rig.read("movers[1].Busy") and rig.read("Cobot.BadFrames") == 1
    assert rig.read("Cobot.LastErrorID") == 0x3003


def test_unknown_cperr_code_maps_to_generic_protocol_error(rig):
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    feed(rig, frame("CPERR", "09"))
    rig.scans(2)
    assert rig.read("movers[1].ErrorID") == 0x3015


def test_malformed_frame_is_skipped_and_recorded(rig):
    rig.robot.inject("black_hole")
    go(rig, 1, blend=True)
    rig.scans(3)
    ident = rig.read("movers[1].CmdID_Ack")
    feed(rig, b"$TMSCT,x9,junk\r\n" + frame("TMSCT", f"{ident},OK"))
    rig.scans(2)
    assert rig.read("Cobot.LastErrorID") == 0x3002 and rig.read("movers[1].Done")


def test_queue_tag_unknown_to_robot_ends_waiting_motion(rig):
    go(rig, 1, rz=90.0)
    assert rig.until(lambda: rig.read("movers[1].Active"), 1)
    tag = next(int(s.rsplit("QueueTag(", 1)[1].rstrip(")")) for _, s in rig.scripts_in())
    feed(rig, frame("TMSTA", f"01,{tag:02d},none"))
    rig.scans(2)
    assert rig.read("movers[1].ErrorID") == 0x4004


def test_peer_that_is_not_a_tm_robot_is_refused_after_time_out():
    import socket

    from rig import Rig
    r = Rig(connect=False)
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(1)
    try:
        r.write("Port", silent.getsockname()[1])
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Error"), 15)
        assert r.read("conn.ErrorID") == 0x3004
    finally:
        silent.close()
        r.close()
