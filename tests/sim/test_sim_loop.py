"""The serving loop sleeps until the next thing is due (SimServer.next_due) and wakes at once for a socket or a
call from another thread: what is due, on the virtual clock (poll()), then the real loop (start_background())
with its longest sleep raised to a minute, so a reply or event that arrives proves the loop woke for it."""
import threading

import pytest
from sim_harness import Harness, Peer, sct, sta

from tmsim.net.server import SimServer
from tmsim.protocol import codec

PTP_LONG = 'PTP("JPP",90,0,90,0,90,0,10,200,0,false)'
ANSWER_S = 10.0          # wall seconds a test waits for what the loop sends (the loop's sleep is raised to 60)


# ---- what is due, on the virtual clock ------------------------------------------------------------------------

def arrives_at(h, peer, due):
    """A poll just before ``due`` sends ``peer`` nothing, the poll at ``due`` sends it something: what it got."""
    before = len(peer.frames)
    h.srv.poll(due - 0.001)
    peer.pump()
    assert len(peer.frames) == before, f"sent before it was due: {peer.texts()[before:]}"
    h.srv.poll(due)
    assert h.until(lambda: len(peer.frames) > before, timeout=0.01, dt=0.0001), "nothing sent when it was due"
    return peer.texts()[before:]


def test_an_idle_server_has_nothing_due(harness):
    harness.connect()
    harness.run(0.1)
    assert harness.srv.next_due() is None


def test_a_moving_arm_is_due_at_every_poll_until_its_motion_ends(harness):
    peer = harness.connect()
    assert harness.request(peer, sct("m", PTP_LONG)) == [("TMSCT", "m,OK")]
    harness.step()
    assert harness.robot.state()["moving"]
    assert harness.srv.next_due() == harness.srv.now
    assert harness.until(lambda: not harness.robot.state()["moving"], timeout=30, dt=0.05)
    assert harness.srv.next_due() is None


def test_a_paused_arm_has_nothing_due(harness):
    peer = harness.connect()
    assert harness.request(peer, sct("m", PTP_LONG + "\r\nPause()")) == [("TMSCT", "m,OK")]
    harness.step()
    assert harness.robot.state()["paused"] and harness.robot.state()["queue_length"] == 1
    assert harness.srv.next_due() is None


def test_a_sleeping_script_is_due_at_its_deadline_and_answered_then(harness):
    peer = harness.connect()
    peer.send(sct("s", "Sleep(400)"))
    assert harness.until(lambda: harness.robot.state()["buffered_scripts"] == 1)
    started = harness.srv.now
    due = harness.srv.next_due()
    assert due == pytest.approx(started + 0.4, abs=0.006)
    assert arrives_at(harness, peer, due) == [("TMSCT", "s,OK")]


def test_the_listen_node_timeouts_are_due_when_they_expire():
    h = Harness(data_timeout=2.0, connection_timeout=5.0)
    try:
        h.step()
        assert h.srv.next_due() == pytest.approx(h.robot.session.entered_at + 2.0)   # data timeout is first
        h.srv.robots[0].session.configure(data_timeout=None)
        assert h.srv.next_due() == pytest.approx(h.robot.session.entered_at + 5.0)   # connection timeout
        peer = h.connect()
        h.request(peer, sta("00"))
        assert h.srv.next_due() is None                       # a client is connected; no data timeout set
    finally:
        h.close()


def test_a_delayed_reply_is_due_at_its_release_and_leaves_then(harness):
    peer = harness.connect()
    harness.robot.inject("reply_delay", seconds=0.3)
    peer.send(sta("00"))
    assert harness.until(lambda: harness.srv.next_due() is not None, timeout=1)
    due = harness.srv.next_due()
    asked = harness.srv.now
    assert asked < due <= asked + 0.3
    assert arrives_at(harness, peer, due) == [("TMSTA", "00,true,Listen1")]
    assert harness.srv.next_due() is None


def test_glued_replies_are_due_when_the_oldest_has_waited_max_wait(harness):
    peer = harness.connect()
    harness.robot.inject("glue_replies", count=3, max_wait=0.2)
    peer.send(sta("00"))
    assert harness.until(lambda: harness.srv.next_due() is not None, timeout=1)
    due = harness.srv.next_due()
    assert harness.srv.now < due <= harness.srv.now + 0.2
    assert arrives_at(harness, peer, due) == [("TMSTA", "00,true,Listen1")]


def test_split_replies_are_due_at_every_poll_while_pieces_wait(harness):
    peer = harness.connect()
    harness.robot.inject("split_replies", size=4)
    peer.send(sta("00"))
    assert harness.until(lambda: peer.raw_reads, timeout=1)
    assert harness.srv.next_due() == harness.srv.now          # one piece a poll
    assert harness.until(lambda: peer.texts() == [("TMSTA", "00,true,Listen1")], timeout=1)
    assert harness.srv.next_due() is None


def test_the_ethernet_slave_is_due_at_its_next_data_table_while_a_client_listens():
    h = Harness(svr_port=0, svr_options={"period": 0.5})
    try:
        assert h.srv.next_due() is None                       # no client: nothing streamed
        peer = h.connect_svr()
        h.until(lambda: peer.frames, timeout=1)
        due = h.srv.next_due()
        assert due == pytest.approx(h.robot.svr.next_stream) and h.srv.now < due <= h.srv.now + 0.5
        [(header, table)] = arrives_at(h, peer, due)
        assert header == "TMSVR" and table.startswith("1,1,")      # the second data table (IDs 0..9 in turn)
        h.robot.svr.inject("stall")
        assert h.srv.next_due() is None
    finally:
        h.close()


# ---- the real loop -------------------------------------------------------------------------------------------

@pytest.fixture
def long_sleep(monkeypatch):
    """The loop's longest sleep raised to a minute: whatever arrives within ANSWER_S, the loop woke for."""
    monkeypatch.setattr("tmsim.net.server.LOOP_WAIT_MAX_S", 60.0)


def client(port, headers=codec.HEADERS):
    return Peer(port, headers)


def receive(peer, count=1):
    """Read until ``count`` more frames arrived (TimeoutError after ANSWER_S without a byte)."""
    peer.sock.settimeout(ANSWER_S)
    want = len(peer.frames) + count
    while len(peer.frames) < want:
        data = peer.sock.recv(65536)
        if not data:
            raise ConnectionError("the simulator closed the connection")
        peer.rbuf += data
        peer.frames.extend(item for item in codec.decode_all(peer.rbuf, peer.headers)
                           if isinstance(item, codec.Frame))
    return peer.texts()[want - count:]


def sleeping(srv):
    """Wait (bounded) until the loop has slept once: the server is started and idle."""
    flag = threading.Event()
    for _ in range(500):
        if srv.loop_waits:
            return
        flag.wait(0.01)
    raise AssertionError("the serving loop never slept")


def test_an_idle_loop_sleeps_instead_of_polling(long_sleep):
    srv = SimServer(port=0, svr_port=0).start_background()
    try:
        sleeping(srv)
        before = srv.loop_waits
        threading.Event().wait(0.3)                        # the old loop polled 150 times meanwhile
        assert srv.loop_waits - before <= 2
    finally:
        srv.close()


def test_a_request_wakes_the_loop_at_once(long_sleep):
    srv = SimServer(port=0).start_background()
    try:
        sleeping(srv)
        peer = client(srv.ports[0])
        peer.send(sta("00"))
        assert receive(peer) == [("TMSTA", "00,true,Listen1")]
        peer.close()
    finally:
        srv.close()


def test_entering_the_node_from_another_thread_wakes_the_loop_to_send_its_message(long_sleep):
    srv = SimServer(port=0, auto_enter=False).start_background()
    try:
        peer = client(srv.ports[0])
        peer.send(sta("00"))
        assert receive(peer) == [("TMSTA", "00,false,")]
        sleeping(srv)
        woken = srv.wakeups
        srv.robots[0].enter_listen_node()                  # this thread: the Listen node's message waits for the loop
        assert receive(peer) == [("TMSCT", "0,Listen1")]
        assert srv.wakeups > woken
        peer.close()
    finally:
        srv.close()


def test_a_fault_injected_from_another_thread_wakes_the_loop(long_sleep):
    srv = SimServer(port=0).start_background()
    try:
        peer = client(srv.ports[0])
        peer.send(sct("s", "Sleep(100000)"))               # due in 100 s of robot clock
        assert srv.robots[0].wait_event("frame_in", timeout=ANSWER_S, conn=1)
        sleeping(srv)
        srv.robots[0].inject("leave_node", path="Fail")    # the running script is answered as the node is left
        assert receive(peer) == [("TMSCT", "s,OK")]
        peer.close()
    finally:
        srv.close()


def test_a_project_started_from_another_thread_has_its_connection_timeout_served(long_sleep):
    srv = SimServer(port=0, speedup=10, connection_timeout=1.0).start_background()
    robot = srv.robots[0]
    try:
        peer = client(srv.ports[0])
        peer.send(sta("00"))
        receive(peer)
        robot.stop_project()                               # nothing is due while the project is stopped
        peer.close()
        sleeping(srv)
        since = len(robot.events)
        robot.start_project()                              # the loop learns the new timeout from the wake-up
        left = robot.wait_event("state", timeout=ANSWER_S, since=since, event="leave_node")
        assert left is not None and left["reason"] == "connection timeout"
    finally:
        srv.close()


def test_a_delayed_reply_leaves_at_its_time_from_a_sleeping_loop(long_sleep):
    srv = SimServer(port=0, speedup=10).start_background()
    robot = srv.robots[0]
    try:
        peer = client(srv.ports[0])
        robot.inject("reply_delay", seconds=1.0)
        sleeping(srv)
        peer.send(sta("00"))
        asked = robot.wait_event("frame_in", timeout=ANSWER_S, header="TMSTA")
        assert receive(peer) == [("TMSTA", "00,true,Listen1")]
        assert srv.now >= asked["t"] + 1.0 - 1e-6          # not before its time (event times are rounded to 1 us)
        peer.close()
    finally:
        srv.close()


def test_the_data_table_streams_at_its_period_from_a_sleeping_loop(long_sleep):
    srv = SimServer(port=0, speedup=10, svr_port=0, svr_options={"period": 0.5}).start_background()
    try:
        sleeping(srv)
        peer = client(srv.robots[0].svr_port, {"TMSVR", "CPERR"})
        waits = srv.loop_waits
        tables = receive(peer, 5)
        assert [text.split(",")[0] for _, text in tables] == ["0", "1", "2", "3", "4"]
        assert srv.loop_waits - waits <= 5 * 3 + 5         # it slept from one data table to the next
        peer.close()
    finally:
        srv.close()


def test_stop_ends_a_sleeping_loop_at_once(long_sleep):
    before = set(threading.enumerate())
    srv = SimServer(port=0).start_background()
    loop = [thread for thread in threading.enumerate() if thread not in before and thread.name == "tmflow-sim"]
    sleeping(srv)
    srv.stop()                                             # joins the loop for 5 s at most; its sleep is 60 s
    assert len(loop) == 1 and not loop[0].is_alive()
    srv.close()
