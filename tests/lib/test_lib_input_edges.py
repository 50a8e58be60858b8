"""Every input of every public FB at its edges, the robot's own log as the witness (the maintainers' probe, part 1:
the values; part 2, the PLCopen edges and the link, is test_lib_command_edges.py).

For each case either nothing reaches the robot and the FB ends in Error with the ErrorID of docs/library/errors.tsv
and its text in ErrorDescrip, or exactly one script reaches it whose call carries exactly the values given (numbers
as CBTi_FormatReal prints them: up to 3 decimals, no exponent, docs/library/design.md) and the FB reports Done
only when the robot did it (a motion: its motion_end; any other command: the robot's OK). The values: at and just
past each bound (REAL: the next 32-bit float, NaN, +/-Inf, -0.0, the smallest subnormal, written as bit patterns),
0 and negative, undefined enumeration values, empty and longest strings, names and texts with TMscript's
delimiters and UTF-8. Virtual time; one simulator and one PLC per case (the compiled library is shared, a rig costs
milliseconds). Helpers: edges.py."""
from __future__ import annotations

import pytest
from edges import (
    ERRORS,
    INF,
    LONG_JOB,
    MAX_REAL,
    NAN,
    NAN_PAYLOAD,
    NEG_INF,
    NEG_ZERO,
    TINY,
    ZERO_POSE,
    abs_call,
    circle_call,
    command,
    f32,
    line_abs,
    num,
    past,
    pose_text,
    refused,
    refused_or_sent,
    rel_call,
    script_frames,
    sent,
    set_variable,
    svr_writes,
    tcp_call,
    tcp_values,
    vision_call,
)
from rig import HOME_JOINTS, Rig, circ, move_abs, rel

# ---- CBT_MoveAbsolute, CBT_MoveRelative, CBT_MoveCircle: the numbers ---------------------------------------------
MOVE_ABS_CASES = [
    # (id, parameter values, refused with / None = sent)
    ("speed%_1", move_abs(Speed=1, AccelTime=0), None),
    ("speed%_100", move_abs(Speed=100, AccelTime=9999), None),
    ("speed%_0", move_abs(Speed=0), 0x1013),
    ("speed%_101", move_abs(Speed=101), 0x1013),
    ("speed%_65535", move_abs(Speed=65535), 0x1013),
    ("speedmm_4500", line_abs(DataFormat="CAP_Abs", Speed=4500), None),
    ("speedmm_1", line_abs(DataFormat="CAR_Abs", Speed=1, PrecisePositioning=True), None),
    ("speedmm_0", line_abs(DataFormat="CAP_Abs", Speed=0), 0x1014),
    ("speedmm_4501", line_abs(DataFormat="CDP_Abs", Speed=4501), 0x1014),
    ("accel_10000", move_abs(AccelTime=10000), 0x1015),
    ("accel_65535", move_abs(AccelTime=65535), 0x1015),
    ("blend%_100", move_abs(BlendingEnable=True, BlendingValue=100), None),
    ("blend%_101", move_abs(BlendingEnable=True, BlendingValue=101), 0x1016),
    ("blend%_off_65535", move_abs(BlendingEnable=False, BlendingValue=65535), None),
    ("blendmm_1000", line_abs(DataFormat="CPR_Abs", BlendingEnable=True, BlendingValue=1000), None),
    ("blendmm_1001", line_abs(DataFormat="CDR_Abs", BlendingEnable=True, BlendingValue=1001), 0x1017),
    ("ptp_with_line_format", move_abs(MovementCommand="PTP", DataFormat="CPR_Abs"), 0x1011),
    ("line_with_joint_format", move_abs(MovementCommand="Line", DataFormat="JPP_Abs"), 0x1012),
    ("pose_on_line", line_abs(RobotPoseEnable=True), 0x1018),
    ("target_-0.0", move_abs(TargetPosition={**HOME_JOINTS, "X": NEG_ZERO}), None),
    ("target_subnormal", move_abs(TargetPosition={**HOME_JOINTS, "RZ": -TINY}), None),
    ("target_0.0005", move_abs(TargetPosition={**HOME_JOINTS, "RZ": 0.0005}), None),
    ("target_-0.0004", move_abs(TargetPosition={**HOME_JOINTS, "RZ": -0.0004}), None),
    ("target_3_decimals", move_abs(TargetPosition={**HOME_JOINTS, "RZ": -12.345}), None),
    ("target_100000", move_abs(TargetPosition={**HOME_JOINTS, "X": 100000.0}), None),
    ("target_-100000", line_abs(TargetPosition=dict(X=-100000.0, Y=0, Z=0, RX=0, RY=0, RZ=0)), None),
    ("target_past_100000", move_abs(TargetPosition={**HOME_JOINTS, "X": past(100000.0, True)}), 0x101A),
    ("target_past_-100000", move_abs(TargetPosition={**HOME_JOINTS, "RZ": past(-100000.0, False)}), 0x101A),
    ("target_nan", move_abs(TargetPosition={**HOME_JOINTS, "Y": NAN}), 0x101A),
    ("target_nan_payload", move_abs(TargetPosition={**HOME_JOINTS, "RX": NAN_PAYLOAD}), 0x101A),
    ("target_inf", move_abs(TargetPosition={**HOME_JOINTS, "Z": INF}), 0x101A),
    ("target_-inf", move_abs(TargetPosition={**HOME_JOINTS, "RY": NEG_INF}), 0x101A),
    ("target_max_real", move_abs(TargetPosition={**HOME_JOINTS, "X": MAX_REAL}), 0x101A),
]


@pytest.mark.parametrize("values,code", [c[1:] for c in MOVE_ABS_CASES], ids=[c[0] for c in MOVE_ABS_CASES])
def test_move_absolute_numbers(rig, values, code):
    rig.set_struct("MoveParam", values)
    res = command(rig, "mover", "MoveExec")
    refused_or_sent(res, code, lambda: abs_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [
    ("MovementCommand", -1, 0x1010), ("MovementCommand", 2, 0x1010), ("MovementCommand", 32767, 0x1010),
    ("DataFormat", -1, 0x1011), ("DataFormat", 7, 0x1011), ("DataFormat", 255, 0x1011),
    ("RobotPose.Pose1", 2, 0x1019), ("RobotPose.Pose2", -1, 0x1019), ("RobotPose.Pose3", 9, 0x1019),
    ("BufferMode", 2, 0x1030), ("BufferMode", -1, 0x1030),
])
def test_move_absolute_undefined_enumeration_values_are_refused(rig, member, raw, code):
    rig.set_struct("MoveParam", move_abs(MovementCommand="PTP", DataFormat="CPP_Abs", RobotPoseEnable=True,
                                         RobotPose=dict(Pose1="Righty", Pose2="Above", Pose3="NoFlip"),
                                         TargetPosition=dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90)))
    rig.write("mover.BufferMode" if member == "BufferMode" else f"MoveParam.{member}", raw, raw=True)
    refused(command(rig, "mover", "MoveExec"), code)


def test_move_absolute_d_format_on_tmflow_1_is_refused(rig):
    rig.write("Cobot.RobotSoftware", "TMflow1x")
    rig.set_struct("MoveParam", line_abs(DataFormat="CDP_Abs"))
    refused(command(rig, "mover", "MoveExec"), 0x1027)


REL_CASES = [
    ("tool_line_mm", rel(DataFormat="TAR_Rel", Speed=4500, BlendingEnable=True, BlendingValue=1000), None),
    ("tool_ptp", rel(MovementCommand="PTP", DataFormat="TPP_Rel", Speed=100), None),
    ("tool_ptp_with_line_format", rel(MovementCommand="PTP", DataFormat="TPR_Rel"), 0x1011),
    ("joint_line", rel(DataFormat="JPP_Rel"), 0x1012),
    ("speed%_0", rel(DataFormat="TPP_Rel", Speed=0), 0x1013),
    ("speedmm_4501", rel(DataFormat="TDP_Rel", Speed=4501), 0x1014),
    ("accel_10000", rel(AccelTime=10000), 0x1015),
    ("blend%_101", rel(DataFormat="TAP_Rel", BlendingEnable=True, BlendingValue=101), 0x1016),
    ("blendmm_1001", rel(DataFormat="TDR_Rel", BlendingEnable=True, BlendingValue=1001), 0x1017),
    ("delta_-0.0", rel(TargetPosition=dict(X=NEG_ZERO, Y=0, Z=-20.5, RX=0, RY=0, RZ=0)), None),
    ("delta_100000", rel(TargetPosition=dict(X=100000.0, Y=0, Z=0, RX=0, RY=0, RZ=0)), None),
    ("delta_past", rel(TargetPosition=dict(X=0, Y=past(-100000.0, False), Z=0, RX=0, RY=0, RZ=0)), 0x101A),
    ("delta_nan", rel(TargetPosition=dict(X=0, Y=0, Z=NAN, RX=0, RY=0, RZ=0)), 0x101A),
    ("delta_inf", rel(TargetPosition=dict(X=0, Y=0, Z=0, RX=0, RY=0, RZ=INF)), 0x101A),
    ("delta_-inf", rel(TargetPosition=dict(X=NEG_INF, Y=0, Z=0, RX=0, RY=0, RZ=0)), 0x101A),
]


@pytest.mark.parametrize("values,code", [c[1:] for c in REL_CASES], ids=[c[0] for c in REL_CASES])
def test_move_relative_numbers(rig, values, code):
    rig.set_struct("RelParam", values)
    res = command(rig, "rel", "RelExec")
    refused_or_sent(res, code, lambda: rel_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [
    ("MovementCommand", 2, 0x1010), ("MovementCommand", -1, 0x1010),
    ("DataFormat", 14, 0x1012), ("DataFormat", -1, 0x1012), ("BufferMode", 3, 0x1030)])
def test_move_relative_undefined_enumeration_values_are_refused(rig, member, raw, code):
    rig.set_struct("RelParam", rel())
    rig.write("rel.BufferMode" if member == "BufferMode" else f"RelParam.{member}", raw, raw=True)
    refused(command(rig, "rel", "RelExec"), code)


CIRCLE_CASES = [
    ("arc_0", circ(ArcAngle=0), None),
    ("arc_360", circ(DataFormat="CPP_Circle", ArcAngle=360, Speed=100, AccelTime=9999), None),
    ("arc_361", circ(ArcAngle=361), 0x101B),
    ("arc_65535", circ(ArcAngle=65535), 0x101B),
    ("mm_speed_4500", circ(DataFormat="CAP_Circle", Speed=4500, BlendingEnable=True, BlendingValue=100), None),
    ("blend_101", circ(BlendingEnable=True, BlendingValue=101), 0x1016),
    ("speed%_101", circ(DataFormat="CPP_Circle", Speed=101), 0x1013),
    ("speed%_0", circ(DataFormat="CPP_Circle", Speed=0), 0x1013),
    ("speedmm_4501", circ(DataFormat="CAP_Circle", Speed=4501), 0x1014),
    ("speedmm_0", circ(DataFormat="CDP_Circle", Speed=0), 0x1014),
    ("accel_10000", circ(AccelTime=10000), 0x1015),
    ("arc_point_nan", circ(ArcPoint=dict(X=NAN, Y=0, Z=0, RX=0, RY=0, RZ=0)), 0x101D),
    ("end_point_-inf", circ(EndPoint=dict(X=0, Y=0, Z=0, RX=0, RY=0, RZ=NEG_INF)), 0x101D),
    ("end_point_past", circ(EndPoint=dict(X=0, Y=0, Z=past(100000.0, True), RX=0, RY=0, RZ=0)), 0x101D),
    ("points_at_limits", circ(ArcPoint=dict(X=-100000.0, Y=100000.0, Z=0.001, RX=NEG_ZERO, RY=0, RZ=0),
                              EndPoint=dict(X=100000.0, Y=-99999.992, Z=0, RX=0, RY=0, RZ=0)), None),
]


@pytest.mark.parametrize("values,code", [c[1:] for c in CIRCLE_CASES], ids=[c[0] for c in CIRCLE_CASES])
def test_move_circle_numbers(rig, values, code):
    rig.set_struct("CircParam", values)
    res = command(rig, "circ", "CircExec")
    refused_or_sent(res, code, lambda: circle_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [("DataFormat", 3, 0x101C), ("DataFormat", 4, 0x101C),
                                             ("DataFormat", -1, 0x101C), ("BufferMode", 2, 0x1030)])
def test_move_circle_undefined_enumeration_values_are_refused(rig, member, raw, code):
    rig.set_struct("CircParam", circ())
    rig.write("circ.BufferMode" if member == "BufferMode" else f"CircParam.{member}", raw, raw=True)
    refused(command(rig, "circ", "CircExec"), code)


# ---- CBT_ChangeBase, CBT_ChangeTCP ------------------------------------------------------------------------------
@pytest.mark.parametrize("member,value,code", [
    ("X", 100000.0, None), ("Y", -100000.0, None), ("Z", NEG_ZERO, None), ("RX", TINY, None),
    ("RY", -99999.992, None), ("RZ", 0.0015, None),
    ("X", past(100000.0, True), 0x101E), ("Y", past(-100000.0, False), 0x101E), ("Z", NAN, 0x101E),
    ("RX", NAN_PAYLOAD, 0x101E), ("RY", INF, 0x101E), ("RZ", NEG_INF, 0x101E), ("X", -MAX_REAL, 0x101E)])
def test_change_base_numbers(rig, member, value, code):
    pose = {**ZERO_POSE, member: value}
    rig.set_struct("BaseParam.Transformation", pose)
    res = command(rig, "base", "BaseExec")
    if code is not None:
        refused(res, code)
        return
    sent(res, f"ChangeBase({pose_text(pose)})")
    assert res.done
    assert rig.events("setting")[-1]["pose"] == pytest.approx(tuple(f32(pose[k]) for k in pose), abs=5e-4)


@pytest.mark.parametrize("kw,code", [
    (dict(Weight=0.0), None), (dict(Weight=14.0), None), (dict(Weight=NEG_ZERO), None),
    (dict(Weight=past(14.0, True)), 0x1020), (dict(Weight=-TINY), 0x1020), (dict(Weight=NAN), 0x1020),
    (dict(Weight=INF), 0x1020), (dict(Weight=NEG_INF), 0x1020),
    (dict(MomentOfInertia__Ixx=100000.0, MomentOfInertia__Iyy=0.001, MomentOfInertia__Izz=NEG_ZERO), None),
    (dict(MomentOfInertia__Ixx=past(100000.0, True)), 0x1021), (dict(MomentOfInertia__Iyy=-TINY), 0x1021),
    (dict(MomentOfInertia__Izz=NAN), 0x1021), (dict(MomentOfInertia__Izz=INF), 0x1021),
    (dict(TCPOffset__X=-100000.0, MassCenter__RZ=100000.0), None),
    (dict(TCPOffset__RZ=past(100000.0, True)), 0x101F), (dict(TCPOffset__Y=NAN), 0x101F),
    (dict(MassCenter__X=NEG_INF), 0x101F), (dict(MassCenter__Z=NAN_PAYLOAD), 0x101F),
    # all sixteen numbers at their longest text: the script must still be sent whole
    (dict(TCPOffset={k: -99999.992 for k in ZERO_POSE}, Weight=13.999,
          MomentOfInertia=dict(Ixx=99999.992, Iyy=99999.992, Izz=99999.992),
          MassCenter={k: -99999.992 for k in ZERO_POSE}), None),
], ids=lambda v: ",".join(f"{k}={v[k]}" for k in v) if isinstance(v, dict) else str(v))
def test_change_tcp_numbers(rig, kw, code):
    values = tcp_values(**kw)
    rig.set_struct("TcpParam", values)
    res = command(rig, "tcp", "TcpExec")
    if code is not None:
        refused(res, code)
    else:
        sent(res, tcp_call(values))
        assert res.done


# ---- CBT_SetOutput, CBT_Stop, CBT_ProgramControl -----------------------------------------------------------------
@pytest.mark.parametrize("module,channel,code", [
    ("ControlBox", 0, None), ("ControlBox", 15, None), ("ControlBox", 16, 0x1025), ("ControlBox", 65535, 0x1025),
    ("EndModule", 0, None), ("EndModule", 3, None), ("EndModule", 4, 0x1025),
    (-1, 0, 0x1024), (2, 0, 0x1024), (127, 0, 0x1024)])
def test_set_output_module_and_channel(rig, module, channel, code):
    rig.write("OutParam.Module", module, raw=isinstance(module, int))
    rig.write("OutParam.Channel", channel)
    rig.write("OutParam.Value", True)
    res = command(rig, "dout", "OutExec")
    if code is not None:
        refused(res, code)
    else:
        sent(res, f'IO["{module}"].DO[{channel}]=1')
        assert res.done


@pytest.mark.parametrize("mode,script", [("StopNormal", "StopAndClearBuffer()"),
                                         ("StopImmediate", "StopAndClearBuffer(0)"),
                                         ("StopAbortScript", "StopAndClearBuffer(1)"),
                                         ("StopDiscardAll", "StopAndClearBuffer(2)"),
                                         (-1, 0x1023), (4, 0x1023), (99, 0x1023)])
def test_stop_modes(rig, mode, script):
    rig.write("StopParam.Mode", mode, raw=isinstance(mode, int))
    res = command(rig, "stop", "StopExec")
    if isinstance(script, int):
        refused(res, script)
        assert not rig.read("Cobot.Stopping")
    else:
        assert res.done and res.scripts == [script]


@pytest.mark.parametrize("cmd,expected", [("Pause", "Pause()"), ("Resume", "Resume()"),
                                          (-1, 0x1022), (2, 0x1022), (200, 0x1022)])
def test_program_control_commands(rig, cmd, expected):
    rig.write("PrgParam.Command", cmd, raw=isinstance(cmd, int))
    res = command(rig, "prg", "PrgExec")
    if isinstance(expected, int):
        refused(res, expected)
    else:
        assert res.done and res.scripts == [expected]


# ---- CBT_ReadVariable, CBT_WriteVariable: names, types, counts, texts, floats (Ethernet Slave) -------------------
@pytest.mark.parametrize("text", ["a,b", "$", "$R$N", "*", "50 %", "a=b;c", "{x}", "\\", "'", "é", "Ω≈",
                                  "", "x" * 80, " lead and trail "],
                         ids=["comma", "dollar", "dollar_escape", "star", "percent", "equals", "braces",
                              "backslash", "quote1", "latin1", "non_latin", "empty", "80_bytes", "spaces"])
def test_write_variable_text_arrives_exactly(var, text):
    """A text with TMscript's delimiters reaches the robot's variable unchanged: one write, nothing refused. The
    robot's texts are UTF-8 (CBT_ReadVariable.md); vplc holds a STRING as one character per byte, so a non-ASCII
    text is written as its UTF-8 bytes, as an HMI writing UTF-8 into the controller leaves it."""
    set_variable(var, "WrVar", "g_text", "VarString", 1, "StringValue", [text.encode("utf-8").decode("latin-1")])
    res = command(var, "wr", "WrExec")
    assert res.done, (hex(res.error_id), res.descrip)
    assert res.svr == [("svr_write", 2, {"g_text": text})]
    assert var.robot.svr.variables["g_text"] == text
    assert res.scripts == []


@pytest.mark.parametrize("text", ['say "hi"', '"', "a\r\nb", "a\rb", "b\n"], ids=["quotes", "quote", "crlf", "cr",
                                                                                 "lf"])
def test_write_variable_text_the_format_cannot_carry_is_refused(var, text):
    set_variable(var, "WrVar", "g_texts", "VarString", 2, "StringValue", ["ok", text])
    refused(command(var, "wr", "WrExec"), 0x1054)
    assert svr_writes(var) == []


@pytest.mark.parametrize("value,code", [(1000000.0, None), (-1000000.0, None), (NEG_ZERO, None), (TINY, None),
                                        (-0.0005, None), (past(1000000.0, True), 0x1053),
                                        (past(-1000000.0, False), 0x1053), (NAN, 0x1053), (NAN_PAYLOAD, 0x1053),
                                        (INF, 0x1053), (NEG_INF, 0x1053)])
def test_write_variable_float_edges(var, value, code):
    set_variable(var, "WrVar", "g_fs", "VarFloat", 2, "FloatValue", [1.5, value])
    res = command(var, "wr", "WrExec")
    if code is not None:
        refused(res, code)
        return
    assert res.done, res.descrip
    assert len(res.svr) == 1
    assert var.robot.svr.variables["g_fs"] == pytest.approx([1.5, float(num(value))], abs=1e-9)


def test_write_variable_checks_only_the_elements_it_writes(var):
    """Count 1: FloatValue[2..16] are not written, so a NaN there is not an error."""
    set_variable(var, "WrVar", "g_f", "VarFloat", 1, "FloatValue", [2.25, NAN])
    res = command(var, "wr", "WrExec")
    assert res.done and var.robot.svr.variables["g_f"] == pytest.approx(2.25)


@pytest.mark.parametrize("fb,path,execute", [("wr", "WrVar", "WrExec"), ("rd", "RdVar", "RdExec")])
@pytest.mark.parametrize("name,kind,count,code", [
    ("", "VarInt", 1, 0x1050), ("1g", "VarInt", 1, 0x1050),
    ("g n", "VarInt", 1, 0x1050), ("g,n", "VarInt", 1, 0x1050), ('g"n', "VarInt", 1, 0x1050),
    ("g=n", "VarInt", 1, 0x1050), ("g$n", "VarInt", 1, 0x1050), ("g*n", "VarInt", 1, 0x1050),
    ("g_né", "VarInt", 1, 0x1050), ("g\r\nn", "VarInt", 1, 0x1050), ("g_n", -1, 1, 0x1051), ("g_n", 4, 1, 0x1051),
    ("g_n", "VarInt", 0, 0x1052), ("g_n", "VarInt", 17, 0x1052), ("g_n", "VarInt", 65535, 0x1052),
    ("g_n", "VarInt", 1, None), ("g_" + "x" * 30, "VarInt", 1, None), ("_g", "VarInt", 1, 0x4040)],
    ids=["empty", "digit_first", "space", "comma", "quote", "equals", "dollar", "star", "non_ascii",
         "crlf", "type_-1", "type_4", "count_0", "count_17", "count_65535", "valid", "32_chars", "not_on_robot"])
def test_variable_name_type_and_count(var, fb, path, execute, name, kind, count, code):
    set_variable(var, path, name, kind, count, "IntValue", [7])
    res = command(var, fb, execute)
    if code is not None and code < 0x2000:
        refused(res, code)
        return
    if code is None:                                              # sent once, the name exactly as given
        assert res.done, res.descrip
        assert len(res.svr) == 1 and list(res.svr[0][2]) == [name], res.svr
    else:                                                         # the robot's answer: sent, and refused there
        assert res.error and res.error_id == code and res.descrip == ERRORS[code][:80]


# ---- CBT_VisionJob: job and variable names, mode, speeds, index --------------------------------------------------
@pytest.mark.parametrize("kw,code", [
    (dict(JobName=""), 0x1060), (dict(JobName='job"1'), 0x1060), (dict(JobName="job,1"), 0x1060),
    (dict(JobName="job 1"), 0x1060), (dict(JobName="job$1"), 0x1060), (dict(JobName="job*1"), 0x1060),
    (dict(JobName="jöb1"), 0x1060), (dict(JobName="job1\r\n"), 0x1060), (dict(JobName="1job"), 0x1060),
    (dict(JobName=LONG_JOB, ObjectVariable=LONG_JOB + "_Base_TM"), None),
    (dict(Mode=3), 0x1061), (dict(Mode=-1), 0x1061),
    (dict(Mode="VisionPTP", Speed=0), 0x1062), (dict(Mode="VisionLine", Speed=101), 0x1062),
    (dict(Mode="VisionLine", Speed=-32768), 0x1062), (dict(Mode="VisionPTP", Speed=1, AccelTime=1), None),
    (dict(Mode="VisionLine", Speed=100), None), (dict(Mode="VisionAtPosition", Speed=-5, AccelTime=-5), None),
    (dict(Mode="VisionPTP", AccelTime=0), 0x1063), (dict(Mode="VisionPTP", AccelTime=10001), 0x1063),
    (dict(Mode="VisionPTP", AccelTime=10000), None), (dict(Mode="VisionLine", AccelTime=-1), None),
    (dict(ObjectVariable=""), 0x1064), (dict(ObjectVariable="job1,Base"), 0x1064),
    (dict(ObjectVariable='job1"'), 0x1064), (dict(ObjectVariable="V" * 48), None),
    (dict(ObjectIndex=-1), 0x1065), (dict(ObjectIndex=64), 0x1065), (dict(ObjectIndex=32767), 0x1065),
    (dict(ObjectIndex=63), None)],
    ids=lambda v: ",".join(f"{k}={v[k]!r}" for k in v) if isinstance(v, dict) else str(v))
def test_vision_job_inputs(vis, kw, code):
    p = dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200, ObjectVariable="job1_Base_TM",
             ObjectIndex=0)
    p.update(kw)
    for key, value in p.items():
        vis.write(f"VisParam.{key}", value, raw=key == "Mode" and isinstance(value, int))
    res = command(vis, "vis", "VisExec")
    if code is not None:
        refused(res, code)
        return
    assert res.scripts[0] == vision_call(p["JobName"], p["Mode"], p["Speed"], p["AccelTime"]), res.scripts
    assert sum("Vision_DoJob" in s for s in res.scripts) == 1         # the job ran once
    assert res.done, res.descrip
    assert vis.read("vis.Found") == (p["ObjectIndex"] == 0 and p["ObjectVariable"].endswith("_Base_TM"))


# ---- CBT_Teach, CBT_ReadActualPosition, CBT_ProjectControl, CBT_SetOverride, CBT_Jog, CBT_Connect ---------------
@pytest.mark.parametrize("name", ['a,b"$*', "P\r\n1", "Ω", "x" * 23], ids=["delimiters", "crlf", "utf8", "23_chars"])
def test_teach_name_is_stored_as_given_and_never_sent(name):
    r = Rig(program="Main_Jog.st")
    try:
        stored = name.encode("utf-8").decode("latin-1")
        r.write("TeachName", stored)
        res = command(r, "teach", "TeachExec", seconds=3)
        assert res.done, res.descrip
        assert r.read("Table[1].Name") == stored and r.read("Table[1].Taught")
        assert not any(stored in s for s in res.scripts)
    finally:
        r.close()


@pytest.mark.parametrize("period_ms,ok", [(10, True), (10000, True), (9, False), (10001, False), (0, False),
                                          (-1, False)])
def test_read_actual_position_period(rig, period_ms, ok):
    rig.write("ReadPeriod", period_ms * 1_000_000)                    # TIME in ns
    rig.write("ReadEnable", True)
    assert rig.until(lambda: rig.read("rd.Valid") or rig.read("rd.Error"), 1)
    if ok:
        assert rig.read("rd.Valid") and not rig.read("rd.Error")
    else:
        before = len(script_frames(rig))
        rig.scans(300)
        assert rig.read("rd.Error") and rig.read("rd.ErrorID") == 0x1004
        assert rig.read("rd.ErrorDescrip") == ERRORS[0x1004][:80]
        assert len(script_frames(rig)) == before                      # nothing asked of the robot
    rig.write("ReadEnable", False)
    rig.scans(2)
    assert not rig.read("rd.Error")


@pytest.mark.parametrize("raw", [-1, 3, 255])
def test_project_control_undefined_command(rig, raw):
    rig.write("ProjCmd", raw, raw=True)
    refused(command(rig, "proj", "ProjExec"), 0x1026)


@pytest.mark.parametrize("value,code", [(5, None), (100, None), (95, None), (0, 0x1040), (4, 0x1040), (7, 0x1040),
                                        (101, 0x1040), (105, 0x1040), (255, 0x1040)])
def test_set_override_values(cell, value, code):
    cell.write("OvrValue", value)
    res = command(cell, "ovr", "OvrExec", seconds=5)
    if code is not None:
        refused(res, code)
        return
    assert res.done, res.descrip
    assert res.svr == [("svr_write", 2, {"Project_Speed": str(value)})] or \
        [s[2] for s in res.svr] == [{"Project_Speed": value}], res.svr
    assert res.scripts == []


@pytest.mark.parametrize("path,value,code", [("JogAxis", 0, 0x1071), ("JogAxis", 7, 0x1071), ("JogAxis", 255, 0x1071),
                                             ("JogVelocity", 0, 0x1072), ("JogVelocity", 101, 0x1072),
                                             ("JogVelocity", 65535, 0x1072), ("JogFrame", 3, 0x1070),
                                             ("JogFrame", -1, 0x1070), ("JogFrame", 127, 0x1070)])
def test_jog_inputs_out_of_range(path, value, code):
    r = Rig(program="Main_Jog.st")
    try:
        r.write(path, value, raw=path == "JogFrame")
        before = len(script_frames(r))
        r.write("JogFwd", True)
        r.scans(20)
        assert r.read("jog.Error") and r.read("jog.ErrorID") == code and r.read("jog.ErrorDescrip") == ERRORS[code][:80]
        assert len(script_frames(r)) == before
    finally:
        r.close()


@pytest.mark.parametrize("address", ["", "127.0.0.1,5890", '127.0.0.1"', "127.0.0.1$R$N", "*", "999.1.1.1",
                                     "127.0.0.1 ", "localhost", "::1", "1" * 49],
                         ids=["empty", "comma", "quote", "crlf", "star", "octet_999", "trailing_space", "name",
                              "ipv6", "49_chars"])
def test_connect_address_that_is_not_an_ipv4_address_never_connects(address):
    """Empty: 16#1002 at once; anything else that is not a dotted IPv4 address: an error with its text, never
    Connected, and the robot sees no connection."""
    r = Rig(connect=False)
    try:
        r.write("Ip", address)
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Error"), 15), "no error for a bad address"
        error_id = r.read("conn.ErrorID")
        assert r.read("conn.ErrorDescrip") == ERRORS[error_id][:80]
        if address == "":
            assert error_id == 0x1002
        assert not r.read("Cobot.Connected") and r.events("connect") == []
    finally:
        r.close()


# ---- the whole script of the options: arm configuration, Aborting, ExitNode, InstantDO ---------------------------
CPP_TARGET = dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90)


@pytest.mark.parametrize("pose,text", [(("Righty", "Above", "NoFlip"), "0,2,4"), (("Lefty", "Below", "Flip"), "1,3,5"),
                                       (("Lefty", "Above", "Flip"), "1,2,5"), (("Righty", "Below", "NoFlip"), "0,3,4")])
def test_move_absolute_arm_configuration_is_the_three_pose_integers(rig, pose, text):
    """TMscript 2.24 §13.8 PTP Syntax 2: Config1 0/1, Config2 2/3, Config3 4/5 after the precise-positioning flag."""
    values = move_abs(DataFormat="CPP_Abs", TargetPosition=CPP_TARGET, RobotPoseEnable=True,
                      RobotPose=dict(Pose1=pose[0], Pose2=pose[1], Pose3=pose[2]))
    rig.set_struct("MoveParam", values)
    res = command(rig, "mover", "MoveExec")
    assert res.scripts and res.scripts[0].split("\r\n")[0] == abs_call(values)[:-1] + f",{text})", res.scripts


@pytest.mark.parametrize("fb,param,values,tail", [
    ("mover", "MoveParam", move_abs(ExitNode=True), "QueueTag(1)\r\nScriptExit()"),
    ("rel", "RelParam", rel(ExitNode=True, BlendingEnable=True, BlendingValue=50), "ScriptExit()"),
    ("circ", "CircParam", circ(ExitNode=True), "QueueTag(1)\r\nScriptExit()")])
def test_exit_node_is_the_last_line_after_the_queue_tag(rig, fb, param, values, tail):
    rig.set_struct(param, values)
    res = command(rig, fb, {"mover": "MoveExec", "rel": "RelExec", "circ": "CircExec"}[fb])
    assert len(res.scripts) == 1 and res.scripts[0].split("\r\n", 1)[1] == tail, res.scripts


@pytest.mark.parametrize("fb,param,values,call", [
    ("mover", "MoveParam", move_abs(), abs_call(move_abs())),
    ("rel", "RelParam", rel(), rel_call(rel())),
    ("circ", "CircParam", circ(), circle_call(circ()))])
def test_aborting_is_one_script_stop_and_clear_then_the_motion(rig, fb, param, values, call):
    """TMscript 2.24 §13.4: StopAndClearBuffer() first, in the same script, so nothing runs in between."""
    rig.set_struct(param, values)
    rig.write(f"{fb}.BufferMode", "Aborting")
    res = command(rig, fb, {"mover": "MoveExec", "rel": "RelExec", "circ": "CircExec"}[fb])
    assert len(res.scripts) == 1 and res.scripts[0].split("\r\n")[:2] == ["StopAndClearBuffer()", call], res.scripts
    assert res.done


@pytest.mark.parametrize("immediate,value,text", [(True, True, 'IO["ControlBox"].InstantDO[15]=1'),
                                                  (True, False, 'IO["ControlBox"].InstantDO[15]=0'),
                                                  (False, False, 'IO["ControlBox"].DO[15]=0')])
def test_set_output_immediate_and_value(rig, immediate, value, text):
    rig.set_struct("OutParam", dict(Module="ControlBox", Channel=15, Value=value, Immediate=immediate))
    res = command(rig, "dout", "OutExec")
    assert res.done and res.scripts == [text], res.scripts


@pytest.mark.parametrize("texts", [["}", "a,b}"], ["{", ""], ["$", "*"], ["\\", "\\\\"], ["a\tb", " "]],
                         ids=["close_brace", "open_brace", "dollar_star", "backslashes", "tab_space"])
def test_write_variable_text_array_with_the_array_delimiters_arrives_exactly(var, texts):
    """An array is written as {"..","..."} (TMscript 2.24 §17.4.3): braces and commas inside the texts stay texts."""
    set_variable(var, "WrVar", "g_texts", "VarString", 2, "StringValue", texts)
    res = command(var, "wr", "WrExec")
    assert res.done, res.descrip
    assert len(res.svr) == 1 and var.robot.svr.variables["g_texts"] == texts
