"""The "D" data formats (absolute speed in mm/s not scaled by the project speed, TMscript 2.24 §13.10 Line,
§13.11 Move_Line, §13.12 Circle) in CBT_MoveAbsolute, CBT_MoveRelative and CBT_MoveCircle: validated like
the A formats, sent as written, run by a TMflow 2.x robot; refused with 16#1027 (nothing sent) when the
connection's RobotSoftware is TMflow1x, and a TMflow 1.8 robot would reject them (ERROR;1)."""
import pytest
from rig import Rig, circ, move_abs, rel, run

from tmsim.tmscript.profiles import Profile

LINE = dict(MovementCommand=0, TargetPosition=dict(X=417.5, Y=-122.3, Z=300, RX=180, RY=0, RZ=90))
ABS = {"CDP_Abs": 5, "CDR_Abs": 6}
REL = {"CDP_Rel": 9, "CDR_Rel": 10, "TDP_Rel": 11, "TDR_Rel": 12}


@pytest.mark.parametrize("name,value", sorted(ABS.items()))
def test_manual_13_10_line_with_a_d_format_runs_on_tmflow_2(rig, name, value):
    script = run(rig, "mover", "MoveExec", "MoveParam", move_abs(DataFormat=value, Speed=250, **LINE))
    assert rig.read("mover.Done") and script.startswith(f'Line("{name[:3]}",417.5,-122.3,300,180,0,90,250,200,0,')


@pytest.mark.parametrize("name,value", sorted(REL.items()))
def test_manual_13_11_relative_line_with_a_d_format_runs_on_tmflow_2(rig, name, value):
    script = run(rig, "rel", "RelExec", "RelParam", rel(DataFormat=value, Speed=300))
    assert rig.read("rel.Done") and script.startswith(f'Move_Line("{name[:3]}",0,0,-20.5,0,0,0,300,200,0,')


def test_manual_13_12_circle_with_cdp_runs_on_tmflow_2(rig):
    script = run(rig, "circ", "CircExec", "CircParam", circ(DataFormat=2, Speed=150))
    assert rig.read("circ.Done") and script.startswith('Circle("CDP",417.5,-72.3,359.7,180,0,90,')


@pytest.mark.parametrize("fb,exec_,param,values,error_id", [
    ("mover", "MoveExec", "MoveParam", move_abs(DataFormat=5, Speed=0, **LINE), 0x1014),
    ("mover", "MoveExec", "MoveParam", move_abs(DataFormat=6, Speed=4501, **LINE), 0x1014),
    ("mover", "MoveExec", "MoveParam", move_abs(DataFormat=6, Speed=100, BlendingEnable=True, BlendingValue=1001,
                                                **LINE), 0x1017),
    ("mover", "MoveExec", "MoveParam", move_abs(DataFormat=5, MovementCommand=1), 0x1011),   # PTP has no D
    ("rel", "RelExec", "RelParam", rel(DataFormat=11, MovementCommand=1), 0x1011),
    ("rel", "RelExec", "RelParam", rel(DataFormat=12, Speed=0), 0x1014),
    ("circ", "CircExec", "CircParam", circ(DataFormat=2, Speed=5000), 0x1014),
])
def test_d_formats_are_validated_like_the_a_formats_and_nothing_is_sent(rig, fb, exec_, param, values, error_id):
    run(rig, fb, exec_, param, values)
    assert rig.read(f"{fb}.Error") and rig.read(f"{fb}.ErrorID") == error_id and rig.scripts_in() == []


@pytest.mark.parametrize("fb,exec_,param,values", [
    ("mover", "MoveExec", "MoveParam", move_abs(DataFormat=5, Speed=250, **LINE)),
    ("rel", "RelExec", "RelParam", rel(DataFormat=12, Speed=300)),
    ("circ", "CircExec", "CircParam", circ(DataFormat=2, Speed=150)),
])
def test_a_d_format_on_a_tmflow_1x_connection_is_refused_with_1027_and_nothing_is_sent(fb, exec_, param, values):
    r = Rig(profile=Profile(tmflow="1.8"))
    try:
        r.write("Cobot.RobotSoftware", "TMflow1x")
        run(r, fb, exec_, param, values)
        assert r.read(f"{fb}.Error") and r.read(f"{fb}.ErrorID") == 0x1027 and r.scripts_in() == []
        assert r.read(f"{fb}.ErrorDescrip") == "DataFormat CDx/TDx needs TMflow 2.x: robot set to TMflow1x"
    finally:
        r.close()


def test_a_tmflow_1_8_robot_rejects_a_d_format_the_connection_was_not_told_about():
    r = Rig(profile=Profile(tmflow="1.8"))
    try:
        run(r, "mover", "MoveExec", "MoveParam", move_abs(DataFormat=5, Speed=250, **LINE))
        assert r.read("mover.Error") and r.read("mover.ErrorID") == 0x4001
        assert r.read("Cobot.RobotSoftware") == "TMflow2x"                          # the default
    finally:
        r.close()
