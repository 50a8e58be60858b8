"""Scenario lines that act on the robot simulator (`robot N ...` through its control channel, --sim-control),
reactions (`when ... then set ...`) and the list of unmet expectations."""
import os
import re

import pytest
from cli_main import run_in_process

from tmsim.net.server import SimServer
from vplc.cli import simlink

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

PROG = """PROGRAM Main
VAR Start : BOOL; Count : INT; Alarm : BOOL; Reset : BOOL; Resets : INT; Level : REAL; t : TON; END_VAR
t(IN := Start AND NOT t.Q, PT := T#10ms);
IF t.Q AND Count < 100 THEN
    Count := Count + 1;
    IF Count = 3 OR Count = 6 THEN Alarm := TRUE; END_IF;      (* an alarm that needs Reset *)
END_IF;
IF Reset AND Alarm THEN Alarm := FALSE; Resets := Resets + 1; END_IF;
Level := INT_TO_REAL(Count) * 1.5;
END_PROGRAM
"""


def vplc(*args):
    """`vplc args...` in this process (these tests are about what a run says and returns, not the process)."""
    return run_in_process(*args)


def run(tmp_path, scenario, *args):
    (tmp_path / "m.st").write_text(PROG)
    (tmp_path / "s.scn").write_text(scenario)
    return vplc("run", str(tmp_path / "m.st"), "--scenario", str(tmp_path / "s.scn"), *args)


@pytest.fixture
def sim():
    s = SimServer(port=0, robots=2, speedup=1, control_port=0, svr_port=0)
    s.start_background()
    yield s
    s.close()


def control(sim):
    return f"127.0.0.1:{sim.control.port}"


# ---- the command table is the documented one ------------------------------------------------------------
def _doc_section(title):
    with open(os.path.join(ROOT, "docs", "simulator.md"), encoding="utf-8") as f:
        text = f.read()
    start = text.index(title)
    return text[start:text.index("\n## ", start + 1)] if "\n## " in text[start + 1:] else text[start:]


def test_every_action_of_the_documented_control_channel_is_a_scenario_command():
    table = _doc_section("## Control channel")
    documented = set()
    for row in re.findall(r"^\| `(\{[^|]*?\})`[^|]*\|", table, re.M):
        documented.update(re.findall(r'"cmd": "(\w+)"', row))
    documented.update(re.findall(r"^\| `\{\"cmd\": \"enter_listen_node\"\}` / (.*?) \|", table, re.M)[0]
                      .replace("`", "").replace(" ", "").split("/"))
    documented.update(re.findall(r'`\{"cmd": "svr_clear_faults"\}`', table) and ["svr_clear_faults"])
    assert documented - set(simlink.QUERIES) == set(simlink.COMMANDS)


def test_every_documented_fault_and_its_parameters_are_known():
    def faults(section, heading):
        part = _doc_section(section)
        part = part[part.index(heading):]
        rows = re.findall(r"^\| `(\w+)` \| ([^|]*) \|", part, re.M)
        return {name: tuple(re.findall(r"`(\w+)=", params)) for name, params in rows}
    listen = faults("## Fault injection", "| fault | parameters (range) | effect |")
    assert listen == simlink.FAULTS
    svr = faults("## Ethernet Slave", "**Faults**")
    assert {k: v for k, v in svr.items() if k in ("stall", "corrupt_checksum", "disconnect", "refuse_writes")} \
        == simlink.SVR_FAULTS


def test_robot_words_become_the_documented_requests():
    assert simlink.build_request(["cut_link"]) == {"cmd": "inject", "fault": "disconnect"}
    assert simlink.build_request(["estop"]) == {"cmd": "estop", "pressed": True}
    assert simlink.build_request(["release_estop"]) == {"cmd": "estop", "pressed": False}
    assert simlink.build_request(["inject", "reply_delay", "seconds=0.5", "count=2"]) == \
        {"cmd": "inject", "fault": "reply_delay", "params": {"seconds": 0.5, "count": 2}}
    assert simlink.build_request(["inject", "leave_node", "path=Fail"]) == \
        {"cmd": "inject", "fault": "leave_node", "params": {"path": "Fail"}}
    assert simlink.build_request(["operation_mode", "manual"]) == {"cmd": "operation_mode", "mode": "manual"}
    assert simlink.build_request(["svr_config", "period=0.05", "items=Robot_Link,ESTOP", "write_permission=false"]) \
        == {"cmd": "svr_config", "period": 0.05, "items": ["Robot_Link", "ESTOP"], "write_permission": False}
    assert simlink.build_request(["svr_inject", "refuse_writes", "status=6"]) == \
        {"cmd": "svr_inject", "fault": "refuse_writes", "params": {"status": 6}}
    job = simlink.build_request(["vision_job", "job1", "objects=300,0,5,0,0,0;310,60,5,0,0,90", "pass=false",
                                 "seconds=0.5", "capture=0,0,90,0,90,0", "variable=job1_Out"])
    assert job == {"cmd": "vision_job", "job": "job1", "objects": [[300, 0, 5, 0, 0, 0], [310, 60, 5, 0, 0, 90]],
                   "pass": False, "seconds": 0.5, "capture": [0, 0, 90, 0, 90, 0], "variable": "job1_Out"}
    assert simlink.describe(job) == ("vision_job job1 objects=300,0,5,0,0,0;310,60,5,0,0,90 pass=false "
                                     "seconds=0.5 capture=0,0,90,0,90,0 variable=job1_Out")
    assert simlink.build_request(["vision_remove", "job1"]) == {"cmd": "vision_remove", "job": "job1"}


# ---- usage errors before the run -------------------------------------------------------------------------
@pytest.mark.slow
def test_scenario_mistakes_about_the_simulator_are_usage_errors_with_file_and_line(tmp_path, sim):
    cases = {"at 1s robot 3 cut_link\n": ":1: robot 3 does not exist: the simulator at 127.0.0.1:",
             "\nat 1s robot 0 estop\n": ":2: `robot 0`: robots are numbered from 1",
             "at 1s robot 1 explode\n": ":1: unknown simulator command `explode`; known: enter_listen_node",
             "at 1s robot 1 inject\n": ":1: `inject` needs its fault: one of reply_delay",
             "at 1s robot 1 inject slow\n": ":1: `slow` is not a fault of `inject`; known: reply_delay",
             "at 1s robot 1 inject reply_delay secs=2\n": ":1: `secs` is not a parameter of `reply_delay`; known: "
                                                          "seconds, count",
             "at 1s robot 1 inject reply_delay seconds=1e400\n": ":1: `seconds` must be a finite number, got `1e400`",
             "at 1s robot 1 svr_config period=soon\n": ":1: `period` is a number, got `soon`",
             "at 1s robot 1 vision_job job1 capture=0,0,90\n": ":1: `capture`: `0,0,90` is not six numbers",
             "at 1s robot 1 vision_remove\n": ":1: `vision_remove` needs its job, e.g. `vision_remove job1`",
             "at 1s robot 1 operation_mode\n": ":1: `operation_mode` needs its mode: one of auto, manual",
             "at 1s robot 1 svr_config\n": ":1: `svr_config` needs at least one of period, mode, items",
             "at 1s robot 1 state\n": ":1: `state` asks the simulator for something; a scenario line acts",
             "robot 1 estop\n": ":1: `robot` needs a time or a condition",
             "when Main.Nope = TRUE robot 1 estop\n": ":1: `Nope` is not a variable of Main",
             "when Main.Alarm > TRUE then set Main.Reset TRUE\n": ":1: `>` compares numbers; Main.Alarm is a BOOL",
             "when Main.Alarm = TRUE then set Main.Count 'x'\n": ":1: `'x'` is not a value for Main.Count (INT)",
             "when Main.Alarm then set Main.Reset TRUE\n": ":1: condition `Main.Alarm` is not `VAR OP VALUE`",
             "when Main.Alarm = TRUE for 5 then set Main.Reset TRUE\n": ":1: hold time `5` is not a time",
             "when Main.Alarm = TRUE press Main.Reset\n": ":1: cannot read `when Main.Alarm = TRUE press"}
    for text, message in cases.items():
        r = run(tmp_path, text, "--virtual-time", "--sim-control", control(sim))
        assert r.returncode == 2, text
        assert message in r.stderr, (text, r.stderr)
        assert "Traceback" not in r.stderr


def test_robot_lines_without_the_control_channel_or_without_a_simulator_are_usage_errors(tmp_path, sim):
    r = run(tmp_path, "at 1s robot 1 cut_link\n", "--virtual-time")
    assert r.returncode == 2
    assert r.stderr.strip().endswith("s.scn:1: `robot` lines act on the simulator: give its control channel with "
                                     "--sim-control HOST:PORT (e.g. 127.0.0.1:5889)")
    port = sim.control.port
    sim.close()
    r = run(tmp_path, "at 1s robot 1 cut_link\n", "--virtual-time", "--sim-control", f"127.0.0.1:{port}")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert f"cannot reach the simulator's control channel at 127.0.0.1:{port}" in r.stderr
    r = run(tmp_path, "at 1s robot 1 cut_link\n", "--virtual-time", "--sim-control", "localhost:99999")
    assert r.returncode == 2 and "is not HOST:PORT" in r.stderr


# ---- acting on the simulator -----------------------------------------------------------------------------
def test_timed_and_conditional_requests_reach_the_robot_with_the_controller_time_in_its_log(tmp_path, sim):
    r = run(tmp_path, "at 0s set Main.Start TRUE\n"
                      "at 20ms robot 2 inject reply_delay seconds=0.25\n"
                      "when Main.Count >= 4 robot 1 estop\n"
                      "expect Main.Count = 5 within 1s\n", "--virtual-time", "--sim-control", control(sim))
    assert r.returncode == 0, r.stderr
    assert "     0.020 s  robot 2: inject reply_delay seconds=0.25 (" in r.stdout
    assert re.search(r"     0\.04\d s  robot 1: estop \(.*s\.scn:3\)", r.stdout)
    assert sim.robots[1].state()["faults"] and sim.robots[0].state()["estop"]
    marks = [e for e in sim.robots[1].events if e["kind"] == "control"]
    assert [(e["cmd"], e["plc_time"]) for e in marks] == [("ping", 0.0), ("inject", 0.02)]
    estop = [e for e in sim.robots[0].events if e["kind"] == "control" and e["cmd"] == "estop"]
    assert len(estop) == 1 and 0.04 <= estop[0]["plc_time"] < 0.05


def test_a_request_the_simulator_refuses_fails_the_run_with_its_reason(tmp_path, sim):
    r = run(tmp_path, "at 10ms robot 1 inject reply_delay seconds=99999\nexpect Main.Count = 0 within 1s\n"
                      "at 50ms stop\n", "--virtual-time", "--sim-control", control(sim))
    assert r.returncode == 1
    last = r.stderr.strip().splitlines()[-1]
    assert last.startswith("vplc run: FAILED: ") and "s.scn:1: the simulator refused `inject reply_delay " \
                                                    "seconds=99999`: " in last and "seconds" in last


def test_a_request_refused_on_real_time_fails_the_run_too(tmp_path, sim):
    r = run(tmp_path, "at 10ms robot 1 operation_mode manual\nat 20ms robot 1 start_project\nat 300ms stop\n",
            "--sim-control", control(sim))
    assert r.returncode == 1, r.stdout + r.stderr
    assert "s.scn:2: the simulator refused `start_project`: " in r.stderr.strip().splitlines()[-1]


# ---- reactions ------------------------------------------------------------------------------------------
def test_a_reaction_plays_the_operator_each_time_the_condition_becomes_true(tmp_path):
    r = run(tmp_path, "at 0s set Main.Start TRUE\n"
                      "when Main.Alarm = TRUE for 5ms then set Main.Reset TRUE after 2ms every time\n"
                      "when Main.Reset = TRUE then set Main.Reset FALSE every time\n"
                      "when Main.Count >= 8 and time >= 50ms then set Main.Start FALSE\n"
                      "expect Main.Resets = 2 within 1s\nat 200ms expect Main.Count = 8\n",
            "--virtual-time", "--watch", "Main.Reset,Main.Alarm")
    assert r.returncode == 0, r.stdout + r.stderr
    lines = r.stdout.splitlines()
    # the scan at 34 ms raises the alarm; judged before the scan at 35 ms, true for 5 ms by the one at 40 ms,
    # the write 2 ms later: the scan at 42 ms resets; the second reaction releases Reset before the next scan
    assert "     0.034 s  Main.Alarm = TRUE" in lines and "     0.042 s  Main.Reset = TRUE" in lines
    assert "     0.042 s  Main.Alarm = FALSE" in lines and "     0.043 s  Main.Reset = FALSE" in lines
    assert \
        sum(1 for line in lines if line.endswith("Main.Reset = TRUE")) == 2      # every time: 2 alarms


def test_a_once_reaction_fires_only_on_the_first_edge(tmp_path):
    r = run(tmp_path, "at 0s set Main.Start TRUE\n"
                      "when Main.Alarm = TRUE then set Main.Reset TRUE\n"
                      "when Main.Reset = TRUE then set Main.Reset FALSE every time\n"
                      "at 150ms expect Main.Resets = 1\n", "--virtual-time")
    assert r.returncode == 0, r.stdout + r.stderr


# ---- results ---------------------------------------------------------------------------------------------
def test_every_unmet_expectation_is_listed_with_its_last_value_and_the_first_marked(tmp_path):
    r = run(tmp_path, "at 0s set Main.Start TRUE\n"
                      "expect Main.Alarm = FALSE always\n"
                      "expect Main.Count < 3 always\n"
                      "expect Main.Count = 50 within 2s\n"
                      "expect Main.Level >= 0 always\n", "--virtual-time")
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    where = str(tmp_path / "s.scn")
    assert lines[-5:] == [
        "vplc run: 3 expectation(s) not met:",
        f"  failed at 0.034 s (first): expect Main.Alarm = FALSE always ({where}:2); Main.Alarm was TRUE since "
        "0.034 s",
        f"  failed at 0.034 s: expect Main.Count < 3 always ({where}:3); Main.Count was 3 since 0.034 s",
        f"  not decided: expect Main.Count = 50 within 2s ({where}:4); Main.Count was 3 since 0.034 s",
        f"vplc run: FAILED: expectation failed at 0.034 s: expect Main.Alarm = FALSE always ({where}:2); "
        "Main.Alarm is TRUE"]


def test_the_simulator_refuses_a_controller_time_that_is_not_a_time(sim):
    from tmsim.net.control import request
    for bad in (-1, "5s", True, 1e10):
        answer = request(sim.control.port, {"cmd": "ping", "plc_time": bad})
        assert answer["ok"] is False and "'plc_time' must be the controller time in seconds" in answer["error"]
    assert request(sim.control.port, {"cmd": "ping", "robot": 1, "plc_time": 2.5}) == {"ok": True, "result": "pong"}
    assert [e["plc_time"] for e in sim.robots[1].events if e["kind"] == "control"] == [2.5]


def test_members_and_unchanged_values_are_judged_like_any_other(tmp_path):
    """A reaction on an FB member (read through the API each scan) and expectations whose variable never changes
    (judged at their time and at their deadline, not only on a change)."""
    r = run(tmp_path, "at 0s set Main.Start TRUE\n"
                      "when Main.t.Q = TRUE then set Main.Reset TRUE\n"
                      "at 30ms expect Main.Resets = 0\n"
                      "expect Main.Level = 99 within 50ms\n", "--virtual-time", "--watch", "Main.Reset")
    assert r.returncode == 1
    assert "     0.011 s  Main.Reset = TRUE" in r.stdout.splitlines()       # t.Q after the scan at 10 ms
    assert r.stderr.strip().splitlines()[-1].startswith("vplc run: FAILED: expectation failed at 0.050 s: "
                                                        "expect Main.Level = 99 within 50ms")


def test_a_scenario_defines_what_the_robots_camera_finds(tmp_path, sim):
    from tmsim.net.control import request
    r = run(tmp_path, "at 10ms robot 2 vision_job job1 objects=300,0,5,0,0,0;310,60,5,0,0,90 seconds=0.1\n"
                      "at 20ms robot 2 vision_job job2 pass=false\nat 30ms robot 2 vision_remove job2\nat 40ms stop\n",
            "--virtual-time", "--sim-control", control(sim))
    assert r.returncode == 0, r.stdout + r.stderr
    camera = request(sim.control.port, {"cmd": "vision", "robot": 1})["result"]
    assert camera["jobs"] == [{"job": "job1", "objects": [[300, 0, 5, 0, 0, 0], [310, 60, 5, 0, 0, 90]],
                               "pass": True, "seconds": 0.1, "capture": None, "variable": "job1_Base_TM"}]


def test_vplc_speaks_to_the_simulator_only_through_its_documented_protocol():
    """vplc and the simulator stay independent packages: nothing in vplc imports tmsim."""
    src = os.path.join(ROOT, "src", "vplc")
    for folder, _dirs, files in os.walk(src):
        for name in files:
            if name.endswith(".py"):
                with open(os.path.join(folder, name), encoding="utf-8") as f:
                    text = f.read()
                assert not re.search(r"^\s*(from|import)\s+(tmsim|sim)\b", text, re.M), os.path.join(folder, name)
