"""The virtual camera (tmsim/robot/camera.py) behind the vision functions of TMscript 2.24: Vision_IsJobAvailable
(§14.1), Vision_DoJob / _PTP / _Line (§13.32-13.34: run in order with the motions, True = the job passed,
False = failed or could not run, a capture point refused by Vision_DoJob), Vision_GetOutputArraySize /
Vision_GetOutputArrayValue (§14.2: one row per object, an index outside the rows is an error); jobs set through
the control channel and --vision-job."""
import json

import pytest
from session_rig import PTP_LONG, sct

from tmsim.cli import build_parser, check_vision_jobs
from tmsim.net.server import SimServer
from tmsim.protocol import codec
from tmsim.robot.camera import Camera, camera_of, parse_option

PARTS = [[300, 0, 5, 0, 0, 0], [300, 60, 5, 0, 0, 90], [240, -60, 5, 0, 0, -45.5]]


def reply(ident, status):
    return codec.encode("TMSCT", f"{ident},{status}").decode()


def pushes(frames):
    return [f for f in frames if f.startswith("$TMSTA")]


@pytest.fixture
def node(node):
    """The shared node (conftest.py) with job1 defined on its camera."""
    camera_of(node.s.robot).define("job1", objects=PARTS, seconds=0.5)
    return node


def test_an_unknown_job_is_not_available_and_does_not_run(node):
    """§14.1 False: absent; Vision_DoJob of it returns False ("fail to execute", §13.32) - no ERROR."""
    out = node.send(1, sct("1", 'ListenSend(90,GetString(Vision_IsJobAvailable("nojob")))\r\n'
                                'ListenSend(91,GetString(Vision_DoJob("nojob")))'))
    assert out[-1] == reply("1", "OK")
    assert "false" in pushes(out)[0] and "false" in pushes(out)[1]
    assert ("vision_job", {"job": "nojob", "result": "unknown"}) in node.events


def test_a_passed_job_takes_its_time_and_fills_its_output_variable_one_row_per_object(node):
    out = node.send(1, sct("2", 'bool ok = Vision_DoJob("job1")\r\n'
                                'ListenSend(90,GetString(ok)+";"+GetString(Vision_GetOutputArraySize("job1_Base_TM")))\r\n'
                                'ListenSend(91,GetString(Vision_GetOutputArrayValue("job1_Base_TM",2)))'))
    assert out == []                                      # the job takes 0.5 s: the script waits for it
    node.advance(0.45)
    assert node.s.robot.state() and not any(k == "vision_job" for k, _ in node.events)
    texts = []
    for _ in range(20):
        node.advance(0.01)
        texts += node.out(1)
    assert texts[-1] == reply("2", "OK")
    assert "true;3" in texts[0] and "{240,-60,5,0,0,-45.5}" in texts[1]
    assert ("vision_job", {"job": "job1", "result": "pass", "objects": 3}) in node.events


def test_an_index_outside_the_objects_is_an_error_of_its_line(node):
    """§14.2.2: "Return error. Exceeding the access range." """
    node.send(1, sct("3", 'Vision_DoJob("job1")'))
    node.advance(0.6)
    node.out(1)
    assert node.send(1, sct("4", 'ListenSend(90,GetString(Vision_GetOutputArrayValue("job1_Base_TM",3,0)))')) \
        == [reply("4", "ERROR;1")]
    assert node.send(1, sct("5", 'ListenSend(90,GetString(Vision_GetOutputArrayValue("job1_Base_TM",1,6)))')) \
        == [reply("5", "ERROR;1")]


def test_a_failed_job_returns_false_and_leaves_no_object(node):
    camera_of(node.s.robot).define("job1", objects=PARTS, passed=False, seconds=0)
    out = node.send(1, sct("6", 'ListenSend(90,GetString(Vision_DoJob("job1"))+";"+'
                                'GetString(Vision_GetOutputArraySize("job1_Base_TM")))'))
    assert "false;0" in pushes(out)[0] and out[-1] == reply("6", "OK")


def test_the_job_waits_for_the_motions_queued_before_it(node):
    camera_of(node.s.robot).define("job1", objects=PARTS, seconds=0)
    node.send(1, sct("7", PTP_LONG))
    node.out(1)
    node.send(1, sct("8", 'Vision_DoJob("job1")'))
    node.advance(5.0)
    assert not any(k == "vision_job" for k, _ in node.events)
    node.advance(0.5)
    ends = [i for i, (k, _) in enumerate(node.events) if k == "motion_end"]
    runs = [i for i, (k, _) in enumerate(node.events) if k == "vision_job"]
    assert ends and runs and ends[0] < runs[0]


def test_ptp_moves_to_the_capture_point_first_and_vision_do_job_refuses_a_job_with_one(node):
    camera_of(node.s.robot).define("job2", objects=PARTS[:1], seconds=0, capture=[10, 0, 90, 0, 90, 0])
    out = node.send(1, sct("9", 'ListenSend(90,GetString(Vision_DoJob("job2")))'))
    assert "false" in pushes(out)[0]                      # §13.32 False case 3
    node.send(1, sct("10", 'ListenSend(90,GetString(Vision_DoJob_PTP("job2",50,200)))'))
    node.advance(3.0)
    assert node.s.robot.state()["joints"][0] == pytest.approx(10, abs=0.01)
    assert ("vision_job", {"job": "job2", "result": "pass", "objects": 1}) in node.events


def test_line_moves_to_the_capture_point_in_a_straight_line(node):
    camera_of(node.s.robot).define("job3", objects=PARTS[:1], seconds=0, capture=[0, 10, 80, 0, 90, 0])
    node.send(1, sct("11", 'Vision_DoJob_Line("job3",100,300)'))
    node.advance(3.0)
    assert node.s.robot.state()["joints"][1] == pytest.approx(10, abs=0.05)
    assert any(k == "motion_start" and f.get("function", "Line") == "Line" for k, f in node.events)


@pytest.mark.parametrize("kwargs, words", [
    (dict(name="1job"), "job name"), (dict(name="job", objects=[[1, 2, 3]]), "6 numbers"),
    (dict(name="job", objects=[[1, 2, 3, 4, 5, float("nan")]]), "finite"),
    (dict(name="job", seconds=-1), "'seconds'"), (dict(name="job", passed="yes"), "'pass'"),
    (dict(name="job", capture=[0] * 5), "capture point"), (dict(name="job", variable="a b"), "output variable")])
def test_a_bad_job_definition_is_refused_with_its_reason(kwargs, words):
    with pytest.raises(ValueError, match=words):
        Camera().define(**kwargs)


def test_the_control_channel_sets_and_removes_jobs_and_shows_the_camera():
    srv = SimServer(port=0, control_port=0).start()
    try:
        def ask(request):
            return srv.control.execute(json.dumps(request).encode())
        answer = ask({"cmd": "vision_job", "job": "job1", "objects": PARTS, "pass": True, "seconds": 0.3})["result"]
        assert answer["objects"][1] == [300, 60, 5, 0, 0, 90] and answer["variable"] == "job1_Base_TM"
        assert ask({"cmd": "vision"})["result"]["jobs"][0]["job"] == "job1"
        assert ask({"cmd": "vision_remove", "job": "job1"}) == {"ok": True, "result": True}
        refused = ask({"cmd": "vision_job", "job": "job1", "objects": "x"})
        assert refused["ok"] is False and "'objects'" in refused["error"], refused
    finally:
        srv.close()


def test_the_start_up_option_defines_jobs_and_names_a_bad_one():
    assert parse_option("job1=300,0,5,0,0,0;300,60,5,0,0,90@0.5") == dict(
        name="job1", objects=[[300, 0, 5, 0, 0, 0], [300, 60, 5, 0, 0, 90]], passed=True, seconds=0.5)
    assert parse_option("empty=!fail")["passed"] is False
    args = build_parser().parse_args(["--vision-job", "job1=1,2,3", "--vision-job", "ok=1,2,3,4,5,6"])
    problems, jobs = check_vision_jobs(args)
    assert len(problems) == 1 and "--vision-job job1=1,2,3" in problems[0] and "6 numbers" in problems[0]
    assert [j["name"] for j in jobs] == ["ok"]
