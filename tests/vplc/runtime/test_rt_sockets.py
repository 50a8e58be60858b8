"""Sysmac socket instructions over real loopback sockets, driven scan by scan on virtual time."""
import socket

import pytest
from rt_helpers import plc_from

DECLS = """
Port : UINT; Adr : STRING[20] := '127.0.0.1'; Go, DoSend, DoRcv, DoStat, DoClose : BOOL;
con : SktTCPConnect; snd : SktTCPSend; rcv : SktTCPRcv; st : SktGetTCPStatus; cls : SktClose;
sock : _sSOCKET; tx : ARRAY[0..9] OF BYTE := [16#41, 16#42, 16#43]; rx : ARRAY[0..15] OF BYTE;
RcvTimeOut : UINT;
"""
BODY = """
con(Execute := Go, SrcTcpPort := 0, DstAdr := Adr, DstTcpPort := Port, Socket => sock);
snd(Execute := DoSend, Socket := sock, SendDat := tx[1], Size := 2);
rcv(Execute := DoRcv, Socket := sock, TimeOut := RcvTimeOut, Size := 16, RcvDat := rx[0]);
st(Execute := DoStat, Socket := sock);
cls(Execute := DoClose, Socket := sock);
"""


@pytest.fixture
def server():
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(64)
    srv.setblocking(False)
    yield srv
    srv.close()


def _accept(srv, conns):
    try:
        c, _ = srv.accept()
        c.setblocking(True)
        c.settimeout(5)
        conns.append(c)
    except BlockingIOError:
        pass


def _connected(tmp_path, server, **kw):
    plc = plc_from(tmp_path, BODY, DECLS, **kw)
    plc.write("Main.Port", server.getsockname()[1])
    plc.write("Main.Go", True)
    conns = []
    plc.scan(0)
    assert plc.read("Main.con.Busy") is True and plc.read("Main.con.Done") is False
    assert plc.run_until(lambda: plc.read("Main.con.Done"), 1_000_000_000, on_scan=lambda t: _accept(server, conns))
    assert plc.run_until(lambda: bool(conns), 1_000_000_000, on_scan=lambda t: _accept(server, conns))
    return plc, conns[0]


def _pulse(plc, flag, done_var, timeout_ns=1_000_000_000):
    plc.write(flag, True)
    plc.scan(plc.now_ns + plc.period_ns)
    busy = plc.read(done_var.rsplit(".", 1)[0] + ".Busy")
    ok = plc.run_until(lambda: plc.read(done_var.rsplit(".", 1)[0] + ".Done") or
                       plc.read(done_var.rsplit(".", 1)[0] + ".Error"), timeout_ns)
    plc.write(flag, False)
    plc.scan(plc.now_ns + plc.period_ns)
    return busy, ok


def test_connect_is_busy_for_a_scan_then_done_with_a_handle(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    assert plc.read("Main.sock.Handle") > 0
    assert plc.read("Main.sock.DstAdr.PortNo") == server.getsockname()[1]
    peer.close()
    plc.close()


def test_send_leaves_in_the_scan_it_is_started_done_comes_a_call_later(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    plc.write("Main.DoSend", True)
    plc.scan(plc.now_ns + plc.period_ns)
    assert plc.read("Main.snd.Busy") and not plc.read("Main.snd.Done")
    assert peer.recv(10) == b"BC"                   # on the wire before the instruction is called again
    plc.scan(plc.now_ns + plc.period_ns)
    assert plc.read("Main.snd.Done") and not plc.read("Main.snd.Busy")
    plc.close()
    peer.close()


def test_send_array_from_an_element_reaches_the_peer(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    busy, ok = _pulse(plc, "Main.DoSend", "Main.snd.Done")
    assert busy and ok
    assert peer.recv(10) == b"BC"
    plc.close()
    peer.close()


def test_receive_copies_waiting_bytes_and_reports_the_size(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    peer.sendall(b"hello")
    plc.write("Main.DoStat", True)
    assert plc.run_until(lambda: plc.read("Main.st.Done"), 100_000_000)
    assert plc.read("Main.st.TcpStatus") == "_ESTABLISHED"
    assert plc.read("Main.st.DatRcvFlag") is True
    busy, ok = _pulse(plc, "Main.DoRcv", "Main.rcv.Done")
    assert ok and plc.read("Main.rcv.RcvSize") == 5
    assert bytes(plc.read("Main.rx")[:5]) == b"hello"
    plc.close()
    peer.close()


def test_receive_with_timeout_zero_waits_busy_until_data_arrives_seconds_later(tmp_path, server):
    """W506 9-2 (SktTCPRcv monitors the receive timeout) and Sysmac field code: TimeOut 0 = no timeout."""
    plc, peer = _connected(tmp_path, server)
    plc.write("Main.DoRcv", True)
    start = plc.now_ns
    sent = []

    def reply_after_3s(t):
        if not sent and t - start >= 3_000_000_000:
            peer.sendall(b"OK")
            sent.append(t)
    assert not plc.run_until(lambda: plc.read("Main.rcv.Done") or plc.read("Main.rcv.Error"), 2_900_000_000,
                             on_scan=reply_after_3s)
    assert plc.read("Main.rcv.Busy") is True
    assert plc.run_until(lambda: plc.read("Main.rcv.Done"), 5_000_000_000, on_scan=reply_after_3s)
    assert not plc.read("Main.rcv.Error") and plc.read("Main.rcv.RcvSize") == 2
    assert bytes(plc.read("Main.rx")[:2]) == b"OK"
    plc.close()
    peer.close()


def test_receive_with_timeout_in_tenths_of_a_second_ends_with_2006(tmp_path, server):
    """TimeOut counts 0.1 s units: TimeOut 5 and nothing arriving ends with Error after 0.5 s, not before."""
    plc, peer = _connected(tmp_path, server)
    plc.write("Main.RcvTimeOut", 5)
    plc.write("Main.DoRcv", True)
    start = plc.now_ns
    assert plc.run_until(lambda: plc.read("Main.rcv.Error"), 1_000_000_000)
    assert plc.read("Main.rcv.ErrorID") == 0x2006
    assert plc.now_ns - start >= 500_000_000
    plc.close()
    peer.close()


def test_peer_close_shows_close_wait_and_send_then_fails_with_2007(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    peer.close()
    plc.write("Main.DoStat", True)
    assert plc.run_until(lambda: plc.read("Main.st.Done"), 100_000_000)
    assert plc.read("Main.st.TcpStatus") == "_CLOSE_WAIT"
    plc.write("Main.DoSend", True)
    plc.scan(plc.now_ns + plc.period_ns)
    assert plc.run_until(lambda: plc.read("Main.snd.Error"), 100_000_000)
    assert plc.read("Main.snd.ErrorID") == 0x2007
    plc.close()


def test_close_releases_the_handle_and_a_second_close_reports_2003(tmp_path, server):
    plc, peer = _connected(tmp_path, server)
    _busy, ok = _pulse(plc, "Main.DoClose", "Main.cls.Done")
    assert ok and plc.read("Main.cls.Done") is False and not plc.engine.sockets.conns
    plc.write("Main.DoClose", True)
    plc.scan(plc.now_ns + plc.period_ns)
    assert plc.run_until(lambda: plc.read("Main.cls.Error"), 100_000_000)
    assert plc.read("Main.cls.ErrorID") == 0x2003
    peer.close()


def test_connection_refused_and_bad_address_give_documented_error_ids(tmp_path, free_port):
    port = free_port()                                 # reserved, and nothing listens there
    plc = plc_from(tmp_path, BODY, DECLS)
    plc.write("Main.Port", port)
    plc.write("Main.Go", True)
    assert plc.run_until(lambda: plc.read("Main.con.Error"), 1_000_000_000)
    assert plc.read("Main.con.ErrorID") == 0x2008
    plc2 = plc_from(tmp_path, BODY, DECLS)
    plc2.write("Main.Adr", "robot.local")
    plc2.write("Main.Port", 5890)
    plc2.write("Main.Go", True)
    assert plc2.run_until(lambda: plc2.read("Main.con.Error"), 100_000_000)
    assert plc2.read("Main.con.ErrorID") == 0x2002


def test_one_thousand_connects_end_in_the_socket_limit_error(tmp_path, server):
    plc = plc_from(tmp_path, """ok := 0; full := 0;
        FOR i := 1 TO 1000 DO
            c[i](Execute := TRUE, DstAdr := '127.0.0.1', DstTcpPort := Port);
            IF c[i].Done THEN ok := ok + 1; ELSIF c[i].Error AND c[i].ErrorID = 16#2004 THEN full := full + 1; END_IF;
        END_FOR;""", "c : ARRAY[1..1000] OF SktTCPConnect; i : INT; ok, full : INT; Port : UINT;", socket_limit=30)
    plc.write("Main.Port", server.getsockname()[1])
    conns = []
    plc.run_until(lambda: False, 5_000_000, on_scan=lambda t: _accept(server, conns))
    assert plc.read("Main.full") == 970
    assert 0 < plc.read("Main.ok") <= 30
    plc.close()
    assert not plc.engine.sockets.conns
    for c in conns:
        c.close()


def test_latency_model_delays_completion_by_controller_time(tmp_path, server):
    plc = plc_from(tmp_path, BODY, DECLS, socket_latency_ns=5_000_000)
    plc.write("Main.Port", server.getsockname()[1])
    plc.write("Main.Go", True)
    conns = []
    assert plc.run_until(lambda: plc.read("Main.con.Done"), 1_000_000_000, on_scan=lambda t: _accept(server, conns))
    assert plc.now_ns == 5_000_000
    plc.close()
    for c in conns:
        c.close()


def test_accept_waits_for_a_client_and_times_out_with_2006(tmp_path, free_port):
    port = free_port()
    plc = plc_from(tmp_path, "acc(Execute := Go, SrcTcpPort := Port, TimeOut := 5, Socket => sock);",
                   "acc : SktTCPAccept; Go : BOOL; Port : UINT; sock : _sSOCKET;")
    plc.write("Main.Port", port)
    plc.write("Main.Go", True)
    plc.scan(0)
    client = socket.create_connection(("127.0.0.1", port), timeout=5)
    assert plc.run_until(lambda: plc.read("Main.acc.Done"), 100_000_000)
    assert plc.read("Main.sock.Handle") > 0 and plc.read("Main.sock.DstAdr.PortNo") == client.getsockname()[1]
    client.close()
    plc.write("Main.Go", False)
    plc.scan(plc.now_ns + 1_000_000)
    plc.write("Main.Go", True)
    assert plc.run_until(lambda: plc.read("Main.acc.Error"), 1_000_000_000)
    assert plc.read("Main.acc.ErrorID") == 0x2006 and plc.now_ns >= 500_000_000
    plc.close()
