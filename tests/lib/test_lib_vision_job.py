"""CBT_VisionJob (issue 26 item 6) on the virtual PLC against the simulator's virtual camera over loopback: the job
runs in order with the motions (TMscript 2.24 §13.32-13.34), its objects are read through
Vision_GetOutputArraySize / Vision_GetOutputArrayValue (§14.2) only as far as they exist; Done with Found and the
object's vision base, which CBT_ChangeBase and a relative move use to reach the part; an unknown job (§14.1), a
failed job and a missing object each end as the page says; every parameter row of ranges.tsv is checked before
anything is sent."""
import importlib.util
import sys

import pytest
from rig import ROOT, SEC, Rig, move_abs

from tmsim.robot.camera import camera_of

PARTS = [[417.5, -122.3, 300, 0, 0, 0], [467.5, -62.3, 300, 0, 0, 30], [377.5, -182.3, 310, 0, 0, -45]]
NOT_CONNECTED = 0x2001


@pytest.fixture
def rig():
    r = Rig(program="Main_Vision.st")
    r.camera = camera_of(r.robot.session.robot)
    r.camera.define("job1", objects=PARTS, seconds=0.3)
    yield r
    r.close()


def vision(rig, **kw):
    p = dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200, ObjectVariable="job1_Base_TM",
             ObjectIndex=0)
    p.update(kw)
    rig.set_struct("VisParam", p)
    rig.write("VisExec", True)
    assert rig.until(lambda: rig.read("vis.Done") or rig.read("vis.Error") or rig.read("vis.CommandAborted"), 10)


def release(rig):
    rig.write("VisExec", False)
    rig.scans(1)
    assert not any(rig.read(f"vis.{o}") for o in ("Done", "Busy", "Error", "CommandAborted"))


def pose(rig, path):
    return [rig.read(f"{path}.{m}") for m in ("X", "Y", "Z", "RX", "RY", "RZ")]


@pytest.mark.parametrize("index", [0, 1, 2])
def test_done_with_the_located_object_each_index_its_own(rig, index):
    vision(rig, ObjectIndex=index)
    assert rig.read("vis.Done"), rig.read("vis.ErrorDescrip")
    assert rig.read("vis.Found") and rig.read("vis.ObjectCount") == 3
    assert pose(rig, "vis.Object") == pytest.approx(PARTS[index], abs=1e-3)
    scripts = [s for _, s in rig.scripts_in()]
    assert scripts == ['ListenSend(90,GetString(Vision_IsJobAvailable("job1")))\r\n'
                       'ListenSend(91,GetString(Vision_DoJob("job1")))',
                       'ListenSend(90,GetString(Vision_GetOutputArraySize("job1_Base_TM")))',
                       f'ListenSend(90,GetString(Vision_GetOutputArrayValue("job1_Base_TM",{index})))']
    assert rig.read("vis.CmdID_Ack") == int(rig.scripts_in()[0][0])
    release(rig)


def test_busy_while_the_job_takes_its_time_and_done_holds_while_execute(rig):
    rig.set_struct("VisParam", dict(JobName="job1", ObjectVariable="job1_Base_TM"))
    rig.write("VisExec", True)
    rig.scans(1)
    assert rig.read("vis.Busy")
    started = rig.plc.now_ns
    assert rig.until(lambda: rig.read("vis.Done"), 2)
    assert rig.plc.now_ns - started >= 0.3 * SEC                  # the job's 0.3 s
    assert not rig.read("vis.Busy")
    rig.scans(5)
    assert rig.read("vis.Done") and rig.read("vis.Found")
    release(rig)


def test_pick_through_the_vision_base_change_base_and_a_relative_move(rig):
    """As TMflow users do: the vision base becomes the base, the approach point is taught in it, a relative move
    goes down to the part - the TCP ends at the part the camera found."""
    vision(rig, ObjectIndex=1)
    rig.set_struct("BaseParam.Transformation",
                   dict(zip(("X", "Y", "Z", "RX", "RY", "RZ"), pose(rig, "vis.Object"), strict=False)))
    rig.write("BaseExec", True)
    assert rig.until(lambda: rig.read("base.Done"), 1), rig.read("base.ErrorDescrip")
    rig.set_struct("MoveParam", move_abs(MovementCommand="Line", DataFormat="CPP_Abs", Speed=100,
                                         TargetPosition=dict(X=0, Y=0, Z=40, RX=180, RY=0, RZ=90)))
    rig.write("MoveExec", True)
    assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 20), rig.read("mover.ErrorDescrip")
    rig.set_struct("RelParam", dict(MovementCommand="Line", DataFormat="CPP_Rel", Speed=50, AccelTime=200,
                                    TargetPosition=dict(X=0, Y=0, Z=-40, RX=0, RY=0, RZ=0)))
    rig.write("RelExec", True)
    assert rig.until(lambda: rig.read("rel.Done") or rig.read("rel.Error"), 20), rig.read("rel.ErrorDescrip")
    state = rig.robot.session.robot.state()
    assert state["base"]["pose"] == pytest.approx(PARTS[1], abs=1e-3)
    x, y, z, rx, ry, rz = state["tcp"]                       # at the part: its origin, the tool pointing down
    assert [x, y, z, abs(rx), ry, rz] == pytest.approx([0, 0, 0, 180, 0, 90], abs=0.01)


def test_the_job_runs_after_the_motion_sent_before_it(rig):
    rig.set_struct("MoveParam", move_abs(TargetPosition=dict(X=30, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    rig.write("MoveExec", True)
    assert rig.until(lambda: rig.read("mover.Busy"), 0.1)
    vision(rig)
    assert rig.read("vis.Done")
    ends = [e["t"] for e in rig.robot.events if e["kind"] == "motion_end"]
    runs = [e["t"] for e in rig.robot.events if e["kind"] == "vision_job"]
    assert ends and runs and ends[0] <= runs[0]


def test_ptp_mode_moves_to_the_capture_point_first(rig):
    rig.camera.define("job2", objects=PARTS[:1], seconds=0, capture=[20, 0, 90, 0, 90, 0])
    vision(rig, JobName="job2", ObjectVariable="job2_Base_TM", Mode="VisionPTP", Speed=80, AccelTime=300)
    assert rig.read("vis.Done") and rig.read("vis.Found"), rig.read("vis.ErrorDescrip")
    assert 'Vision_DoJob_PTP("job2",80,300)' in rig.scripts_in()[0][1]
    assert rig.robot.session.robot.state()["joints"][0] == pytest.approx(20, abs=0.01)


def test_line_mode_sends_vision_do_job_line(rig):
    rig.camera.define("job3", objects=PARTS[:1], seconds=0, capture=[0, 5, 85, 0, 90, 0])
    vision(rig, JobName="job3", ObjectVariable="job3_Base_TM", Mode="VisionLine", Speed=40)
    assert rig.read("vis.Done") and rig.read("vis.Found"), rig.read("vis.ErrorDescrip")
    assert 'Vision_DoJob_Line("job3",40)' in rig.scripts_in()[0][1]


def test_an_unknown_job_is_16_4050_and_nothing_more_is_asked(rig):
    vision(rig, JobName="nojob")
    assert rig.read("vis.Error") and rig.read("vis.ErrorID") == 0x4050
    assert rig.read("vis.ErrorDescrip") == "Vision job not in the robot's project"
    assert len(rig.scripts_in()) == 1 and not rig.read("vis.Found")
    release(rig)


def test_a_failed_job_is_16_4051(rig):
    rig.camera.define("job1", objects=PARTS, passed=False, seconds=0)
    vision(rig)
    assert rig.read("vis.ErrorID") == 0x4051 and len(rig.scripts_in()) == 1


def test_a_vision_do_job_on_a_job_with_a_capture_point_is_16_4051(rig):
    """§13.32 False case 3: Vision_DoJob does not run a job with a capture point."""
    rig.camera.define("job2", objects=PARTS, seconds=0, capture=[0, 0, 90, 0, 90, 0])
    vision(rig, JobName="job2", ObjectVariable="job2_Base_TM")
    assert rig.read("vis.ErrorID") == 0x4051


def test_no_object_with_that_index_is_done_found_false_and_the_row_is_never_asked(rig):
    rig.camera.define("job1", objects=PARTS[:1], seconds=0)
    vision(rig, ObjectIndex=2)
    assert rig.read("vis.Done") and not rig.read("vis.Found") and rig.read("vis.ObjectCount") == 1
    assert len(rig.scripts_in()) == 2
    rig.camera.define("job1", objects=[], seconds=0)
    release(rig)
    vision(rig, ObjectIndex=0)
    assert rig.read("vis.Done") and not rig.read("vis.Found") and rig.read("vis.ObjectCount") == 0


def test_a_row_that_is_not_a_pose_is_16_4053(rig):
    rig.camera.define("job1", objects=PARTS, seconds=0, variable="job1_Score_TM")
    vision(rig, ObjectVariable="job1_Score_TM")
    assert rig.read("vis.Found")
    release(rig)
    rig.camera.outputs["job1_Score_TM"] = [["0.93"]]         # another output of the job: one number per object
    rig.camera.jobs["job1"].seconds = 0
    rig.camera.finish = lambda job: True                     # the job passes and leaves that output as it is
    vision(rig, ObjectVariable="job1_Score_TM")
    assert rig.read("vis.ErrorID") == 0x4053


def test_a_row_printed_with_quoted_values_is_read_as_the_same_pose(rig):
    """The manual does not show how GetString prints a string array; {"300","60",...} reads as {300,60,...}."""
    rig.camera.define("job1", objects=PARTS, seconds=0)
    rig.camera.finish(rig.camera.jobs["job1"])
    rig.camera.outputs["job1_Base_TM"] = [[f'"{v}"' for v in row] for row in rig.camera.outputs["job1_Base_TM"]]
    rig.camera.finish = lambda job: True                     # the next run leaves the quoted rows as they are
    vision(rig, ObjectIndex=2)
    assert rig.read("vis.Found") and pose(rig, "vis.Object") == pytest.approx(PARTS[2], abs=1e-3)


def test_a_new_rising_edge_while_reading_replaces_the_command(rig):
    rig.set_struct("VisParam", dict(JobName="job1", ObjectVariable="job1_Base_TM", ObjectIndex=0))
    rig.write("VisExec", True)
    assert rig.until(lambda: len(rig.scripts_in()) >= 2, 2)
    rig.write("VisExec", False)
    rig.scans(1)
    rig.write("VisParam.ObjectIndex", 2)
    rig.write("VisExec", True)
    assert rig.until(lambda: rig.read("vis.Done") or rig.read("vis.Error"), 5)
    assert rig.read("vis.Done") and pose(rig, "vis.Object") == pytest.approx(PARTS[2], abs=1e-3)


@pytest.mark.parametrize("mode, aborted", [("StopNormal", False), ("StopImmediate", False),
                                           ("StopAbortScript", True), ("StopDiscardAll", True)])
def test_a_stop_while_the_job_runs(rig, mode, aborted):
    """StopAndClearBuffer() / (0) leave the running script (§13.4, §15.8): the job ends and is Done; (1) and (2)
    abandon it, the robot answers OK without its answers: CommandAborted, the job never finished."""
    rig.camera.define("job1", objects=PARTS, seconds=2.0)
    rig.set_struct("VisParam", dict(JobName="job1", ObjectVariable="job1_Base_TM"))
    rig.write("StopParam.Mode", mode)
    rig.write("VisExec", True)
    assert rig.until(lambda: rig.read("vis.Busy"), 0.1)
    rig.until(lambda: False, 0.2)
    rig.write("StopExec", True)
    assert rig.until(lambda: not rig.read("vis.Busy"), 5)
    runs = [e["result"] for e in rig.robot.events if e["kind"] == "vision_job"]
    if aborted:
        assert rig.read("vis.CommandAborted") and not rig.read("vis.Error") and runs == []
    else:
        assert rig.read("vis.Done") and rig.read("vis.Found") and runs == ["pass"]


# ---- every parameter row of ranges.tsv (the generic test leaves this struct to this file) ----------------------
def _make_types():
    spec = importlib.util.spec_from_file_location("make_types", ROOT / "docs" / "library" / "make_types.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_types"] = module
    spec.loader.exec_module(module)
    return module


ROWS = [r for r in _make_types().read_ranges() if r.struct == "CBT_VisionJob"]     # members of Parameters


@pytest.fixture(scope="module")
def offline():
    r = Rig(program="Main_Vision.st", connect=False)
    yield r
    r.close()


def outcome(rig, member, value, when) -> int:
    rig.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    for key, text in when.items():
        rig.write(f"VisParam.{key.removeprefix('Parameters.')}", text)
    rig.write(f"VisParam.{member.removeprefix('Parameters.')}", value)
    rig.write("VisExec", True)
    rig.scans(2)
    err = rig.read("vis.ErrorID")
    rig.write("VisExec", False)
    rig.scans(2)
    return err


@pytest.mark.parametrize("row", ROWS, ids=lambda r: f"{r.member}:{r.line}")
def test_range_row_matches_the_st_check(offline, row):
    code = int(row.error[3:], 16)
    conditions = [{}]
    for key, values in row.when.items():
        conditions = [{**c, key: v} for c in conditions for v in values]
    for when in conditions:
        if row.allowed is not None:
            for value in row.allowed:
                assert outcome(offline, row.member, value, when) == NOT_CONNECTED, value
            for raw in (-1, len(row.allowed), 32767):
                offline.write(f"VisParam.{row.member.removeprefix('Parameters.')}", raw, raw=True)
                offline.write("VisExec", True)
                offline.scans(2)
                assert offline.read("vis.ErrorID") == code, raw
                offline.write("VisExec", False)
                offline.scans(2)
            continue
        assert outcome(offline, row.member, int(row.low), when) == NOT_CONNECTED
        assert outcome(offline, row.member, int(row.high), when) == NOT_CONNECTED
        assert outcome(offline, row.member, int(row.low) - 1, when) == code
        assert outcome(offline, row.member, int(row.high) + 1, when) == code


@pytest.mark.parametrize("member, value, code", [
    ("JobName", "", 0x1060), ("JobName", "1job", 0x1060), ("JobName", 'job"1', 0x1060), ("JobName", "job\n", 0x1060),
    ("ObjectVariable", "", 0x1064), ("ObjectVariable", "x y", 0x1064), ("ObjectVariable", "v,1", 0x1064)])
def test_a_name_that_could_change_the_script_is_refused_before_anything_is_sent(offline, member, value, code):
    """The types hold at most 32 / 48 characters (STRING[33] / STRING[49]); what they hold is checked."""
    assert outcome(offline, member, value, {}) == code
    assert outcome(offline, member, "a" * (32 if member == "JobName" else 48), {}) == NOT_CONNECTED


def test_speed_and_accel_time_are_not_checked_where_the_mode_does_not_use_them(offline):
    assert outcome(offline, "Speed", 0, {"Parameters.Mode": "VisionAtPosition"}) == NOT_CONNECTED
    assert outcome(offline, "AccelTime", 0, {"Parameters.Mode": "VisionLine"}) == NOT_CONNECTED
