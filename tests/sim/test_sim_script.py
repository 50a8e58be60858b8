"""Scripts are bounded the way a robot controller bounds them (issue 12, "One script freezes every robot and
its memory is never freed", "A 5,000-digit number or a very long sum ..."). TMscript 2.24 manual: §2.1 Types
(int 32-bit, float 32-bit, byte 8-bit), §2.2 (int and byte results wrap; a byte constant out of range is an
Error), §2.3 (at most 2048 array elements), §2.5 (a value beyond the float range is an Error).
Every probe gets a reply (OK or ERROR;line), nothing is dropped and the project keeps running."""
import pytest
from sim_harness import Harness, sct, sta

from tmsim.limits import ARRAY_MAX, STATEMENTS_MAX, STEPS_MAX, STRING_MAX, TOKENS_MAX, VARIABLE_BYTES_MAX, VARIABLES_MAX
from tmsim.tmscript import parser as script

PTP_LONG = 'PTP("JPP",90,0,90,0,90,0,10,200,0,false)'


@pytest.fixture
def robot():
    h = Harness()
    h.peer = h.connect()
    yield h
    h.close()


def run(h, text, ident="1"):
    (reply,) = h.request(h.peer, sct(ident, text))
    return reply[1].split(",", 1)[1]


def last_error(h):
    return [e for e in h.robot.events if e["kind"] in ("runtime_error", "script_error")][-1]


def variables(h):
    return h.robot.state()["variables"]


def test_index_far_beyond_the_array_limit_is_an_error_and_allocates_nothing(robot):
    """Probe a[30000000] = 1 (old: 6.9 s frozen, +230 MB kept). [MAN 2.24 §2.3] at most 2048 elements."""
    assert run(robot, "int[] a = {0}\r\na[30000000] = 1") == "ERROR;2"
    assert "outside 0..2047" in last_error(robot)["reason"]
    assert variables(robot)["a"] == [0]
    assert run(robot, f"a[{ARRAY_MAX - 1}] = 7", "2") == "OK"
    assert len(variables(robot)["a"]) == ARRAY_MAX


def test_squaring_an_int_wraps_at_32_bits(robot):
    """Probe: 25 lines of x *= x (old: 21 s frozen, a 4,300+ digit integer). [MAN 2.24 §2.2] int wraps."""
    assert run(robot, "int x = 10\r\n" + "\r\n".join(["x *= x"] * 25)) == "OK"
    assert -2 ** 31 <= variables(robot)["x"] < 2 ** 31


def test_state_answer_after_a_large_integer_computation_is_valid_json():
    from sim_harness import Peer
    from sim_probe import ControlClient

    from tmsim.net.server import SimServer
    srv = SimServer(port=0, control_port=0).start_background()
    try:
        peer = Peer(srv.ports[0])
        peer.sock.setblocking(True)
        peer.sock.sendall(sct("1", "int x = 10\r\n" + "\r\n".join(["x *= x"] * 25)))
        assert srv.robots[0].wait_event("frame_out", timeout=5, header="TMSCT", data="1,OK") is not None
        client = ControlClient(srv.control.port)
        state = client.ask({"cmd": "state"})
        assert state["ok"] and -2 ** 31 <= state["result"]["variables"]["x"] < 2 ** 31
        client.close()
        peer.close()
    finally:
        srv.close()


@pytest.mark.parametrize("text, value", [
    ("int i = 2147483647\r\ni = i + 1", -2147483648),            # [MAN 2.24 §2.2] examples
    ("int i = -2147483648 - 1", 2147483647),
    ("int i = 2147483647\r\ni++", -2147483648),
    ("int i = -2147483648\r\ni = -i", -2147483648),
    ("int i = 0xFFFFFFFF", -1),
    ("byte i = 255\r\ni = i + 1", 0),
    ("byte i = 0\r\ni = i - 100", 156),
])
def test_int_and_byte_results_keep_their_low_bits(robot, text, value):
    assert run(robot, text) == "OK"
    assert variables(robot)["i"] == value


@pytest.mark.parametrize("text, line, reason", [
    ("byte b = -100", 1, "outside the byte range"),                              # [MAN 2.24 §2.2] Error
    ("float f = 3e38\r\nf = f * 10", 2, "outside the float range"),              # [MAN 2.24 §2.5]
    ("float f = 1e400", 1, "outside the float range"),
    ("float f = " + "9" * 5000, 1, "outside the float range"),                   # probe: 5,000-digit number
    ("int i = " + "9" * 5000, 1, "does not fit int"),
    ("int i = 0x1FFFFFFFF", 1, "wider than 32 bits"),
    ("int[] a = {" + ",".join(["1"] * (ARRAY_MAX + 1)) + "}", 1, "at most 2048 elements"),
    ("int x = " + "+".join(["1"] * (TOKENS_MAX // 2 + 1)), 1, f"longer than {TOKENS_MAX} elements"),
    ("int x = " + "+".join(["1"] * 20_000), 1, "longer than"),                  # probe: a very long sum
    ("int x = " + "+".join(["1"] * 150), 1, "nested deeper than 100"),
    ("int x = " + "(" * 3000 + "1" + ")" * 3000, 1, "nested deeper than 100"),
    ('IO["ControlBox"].DO[100000] = 1', 1, "IO index 100000 is outside 0..255"),
])
def test_value_beyond_its_bound_is_an_error_of_its_line(robot, text, line, reason):
    assert run(robot, text) == f"ERROR;{line}"
    assert reason in last_error(robot)["reason"]
    assert run(robot, "ChangeLoad(1)", "2") == "OK"                              # the robot keeps working


def test_string_doubling_stops_at_the_string_limit(robot):
    """Probe: 26 doublings of a string (old: 128 MB; 33 would need 16 GB)."""
    doublings = "\r\n".join(["s = s + s"] * 26)
    assert run(robot, 'string s = "ab"\r\n' + doublings) == f"ERROR;{2 + 15}"     # 2 * 2**16 > 65,536
    assert len(variables(robot)["s"]) == STRING_MAX


def test_variable_memory_of_the_project_is_bounded_and_freed_when_the_node_is_left(robot):
    """Probe: 3,000 scripts declaring 60 KB strings (old: 727 MB held while the flow stayed in the node)."""
    text = "x" * 60_000
    replies = []
    for n in range(VARIABLE_BYTES_MAX // 60_000 + 5):
        replies.append(run(robot, f'string s{n} = "{text}"', str(n)))
        if replies[-1] != "OK":
            break
    assert replies[-1] == "ERROR;1" and len(replies) <= VARIABLE_BYTES_MAX // 60_000 + 1
    assert "variable memory full" in last_error(robot)["reason"]
    assert all(len(k) <= 512 for k in script._CACHE)                                  # long lines not cached
    robot.robot.leave_listen_node()
    robot.robot.enter_listen_node()
    robot.run(0.01)
    assert variables(robot) == {}
    assert run(robot, f'string again = "{text}"', "99") == "OK"


def test_variables_per_project_are_bounded(robot):
    decls = "\r\n".join(f"int v{n} = {n}" for n in range(VARIABLES_MAX + 1))
    assert run(robot, decls) == f"ERROR;{VARIABLES_MAX + 1}"
    assert f"at most {VARIABLES_MAX} variables" in last_error(robot)["reason"]


def test_statements_per_script_are_bounded(robot):
    lines = ["int n = 0"] + ["Resume()"] * STATEMENTS_MAX       # a call with constants counts one token
    assert run(robot, "\r\n".join(lines)) == f"ERROR;{STATEMENTS_MAX + 1}"
    assert "at most 5000 statements" in last_error(robot)["reason"]
    assert "n" not in variables(robot)                       # a compile error runs nothing


def test_tokens_per_script_are_bounded(robot):
    lines = ["int n = 0"] + ["n++"] * (TOKENS_MAX // 3)        # 3 tokens a line (n, ++, end of line)
    assert run(robot, "\r\n".join(lines)) == f"ERROR;{TOKENS_MAX // 3}"
    assert f"longer than {TOKENS_MAX} elements" in last_error(robot)["reason"]


def test_work_of_one_script_is_bounded(robot):
    copies = 2 * STEPS_MAX * 8 // ARRAY_MAX                    # a copy counts 1 step per 8 elements
    text = "int[] b = {" + ",".join(["0"] * ARRAY_MAX) + "}\r\nint[] a = b\r\n" + "\r\n".join(["a = b"] * copies)
    reply = run(robot, text)
    assert reply.startswith("ERROR;") and int(reply[6:]) < copies
    assert f"more than {STEPS_MAX} steps" in last_error(robot)["reason"]


def test_long_sum_queued_behind_a_blocking_script_is_an_error_not_an_internal_error(robot):
    """Probe: a very long sum waiting behind another script (old: 'internal error', the project stopped)."""
    h = robot
    h.peer.send(sct("1", PTP_LONG + "\r\nQueueTag(1,1)"))
    h.peer.send(sct("2", "int x = " + "+".join(["1"] * 3000)))
    assert h.until(lambda: len(h.peer.frames) >= 3, timeout=10)
    assert [t for _, t in h.peer.texts()[-2:]] == ["1,OK", "2,ERROR;1"]
    assert h.robot.state()["node_state"] == "in_node"
    assert not [e for e in h.robot.events if e["kind"] == "internal_error"]
    assert h.request(h.peer, sta("00")) == [("TMSTA", "00,true,Listen1")]


def test_printing_arrays_counts_against_the_work_of_a_script(robot):
    """Each element of an array printed by GetString or '+' costs work (a 2048-float array is ~40 ms of text)."""
    prints = STEPS_MAX // (4 * ARRAY_MAX) + 2
    text = ("float[] f = {" + ",".join(["0.1"] * ARRAY_MAX) + "}\r\n" +
            "\r\n".join([f'string s{n} = GetString(f)' for n in range(prints)]))
    reply = run(robot, text)
    assert reply.startswith("ERROR;") and int(reply[6:]) <= prints + 1
    assert f"more than {STEPS_MAX} steps" in last_error(robot)["reason"]


@pytest.mark.parametrize("text, reason", [
    ('IO["ControlBox"].AO[0] = 1e39', "outside the float range"),
    ('IO["ControlBox"].DO[0] = 1e30', "does not fit int"),
    ("Robot[0].CameraLight = 2147483648", "does not fit int"),
])
def test_an_io_or_robot_write_beyond_its_type_is_an_error_of_its_line(robot, text, reason):
    """IO and Robot[0] points take values as variables of their type do [MAN 2.24 §2.2, §2.5]; the write
    converted 1e30 to a 31-digit Python integer before."""
    assert run(robot, text) == "ERROR;1"
    assert reason in last_error(robot)["reason"]
    assert run(robot, "ChangeLoad(1)", "2") == "OK"
