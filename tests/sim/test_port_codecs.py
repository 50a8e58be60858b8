"""The simulator's three ports through their protocol objects' byte interface, with no socket (issue 22 step 2,
pymodbus discipline): the Listen node (ListenSession and its ListenProtocol), the Ethernet Slave (SvrSession) and
the control channel (tmsim.protocol.control) each get the same byte stream whole, split in two at every position,
byte by byte and glued into one piece, and answer the same in every case. A port's answers may not depend on how
TCP cut its input."""
import json

import pytest
from sim_harness import Harness

from tmsim.protocol import codec
from tmsim.protocol.control import RequestError, decode_request, next_line
from tmsim.protocol.listen_protocol import ListenProtocol
from tmsim.tmscript.work import WorkMeter


def feeds(stream: bytes, frames: list[bytes]):
    """(name, chunks) for every way of cutting ``stream``; ``frames`` are its messages in order."""
    yield "whole", list(frames)
    for cut in range(1, len(stream)):
        yield f"split at {cut}", [stream[:cut], stream[cut:]]
    yield "byte by byte", [stream[i:i + 1] for i in range(len(stream))]
    yield "glued", [stream]


@pytest.fixture(scope="module")
def h():
    harness = Harness(svr_port=0, svr_options={"period": 0})
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
    stream = b"".join(LISTEN)
    answers, conn = {}, 1000
    for name, chunks in feeds(stream, LISTEN):
        conn += 1
        session.connect(conn)
        for chunk in chunks:
            session.receive_data(conn, chunk)
        answers[name] = b"".join(session.data_to_send(conn))
        assert session.input_bytes(conn) == 0, name
        session.disconnect(conn)
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
    stream = b"".join(SVR)
    answers, conn = {}, 1000
    for name, chunks in feeds(stream, SVR):
        conn += 1
        session.connect(conn)
        for chunk in chunks:
            session.receive_data(conn, chunk)
        answers[name] = b"".join(session.data_to_send(conn))
        assert not session.has_output(conn), name
        session.disconnect(conn)
    whole = answers["whole"]
    replies = codec.decode_all(bytearray(whole), {"TMSVR", "CPERR"})
    assert [item.data.split(b",")[0] for item in replies] == [b"R1", b"W2", b"02", b"R4"]
    assert {name: answer for name, answer in answers.items() if answer != whole} == {}


# ---- control channel (JSON lines) -------------------------------------------------------------------------
CONTROL = [b'{"cmd": "ping"}\n', b'{"cmd": "state", "robot": 0}\n', b'{"cmd": "ping", "robt": 0}\n',
           b'not json\n', b'{"cmd": "set_input", "name": "End_DI0", "value": 1}\n']


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
    expected = [{"cmd": "ping"}, {"cmd": "state", "robot": 0}]
    for name, chunks in feeds(stream, CONTROL):
        requests = _requests(chunks)
        assert requests[:2] == expected, name
        assert "unknown field 'robt'" in requests[2] and "one JSON object" in requests[3], name
        assert requests[4] == json.loads(CONTROL[4]), name


def test_an_incomplete_control_line_needs_more_bytes():
    assert next_line(b'{"cmd": "pi') == (None, 0)
    assert next_line(b'{"cmd": "ping"}\n{"cm') == (b'{"cmd": "ping"}', 16)
