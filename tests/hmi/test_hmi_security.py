"""HMI access control and server hygiene: every probe of the adversarial review, replayed on loopback.

Each test names the finding it replays (issue "Nobody moves the robot who should not") and asserts the fixed
behaviour: writes only from the HMI's own pages, as JSON, with an access key of a role allowed to change the
variable; malformed requests answered with a clean 4xx; a bounded number of server threads.
"""
from __future__ import annotations

import contextlib
import http.client
import http.server
import json
import socket
import threading

import pytest
from fake_plc import FakePlc, command_program, serving
from hmi_http import Client

from cbt_hmi.web import front
from cbt_hmi.web import server as hmi_server
from cbt_hmi.web.server import HmiServer  # noqa: E402

MOVE = {"execute": "MoveAbs_Execute", "values": {"MoveAbs_Param.TargetPosition.Z": 300.0}}


@pytest.fixture
def plc(fake_plc):
    """The scanning fake PLC of conftest.py under this module's name for it."""
    return fake_plc


@pytest.fixture
def hmi(server):
    """The HMI server of conftest.py (on the fake PLC above) under this module's name for it."""
    return server


@contextlib.contextmanager
def hmi_with(plc, mapping, host: str = "127.0.0.1", **limits):
    """An HMI server with its own bind address and deadlines (front.HttpLimits) on an ephemeral port."""
    server = HmiServer(plc, mapping, host=host, port=0, limits=front.HttpLimits(**limits))
    server.start()
    try:
        yield server
    finally:
        server.stop()


def raw_request(port: int, method: str, path: str, body: bytes = b"", headers: dict | None = None):
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    connection.request(method, path, body=body or None, headers=headers or {})
    response = connection.getresponse()
    payload = response.read()
    connection.close()
    return response.status, payload, response.headers


def read_until_closed(sock) -> bytes:
    answer = b""
    while chunk := sock.recv(4096):
        answer += chunk
    return answer


def test_write_without_an_access_key_is_refused_and_nothing_moves(hmi, plc):
    status, answer = Client(f"http://127.0.0.1:{hmi.port}").json("/api/execute", MOVE)
    assert status == 401 and "monitor mode" in answer["error"]
    assert plc.writes == []


def test_write_with_a_wrong_key_is_refused(hmi, plc):
    status, answer = Client(f"http://127.0.0.1:{hmi.port}", "guessed-key").json("/api/execute", MOVE)
    assert status == 401 and "not valid for this server start" in answer["error"]
    assert plc.writes == []


def test_operator_key_runs_a_command(hmi, plc):
    status, answer = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"]).json("/api/execute", MOVE)
    assert status == 200 and answer["ok"]
    assert plc.read("MoveAbs_Param.TargetPosition.Z") == 300.0


@pytest.mark.parametrize("values", [
    {"Connect_AddressIP": "10.0.0.99"},                       # point the PLC at another robot
    {"Connect_Dest_PortIP": 5999},
    {"ChangeTCP_Param.TCPOffset.Z": 250.0},                    # a different tool
    {"ChangeBase_Param.Transformation.X": 100.0},
    {"SetOutput_Param.Channel": 3},                          # the I/O assignment
])
def test_engineering_settings_need_the_engineer_key(hmi, plc, values):
    operator = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"])
    status, answer = operator.json("/api/write", {"values": values})
    assert status == 403 and "engineering setting" in answer["error"]
    assert plc.writes == []
    engineer = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["engineer"])
    status, answer = engineer.json("/api/write", {"values": values})
    assert status == 200, answer


def test_engineer_only_commands_refuse_the_operator_key(hmi, plc):
    operator = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"])
    status, answer = operator.json("/api/execute", {"execute": "ChangeTCP_Execute"})
    assert status == 403 and plc.writes == []


def test_session_reports_the_role_of_the_key(hmi):
    for key, role in ((None, "monitor"), (hmi.access.keys["operator"], "operator"),
                      (hmi.access.keys["engineer"], "engineer")):
        status, answer = Client(f"http://127.0.0.1:{hmi.port}", key).json("/api/session")
        assert (status, answer["role"]) == (200, role)


@pytest.mark.parametrize("content_type", ["text/plain", "application/x-www-form-urlencoded", "multipart/form-data",
                                          None])
def test_a_simple_cross_site_request_type_is_refused(hmi, plc, content_type):
    """A form or a text/plain fetch needs no CORS preflight; only application/json is accepted."""
    headers = {"X-HMI-Key": hmi.access.keys["operator"]}
    if content_type:
        headers["Content-Type"] = content_type
    status, payload, _ = raw_request(hmi.port, "POST", "/api/execute", json.dumps(MOVE).encode(), headers)
    assert status == 415 and b"application/json" in payload
    assert plc.writes == []


@pytest.mark.parametrize("header, value", [("Origin", "http://attacker.example"),
                                           ("Origin", "http://127.0.0.1:1"),
                                           ("Origin", "null"),
                                           ("Sec-Fetch-Site", "cross-site"),
                                           ("Sec-Fetch-Site", "same-site")])
def test_writes_from_another_origin_are_refused_even_with_the_key(hmi, plc, header, value):
    headers = {"Content-Type": "application/json", "X-HMI-Key": hmi.access.keys["engineer"], header: value}
    status, payload, _ = raw_request(hmi.port, "POST", "/api/execute", json.dumps(MOVE).encode(), headers)
    assert status == 403 and b"own pages" in payload
    assert plc.writes == []


def test_same_origin_browser_write_is_accepted(hmi, plc):
    headers = {"Content-Type": "application/json", "X-HMI-Key": hmi.access.keys["operator"],
               "Origin": f"http://127.0.0.1:{hmi.port}", "Sec-Fetch-Site": "same-origin"}
    status, _, _ = raw_request(hmi.port, "POST", "/api/execute", json.dumps(MOVE).encode(), headers)
    assert status == 200


@pytest.mark.parametrize("method", ["OPTIONS", "PUT", "DELETE", "PATCH"])
def test_no_cors_preflight_is_ever_granted(hmi, method):
    headers = {"Origin": "http://attacker.example", "Access-Control-Request-Method": "POST",
               "Access-Control-Request-Headers": "content-type,x-hmi-key"}
    status, _, answer_headers = raw_request(hmi.port, method, "/api/execute", headers=headers)
    assert status == 405
    assert "Access-Control-Allow-Origin" not in answer_headers


@pytest.mark.parametrize("method", ["GET", "POST"])
def test_dns_rebinding_host_is_refused(hmi, plc, method):
    headers = {"Host": f"rebind.attacker.example:{hmi.port}", "Content-Type": "application/json",
               "X-HMI-Key": hmi.access.keys["operator"]}
    path = "/api/read?names=Connect_AddressIP" if method == "GET" else "/api/execute"
    status, payload, _ = raw_request(hmi.port, method, path, json.dumps(MOVE).encode() if method == "POST" else b"",
                                     headers)
    assert status == 421 and b"addressed to this HMI" in payload
    assert plc.writes == []


def test_localhost_name_is_accepted_on_a_loopback_server(hmi):
    status, _, _ = raw_request(hmi.port, "GET", "/api/session", headers={"Host": f"localhost:{hmi.port}"})
    assert status == 200


@pytest.mark.parametrize("method, path", [("GET", "/api/read?names=Connect_AddressIP,MoveAbs_Param"),
                                          ("GET", "/api/mapping"), ("GET", "/"), ("GET", "/hmi.js"),
                                          ("POST", "/api/execute")])
@pytest.mark.parametrize("host", ["rebind.attacker.example", "127.0.0.1.nip.io", "localhost.attacker.example"])
def test_dns_rebinding_is_refused_on_a_server_bound_to_every_address(plc, mapping, method, path, host):
    """Bound to 0.0.0.0 (the demo's --host 0.0.0.0), the Host check was off: a rebound name read every value
    (writes got 401). Now every request, reads and pages included, must name this server: 421."""
    with hmi_with(plc, mapping, host="0.0.0.0") as server:
        headers = {"Host": f"{host}:{server.port}", "Content-Type": "application/json",
                   "X-HMI-Key": server.access.keys["operator"]}
        status, payload, _ = raw_request(server.port, method, path,
                                         json.dumps(MOVE).encode() if method == "POST" else b"", headers)
    assert status == 421 and b"addressed to this HMI" in payload
    assert plc.writes == []


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost", "192.0.2.10", "[::1]", "[2001:db8::10]"])
def test_an_address_or_this_machine_is_served_on_a_server_bound_to_every_address(plc, mapping, host):
    """What an operator types on a plant network: the PC's IP address (or localhost on the PC itself)."""
    with hmi_with(plc, mapping, host="0.0.0.0") as server:
        status, _, _ = raw_request(server.port, "GET", "/api/read?names=Connect_AddressIP",
                                   headers={"Host": f"{host}:{server.port}"})
        wrong_port, _, _ = raw_request(server.port, "GET", "/api/read?names=Connect_AddressIP",
                                       headers={"Host": f"{host}:{server.port + 1}"})
        machine, _, _ = raw_request(server.port, "GET", "/api/session",
                                    headers={"Host": f"{socket.gethostname()}:{server.port}"})
    assert (status, wrong_port, machine) == (200, 421, 200)


# --- the cross-origin attack in a real browser ---------------------------------------------------------------

ATTACK_PAGE = """<!doctype html><html><body>
<iframe name="sink1"></iframe><iframe name="sink2"></iframe><iframe name="sink3"></iframe>
<form id="plain" method="POST" action="{hmi}api/write" enctype="text/plain" target="sink1">
  <input name='{{"values":{{"MoveRel_Param.TargetPosition.X":50}},"pad":"' value='"}}'></form>
<form id="urlenc" method="POST" action="{hmi}api/execute" target="sink2">
  <input name="execute" value="MoveRel_Execute"></form>
<form id="ip" method="POST" action="{hmi}api/write" enctype="text/plain" target="sink3">
  <input name='{{"values":{{"Connect_AddressIP":"10.66.0.1"}},"pad":"' value='"}}'></form>
<script>
  const done = [];
  fetch("{hmi}api/execute", {{method: "POST", mode: "no-cors", headers: {{"Content-Type": "text/plain"}},
        body: JSON.stringify({move})}}).then(() => done.push("text"), () => done.push("text"));
  fetch("{hmi}api/execute", {{method: "POST", headers: {{"Content-Type": "application/json", "X-HMI-Key": "guess"}},
        body: JSON.stringify({move})}}).then(() => done.push("json"), () => done.push("json"));
  document.getElementById("plain").submit();
  document.getElementById("urlenc").submit();
  document.getElementById("ip").submit();
  window.attackDone = done;
</script></body></html>"""


@pytest.fixture
def attacker_site(hmi):
    page = ATTACK_PAGE.format(hmi=hmi.url, move=json.dumps(MOVE)).encode()

    class Attacker(http.server.BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(page)))
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Attacker)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/"
    server.shutdown()
    server.server_close()


def test_a_page_of_another_origin_cannot_move_the_robot_in_chromium(hmi, plc, attacker_site):
    from browser import Browser, chromium_paths
    if chromium_paths() is None:
        pytest.fail("chromium and chromedriver are needed: run `make browser`")
    browser = Browser()
    try:
        before = hmi.requests
        browser.driver.get(attacker_site)
        # three form posts, a text/plain fetch and the preflight of the JSON fetch all reach the HMI server
        browser.wait_for(lambda d: hmi.requests - before >= 5 and
                         d.execute_script("return window.attackDone && window.attackDone.length === 2"),
                         "the attack page to send all its requests")
    finally:
        browser.close()
    assert plc.writes == []
    assert plc.read("Connect_AddressIP") == "" and plc.read("MoveRel_Param.TargetPosition.X") == 0.0


# --- server hygiene ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("number", [b"9" * 5000, b"-" + b"9" * 5000, b"0." + b"0" * 5000 + b"1",
                                    b"1" * 41 + b"e2"])
def test_a_5000_digit_number_in_a_body_is_a_clean_400_in_the_hmi_own_words(hmi, plc, number):
    """It answered with Python's own text ("Exceeds the limit (4300 digits) for integer string conversion ...
    use sys.set_int_max_str_digits()"); now the HMI says what is wrong, and no Python integer is built."""
    body = b'{"values": {"MoveAbs_Param.Speed": ' + number + b"}}"
    status, answer = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"]).json("/api/write", raw=body)
    assert status == 400
    assert answer["error"] == f"a number in the request has more than {hmi_server.MAX_DIGITS} digits"
    assert plc.writes == []


def test_a_point_number_of_5000_digits_in_the_trail_address_is_a_clean_400(hmi):
    status, payload, _ = raw_request(hmi.port, "GET", "/api/trail?since=" + "9" * 5000)
    assert status == 400 and json.loads(payload)["error"] == "since must be a point number: /api/trail?since=0"


def post_with_content_length(hmi, declared: str, body: bytes = b""):
    """POST /api/write with the operator key and a Content-Length header as given; (status, answer)."""
    connection = http.client.HTTPConnection("127.0.0.1", hmi.port, timeout=5)
    connection.putrequest("POST", "/api/write")
    connection.putheader("Content-Type", "application/json")
    connection.putheader("X-HMI-Key", hmi.access.keys["operator"])
    connection.putheader("Content-Length", declared)
    connection.endheaders(body or None)
    response = connection.getresponse()
    answer = json.loads(response.read())
    connection.close()
    return response.status, answer


@pytest.mark.parametrize("declared", ["-5", "abc", "1.5", "+5", "1_0", "\u00b2"])
def test_a_content_length_that_is_no_whole_number_is_a_clean_400(hmi, plc, declared):
    """-5 answered 413 "request body of -5 bytes exceeds the limit", abc 411 "needs a Content-Length"."""
    status, answer = post_with_content_length(hmi, declared)
    assert (status, answer) == (400, {"ok": False, "error": "Content-Length must be a whole number of bytes"})
    assert plc.writes == []


@pytest.mark.parametrize("extra", [b"Content-Length: 2\r\n", b"Transfer-Encoding: chunked\r\n"],
                         ids=["two_lengths", "length_and_chunked"])
def test_a_body_that_could_be_read_two_ways_is_refused(hmi, plc, extra):
    """Two Content-Length headers, or one beside Transfer-Encoding (RFC 9112 6.3): the first length was taken."""
    body = json.dumps({"values": {"MoveAbs_Param.Speed": 30}}).encode()
    with socket.create_connection(("127.0.0.1", hmi.port), timeout=5) as sock:
        sock.sendall(b"POST /api/write HTTP/1.1\r\nHost: 127.0.0.1:" + str(hmi.port).encode() +
                     b"\r\nContent-Type: application/json\r\nX-HMI-Key: " + hmi.access.keys["operator"].encode() +
                     b"\r\nContent-Length: " + str(len(body)).encode() + b"\r\n" + extra + b"\r\n" + body)
        answer = read_until_closed(sock)
    head, _, payload = answer.partition(b"\r\n\r\n")
    assert head.split(b" ")[1] == b"400" and json.loads(payload) == {
        "ok": False, "error": "the request must have one Content-Length and no Transfer-Encoding"}
    assert plc.writes == []


def test_a_content_length_of_5000_digits_is_413_without_python_text(hmi):
    status, answer = post_with_content_length(hmi, "9" * 5000)
    assert status == 413 and answer["error"] == (f"request body of 999999999999... bytes exceeds the limit of "
                                                 f"{hmi_server.MAX_BODY} bytes")


def test_a_body_shorter_than_its_content_length_gets_408_at_its_deadline(plc, mapping):
    """Content-Length 100 with 4 bytes sent got no answer at all: the connection closed silently after the
    idle timeout. Now the body deadline answers 408 with a JSON error, then closes (0.3 s here)."""
    with hmi_with(plc, mapping, body_s=0.3) as hmi, \
            socket.create_connection(("127.0.0.1", hmi.port), timeout=5) as sock:
        sock.sendall(b"POST /api/write HTTP/1.1\r\nHost: 127.0.0.1:" + str(hmi.port).encode() +
                     b"\r\nContent-Type: application/json\r\nX-HMI-Key: " + hmi.access.keys["operator"].encode() +
                     b"\r\nContent-Length: 100\r\n\r\n{\"va")
        answer = read_until_closed(sock)                         # the server answers, then closes
    head, _, body = answer.partition(b"\r\n\r\n")
    assert head.split(b"\r\n")[0].split(b" ")[1] == b"408"
    assert json.loads(body) == {"ok": False, "error": "the request body did not arrive: Content-Length announced "
                                                      "100 bytes, fewer came within 0.3 s"}
    assert plc.writes == []


def test_a_body_cut_short_by_the_client_closing_its_side_is_a_clean_400(hmi, plc):
    with socket.create_connection(("127.0.0.1", hmi.port), timeout=5) as sock:
        sock.sendall(b"POST /api/write HTTP/1.1\r\nHost: 127.0.0.1:" + str(hmi.port).encode() +
                     b"\r\nContent-Type: application/json\r\nX-HMI-Key: " + hmi.access.keys["operator"].encode() +
                     b"\r\nContent-Length: 100\r\n\r\n{\"va")
        sock.shutdown(socket.SHUT_WR)
        answer = read_until_closed(sock)
    head, _, body = answer.partition(b"\r\n\r\n")
    assert head.split(b"\r\n")[0].split(b" ")[1] == b"400"
    assert json.loads(body)["error"] == "the request body ended after 4 of the 100 bytes that Content-Length announced"


def test_a_deeply_nested_body_is_a_clean_400(hmi):
    body = b"[" * 60000 + b"]" * 60000
    status, answer = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"]).json(
        "/api/write", raw=body[: hmi_server.MAX_BODY])
    assert status == 400


def test_a_nul_in_the_address_is_a_clean_400(hmi):
    with socket.create_connection(("127.0.0.1", hmi.port), timeout=5) as sock:
        sock.sendall(b"GET /hmi.js\x00.png HTTP/1.0\r\nHost: 127.0.0.1:" + str(hmi.port).encode() + b"\r\n\r\n")
        answer = read_until_closed(sock)
    assert answer.startswith(b"HTTP/1.0 400") or answer.startswith(b"HTTP/1.1 400")
    status, _, _ = raw_request(hmi.port, "GET", "/hmi.js%00")
    assert status == 404


def test_garbage_request_line_gets_a_json_4xx(hmi):
    with socket.create_connection(("127.0.0.1", hmi.port), timeout=5) as sock:
        sock.sendall(b"\x16\x03\x01\x02\x00 not http\r\n\r\n")
        answer = read_until_closed(sock)
    head, _, body = answer.partition(b"\r\n\r\n")
    assert b" 400 " in head.split(b"\r\n")[0]
    assert json.loads(body)["ok"] is False


def test_stalled_connections_are_bounded_and_time_out(plc, mapping):
    """600 stalled connections once kept 604 threads: now they hold no thread at all, and each one's header
    deadline answers it 408 and closes it."""
    threads_before = threading.active_count()
    with hmi_with(plc, mapping, header_s=0.25, idle_s=0.25) as hmi:
        stalled = [socket.create_connection(("127.0.0.1", hmi.port), timeout=5) for _ in range(120)]
        try:
            for sock in stalled:
                sock.sendall(b"GET /api/session HTTP/1.0\r\n")          # never finishes the header
            status, _, _ = raw_request(hmi.port, "GET", "/api/session")
            assert status == 200
            assert threading.active_count() <= threads_before + front.WORKERS + 1
            answers = []
            for sock in stalled:                                   # every one ends: 408, then the close
                answer = b""
                while chunk := sock.recv(4096):
                    answer += chunk
                answers.append(answer.split(b" ", 2)[1])
        finally:
            for sock in stalled:
                sock.close()
    assert set(answers) == {b"408"}


def test_many_simultaneous_pollers_are_all_answered(hmi):
    """The listen backlog was 5: with 50 pollers some waited for a SYN retry; now every one is answered."""
    results = []

    def poll():
        status, _, _ = raw_request(hmi.port, "GET", "/api/read?names=MoveAbs_Busy")
        results.append(status)

    threads = [threading.Thread(target=poll) for _ in range(50)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=10)
    assert front.LISTEN_BACKLOG >= 128
    assert sorted(set(results)) == [200] and len(results) == 50


def test_execute_on_a_stopped_plc_writes_nothing(mapping):
    """/api/execute answered 503 after it had already written the values; a 503 now means nothing changed."""
    plc = FakePlc(mapping, command_program)            # never scanned
    with serving(plc, mapping) as server:
        status, answer = Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"]).json(
            "/api/execute", MOVE)
    assert status == 503 and "nothing was written" in answer["error"]
    assert plc.read("MoveAbs_Param.TargetPosition.Z") == 0.0 and plc.read("MoveAbs_Execute") is False


@pytest.mark.parametrize("stops_before", ["the Execute FALSE cycle", "the Execute TRUE cycle"])
def test_execute_when_the_plc_stops_midway_restores_every_value(mapping, monkeypatch, stops_before):
    """The PLC scans when the request arrives, then stops before it has seen Execute TRUE: every value
    written goes back, so the 503 is the truth."""
    plc = FakePlc(mapping, command_program)
    waits = []
    fail_at = 2 if stops_before == "the Execute FALSE cycle" else 3

    def scanning_until_it_stops(self, what):
        waits.append(plc.read("MoveAbs_Execute"))
        if len(waits) == fail_at:
            raise hmi_server.RequestError(f"the PLC is not scanning: {what}", 503)
        plc.scan()                                      # one task cycle passes

    monkeypatch.setattr(HmiServer, "_await_task_cycles", scanning_until_it_stops)
    with serving(plc, mapping) as server:
        status, _ = Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"]).json(
            "/api/execute", MOVE)
    assert status == 503 and len(waits) == fail_at
    assert waits[-1] is (fail_at == 3)                   # the values really were written before the stop
    assert plc.read("MoveAbs_Param.TargetPosition.Z") == 0.0 and plc.read("MoveAbs_Execute") is False


def test_a_write_the_plc_refuses_halfway_leaves_no_partial_change(hmi, plc, monkeypatch):
    real_write = plc.write

    def refuse_speed(path, value):
        if path == "MoveAbs_Param.Speed":
            raise ValueError("refused by the PLC")
        real_write(path, value)

    monkeypatch.setattr(plc, "write", refuse_speed)
    client = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["operator"])
    status, answer = client.json("/api/write", {"values": {"MoveAbs_Param.TargetPosition.X": 123.0,
                                                           "MoveAbs_Param.Speed": 20}})
    assert status == 400 and "nothing was written" in answer["error"]
    assert plc.read("MoveAbs_Param.TargetPosition.X") == 0.0


def test_a_taken_port_is_an_oserror_not_a_traceback(hmi, plc, mapping):
    """The pool was created after the base class bound the socket: a refused bind raised AttributeError."""
    second = HmiServer(plc, mapping, port=hmi.port)
    with pytest.raises(OSError):
        second.start()


@pytest.mark.parametrize("path, expected", [
    ("PnP_MoveParameters", "is a structure or array: write its elements one by one, e.g. 'PnP_MoveParameters[0]."),
    ("PnP_MoveParameters[9].Speed", "the index is outside PnP_MoveParameters[0..5]"),
    ("Secret_Recipe", "is not in the HMI variable table"),
])
def test_writes_that_name_no_single_value_say_why(hmi, path, expected):
    client = Client(f"http://127.0.0.1:{hmi.port}", hmi.access.keys["engineer"])
    status, answer = client.json("/api/write", {"values": {path: 1}})
    assert status == 403 and expected in answer["error"]


def test_get_on_a_write_endpoint_is_405(hmi):
    status, payload, _ = raw_request(hmi.port, "GET", "/api/write")
    assert status == 405 and b"takes POST" in payload
