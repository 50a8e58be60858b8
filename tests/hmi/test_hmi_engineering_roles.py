"""Roles that mean something (issue 25, item 2): an engineering setting is refused by the server for the operator
(403, nothing written), not only hidden on the page. Exit Listen Node is one in every structure that has it: one
command with it leaves the robot outside its Listen node and every later command fails 16#4002."""
from __future__ import annotations

import pytest
from hmi_http import Client

ENGINEERING = [
    ("MoveAbs_Param.ExitNode", True), ("MoveRel_Param.ExitNode", True), ("MoveCircle_Param.ExitNode", True),
    ("PnP_MoveParameters[2].ExitNode", True), ("ChangeBase_Param.ExitNode", True),
    ("Connect_AddressIP", "10.0.0.9"), ("Connect_Dest_PortIP", 5891), ("ChangeBase_Param.Transformation.X", 10.0),
    ("ChangeTCP_Param.Weight", 1.0), ("SetOutput_Param.Value", True),
]


@pytest.fixture
def operator(server):
    return Client(f"http://127.0.0.1:{server.port}", server.access.keys["operator"])


@pytest.mark.parametrize("path, value", ENGINEERING)
def test_the_operator_is_refused_an_engineering_setting_and_nothing_is_written(fake_plc, operator, path, value):
    fake_plc.writes.clear()
    status, answer = operator.json("/api/write", {"values": {"MoveAbs_Param.Speed": 20, path: value}})
    assert status == 403, answer
    assert answer["error"].startswith(f"'{path}' is an engineering setting")
    assert "open the engineer address printed at start-up" in answer["error"]
    assert fake_plc.writes == []


def test_exit_listen_node_says_why_it_is_refused(operator):
    status, answer = operator.json("/api/write", {"values": {"MoveAbs_Param.ExitNode": True}})
    assert status == 403 and answer["error"] == (
        "'MoveAbs_Param.ExitNode' is an engineering setting (it would make the robot leave its Listen node): the "
        "operator may not change it; open the engineer address printed at start-up")


def test_an_operator_execute_carrying_exit_listen_node_is_refused_before_anything_is_written(fake_plc, operator):
    fake_plc.writes.clear()
    status, answer = operator.json("/api/execute", {"execute": "MoveAbs_Execute",
                                                    "values": {"MoveAbs_Param.Speed": 20,
                                                               "MoveAbs_Param.ExitNode": True}})
    assert status == 403 and "engineering setting" in answer["error"]
    assert fake_plc.writes == []


def test_the_operator_runs_a_motion_without_exit_listen_node(fake_plc, operator):
    status, answer = operator.json("/api/execute", {"execute": "MoveAbs_Execute",
                                                    "values": {"MoveAbs_Param.Speed": 20}})
    assert status == 200, answer
    assert ("MoveAbs_Param.Speed", 20) in fake_plc.writes


def test_the_engineer_may_set_exit_listen_node(fake_plc, client):
    status, answer = client.json("/api/write", {"values": {"MoveAbs_Param.ExitNode": True}})
    assert status == 200, answer
    assert fake_plc.vars["MoveAbs_Param"]["ExitNode"] is True


def test_the_variable_table_names_exit_listen_node_an_engineering_member(mapping):
    assert mapping.leaves["MoveAbs_Param.ExitNode"].role == "engineer"
    assert mapping.leaves["PnP_MoveParameters[5].ExitNode"].role == "engineer"
    assert mapping.leaves["MoveAbs_Param.Speed"].role == "operator"


@pytest.mark.parametrize("execute, setting", [("MoveRel_Execute", "MoveRel_Param"),
                                              ("MoveAbs_Execute", "MoveAbs_Param"),
                                              ("MoveCircle_Execute", "MoveCircle_Param")])
def test_exit_listen_node_left_ticked_by_the_engineer_does_not_go_with_the_operators_execute(
        fake_plc, operator, client, execute, setting):
    """Driving the demo: the engineer ran one Move Relative with Exit Listen Node; the box stayed TRUE in the PLC,
    and the operator's next Move Relative (its box locked, so it could not untick it) left the Listen node again.
    The operator's Execute is now refused while it is set; the engineer's goes on."""
    fake_plc.vars[setting]["ExitNode"] = True
    fake_plc.writes.clear()
    status, answer = operator.json("/api/execute", {"execute": execute, "values": {f"{setting}.Speed": 20}})
    assert status == 403, answer
    assert answer["error"] == (
        f"Exit Listen Node is ticked for this command ('{setting}.ExitNode', an engineering setting (it would make the "
        "robot leave its Listen node)): the operator may not send it; ask the engineer to clear it. Nothing was sent")
    assert fake_plc.writes == []
    status, answer = client.json("/api/execute", {"execute": execute, "values": {f"{setting}.Speed": 20}})
    assert status == 200, answer
    fake_plc.vars[setting]["ExitNode"] = False
    status, answer = operator.json("/api/execute", {"execute": execute, "values": {f"{setting}.Speed": 20}})
    assert status == 200, answer


def test_each_command_knows_the_engineering_settings_it_carries(mapping):
    assert mapping.execute_settings["MoveRel_Execute"] == ["MoveRel_Param.ExitNode"]
    assert mapping.execute_settings["SetOutput_Execute"] == ["SetOutput_Param.ExitNode"]
    assert mapping.execute_settings["Stop_Execute"] == []
