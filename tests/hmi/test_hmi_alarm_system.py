"""The alarm system the server owns (issue 25, item 4; ISA-18.2), sample by sample on a clock the test turns:
states, one alarm per cause with its consequences as details, first-out, priority, alarms that follow the process
condition, refused starts that are no alarms, acknowledge through the API, and a history that survives a
restart and never makes a sample wait for the disk."""
from __future__ import annotations

import json
import os
import threading

import pytest
from fake_plc import FakePlc, command_program
from hmi_http import Client

from cbt_hmi.web import alarms as alarm_module
from cbt_hmi.web.alarms import HISTORY, ON_DELAY_S, AlarmSystem

START = 1_900_000_000.0          # 2030-03-17, whatever the test machine's clock says


class Clock:
    def __init__(self):
        self.now = START

    def __call__(self):
        return self.now


@pytest.fixture
def plant(mapping, tmp_path):
    """A connected robot in its Listen node with its project running; the alarm system sampling on demand. No
    program: the variables hold what the test sets."""
    plc = FakePlc(mapping)
    plc.vars.update(Connect_Execute=True, Connect_Connected=True, Robot_InListenNode=True, RobotStatus_Valid=True)
    plc.vars["RobotStatus"].update(ProjectRunning=True, AutoMode=True)
    clock = Clock()
    system = AlarmSystem(plc, mapping, tmp_path / "alarms.jsonl", clock=clock, monotonic=clock)
    return plc, system, clock


def step(plant, seconds=0.1, times=1):
    plc, system, clock = plant
    for _ in range(times):
        plc.scan()
        clock.now += seconds
        system.sample()
    return system.summary(history=HISTORY)


def listed(summary):
    return [(a["key"], a["state"]) for a in summary["alarms"]]


def test_a_healthy_robot_has_no_alarm_and_reads_ready(plant):
    summary = step(plant, times=20)
    assert summary["alarms"] == [] and summary["robot"] == "ready"


def test_an_alarm_goes_through_the_isa_18_2_states(plant):
    plc, system, _ = plant
    plc.vars["RobotStatus"]["EStop"] = True
    assert listed(step(plant)) == [("estop", "active-unacknowledged")]
    number = step(plant)["alarms"][0]["number"]
    assert system.acknowledge([number], "operator") == 1
    assert listed(step(plant)) == [("estop", "active-acknowledged")]
    plc.vars["RobotStatus"]["EStop"] = False
    summary = step(plant)
    assert summary["alarms"] == []                               # acknowledged and gone: normal
    assert [e["event"] for e in summary["history"]][:4] == ["normal", "returned", "acknowledged", "raised"]


def test_an_alarm_that_returns_unacknowledged_waits_for_its_acknowledge_and_comes_back_as_the_same(plant):
    plc, system, _ = plant
    plc.vars["RobotStatus"]["EStop"] = True
    number = step(plant)["alarms"][0]["number"]
    plc.vars["RobotStatus"]["EStop"] = False
    assert listed(step(plant)) == [("estop", "returned-unacknowledged")]
    plc.vars["RobotStatus"]["EStop"] = True
    summary = step(plant)
    assert listed(summary) == [("estop", "active-unacknowledged")] and summary["alarms"][0]["number"] == number
    plc.vars["RobotStatus"]["EStop"] = False
    step(plant)
    system.acknowledge(None, "operator")
    assert step(plant)["alarms"] == []


def test_an_e_stop_is_one_alarm_with_its_consequences_as_details(plant):
    """The E-stop stops the project with a robot error, the link closes and the running motion fails 16#4006:
    one alarm (the E-stop, high priority, first-out), the rest are its details."""
    plc, _, _ = plant
    plc.vars["RobotStatus"]["EStop"] = True
    step(plant)
    plc.vars["RobotStatus"].update(RobotError=True, ErrorCode=0x10001, ErrorText="Emergency stop",
                                   ProjectRunning=False, ProjectStopped=True)
    plc.vars.update(MoveAbs_Error=True, MoveAbs_ErrorID=0x4006, MoveAbs_ErrorDescrip="Robot error stopped the project",
                    Connect_Connected=False, Connect_Reconnecting=True, Connect_ErrorID=0x4006)
    summary = step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)
    assert listed(summary) == [("estop", "active-unacknowledged")]
    alarm = summary["alarms"][0]
    assert alarm["priority"] == "high" and alarm["first_out"] is True
    details = [d["text"] for d in alarm["details"]]
    assert details == ["Robot: Robot error 16#00010001: Emergency stop",
                       ("Connection 16#4006: Connection to the robot lost, reconnecting — Robot error stopped the "
                        "project"),          # the operator's words: not "code and text in CBT_RobotStatus" (issue 25)
                       "Move Absolute 16#4006: Robot error stopped the project"]
    assert summary["robot"] == "E-stop"


def test_a_consequence_lasting_after_its_cause_raises_no_alarm_until_it_has_cleared(plant):
    """Play restarts the project after a robot error: the robot error returns, the link still reconnects for a
    moment (a consequence of the error): no new alarm for that; a later loss of the link is an alarm again."""
    plc, system, _ = plant
    plc.vars["RobotStatus"].update(RobotError=True, ErrorCode=0x10001, ErrorText="Line: target pose is out of reach")
    step(plant)
    plc.vars.update(Connect_Connected=False, Connect_Reconnecting=True, Connect_ErrorID=0x4006)
    step(plant, times=3)
    plc.vars["RobotStatus"]["RobotError"] = False
    system.acknowledge(None, "operator")
    assert step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)["alarms"] == []
    plc.vars.update(Connect_Connected=True, Connect_Reconnecting=False, Connect_ErrorID=0)
    step(plant)
    plc.vars.update(Connect_Connected=False, Connect_Reconnecting=True, Connect_ErrorID=0x2006)
    assert listed(step(plant, times=int(ON_DELAY_S / 0.1) + 2)) == [("link", "active-unacknowledged")]


def test_the_robot_error_an_e_stop_leaves_becomes_its_own_alarm_once_the_e_stop_is_released(plant):
    """Driving the demo: the E-stop released, its alarm returned and was acknowledged, and the list was empty while
    the robot error it left (and the stopped project) stood until Play: a condition that waits for the operator
    with no alarm. It is an alarm of its own now, back to normal after Play; the E-stop stays one alarm while it is
    pressed, and the link reconnecting after Play still raises none (it clears by itself)."""
    plc, system, _ = plant
    plc.vars["RobotStatus"]["EStop"] = True
    step(plant)
    plc.vars["RobotStatus"].update(RobotError=True, ErrorCode=0x20001, ErrorText="emergency stop pressed",
                                   ProjectRunning=False, ProjectStopped=True)
    plc.vars.update(Connect_Connected=False, Connect_Reconnecting=True, Connect_ErrorID=0x4006)
    assert listed(step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)) == [("estop", "active-unacknowledged")]
    plc.vars["RobotStatus"]["EStop"] = False
    step(plant)
    system.acknowledge(None, "operator")
    summary = step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)
    assert listed(summary) == [("robot", "active-unacknowledged")], listed(summary)
    assert summary["alarms"][0]["text"] == "Robot error 16#00020001: emergency stop pressed"
    assert "press Play on the Main screen" in summary["alarms"][0]["remedy"]
    plc.vars["RobotStatus"].update(RobotError=False, ErrorCode=0, ErrorText="", ProjectRunning=True,
                                   ProjectStopped=False)                          # Play
    system.acknowledge(None, "operator")
    assert step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)["alarms"] == []      # the link still reconnects
    plc.vars.update(Connect_Connected=True, Connect_Reconnecting=False, Connect_ErrorID=0)
    assert step(plant)["alarms"] == []


def test_a_consequence_seen_before_its_cause_waits_for_it(plant):
    """The motion's 16#4006 reaches the PLC a sample before the Ethernet Slave shows the robot error: the on-delay
    lets the robot error take it as a detail instead of raising two alarms."""
    plc, _, _ = plant
    plc.vars.update(MoveAbs_Error=True, MoveAbs_ErrorID=0x4006, MoveAbs_ErrorDescrip="Robot error stopped the project")
    step(plant)
    plc.vars["RobotStatus"].update(RobotError=True, ErrorCode=0x10001, ErrorText="Line: target pose is out of reach")
    summary = step(plant, times=int(2 * ON_DELAY_S / 0.1) + 2)
    assert listed(summary) == [("robot", "active-unacknowledged")]
    assert [d["text"] for d in summary["alarms"][0]["details"]] == [
        "Move Absolute 16#4006: Robot error stopped the project"]


def test_alarms_are_listed_by_priority_and_the_first_out_is_marked(plant):
    plc, _, _ = plant
    plc.vars.update(MoveAbs_Error=True, MoveAbs_ErrorID=0x3001, MoveAbs_ErrorDescrip="No reply from robot")
    step(plant, times=int(ON_DELAY_S / 0.1) + 2)
    plc.vars["RobotStatus"]["EStop"] = True
    summary = step(plant)
    assert [(a["key"], a["priority"], a["first_out"]) for a in summary["alarms"]] == [
        ("estop", "high", False), ("command:Move Absolute", "low", True)]


def test_a_failed_command_is_an_event_that_does_not_stay_active_while_execute_is_held(plant):
    """The page keeps Execute TRUE so Error stays visible; the alarm must not stay active for that."""
    plc, system, _ = plant
    plc.vars.update(MoveAbs_Execute=True, MoveAbs_Error=True, MoveAbs_ErrorID=0x3001,
                    MoveAbs_ErrorDescrip="No reply from robot within ReplyTimeout")
    summary = step(plant, times=int(ON_DELAY_S / 0.1) + 2)
    assert listed(summary) == [("command:Move Absolute", "returned-unacknowledged")]
    assert summary["alarms"][0]["id"] == "16#3001"
    system.acknowledge(None, "operator")
    assert step(plant, times=30)["alarms"] == []                # Error still TRUE: no new alarm for it


@pytest.mark.parametrize("error_id", [0x1013, 0x2001, 0x4005])
def test_a_refused_start_is_a_message_not_an_alarm(plant, error_id):
    plc, _, _ = plant
    plc.vars.update(MoveAbs_Error=True, MoveAbs_ErrorID=error_id, MoveAbs_ErrorDescrip="refused")
    assert step(plant, times=20)["alarms"] == []


def test_leaving_the_listen_node_is_an_alarm_that_returns_when_the_robot_is_back(plant):
    plc, _, _ = plant
    plc.vars["Robot_InListenNode"] = False
    summary = step(plant, times=int(ON_DELAY_S / 0.1) + 2)
    assert listed(summary) == [("listen", "active-unacknowledged")] and summary["robot"] == "left the Listen node"
    assert summary["alarms"][0]["remedy"].startswith("Press Back to Listen Node on the Main screen")
    plc.vars["Robot_InListenNode"] = True
    summary = step(plant)
    assert listed(summary) == [("listen", "returned-unacknowledged")] and summary["robot"] == "ready"


def test_a_first_connect_retried_is_not_called_a_lost_link(plant):
    plc, _, _ = plant
    plc.vars.update(Connect_Connected=False, Connect_Reconnecting=True, Connect_RetryCount=1, Connect_Error=True,
                    Connect_ErrorID=0x2004, Connect_ErrorDescrip="Robot not reachable")
    plant[1].forget_connection()
    alarm = step(plant, times=int(ON_DELAY_S / 0.1) + 2)["alarms"][0]
    assert alarm["text"] == "Not connected to the robot, retrying (attempt 1) — Robot not reachable"


def test_a_stalled_plc_is_a_high_alarm(plant):
    _, system, clock = plant
    for _ in range(15):                                          # the PLC stops scanning
        clock.now += 0.1
        system.sample()
    alarm = system.summary()["alarms"][0]
    assert (alarm["key"], alarm["priority"]) == ("plc", "high")
    assert alarm["text"] == "PLC stopped: its tasks completed no cycle for 1 s"


def test_a_major_fault_of_the_plc_is_one_high_alarm_and_the_rest_waits(plant):
    """After a major fault the PLC keeps its variables as they were: nothing else is judged from them."""
    import types

    from vplc.api import PlcFault
    plc, _, _ = plant
    plc.vars["RobotStatus"]["EStop"] = True
    plc.engine = types.SimpleNamespace(fault=PlcFault(
        "examples/PnP_Example.st:57: major fault in PnP_Example: integer division by zero (100 / 0)"))
    alarm, = step(plant, times=10)["alarms"]
    assert (alarm["key"], alarm["priority"], alarm["text"]) == (
        "plc", "high", "PLC stopped: integer division by zero (100 / 0)")
    assert alarm["remedy"].startswith("Call the maintenance engineer: the PLC must be restarted")


def test_timestamps_are_the_servers_date_and_24_hour_time(plant):
    plc, _, clock = plant
    clock.now = 1_900_000_000.25 + 13 * 3600                    # whatever hour, shown 0..23
    plc.vars["RobotStatus"]["EStop"] = True
    alarm = step(plant, seconds=0)["alarms"][0]
    import time
    assert alarm["time"] == time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(clock.now)) + ".250"


def test_the_history_survives_a_restart_and_keeps_the_newest_entries(mapping, tmp_path):
    path = tmp_path / "alarms.jsonl"
    plc = FakePlc(mapping, command_program)
    plc.vars.update(Connect_Execute=True, Connect_Connected=True, Robot_InListenNode=True)
    clock = Clock()
    system = AlarmSystem(plc, mapping, path, clock=clock, monotonic=clock)
    system.history.start()
    for n in range(700):                                        # 2100 entries: raised, acknowledged... normal
        plc.vars["RobotStatus_Valid"] = True
        plc.vars["RobotStatus"]["EStop"] = n % 2 == 0
        plc.scan()
        clock.now += 0.1
        system.sample()
        system.acknowledge(None, "operator")
    system.history.stop()
    kept = [json.loads(line) for line in path.read_text().splitlines()]
    assert 500 <= len(kept) <= 2 * HISTORY
    again = AlarmSystem(plc, mapping, path, clock=clock, monotonic=clock)
    entries = again.summary(history=HISTORY)["history"]
    assert len(entries) == HISTORY and entries[0]["n"] == system.entry_number
    assert again.alarm_number == system.alarm_number             # numbering goes on after a restart


def test_a_sample_never_waits_for_the_disk(plant, monkeypatch):
    """The writer thread is held (a disk that does not answer): sampling and acknowledging go on."""
    plc, system, _ = plant
    held = threading.Event()
    writing = threading.Event()

    def stuck(self, path):
        writing.set()
        held.wait(30)
    monkeypatch.setattr(alarm_module.History, "_write", stuck)
    system.history.start()
    assert writing.wait(5), "the history writer did not start"

    def work():
        for n in range(200):
            plc.vars["RobotStatus"]["EStop"] = n % 2 == 0
            step(plant)
            system.acknowledge(None, "operator")
    worker = threading.Thread(target=work)
    worker.start()
    worker.join(timeout=20)
    stuck_thread = worker.is_alive()
    held.set()
    assert not stuck_thread, "a sample waited for the history file"
    assert system.summary(history=5)["history"][0]["n"] == system.entry_number


def test_a_flood_of_unacknowledged_events_keeps_the_list_bounded(plant):
    plc, system, _ = plant
    for n in range(alarm_module.MAX_LISTED + 50):               # a failed command, every time another ErrorID
        plc.vars.update(MoveAbs_Error=True, MoveAbs_ErrorID=0x3001 + n % 2, MoveAbs_ErrorDescrip="No reply")
        step(plant, seconds=ON_DELAY_S)
    summary = step(plant, seconds=ON_DELAY_S, times=2)
    assert len(summary["alarms"]) == alarm_module.MAX_LISTED
    assert summary["alarms"][-1]["number"] == system.alarm_number - alarm_module.MAX_LISTED + 1
    assert any(e["event"] == "left the full list unacknowledged" for e in summary["history"])


def test_a_history_file_with_a_damaged_line_is_read_without_it(mapping, tmp_path):
    path = tmp_path / "alarms.jsonl"
    path.write_text('{"n": 1, "alarm": 1, "event": "raised"}\nnot json\n{"n": 2, "alarm": 1, "event": "normal"}\n'
                    '{"n": 2, "alarm": 1, "event": "normal"}\n')
    system = AlarmSystem(FakePlc(mapping), mapping, path)
    assert [e["n"] for e in system.summary(history=10)["history"]] == [2, 1]


def test_a_history_path_that_is_a_pipe_or_a_device_or_too_large_is_not_read(mapping, tmp_path, monkeypatch):
    """A pipe would hold the start-up for ever, /dev/zero fill the memory: neither is read; a file larger than
    this history ever writes starts a new history."""
    os.mkfifo(tmp_path / "pipe.jsonl")
    os.symlink("/dev/zero", tmp_path / "zero.jsonl")
    for name in ("pipe.jsonl", "zero.jsonl"):
        history = alarm_module.History(tmp_path / name)
        assert list(history.entries) == []
    monkeypatch.setattr(alarm_module, "MAX_HISTORY_FILE_BYTES", 100)
    big = tmp_path / "big.jsonl"
    big.write_text('{"n": 1, "alarm": 1, "event": "raised"}\n' * 10)
    assert list(alarm_module.History(big).entries) == []


# --- the API ---------------------------------------------------------------------------------------------------
def test_acknowledge_over_the_api_needs_an_operator_key_and_a_list_of_alarms(server, fake_plc):
    base = f"http://127.0.0.1:{server.port}"
    with fake_plc.lock:
        fake_plc.vars.update(RobotStatus_Valid=True)
        fake_plc.vars["RobotStatus"]["EStop"] = True
    operator = Client(base, server.access.keys["operator"])
    deadline_reads = 0
    while not operator.json("/api/alarms")[1]["alarms"] and deadline_reads < 200:
        threading.Event().wait(0.05)
        deadline_reads += 1
    status, summary = operator.json("/api/alarms")
    number = summary["alarms"][0]["number"]
    assert Client(base).json("/api/alarms/ack", {"all": True})[0] == 401
    assert operator.json("/api/alarms/ack", {"alarms": "all"}) == (
        400, {"ok": False, "error": 'give the alarms to acknowledge: {"alarms": [number, ...]} or {"all": true}'})
    status, answer = operator.json("/api/alarms/ack", {"alarms": [number]})
    assert status == 200 and answer["acknowledged"] == 1
    status, summary = Client(base).json("/api/alarms")             # every panel, even a monitor, sees it
    assert summary["alarms"][0]["state"] == "active-acknowledged"
    status, read = operator.json("/api/read?names=Connect_Connected")
    assert read["alarms"] == summary["seq"] and read["robot"] == "E-stop"
    assert operator.json("/api/alarms?history=x")[0] == 400
    assert operator.json(f"/api/alarms?history={HISTORY + 1}")[0] == 400
