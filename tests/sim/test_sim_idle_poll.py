"""A poll with nothing to do is cheap (SimServer._poll ends after advancing the robots when no socket was ready,
nothing is left over and every robot is settled) and changes nothing a client or the event log can see, while
the first poll after a client sends, after a timer falls due, and every poll while the arm moves serve what is
there at the same virtual time as a poll that does every step: the same event log, the same frames at the same
polls, as a server whose polls never take the short way."""
import pytest
from sim_harness import Harness, sct, sta

from tmsim.net.server import SimServer

PTP_SHORT = 'PTP("JPP",20,0,90,0,90,0,100,100,0,false)'


@pytest.fixture
def quiet(harness):
    """The harness's robot with one client connected and everything it was sent read: nothing is due."""
    peer = harness.connect()
    harness.run(0.05, dt=0.001)
    assert harness.srv.next_due() is None and peer.frames == []
    return harness, peer


def counting_flushes(srv, monkeypatch):
    """The robots ``srv`` flushes from now on. The sockets are not served in between the robots' advances
    (IO_SLICE_S, wall clock): a poll that a loaded machine stretches would do it, and then every step."""
    monkeypatch.setattr("tmsim.net.server.IO_SLICE_S", 60.0)
    calls = []
    flush = srv.flush

    def counted(robot, only=None):
        calls.append(robot.index)
        flush(robot, only)
    monkeypatch.setattr(srv, "flush", counted)
    return calls


def test_a_poll_with_nothing_due_writes_nothing_logs_nothing_and_flushes_no_robot(quiet, monkeypatch):
    h, peer = quiet
    flushes = counting_flushes(h.srv, monkeypatch)
    events, state = len(h.robot.events), h.robot.state()
    for _ in range(200):
        h.step()
    assert flushes == [] and peer.frames == [] and peer.raw_reads == []
    assert len(h.robot.events) == events
    assert h.robot.state() == state


def test_the_robot_clock_moves_on_with_quiet_polls(quiet):
    h, _peer = quiet
    h.run(0.2, dt=0.001)
    h.robot.inject("reply_error")                  # an event logged between two polls carries the last poll's time
    assert h.robot.events[-1]["kind"] == "fault" and h.robot.events[-1]["t"] == round(h.t, 6)


def test_the_first_poll_after_a_client_sends_answers_it_at_that_poll(quiet):
    h, peer = quiet
    peer.send(sta("00"))
    h.step()
    assert peer.texts() == [("TMSTA", "00,true,Listen1")]
    frame_in, frame_out = [e for e in h.robot.events if e["kind"] in ("frame_in", "frame_out")]
    assert frame_in["t"] == frame_out["t"] == round(h.t, 6)


def test_a_sleep_is_answered_by_the_first_poll_at_its_deadline(quiet):
    h, peer = quiet
    peer.send(sct("s", "Sleep(40)"))
    h.step()
    started, due = h.t, h.srv.next_due()
    assert due == pytest.approx(started + 0.04)
    while h.t + 0.001 < due:
        h.step()
        assert peer.frames == [], f"answered at {h.t}, before its deadline {due}"
    h.step()
    assert h.t >= due and peer.texts() == [("TMSCT", "s,OK")]


def test_a_moving_arm_advances_at_every_poll(quiet):
    h, peer = quiet
    peer.send(sct("m", PTP_SHORT))
    h.step()
    assert peer.texts() == [("TMSCT", "m,OK")] and h.robot.state()["moving"]
    arm = h.robot.session.robot
    previous = arm.current_joints()[0]
    while h.robot.state()["moving"]:
        assert h.srv.next_due() == h.srv.now
        h.step()
        joint = arm.current_joints()[0]
        assert joint > previous or joint == 20.0, f"the arm did not move at the poll of {h.t}"   # (or settles)
        previous = joint
    assert previous == pytest.approx(20.0)


def run_scenario(settle: bool, monkeypatch):
    """A session of every kind of work on 1 ms polls: requests, a Sleep, a motion with its tag push, a delayed
    reply, a data timeout, and a robot error raised on the session directly (no lock, between two polls).
    ``settle`` False: every poll does every step (the short way is never taken). Returns the event log (ports
    left out) and the frames the client got, each with the poll time it arrived at."""
    if not settle:
        advance_all = SimServer._advance_all
        monkeypatch.setattr(SimServer, "_advance_all", lambda srv, now: advance_all(srv, now) and False)
    h = Harness()
    try:
        peer = h.connect()
        got = []

        def run(seconds):
            end = h.t + seconds
            while h.t < end - 1e-9:
                before = len(peer.frames)
                h.step()
                got.extend((round(h.t, 6), text) for text in peer.texts()[before:])
        run(0.05)
        peer.send(sta("00"))
        run(0.02)
        peer.send(sct("s", "Sleep(40)"))
        run(0.1)
        peer.send(sct("m", PTP_SHORT + "\r\nQueueTag(1,1)"))
        run(1.5)
        h.robot.inject("reply_delay", seconds=0.025)
        peer.send(sta("01,1"))
        run(0.1)
        h.robot.clear_faults()
        run(0.05)
        h.robot.session.configure(data_timeout=0.3)    # set on the session directly, between two polls
        run(0.5)                                   # no packet for 0.3 s: the node is left by its Fail path
        h.robot.enter_listen_node()
        run(0.1)
        h.robot.session.fire("robot_fault", reason="raised on the session between two polls")
        run(0.05)
        assert peer.closed
        events = [{k: v for k, v in e.items() if k != "port"} for e in h.robot.events]
        return events, got
    finally:
        h.close()
        monkeypatch.undo()


def test_quiet_polls_leave_the_same_event_log_and_frames_as_polls_that_do_every_step(monkeypatch):
    settled_events, settled_frames = run_scenario(True, monkeypatch)
    full_events, full_frames = run_scenario(False, monkeypatch)
    kinds = {e["kind"] for e in settled_events}
    assert {"frame_in", "frame_out", "motion_end", "state", "closed", "fault"} <= kinds
    assert ("TMSTA", "01,01,true") in [text for _t, text in settled_frames]
    assert settled_frames == full_frames
    assert settled_events == full_events
