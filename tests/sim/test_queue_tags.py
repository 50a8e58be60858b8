"""Queue tags as the TMscript 2.24 manual describes them (§13.1 QueueTag, §13.2 WaitQueueTag, §13.3
CheckQueueTag): the last four tags only, 1 / 0 / -1 results, the no-argument wait, and what a stop does."""
import pytest
from session_rig import PTP_LONG, S, sct, sta

from tmsim.protocol import codec
from tmsim.tmscript.profiles import Profile

PTP_SHORT = 'PTP("JPP",0,0,90,0,90,10,100,200,0,false)'


def reply(ident, status):
    return codec.encode("TMSCT", f"{ident},{status}").decode()


_names = iter(range(1_000_000))


def result_of(node, expr, wait=0.0):
    """Run ``int rN = expr`` and return rN as the script ListenSends it (and the frames that came)."""
    name = f"r{next(_names)}"
    frames = node.send(1, sct("R", f"int {name} = {expr}\r\nListenSend(90, GetString({name}))"))
    if wait:
        node.advance(wait)
        frames += node.out(1)
    data = [f for f in frames if f.startswith("$TMSTA") and ",90," in f]
    return (int(data[0].split(",")[3]) if data else None), frames


def status(node, tag):
    """TMSTA 01 answer for ``tag`` (true / false / none)."""
    reply = node.send(1, sta(f"01,{tag:02d}"))
    assert len(reply) == 1 and reply[0].startswith("$TMSTA,") and f",01,{tag:02d}," in reply[0]
    return reply[0].split(",")[4]


@pytest.fixture
def node(node):
    """The shared node (conftest.py) with what connecting sent already read."""
    node.out(1)
    return node


def test_manual_13_2_only_the_last_four_queued_tags_exist_even_while_their_motion_runs(node):
    node.send(1, sct("A", PTP_LONG + "\r\n" + "\r\n".join(f"QueueTag({t})" for t in range(1, 7))))
    assert status(node, 1) == "none"
    assert status(node, 2) == "none"
    assert status(node, 3) == "false"
    node.advance(6.0)
    pushes = [f for f in node.out(1) if ",01," in f]
    assert [p.split(",")[3] for p in pushes] == ["01", "02", "03", "04", "05", "06"]   # forgotten tags still push
    assert status(node, 1) == "none"
    assert status(node, 6) == "true"


def test_manual_13_2_wait_queue_tag_returns_1_when_done_and_minus_1_when_not_existed_without_waiting(node):
    node.send(1, sct("A", PTP_SHORT + "\r\nQueueTag(3)"))
    assert result_of(node, "WaitQueueTag(7, 5000)")[0] == -1          # never queued: no waiting
    assert result_of(node, "WaitQueueTag(3, -1)", wait=3.0)[0] == 1


def test_manual_13_2_timeout_0_checks_once_and_a_positive_timeout_returns_0_when_it_passes(node):
    node.send(1, sct("A", PTP_LONG + "\r\nQueueTag(3)"))
    assert result_of(node, "WaitQueueTag(3, 0)")[0] == 0
    value, frames = result_of(node, "WaitQueueTag(3, 500)")
    assert value is None and frames == []                            # still waiting
    node.advance(0.49)
    assert node.out(1) == []
    node.advance(0.02)
    out = node.out(1)
    assert int(out[0].split(",")[3]) == 0 and out[1] == reply("R", "OK")


def test_manual_13_3_check_queue_tag_is_one_check_1_0_or_minus_1(node):
    node.send(1, sct("A", PTP_SHORT + "\r\nQueueTag(2)"))
    assert result_of(node, "CheckQueueTag(2)")[0] == 0
    assert result_of(node, "CheckQueueTag(9)")[0] == -1
    node.advance(3.0)
    node.out(1)
    assert result_of(node, "CheckQueueTag(2)")[0] == 1
    assert node.send(1, sct("B", "CheckQueueTag(1.5)")) == [reply("B", "OK;1")]     # float -> int: warning
    assert node.send(1, sct("C", 'CheckQueueTag("2")')) == [reply("C", "ERROR;1")]
    assert node.send(1, sct("D", "CheckQueueTag()")) == [reply("D", "ERROR;1")]


@pytest.mark.parametrize("expr,value,delay", [("WaitQueueTag(0)", 0, 0.0), ("WaitQueueTag(0, 0)", 0, 0.0),
                                              ("WaitQueueTag(0, 300)", 0, 0.3), ("WaitQueueTag(16, 1000)", -1, 0.0),
                                              ("WaitQueueTag(-1, 1000)", -1, 0.0)])
def test_manual_13_2_tag_0_waits_for_the_timeout_and_tags_outside_0_to_15_do_not_exist(node, expr, value, delay):
    got, frames = result_of(node, expr)
    if delay:
        assert got is None
        node.advance(delay - 0.02)
        assert node.out(1) == []
        got, _ = result_of_out(node, 0.03)
    assert got == value


def result_of_out(node, seconds):
    node.advance(seconds)
    frames = node.out(1)
    data = [f for f in frames if ",90," in f]
    return (int(data[0].split(",")[3]) if data else None), frames


def test_manual_13_2_syntax_3_wait_queue_tag_without_argument_waits_for_every_queued_motion(node):
    assert node.send(1, sct("A", PTP_SHORT + "\r\n" + PTP_LONG + "\r\nWaitQueueTag()")) == []
    node.advance(5.0)
    assert node.out(1) == []
    node.advance(1.0)
    assert node.out(1) == [reply("A", "OK")]
    assert node.send(1, sct("B", "WaitQueueTag()")) == [reply("B", "OK")]       # idle: at once
    assert node.send(1, sct("C", "int r = WaitQueueTag()")) == [reply("C", "ERROR;1")]   # no return value


def test_a_reused_tag_answers_for_its_latest_queue_tag_not_an_older_one(node):
    node.send(1, sct("A", PTP_SHORT + "\r\nQueueTag(5)\r\n" + PTP_LONG + "\r\nQueueTag(5)"))
    node.advance(2.0)
    assert [f for f in node.out(1) if ",01,05,true" in f]             # the first item pushed
    assert status(node, 5) == "false"   # the second is pending


def test_our_choice_a_stop_forgets_the_tags_it_drops_by_default(node):
    node.send(1, sct("A", PTP_LONG + "\r\nQueueTag(4)"))
    node.advance(0.5)
    node.send(1, sct("S", "StopAndClearBuffer(0)"))
    assert status(node, 4) == "none"
    assert result_of(node, "WaitQueueTag(4)")[0] == -1


def test_our_choice_stop_tags_reached_makes_dropped_tags_answer_true_without_a_push():
    n = S(profile=Profile(stop_tags="reached"))
    n.connect(1)
    n.out(1)
    n.send(1, sct("A", PTP_LONG + "\r\nQueueTag(4)"))
    n.advance(0.5)
    assert n.send(1, sct("S", "StopAndClearBuffer(0)")) == [reply("S", "OK")]
    assert status(n, 4) == "true"
    assert result_of(n, "WaitQueueTag(4)")[0] == 1


def test_a_script_waiting_in_queue_tag_wait_ends_when_a_priority_stop_drops_the_tag(node):
    node.send(1, sct("A", PTP_LONG + "\r\nQueueTag(2,1)"))
    node.advance(0.5)
    # TMscript 2.24 §15.8 example 2: the released script's OK comes before the priority command's
    assert node.send(1, sct("S", "StopAndClearBuffer(0)")) == [reply("A", "OK"), reply("S", "OK")]


def test_sleep_delays_the_rest_of_the_script(node):
    assert node.send(1, sct("A", "Sleep(250)\r\nListenSend(90, \"x\")")) == []
    node.advance(0.24)
    assert node.out(1) == []
    node.advance(0.02)
    assert node.out(1)[-1] == reply("A", "OK")
    assert node.send(1, sct("B", "Sleep(0)")) == [reply("B", "OK")]
    assert node.send(1, sct("C", "Sleep()")) == [reply("C", "ERROR;1")]


@pytest.mark.parametrize("argument", ["1e30", "2147483648"])
def test_sleep_beyond_int_is_an_error_of_its_line_and_the_robot_serves_the_next_script(node, argument):
    """Sleep(int): a value that does not fit int is ERROR;1 (docs/simulator.md "Limits"); it once waited
    10^27 s and the robot answered no script after it."""
    assert node.send(1, sct("A", f"Sleep({argument})")) == [reply("A", "ERROR;1")]
    assert node.send(1, sct("B", "Sleep(100)\r\nint after_sleep = 1")) == []
    node.advance(0.11)
    assert node.out(1) == [reply("B", "OK")] and node.s.variables["after_sleep"] == 1


@pytest.mark.parametrize("wait", ["Sleep(2147483647)", "WaitQueueTag(0, 2147483647)"])
def test_the_longest_legal_wait_keeps_status_queries_answered_and_priority_stop_1_ends_it(node, wait):
    """A 24.8-day wait (INT_MAX ms) is legal TMscript; like on the robot, TMSTA is answered meanwhile,
    StopAndClearBuffer(0) stops the arm and lets the script continue, StopAndClearBuffer(1) ends it
    (TMflow manual, Listen node priority commands) and the next buffered packet runs."""
    assert node.send(1, sct("A", wait) + sct("B", "int after_wait = 1")) == []
    node.advance(3600, dt=10)
    assert node.send(1, sta("00")) == [codec.encode("TMSTA", "00,true,Listen1").decode()]
    assert node.send(1, sct("S0", "StopAndClearBuffer(0)")) == [reply("S0", "OK")]
    node.advance(1)
    assert node.out(1) == []                                     # the script still waits
    assert node.send(1, sct("S1", "StopAndClearBuffer(1)")) == [reply("A", "OK"), reply("S1", "OK"),
                                                                 reply("B", "OK")]
    assert node.s.variables["after_wait"] == 1


@pytest.mark.parametrize("command", ["ScriptExit(0)", "ScriptExit(1)", "StopAndClearBuffer(2)"])
def test_the_longest_sleep_ends_with_every_priority_command_that_ends_a_script(node, command):
    assert node.send(1, sct("A", "Sleep(2147483647)")) == []
    node.advance(60, dt=1)
    assert node.send(1, sct("P", command))[:2] == [reply("A", "OK"), reply("P", "OK")]
    assert node.s.running is None


def test_manual_13_18_to_13_21_pvt_exit_pause_resume_outside_pvt_mode_are_rejected_false_without_effect(node):
    def answer(call):
        name = f"b{next(_names)}"
        frames = node.send(1, sct("B", f"bool {name} = {call}\r\nListenSend(90, GetString({name}))"))
        return frames[0].split(",")[3]
    assert answer("PVTPause()") == "false" and node.s.robot.paused is False
    assert answer("PVTExit()") == "false" and node.s.robot.queue_length == 0
    assert answer("PVTResume()") == "false"
    node.send(1, sct("P", "PVTEnter(0)"))
    assert answer("PVTExit()") == "true"                               # PVTEnter still queued: accepted


def test_manual_13_4_stop_and_clear_buffer_then_a_motion_in_one_script_runs_the_motion_and_pushes_its_tag(node):
    """§13.4: StopAndClearBuffer() stops the robot and clears the commands already in its buffer; the lines after
    it in the same script run as usual (CBT_Move* BufferMode Aborting): the new motion and its tag are queued after
    the clear, the cleared tags never push and answer 'none' (our choice, 'forget')."""
    node.send(1, sct("A", PTP_LONG + "\r\nQueueTag(1)\r\n" + PTP_LONG + "\r\nQueueTag(2)"))
    node.advance(0.5)
    assert node.send(1, sct("B", "StopAndClearBuffer()\r\n" + PTP_SHORT + "\r\nQueueTag(3)")) == [reply("B", "OK")]
    assert status(node, 1) == "none" and status(node, 2) == "none" and status(node, 3) == "false"
    node.advance(6.0)
    pushes = [f.split(",")[3] for f in node.out(1) if ",01," in f]
    assert pushes == ["03"] and status(node, 3) == "true"
