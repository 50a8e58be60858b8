"""HTTP API of the HMI server against a fake PLC: what it serves, what it writes and what it refuses."""
from __future__ import annotations

import json

import pytest
from fake_plc import FakePlc
from hmi_http import Client

from cbt_hmi.web.mapping import Mapping, MappingError
from cbt_hmi.web.server import MAX_BODY, HmiServer


def test_main_page_and_script_are_served_with_text_types(client):
    status, body, headers = client.request("/")
    assert status == 200 and b'<script src="hmi.js?v=' in body        # its version: cbt_hmi.web.assets
    assert headers["Content-Type"].startswith("text/html")
    status, _, headers = client.request("/hmi.js")
    assert status == 200 and "javascript" in headers["Content-Type"]


@pytest.mark.parametrize("page", ["index", "connect", "pnp"])
def test_every_listed_page_is_served_from_the_one_page_shell(client, page):
    _, shell, _ = client.request("/")
    status, body, headers = client.request(f"/{page}.html")
    assert status == 200 and body == shell and headers["Content-Type"].startswith("text/html")


@pytest.mark.parametrize("path", ["/nothing.html", "/../web/server.py", "/%2e%2e/Makefile"])
def test_unknown_or_escaping_paths_are_not_found(client, path):
    status, answer = client.json(path)
    assert status == 404 and answer["ok"] is False and "no such page" in answer["error"]


def test_mapping_endpoint_returns_the_variable_table(client):
    status, answer = client.json("/api/mapping")
    assert status == 200
    assert answer["variables"]["MoveAbs_Param"]["type"] == "stCBT_MovAbsParam"
    assert answer["types"]["eCBT_MovCmd_Movement"]["enum"] == {"Line": 0, "PTP": 1}


def test_read_returns_mapped_values_and_the_plc_time(client, fake_plc):
    fake_plc.vars["MoveAbs_ErrorDescrip"] = "Speed range in PTP: 0~100 %"
    status, answer = client.json("/api/read?names=MoveAbs_Busy,MoveAbs_ErrorDescrip,MoveAbs_Param.Speed")
    assert status == 200 and isinstance(answer["time_ns"], int)
    assert answer["values"] == {"MoveAbs_Busy": False, "MoveAbs_ErrorDescrip": "Speed range in PTP: 0~100 %",
                                "MoveAbs_Param.Speed": 0}


def test_read_of_a_whole_array_returns_a_list_of_structs(client):
    status, answer = client.json("/api/read?names=PnP_MoveParameters")
    assert status == 200 and len(answer["values"]["PnP_MoveParameters"]) == 6
    assert set(answer["values"]["PnP_MoveParameters"][0]["TargetPosition"]) == {"X", "Y", "Z", "RX", "RY", "RZ"}


def test_read_of_an_unmapped_variable_is_refused(client):
    status, answer = client.json("/api/read?names=MoveAbs_Busy,Secret_Recipe")
    assert status == 403 and "not in the HMI variable table: Secret_Recipe" in answer["error"]


def test_read_without_names_explains_the_syntax(client):
    status, answer = client.json("/api/read")
    assert status == 400 and "/api/read?names=" in answer["error"]


def test_valid_write_reaches_the_plc_leaf_by_leaf(client, fake_plc):
    values = {"MoveAbs_Param.Speed": 40, "MoveAbs_Param.TargetPosition.X": 412.5,
              "MoveAbs_Param.MovementCommand": "PTP", "PnP_MoveParameters[3].BlendingEnable": True,
              "Connect_AddressIP": "127.0.0.1"}
    status, answer = client.json("/api/write", {"values": values})
    assert status == 200 and answer["ok"] is True
    assert fake_plc.vars["MoveAbs_Param"]["Speed"] == 40
    assert fake_plc.vars["MoveAbs_Param"]["TargetPosition"]["X"] == 412.5
    assert fake_plc.vars["MoveAbs_Param"]["MovementCommand"] == 1
    assert fake_plc.vars["PnP_MoveParameters"][3]["BlendingEnable"] is True
    assert fake_plc.vars["Connect_AddressIP"] == "127.0.0.1"


@pytest.mark.parametrize("values, status, fragment", [
    ({"Secret_Recipe": 1}, 403, "'Secret_Recipe' is not in the HMI variable table"),
    ({"MoveAbs_Param.Nonsense": 1}, 403, "not in the HMI variable table"),
    ({"MoveAbs_Done": True}, 403, "'MoveAbs_Done' is read-only"),
    ({"MoveAbs_Param.Speed": "fast"}, 400, "is UINT: expected a whole number"),
    ({"MoveAbs_Param.Speed": 12.5}, 400, "is UINT: expected a whole number"),
    ({"MoveAbs_Param.Speed": True}, 400, "is UINT: expected a whole number"),
    ({"MoveAbs_Param.Speed": 4501}, 400, "4501 is out of range 1 .. 4500"),
    ({"MoveAbs_Param.Speed": 0}, 400, "0 is out of range 1 .. 4500"),
    ({"MoveAbs_Param.Speed": 1e308}, 400, "'MoveAbs_Param.Speed': 1e+308 is out of range 1 .. 4500"),   # 9 chars
    ({"MoveAbs_Param.Speed": 70000.0}, 400, "'MoveAbs_Param.Speed': 70000 is out of range 1 .. 4500"),
    ({"MoveAbs_Param.AccelTime": 10000}, 400, "10000 is out of range 0 .. 9999"),
    ({"MoveAbs_Param.TargetPosition.X": "1e9"}, 400, "is REAL: expected a number"),
    ({"MoveAbs_Param.TargetPosition.Z": 100001}, 400, "100001 is out of range -100000 .. 100000"),
    ({"ChangeTCP_Param.MomentOfInertia.Ixx": 100001}, 400, "100001 is out of range 0 .. 100000"),
    ({"MoveAbs_Param.BlendingEnable": 1}, 400, "is BOOL: expected true or false"),
    ({"MoveAbs_Param.MovementCommand": "Spline"}, 400, "expected one of Line (0), PTP (1)"),
    ({"MoveAbs_Param.RobotPose.Pose2": 2}, 400, "expected one of Above (0), Below (1)"),
    ({"ReadPos_Position.Joints[1]": 0.0}, 403, "'ReadPos_Position.Joints[1]' is read-only"),
    ({"Connect_AddressIP": "robot.local"}, 400, "is not an IPv4 address"),
    ({"Connect_AddressIP": "1" * 60}, 400, "at most 49 ASCII characters"),
    ({"Connect_Time_Out": 5}, 400, "5 is out of range 10 .. 300"),
    ({}, 400, '"values" must be a non-empty object'),
])
def test_rejected_writes_say_why_and_change_nothing(client, fake_plc, values, status, fragment):
    before = json.dumps(fake_plc.vars, sort_keys=True)
    got, answer = client.json("/api/write", {"values": values})
    assert got == status and answer["ok"] is False and fragment in answer["error"]
    assert json.dumps(fake_plc.vars, sort_keys=True) == before


def test_one_bad_value_rejects_the_whole_batch(client, fake_plc):
    status, answer = client.json("/api/write", {"values": {"MoveAbs_Param.Speed": 30,
                                                           "MoveAbs_Param.AccelTime": 10000}})
    assert status == 400 and "AccelTime" in answer["error"]
    assert fake_plc.vars["MoveAbs_Param"]["Speed"] == 0 and fake_plc.writes == []


def test_oversized_body_is_refused_before_it_is_read(client):
    status, answer = client.json("/api/write", raw=b"{" + b" " * (MAX_BODY + 10) + b"}")
    assert status == 413 and f"limit of {MAX_BODY} bytes" in answer["error"]


@pytest.mark.parametrize("raw, fragment", [(b"{not json", "not valid JSON"), (b"[1, 2]", "must be a JSON object"),
                                            (b"\xff\xfe", "not valid JSON")])
def test_malformed_bodies_are_refused(client, raw, fragment):
    status, answer = client.json("/api/write", raw=raw)
    assert status == 400 and fragment in answer["error"]


def test_unknown_endpoint_is_reported(client):
    status, answer = client.json("/api/format_disk", {"values": {}})
    assert status == 404 and "unknown API endpoint /api/format_disk" in answer["error"]


def test_execute_writes_parameters_then_gives_a_clean_rising_edge(client, fake_plc):
    fake_plc.vars["MoveAbs_Execute"] = True       # left TRUE by a previous command
    status, answer = client.json("/api/execute", {"execute": "MoveAbs_Execute",
                                                  "values": {"MoveAbs_Param.Speed": 35}})
    assert status == 200 and answer["ok"] is True
    execute_writes = [v for p, v in fake_plc.writes if p == "MoveAbs_Execute"]
    assert execute_writes == [False, True]
    assert fake_plc.writes[0] == ("MoveAbs_Param.Speed", 35)


def test_execute_edge_is_seen_by_the_task_even_when_scans_skip_it(client, fake_plc):
    seen = []
    fake_plc.task_every = 3               # two of three scans only advance the clock
    fake_plc.program = lambda plc: seen.append(plc.vars["ProgramControl_Execute"])
    for _ in range(20):
        status, answer = client.json("/api/execute", {"execute": "ProgramControl_Execute"})
        assert status == 200 and answer["ok"] is True
    seen.append(fake_plc.vars["ProgramControl_Execute"])
    edges = sum(1 for before, after in zip(seen, seen[1:], strict=False) if after and not before)
    assert edges == 20, "every Execute request must reach the program as its own rising edge"


def test_execute_refuses_a_variable_that_is_not_an_execute_bit(client):
    status, answer = client.json("/api/execute", {"execute": "MoveAbs_Param.BlendingEnable"})
    assert status == 400 and "must name an Execute variable" in answer["error"]


@pytest.mark.parametrize("values", [[], 0, False, None, "x"])
def test_execute_with_values_that_are_not_an_object_is_refused_not_run_without_them(client, fake_plc, values):
    status, answer = client.json("/api/execute", {"execute": "MoveAbs_Execute", "values": values})
    assert status == 400 and '"values" must be a non-empty object' in answer["error"] and fake_plc.writes == []


def test_execute_with_bad_parameters_sets_nothing(client, fake_plc):
    status, answer = client.json("/api/execute", {"execute": "MoveAbs_Execute",
                                                  "values": {"MoveAbs_Param.Speed": 9000}})
    assert status == 400 and "9000 is out of range" in answer["error"] and fake_plc.writes == []


def test_execute_reports_a_plc_that_is_not_scanning(mapping):
    plc = FakePlc(mapping)
    srv = HmiServer(plc, mapping, port=0)
    srv.start()
    try:
        operator = Client(f"http://127.0.0.1:{srv.port}", srv.access.keys["operator"])
        status, answer = operator.json("/api/execute", {"execute": "Connect_Execute"})
        assert status == 503 and "the PLC is not scanning" in answer["error"]
    finally:
        srv.stop()


def test_mapping_check_lists_every_variable_the_plc_declares_differently(mapping):
    plc = FakePlc(mapping)
    plc.types["MoveAbs_Param.Speed"] = "INT"
    del plc.types["Connect_Time_Out"]
    with pytest.raises(MappingError) as err:
        mapping.check_against_plc(plc)
    text = str(err.value)
    assert "MoveAbs_Param.Speed: the table says UINT, the PLC program declares INT" in text
    assert "Connect_Time_Out: not found in the PLC program" in text


def test_mapping_check_accepts_qualified_library_type_names(mapping):
    plc = FakePlc(mapping)
    plc.types["MoveAbs_Param.MovementCommand"] = "CBT_Commands_Lib\\eCBT_MovCmd_Movement"
    mapping.check_against_plc(plc)


def test_broken_mapping_file_is_reported_with_its_position(tmp_path):
    bad = tmp_path / "mapping.json"
    bad.write_text('{"types": {},\n "variables": {"A": }}', encoding="utf-8")
    with pytest.raises(MappingError, match=r"mapping.json:2:\d+: invalid JSON"):
        Mapping.load(bad)


def test_mapping_with_an_unknown_type_is_refused():
    with pytest.raises(MappingError, match="'A' has unknown type 'stNothing'"):
        Mapping({"types": {}, "variables": {"A": {"type": "stNothing"}}})


def test_post_without_content_length_is_refused(server):
    import http.client
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=5)
    connection.putrequest("POST", "/api/write")
    connection.putheader("Content-Type", "application/json")
    connection.putheader("X-HMI-Key", server.access.keys["operator"])
    connection.endheaders()
    response = connection.getresponse()
    answer = json.loads(response.read())
    connection.close()
    assert response.status == 411 and "needs a Content-Length header" in answer["error"]


def test_date_and_time_is_shown_as_an_iec_literal(client, fake_plc):
    fake_plc.vars["Connect_LastConnTime"] = 1_795_383_758_000_000_000
    status, answer = client.json("/api/read?names=Connect_LastConnTime,Connect_LastLostTime")
    assert answer["values"] == {"Connect_LastConnTime": "DT#2026-11-22-21:42:38", "Connect_LastLostTime": "—"}


@pytest.mark.parametrize("gone", [BrokenPipeError(32, "Broken pipe"), ConnectionResetError(104, "reset")])
def test_a_client_leaving_mid_request_is_one_debug_line_not_a_traceback(server, capsys, caplog, gone):
    caplog.set_level("DEBUG", logger="cbt_hmi")
    try:
        raise gone
    except OSError:
        server.front.handle_error(None, ("127.0.0.1", 50123))
    assert capsys.readouterr().err == ""
    assert [r.getMessage() for r in caplog.records] == [
        f"HMI client 127.0.0.1:50123 left before the answer was sent ({type(gone).__name__})"]


def test_the_server_binds_with_address_reuse_so_a_restart_works_at_once(server):
    import socket
    assert server.front.socket.getsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR)
