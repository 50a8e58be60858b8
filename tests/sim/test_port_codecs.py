"""The simulator's three ports through their protocol objects' byte interface, with no socket (issue 22 step 2,
pymodbus discipline): the Listen node (ListenSession and its ListenProtocol), the Ethernet Slave (SvrSession) and
the control channel (ControlProtocol, answering through the channel's command table) each get the same byte
stream whole, split in two at every position, byte by byte and glued into one piece, and answer the same in
every case. A port's answers may not depend on how TCP cut its input."""
import json

import pytest
from sim_harness import Harness

from tmsim.limits import CONTROL_LINE_MAX, CONTROL_OUTBOX_MAX, CONTROL_TURN_PIECES, CONTROL_TURN_REQUESTS
from tmsim.protocol import codec
from tmsim.protocol.control import (
    CLOSED,
    INPUT_DONE,
    INPUT_LEFT,
    ControlProtocol,
    RequestError,
    Streamed,
    decode_request,
    next_line,
)
from tmsim.protocol.listen_protocol import ListenProtocol
from tmsim.tmscript.work import WorkMeter


def feeds(stream: bytes, frames: list[bytes]):
    """(name, chunks) for every way of cutting ``stream``; ``frames`` are its messages in order."""
    yield "whole", list(frames)
    for cut in range(1, len(stream)):
        yield f"split at {cut}", [stream[:cut], stream[cut:]]
    yield "byte by byte", [stream[i:i + 1] for i in range(len(stream))]
    yield "glued", [stream]


def answers_by_feed(session, frames: list[bytes], drained) -> dict[str, bytes]:
    """Each way of cutting the stream of ``frames`` fed to ``session`` on a fresh connection: {name: answer bytes};
    ``drained(conn)`` is true when the session holds nothing more of that connection."""
    answers, conn = {}, 1000
    for name, chunks in feeds(b"".join(frames), frames):
        conn += 1
        session.connect(conn)
        for chunk in chunks:
            session.receive_data(conn, chunk)
        answers[name] = b"".join(session.data_to_send(conn))
        assert drained(conn), name
        session.disconnect(conn)
    return answers


@pytest.fixture(scope="module")
def h():
    harness = Harness(svr_port=0, svr_options={"period": 0}, control_port=0)
    yield harness
    harness.close()


# ---- Listen node ($TMSCT / $TMSTA) ------------------------------------------------------------------------
LISTEN = [codec.encode("TMSTA", "00"),
          b"noise before a frame",
          b"$TMSTA,2,00,*00\r\n",                       # wrong checksum: CPERR 02
          codec.encode("TMSTA", "01,07"),
          codec.encode("XXXXX", "1,x")]                 # unknown header: CPERR 03


def test_the_listen_node_answers_the_same_however_its_input_is_cut(h):
    session = h.robot.session
    answers = answers_by_feed(session, LISTEN, lambda conn: session.input_bytes(conn) == 0)
    whole = answers["whole"]
    assert [item.header for item in codec.decode_all(bytearray(whole))] == ["TMSTA", "CPERR", "TMSTA", "CPERR"]
    assert b"CPERR,2,02" in whole and b"CPERR,2,03" in whole
    assert {name: answer for name, answer in answers.items() if answer != whole} == {}


class _Node:
    """A stand-in Listen node: it keeps what the protocol hands it and answers every frame with its header."""

    def __init__(self, protocol_events):
        self.now, self.meter, self.items, self.waiting_scripts = 0.0, WorkMeter(), [], 0
        self.protocol = ListenProtocol(self, lambda kind, **fields: protocol_events.append(kind))

    def handle(self, conn, item):
        self.items.append(item)
        if type(item) is codec.Frame:
            self.protocol.send(conn, "TMSTA", item.header)


def test_the_listen_protocol_decodes_for_any_node_the_same_however_its_input_is_cut():
    """The Listen node's bytes are its protocol's (issue 22 step 2): ListenProtocol decodes, limits the CPERR
    answers and logs the frames for any node it serves - here one that is no Listen node at all."""
    stream = b"".join(LISTEN)
    seen = {}
    for name, chunks in feeds(stream, LISTEN):
        events = []
        node = _Node(events)
        node.protocol.connect(1)
        for chunk in chunks:
            node.protocol.receive_data(1, chunk)
        items = [type(item).__name__ for item in node.items if type(item) is not codec.Garbage]   # (noise: per chunk)
        seen[name] = (items, b"".join(node.protocol.data_to_send(1)))
        assert node.protocol.input_bytes(1) == 0 and events.count("frame_in") == 2, name
        assert events.count("frame_out") == 2 and events[0] == "connect", name
    assert seen["whole"][0] == ["Frame", "BadFrame", "Frame", "BadFrame"]
    assert seen["whole"][1] == codec.encode("TMSTA", "TMSTA") * 2
    assert {name: got for name, got in seen.items() if got != seen["whole"]} == {}


# ---- Ethernet Slave ($TMSVR) ------------------------------------------------------------------------------
SVR = [codec.encode("TMSVR", "R1,12,Robot_Link\r\nProject_Run"),
       codec.encode("TMSVR", "W2,2,Nope=1"),                    # unknown item: status 04
       b"$TMSVR,11,R3,12,ESTOP,*00\r\n",                         # wrong checksum: CPERR 02
       codec.encode("TMSVR", "R4,13,[\"Robot_Link\"]")]


def test_the_ethernet_slave_answers_the_same_however_its_input_is_cut(h):
    session = h.robot.svr
    answers = answers_by_feed(session, SVR, lambda conn: not session.has_output(conn))
    whole = answers["whole"]
    replies = codec.decode_all(bytearray(whole), {"TMSVR", "CPERR"})
    assert [item.data.split(b",")[0] for item in replies] == [b"R1", b"W2", b"02", b"R4"]
    assert {name: answer for name, answer in answers.items() if answer != whole} == {}


# ---- control channel (JSON lines) -------------------------------------------------------------------------
CONTROL = [b'{"cmd": "ping"}\n', b'{"cmd": "vision", "robot": 0}\n', b'{"cmd": "ping", "robt": 0}\n',
           b'not json\n', b'{"cmd": "set_input", "name": "End_DI0", "value": 0}\n']


def _keep(_conn):
    """A ``flush`` whose socket takes nothing: every answer stays in the protocol until data_to_send."""
    return True


def _serve(protocol, conn, chunks, execute):
    """Feed ``chunks`` to connection ``conn`` as a server would (each read, then turns until none is left)
    and return the answer bytes; the connection is left connected."""
    for chunk in chunks:
        protocol.receive_data(conn, chunk)
        while protocol.turn(conn, execute, _keep) == INPUT_LEFT:
            pass
    assert protocol.input_bytes(conn) == 0
    return bytes(protocol.data_to_send(conn))


def test_the_control_channel_answers_the_same_however_its_input_is_cut(h):
    """ControlProtocol fed through the channel's command table: the five requests (more than one turn
    takes) get the same five answers whether they come whole, split anywhere, byte by byte or glued."""
    stream = b"".join(CONTROL)
    protocol, answers = ControlProtocol(lambda kind, **fields: None), {}
    for conn, (name, chunks) in enumerate(feeds(stream, CONTROL)):
        protocol.connect(conn)
        answers[name] = _serve(protocol, conn, chunks, h.srv.control.execute)
        protocol.disconnect(conn)
    whole = [json.loads(line) for line in answers["whole"].splitlines()]
    assert [answer["ok"] for answer in whole] == [True, True, False, False, True]
    assert whole[0]["result"] == "pong" and whole[1]["result"]["jobs"] == [] and whole[4]["result"] is None
    assert "unknown field 'robt'" in whole[2]["error"] and "one JSON object" in whole[3]["error"]
    assert {name: answer for name, answer in answers.items() if answer != answers["whole"]} == {}


def _echo(line):
    return {"ok": True, "result": decode_request(line)}


def test_a_control_turn_answers_at_most_its_requests_and_leaves_the_rest_for_the_next():
    protocol = ControlProtocol(lambda kind, **fields: None)
    protocol.connect(1)
    protocol.receive_data(1, b'{"cmd": "ping"}\n' * (CONTROL_TURN_REQUESTS + 2) + b'{"cmd": "pi')
    assert protocol.turn(1, _echo, _keep) == INPUT_LEFT
    assert protocol.data_to_send(1).count(b"\n") == CONTROL_TURN_REQUESTS
    assert protocol.turn(1, _echo, _keep) == INPUT_DONE
    assert protocol.data_to_send(1).count(b"\n") == 2 and protocol.input_bytes(1) == len(b'{"cmd": "pi')


def test_a_control_line_too_long_is_answered_and_ends_the_client():
    events = []
    protocol = ControlProtocol(lambda kind, **fields: events.append((kind, fields)))
    protocol.connect(1)
    protocol.receive_data(1, b"x" * (CONTROL_LINE_MAX + 1))
    assert protocol.turn(1, _echo, _keep) == INPUT_DONE and protocol.closing(1) and not protocol.finished(1)
    answer = json.loads(protocol.data_to_send(1))
    assert answer == {"ok": False, "error": f"request line longer than {CONTROL_LINE_MAX} bytes; connection closed"}
    assert protocol.finished(1) and events == [("control_closed", {"reason": "request line too long"})]


def test_a_control_client_that_reads_no_answers_is_ended_at_the_outbox_bound():
    """Answers of 1 MiB, none taken by the socket: one a turn (CONTROL_TURN_BYTES), and the client is ended
    when an answer is due while more than CONTROL_OUTBOX_MAX bytes wait; what it was not given is handed back
    with ``unsent`` and counts."""
    events = []
    protocol = ControlProtocol(lambda kind, **fields: events.append(fields["reason"]))
    protocol.connect(1)
    protocol.receive_data(1, b'{"cmd": "ping"}\n' * 10)
    big = {"ok": True, "result": "x" * (1 << 20)}
    pending = protocol.data_to_send(1)
    turns = 0
    while protocol.turn(1, lambda line: big, _keep) == INPUT_LEFT:
        turns += 1
        protocol.unsent(1, protocol.data_to_send(1))       # the socket took none of it
    assert turns == CONTROL_OUTBOX_MAX // (1 << 20) and not protocol.is_connected(1) and pending == b""
    assert events == [f"client does not read its answers (more than {CONTROL_OUTBOX_MAX} bytes waiting)"]
    assert protocol.turn(1, _echo, _keep) == CLOSED


def test_a_streamed_control_answer_is_encoded_over_several_turns_and_handed_out_whole():
    numbers = list(range(5 * CONTROL_TURN_PIECES))
    protocol = ControlProtocol(lambda kind, **fields: None)
    protocol.connect(1)
    protocol.receive_data(1, b'{"cmd": "state"}\n{"cmd": "ping"}\n')
    answers = iter([Streamed(ok=True, result=numbers), {"ok": True, "result": "pong"}])
    turns, out = 0, bytearray()
    while protocol.turn(1, lambda line: next(answers), _keep) == INPUT_LEFT:
        turns += 1
        assert protocol.data_to_send(1) == b""                  # never part of an answer
    out += protocol.data_to_send(1)
    assert turns >= 4
    assert [json.loads(line) for line in out.splitlines()] == [{"ok": True, "result": numbers},
                                                                {"ok": True, "result": "pong"}]


def _requests(chunks):
    buf, out = bytearray(), []
    for chunk in chunks:
        buf += chunk
        while True:
            line, used = next_line(buf)
            if not used:
                break
            del buf[:used]
            try:
                out.append(decode_request(line))
            except RequestError as exc:
                out.append(str(exc))
    assert not buf
    return out


def test_the_control_channel_reads_the_same_requests_however_its_input_is_cut():
    stream = b"".join(CONTROL)
    expected = [{"cmd": "ping"}, {"cmd": "vision", "robot": 0}]
    for name, chunks in feeds(stream, CONTROL):
        requests = _requests(chunks)
        assert requests[:2] == expected, name
        assert "unknown field 'robt'" in requests[2] and "one JSON object" in requests[3], name
        assert requests[4] == json.loads(CONTROL[4]), name


def test_an_incomplete_control_line_needs_more_bytes():
    assert next_line(b'{"cmd": "pi') == (None, 0)
    assert next_line(b'{"cmd": "ping"}\n{"cm') == (b'{"cmd": "ping"}', 16)
