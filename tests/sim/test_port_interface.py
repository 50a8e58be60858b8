"""The simulator's three ports share one interface (issue 22 step 2, h11's model): the Listen node
(ListenSession and its ListenProtocol), the Ethernet Slave (SvrSession) and the control channel (ControlProtocol),
each built here with no server and no socket, take bytes with ``receive_data(conn, bytes)``, give theirs with
``data_to_send(conn)``, report what happened with ``events()`` (drained once, bounded, dropped events counted)
and take ``inject(fault, **params)`` / ``clear_faults()`` / ``configure(**settings)`` / ``config()`` with the same
rules: an unknown fault or setting or a value out of its range is a ValueError naming it, and nothing changes."""
import math

import pytest

from tmsim.limits import CONTROL_LINE_MAX, CPERR_BURST, CPERR_PER_S, CPERR_SETTING_MAX, PORT_EVENTS_MAX
from tmsim.protocol import codec, port_events
from tmsim.protocol import svr_table as table
from tmsim.protocol.control import ControlProtocol
from tmsim.protocol.listen_session import IDLE, IN_NODE, NODE_FAULTS, STOPPED, ListenSession, TransitionError
from tmsim.protocol.port_events import PortEvents
from tmsim.protocol.svr_session import SvrConfigError, SvrSession
from tmsim.tmscript.profiles import Profile


def sct(ident: str, script: str) -> bytes:
    return codec.encode("TMSCT", f"{ident},{script}")


def kinds(events: list[dict]) -> list[str]:
    return [event["kind"] for event in events]


@pytest.fixture
def small_bound(monkeypatch):
    """Ports built while this fixture is active keep at most 3 events for events()."""
    monkeypatch.setattr(port_events, "PORT_EVENTS_MAX", 3)
    return 3


# ---- the shared store of events -------------------------------------------------------------------------
def test_the_store_keeps_events_in_order_until_taken_and_drops_the_oldest_beyond_its_bound():
    store = PortEvents(limit=2)
    store.record("a", n=1)
    assert store.take() == [{"kind": "a", "n": 1}] and store.take() == []
    for n in range(5):
        store.record("b", n=n)
    assert len(store) == 2 and store.dropped == 3
    assert store.take() == [{"kind": "b", "n": 3}, {"kind": "b", "n": 4}]
    assert PortEvents().limit == PORT_EVENTS_MAX


@pytest.mark.parametrize("limit", [0, -1, 2.5, True])
def test_the_store_refuses_a_bound_below_one_event(limit):
    with pytest.raises(ValueError, match=f"at least 1, got {limit!r}"):
        PortEvents(limit=limit)


# ---- Listen node ------------------------------------------------------------------------------------------
def listen_node(**kwargs) -> ListenSession:
    node = ListenSession(**kwargs)
    node.connect(1)
    node.events()                       # the start: state events and the connect
    return node


def test_the_listen_node_takes_bytes_gives_frames_and_reports_events_once():
    node = ListenSession()
    start = node.events()
    assert [(e["kind"], e.get("state")) for e in start] == [("state", IDLE), ("state", IN_NODE)]
    node.connect(1)
    stream = sct("1", "int a = 1") + codec.encode("TMSTA", "00")
    for byte in range(len(stream)):                 # byte by byte: the same as whole
        node.receive_data(1, stream[byte:byte + 1])
    assert node.data_to_send(1) == [codec.encode("TMSCT", "1,OK"), codec.encode("TMSTA", "00,true,Listen1")]
    events = node.events()
    assert kinds(events) == ["connect", "frame_in", "script_line", "frame_in", "frame_out", "frame_out"]
    assert events[0] == {"kind": "connect", "conn": 1, "peer": "127.0.0.1"}
    assert events[-1]["header"] == "TMSTA" and events[-1]["data"] == "00,true,Listen1"
    assert node.events() == [] and node.events_dropped == 0
    assert node.protocol.events() == []             # one store: the node's and its protocol's events


def test_a_listen_node_built_with_a_log_callback_hands_it_the_events_and_keeps_none():
    logged = []
    node = ListenSession(log=lambda kind, **fields: logged.append(kind))
    node.connect(1)
    node.receive_data(1, codec.encode("TMSTA", "00"))
    node.data_to_send(1)
    assert logged == ["state", "state", "connect", "frame_in", "frame_out"] and node.events() == []


def test_the_listen_nodes_events_are_bounded_and_the_dropped_ones_counted():
    node = listen_node()
    queries = PORT_EVENTS_MAX // 2 + 10             # a frame_in and a frame_out each
    node.receive_data(1, codec.encode("TMSTA", "00") * queries)
    assert len(node.data_to_send(1)) == queries
    events = node.events()
    assert len(events) == PORT_EVENTS_MAX and node.events_dropped == 2 * queries - PORT_EVENTS_MAX
    assert kinds(events[-2:]) == ["frame_out", "frame_out"]
    assert node.events() == [] and node.events_dropped == 2 * queries - PORT_EVENTS_MAX


def test_the_listen_protocols_bound_is_the_limits_value(small_bound):
    node = listen_node()
    node.receive_data(1, codec.encode("TMSTA", "00") * 4)
    node.data_to_send(1)
    assert len(node.events()) == small_bound and node.events_dropped == 8 - small_bound


def test_fault_reply_error_answers_the_next_scripts_error_without_running_them():
    node = listen_node()
    node.inject("reply_error", count=2)
    node.receive_data(1, sct("1", "int a = 1") + sct("2", "int b = 2") + sct("3", "int c = 3"))
    assert node.data_to_send(1) == [codec.encode("TMSCT", "1,ERROR;1"), codec.encode("TMSCT", "2,ERROR;1"),
                                    codec.encode("TMSCT", "3,OK")]
    faults = [event for event in node.events() if event["kind"] == "fault"]
    assert faults == [{"kind": "fault", "fault": "reply_error", "id": "1"},
                      {"kind": "fault", "fault": "reply_error", "id": "2"}]
    assert set(node.variables) == {"c"}


def test_clear_faults_ends_reply_error():
    node = listen_node()
    node.inject("reply_error")
    node.clear_faults()
    node.receive_data(1, sct("1", "int a = 1"))
    assert node.data_to_send(1) == [codec.encode("TMSCT", "1,OK")]


@pytest.mark.parametrize("path", ["Pass", "Fail"])
def test_fault_leave_node_leaves_by_the_path_given(path):
    node = listen_node()
    node.inject("leave_node", path=path)
    state = [event for event in node.events() if event["kind"] == "state"]
    assert state == [{"kind": "state", "event": "leave_node", "previous": IN_NODE, "state": IDLE, "path": path,
                      "source": "fault"}]
    node.receive_data(1, sct("1", "int a = 1"))
    assert node.data_to_send(1) == [codec.encode("CPERR", codec.CPERR_NOT_IN_NODE)]
    assert node.exit_path == path


def test_fault_leave_node_outside_the_node_is_refused_and_changes_nothing():
    node = listen_node()
    node.inject("leave_node")
    node.events()
    with pytest.raises(TransitionError, match="not in node"):
        node.inject("leave_node", path="Fail")
    assert node.exit_path == "Pass" and node.events() == []


def test_fault_stop_project_stops_the_project():
    node = listen_node()
    node.inject("stop_project")
    state = [event for event in node.events() if event["kind"] == "state"]
    assert [(e["event"], e["state"]) for e in state] == [("stop_project", STOPPED)]
    assert node.node_state() == STOPPED and not node.project_running()


@pytest.mark.parametrize(("fault", "params", "message"), [
    ("black_hole", {}, "unknown Listen node fault 'black_hole'; the node's faults: reply_error, leave_node, "
                       "stop_project"),
    ("nope", {}, "unknown Listen node fault 'nope'"),
    ("reply_error", {"cnt": 1}, "unknown parameter 'cnt' (known: count)"),
    ("reply_error", {"count": 0}, "count must be 1..1000000, got 0"),
    ("reply_error", {"count": 2.5}, "count must be an integer, got 2.5"),
    ("leave_node", {"path": "Maybe"}, "path must be one of Pass, Fail, got 'Maybe'"),
    ("stop_project", {"now": True}, "unknown parameter 'now' (known: none)"),
])
def test_a_bad_listen_node_fault_is_a_value_error_and_changes_nothing(fault, params, message):
    node = listen_node()
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        node.inject(fault, **params)
    assert node.node_state() == IN_NODE and node.events() == []
    node.receive_data(1, sct("1", "int a = 1"))
    assert node.data_to_send(1) == [codec.encode("TMSCT", "1,OK")]
    assert set(NODE_FAULTS) == {"reply_error", "leave_node", "stop_project"}


def test_configure_sets_the_timeouts_of_the_node():
    node = listen_node()
    assert node.config()["data_timeout"] is None and node.config()["connection_timeout"] is None
    node.configure(data_timeout=2)
    assert node.config()["data_timeout"] == 2.0
    node.advance(1.0)
    assert node.node_state() == IN_NODE
    node.advance(2.5)
    assert node.node_state() == IDLE and node.exit_path == "Fail"
    assert [e.get("reason") for e in node.events() if e["kind"] == "state"] == ["data timeout"]
    node.configure(data_timeout=0, connection_timeout=None)
    assert node.config()["data_timeout"] is None and node.config()["connection_timeout"] is None


def test_configure_sets_the_connection_timeout():
    node = ListenSession()
    node.configure(connection_timeout=1.5)
    node.advance(1.6)
    assert node.node_state() == IDLE
    assert [e.get("reason") for e in node.events() if e["kind"] == "state"][-1] == "connection timeout"


def test_configure_sets_the_profile_for_the_next_script():
    node = listen_node()
    node.receive_data(1, sct("1", "Sleep(1)"))
    node.advance(0.1)
    assert node.data_to_send(1) == [codec.encode("TMSCT", "1,OK")]
    older = Profile(tmflow="1.8", tag_history=8, stop_tags="reached")
    node.configure(profile=older)
    assert node.config()["profile"] == older
    assert (node.robot.tag_history, node.robot.stop_tags) == (8, "reached")
    node.receive_data(1, sct("2", "Sleep(1)"))        # Sleep is not a TMflow 1.8 function
    assert node.data_to_send(1) == [codec.encode("TMSCT", "2,ERROR;1")]


def test_configure_sets_the_cperr_limit_of_bad_packets():
    node = listen_node()
    assert (node.config()["cperr_burst"], node.config()["cperr_per_s"]) == (CPERR_BURST, CPERR_PER_S)
    node.configure(cperr_burst=2, cperr_per_s=0)
    bad = b"$TMSTA,2,00,*00\r\n"                       # wrong checksum: CPERR 02
    node.receive_data(1, bad * 5 + codec.encode("TMSTA", "00"))
    assert node.data_to_send(1) == [codec.encode("CPERR", "02")] * 2 + [codec.encode("TMSTA", "00,true,Listen1")]
    suppressed = [event for event in node.events() if event["kind"] == "cperr_suppressed"]
    assert suppressed == [{"kind": "cperr_suppressed", "conn": 1, "count": 3}]
    node.connect(2)                                   # a new client gets the configured burst
    node.receive_data(2, bad * 3)
    assert len(node.data_to_send(2)) == 2
    assert node.protocol.config() == {"cperr_burst": 2, "cperr_per_s": 0}


@pytest.mark.parametrize(("settings", "message"), [
    ({"auto_enter": False}, "unknown setting 'auto_enter' of the Listen node; known: data_timeout, "
                            "connection_timeout, profile, cperr_burst, cperr_per_s"),
    ({"data_timeout": -1}, "setting 'data_timeout' of the Listen node must be 0 (none) .. 86400 seconds or None, "
                           "got -1"),
    ({"connection_timeout": math.nan}, "setting 'connection_timeout' of the Listen node must be 0 (none) .. 86400"),
    ({"data_timeout": 86_401}, "got 86401"),
    ({"data_timeout": True}, "got True"),
    ({"profile": "2.24"}, "setting 'profile' of the Listen node must be a tmsim.tmscript.profiles.Profile, "
                          "got '2.24'"),
    ({"cperr_burst": 0}, "setting 'cperr_burst' of the Listen node protocol must be an integer "
                         f"1..{CPERR_SETTING_MAX}, got 0"),
    ({"cperr_per_s": CPERR_SETTING_MAX + 1}, f"must be an integer 0..{CPERR_SETTING_MAX}"),
    ({"data_timeout": 5, "cperr_burst": 1.5}, "setting 'cperr_burst'"),    # the good one is not set either
    ({"connection_timeout": 5, "profile": None}, "setting 'profile'"),
])
def test_a_bad_listen_node_setting_is_a_value_error_and_changes_nothing(settings, message):
    node = listen_node()
    before = node.config()
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        node.configure(**settings)
    assert node.config() == before


def test_a_bad_listen_protocol_setting_is_a_value_error_and_changes_nothing():
    protocol = listen_node().protocol
    with pytest.raises(ValueError, match="unknown setting 'data_timeout' of the Listen node protocol; known: "
                                         "cperr_burst, cperr_per_s"):
        protocol.configure(data_timeout=1)
    with pytest.raises(ValueError, match="'cperr_per_s' of the Listen node protocol must be an integer"):
        protocol.configure(cperr_burst=3, cperr_per_s="10")
    assert protocol.config() == {"cperr_burst": CPERR_BURST, "cperr_per_s": CPERR_PER_S}


# ---- Ethernet Slave ---------------------------------------------------------------------------------------
class Source:
    """The values of the data table for a session with no robot: every item at its default, writes kept."""

    auto_mode = True

    def __init__(self):
        self.written = {}

    def values(self, names):
        return {name: self.written.get(name, table.default_value(table.ITEMS[name])) for name in names}

    def write(self, items):
        self.written.update(items)


def svr(**kwargs) -> SvrSession:
    session = SvrSession(Source(), period=0, **kwargs)
    session.connect(1)
    session.events()
    return session


def svr_answers(session: SvrSession) -> list[bytes]:
    return [item.data for item in codec.decode_all(bytearray(b"".join(session.data_to_send(1))),
                                                   {"TMSVR", "CPERR"})]


def test_the_ethernet_slave_takes_bytes_gives_frames_and_reports_events_once():
    session = SvrSession(Source(), period=0)
    session.connect(1, "10.0.0.2")
    stream = codec.encode("TMSVR", "R1,12,Project_Speed") + codec.encode("TMSVR", "W2,2,Project_Speed=50")
    for byte in range(len(stream)):
        session.receive_data(1, stream[byte:byte + 1])
    assert svr_answers(session) == [b"R1,12,Project_Speed=0", b"W2,0,00,OK"]
    events = session.events()
    assert events == [{"kind": "svr_connect", "conn": 1, "peer": "10.0.0.2"},
                      {"kind": "svr_read", "conn": 1, "id": "R1", "mode": 12, "items": ["Project_Speed"]},
                      {"kind": "svr_write", "conn": 1, "id": "W2", "mode": 2, "items": {"Project_Speed": 50}}]
    assert session.events() == [] and session.events_dropped == 0
    assert session.source.written == {"Project_Speed": 50}


def test_an_ethernet_slave_built_with_a_log_callback_hands_it_the_events_and_keeps_none():
    logged = []
    session = SvrSession(Source(), log=lambda kind, **fields: logged.append(kind), period=0)
    session.connect(1)
    assert logged == ["svr_connect"] and session.events() == []


def test_the_ethernet_slaves_events_are_bounded_and_the_dropped_ones_counted(small_bound):
    session = svr()
    session.receive_data(1, codec.encode("TMSVR", "R1,12,ESTOP") * 5)
    assert len(svr_answers(session)) == 5
    events = session.events()
    assert len(events) == small_bound and session.events_dropped == 5 - small_bound
    assert [event["id"] for event in events] == ["R1"] * small_bound


def test_ethernet_slave_fault_stall_leaves_requests_unanswered_until_cleared():
    session = svr()
    session.inject("stall")
    session.receive_data(1, codec.encode("TMSVR", "R1,12,ESTOP"))
    assert session.data_to_send(1) == [] and kinds(session.events()) == ["svr_stalled"]
    session.clear_faults()
    session.receive_data(1, codec.encode("TMSVR", "R2,12,ESTOP"))
    assert svr_answers(session) == [b"R2,12,ESTOP=false"]


def test_ethernet_slave_fault_corrupt_checksum_damages_the_next_frames():
    session = svr()
    session.inject("corrupt_checksum", count=1)
    session.receive_data(1, codec.encode("TMSVR", "R1,12,ESTOP") * 2)
    first, second = session.data_to_send(1)
    assert first != codec.encode("TMSVR", "R1,12,ESTOP=false") and first[:-4] == second[:-4]
    assert second == codec.encode("TMSVR", "R1,12,ESTOP=false")


def test_ethernet_slave_fault_refuse_writes_answers_the_status_and_writes_nothing():
    session = svr()
    session.inject("refuse_writes", status=2)
    session.receive_data(1, codec.encode("TMSVR", "W1,2,Project_Speed=50"))
    assert svr_answers(session) == [b"W1,0,02,WritePermission"] and session.source.written == {}


def test_ethernet_slave_fault_answer_other_item_sends_another_item_in_its_place():
    session = svr()
    session.inject("answer_other_item", item="ESTOP", instead="Project_Run")
    session.receive_data(1, codec.encode("TMSVR", "R1,12,ESTOP"))
    assert svr_answers(session) == [b"R1,12,Project_Run=false"]


@pytest.mark.parametrize(("fault", "params", "message"), [
    ("nope", {}, "unknown Ethernet Slave fault 'nope'; known: stall, corrupt_checksum"),
    ("stall", {"seconds": 1}, "fault 'stall' has no parameter seconds"),
    ("corrupt_checksum", {"count": 0}, "'count' of fault 'corrupt_checksum' must be 1..1000000, got 0"),
    ("refuse_writes", {"status": 8}, "'status' of fault 'refuse_writes' must be 1..7"),
    ("answer_other_item", {"item": "ESTOP", "instead": "Nope"}, "'instead' of fault 'answer_other_item' must name"),
])
def test_a_bad_ethernet_slave_fault_is_a_value_error_and_changes_nothing(fault, params, message):
    session = svr()
    with pytest.raises(ValueError, match=message):
        session.inject(fault, **params)
    session.receive_data(1, codec.encode("TMSVR", "R1,12,ESTOP") + codec.encode("TMSVR", "W2,2,Project_Speed=50"))
    assert session.data_to_send(1) == [codec.encode("TMSVR", "R1,12,ESTOP=false"),
                                       codec.encode("TMSVR", "W2,0,00,OK")]


def test_ethernet_slave_configure_sets_the_data_table_and_the_write_permission():
    session = svr()
    session.configure(items=["ESTOP"], mode=2, period=0.5)
    assert session.config() == {"items": ["Robot_Link", "ESTOP"], "mode": 2, "period": 0.5,
                                "write_permission": True}
    session.advance(0.0)
    assert svr_answers(session) == [b"0,2,Robot_Link=0\r\nESTOP=false"]
    session.advance(0.4)
    assert session.data_to_send(1) == []
    session.advance(0.5)
    assert svr_answers(session) == [b"1,2,Robot_Link=0\r\nESTOP=false"]
    session.configure(write_permission=False)
    session.receive_data(1, codec.encode("TMSVR", "W1,2,Project_Speed=50"))
    assert svr_answers(session) == [b"W1,0,02,WritePermission"]


@pytest.mark.parametrize(("settings", "message"), [
    ({"items": ["Nope"]}, "unknown data table item\\(s\\): Nope"),
    ({"mode": 4}, "stream mode must be 1 \\(binary\\), 2 \\(string\\) or 3 \\(JSON\\), got 4"),
    ({"period": 3601, "write_permission": False}, "stream period must be 0 \\(off\\) .. 3600 s, got 3601"),
])
def test_a_bad_ethernet_slave_setting_is_a_config_error_and_changes_nothing(settings, message):
    session = svr()
    before = session.config()
    with pytest.raises(SvrConfigError, match=message):
        session.configure(**settings)
    assert session.config() == before


# ---- control channel --------------------------------------------------------------------------------------
def execute(line: bytes) -> dict:
    return {"ok": True, "echo": line.decode()}


def flush(conn: int) -> bool:
    return True


def test_the_control_channel_takes_bytes_gives_answers_and_reports_events_once():
    protocol = ControlProtocol()
    protocol.connect(1)
    for byte in b'{"cmd":"ping"}\n':
        protocol.receive_data(1, bytes([byte]))
    protocol.turn(1, execute, flush)
    assert protocol.data_to_send(1) == b'{"ok": true, "echo": "{\\"cmd\\":\\"ping\\"}"}\n'
    assert protocol.events() == []                   # an answered request is no event
    protocol.receive_data(1, b"x" * (CONTROL_LINE_MAX + 1))
    protocol.turn(1, execute, flush)
    assert b"request line longer than" in protocol.data_to_send(1)
    assert protocol.events() == [{"kind": "control_closed", "reason": "request line too long"}]
    assert protocol.events() == [] and protocol.events_dropped == 0


def test_a_control_channel_built_with_a_log_callback_hands_it_the_events_and_keeps_none():
    logged = []
    protocol = ControlProtocol(lambda kind, **fields: logged.append(fields["reason"]))
    protocol.connect(1)
    protocol.receive_data(1, b"x" * (CONTROL_LINE_MAX + 1))
    protocol.turn(1, execute, flush)
    assert logged == ["request line too long"] and protocol.events() == []


def test_the_control_channels_events_are_bounded_and_the_dropped_ones_counted(small_bound):
    protocol = ControlProtocol()
    for conn in range(5):
        protocol.connect(conn)
        protocol.receive_data(conn, b"x" * (CONTROL_LINE_MAX + 1))
        protocol.turn(conn, execute, flush)
    assert kinds(protocol.events()) == ["control_closed"] * small_bound
    assert protocol.events_dropped == 5 - small_bound


@pytest.mark.parametrize("fault", ["reply_delay", "stall", "nope"])
def test_the_control_channel_has_no_faults(fault):
    protocol = ControlProtocol()
    with pytest.raises(ValueError, match=f"the control channel has no faults \\(asked for '{fault}'\\)"):
        protocol.inject(fault, seconds=1)
    protocol.clear_faults()
    protocol.connect(1)
    protocol.receive_data(1, b"{}\n")
    protocol.turn(1, execute, flush)
    assert protocol.data_to_send(1) == b'{"ok": true, "echo": "{}"}\n' and protocol.events() == []


def test_the_control_channel_has_no_settings():
    protocol = ControlProtocol()
    protocol.configure()
    assert protocol.config() == {}
    with pytest.raises(ValueError, match="unknown setting 'requests_per_turn' of the control channel: it has none"):
        protocol.configure(requests_per_turn=8)
    assert protocol.config() == {}
