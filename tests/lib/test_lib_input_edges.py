"""Every input of every public FB at its edges, the robot's own log as the witness (the maintainers' probe).

For each case either nothing reaches the robot and the FB ends in Error with the ErrorID of docs/library/errors.tsv
and its text in ErrorDescrip, or exactly one script reaches it whose call carries exactly the values given (numbers
as CBTi_FormatReal prints them: up to 3 decimals, no exponent, docs/library/design.md) and the FB reports Done
only when the robot did it (a motion: its motion_end; any other command: the robot's OK). Besides the values at
and just past each bound (REAL: the next 32-bit float, NaN, +/-Inf, -0.0, the smallest subnormal), undefined
enumeration values, names with TMscript's delimiters, and the PLCopen edges: Execute held, pulsed for one scan,
re-raised while Busy, inputs changed while Busy, two FBs started in one scan, the link lost at each step.
Virtual time; one simulator and one PLC per case (the compiled library is shared, a rig costs milliseconds)."""
from __future__ import annotations

import csv
import struct
from dataclasses import dataclass, field

import pytest
from rig import HOME_JOINTS, ROOT, Rig, circ, move_abs, rel

from tmsim.protocol import svr_table as table
from vplc.runtime.values import PathError

ERRORS = {int(r["id"][3:], 16): r["text"]
          for r in csv.DictReader((ROOT / "docs/library/errors.tsv").open(encoding="utf-8"), delimiter="\t")}

NAN = struct.unpack("<f", struct.pack("<I", 0x7FC00000))[0]
NAN_PAYLOAD = struct.unpack("<f", struct.pack("<I", 0xFFC12345))[0]          # negative quiet NaN with a payload
INF = struct.unpack("<f", struct.pack("<I", 0x7F800000))[0]
NEG_INF = struct.unpack("<f", struct.pack("<I", 0xFF800000))[0]
NEG_ZERO = struct.unpack("<f", struct.pack("<I", 0x80000000))[0]
TINY = struct.unpack("<f", struct.pack("<I", 0x00000001))[0]                  # smallest subnormal, 1.4e-45
MAX_REAL = struct.unpack("<f", struct.pack("<I", 0x7F7FFFFF))[0]


def f32(value: float) -> float:
    return struct.unpack("<f", struct.pack("<f", value))[0]


def past(limit: float, up: bool) -> float:
    """The next 32-bit float beyond ``limit`` (up: towards +Inf)."""
    bits = struct.unpack("<I", struct.pack("<f", limit))[0]
    if limit == 0:
        return TINY if up else -TINY
    bits += 1 if up == (limit > 0) else -1
    return struct.unpack("<f", struct.pack("<I", bits))[0]


def num(value: float) -> str:
    """A REAL as the library must print it into a script: the 32-bit value rounded to 3 decimals, trailing zeros
    dropped, no '+' and no exponent (TMscript 2.24 §1.3 numeric literals; design.md, CBTi_FormatReal)."""
    milli = round(f32(value) * 1000)
    sign = "-" if milli < 0 else ""
    whole, frac = divmod(abs(milli), 1000)
    text = f"{sign}{whole}"
    if frac:
        text += "." + f"{frac:03d}".rstrip("0")
    return text


def pose_text(p: dict) -> str:
    return ",".join(num(p[k]) for k in ("X", "Y", "Z", "RX", "RY", "RZ"))


# ---- the rig around one command ----------------------------------------------------------------------------------
@dataclass
class Outcome:
    done: bool
    error: bool
    aborted: bool
    error_id: int
    descrip: str
    scripts: list[str] = field(default_factory=list)         # every TMSCT script sent since the Execute edge
    svr: list = field(default_factory=list)                  # every Ethernet Slave request since the edge
    motion_ends: int = 0


def script_frames(rig) -> list[str]:
    return [s for _, s in rig.scripts_in()]


def svr_frames(rig) -> list:
    """Every Ethernet Slave request the robot took: (kind, mode, items) - a write's items {name: value text}, a
    read's [name]."""
    return [(e["kind"], e["mode"], e["items"]) for e in rig.robot.events if e["kind"] in ("svr_read", "svr_write")]


def has(rig, path: str) -> bool:
    try:
        rig.read(path)
    except PathError:
        return False
    return True


def command(rig, fb: str, execute: str, seconds: float = 30.0, hold: bool = True) -> Outcome:
    """Raise ``execute``, wait until the FB ends, lower it; what the FB reported and what the robot received."""
    before, svr_before = len(script_frames(rig)), len(svr_frames(rig))
    ends_before = len(rig.events("motion_end"))
    rig.write(execute, True)
    if not hold:
        rig.scans(1)
        rig.write(execute, False)
    seen = {}
    outs = [o for o in ("Done", "Error", "CommandAborted") if has(rig, f"{fb}.{o}")]

    def ended():
        for out in outs:
            if rig.read(f"{fb}.{out}"):
                seen.setdefault("at", (out, rig.read(f"{fb}.ErrorID"), rig.read(f"{fb}.ErrorDescrip"),
                                       len(rig.events("motion_end")) - ends_before))
                return True
        return False
    assert rig.until(ended, seconds), f"{fb} still Busy after {seconds} s"
    out, error_id, descrip, ends = seen["at"]
    rig.write(execute, False)
    rig.scans(3)
    return Outcome(out == "Done", out == "Error", out == "CommandAborted", error_id, descrip,
                   script_frames(rig)[before:], svr_frames(rig)[svr_before:], ends)


def refused(res: Outcome, code: int) -> None:
    """Nothing reached the robot; Error with the documented ErrorID and its text."""
    assert res.scripts == [] and res.svr == [], f"sent although refused: {res.scripts or res.svr}"
    assert res.error and not res.done, res
    assert res.error_id == code, f"ErrorID {res.error_id:#06x}, expected {code:#06x}: {res.descrip}"
    assert res.descrip == ERRORS[code][:80], res.descrip


def sent(res: Outcome, call: str, motion: bool = False) -> str:
    """Exactly one script reached the robot and its command line is ``call``; Done only once the robot did it."""
    assert len(res.scripts) == 1, f"{len(res.scripts)} scripts sent: {res.scripts}"
    lines = res.scripts[0].split("\r\n")
    body = [line for line in lines if not line.startswith(("QueueTag(", "ScriptExit(", "StopAndClearBuffer("))]
    assert body == [call], f"sent {lines}, expected the line {call!r}"
    if res.done and motion:                    # a non-blended motion: Done when it arrived
        assert res.motion_ends == 1, "Done without the robot finishing the motion"
    if not res.done:
        assert res.error or res.aborted, res
        assert res.error_id == 0 or res.descrip, res
    return res.scripts[0]


@pytest.fixture
def lib():
    r = Rig()
    yield r
    r.close()


# ---- CBT_MoveAbsolute, CBT_MoveRelative, CBT_MoveCircle: the numbers ---------------------------------------------
ABS_FORMATS = ["JPP", "CPP", "CPR", "CAP", "CAR", "CDP", "CDR"]            # eCBT_MovCmdAbs_DataFormat's order
REL_FORMATS = ["JPP", "CPP", "CPR", "CAP", "CAR", "TPP", "TPR", "TAP", "TAR", "CDP", "CDR", "TDP", "TDR"]
CIRCLE_FORMATS = ["CPP", "CAP", "CDP"]


def fmt_name(value, names: list[str]) -> str:
    """TM's three letters of a data format given by name ('CPR_Abs') or by its enumeration value."""
    return value[:3] if isinstance(value, str) else names[value]


def abs_call(p: dict) -> str:
    cmd = "PTP" if p["MovementCommand"] in (1, "PTP") else "Line"
    fmt = fmt_name(p["DataFormat"], ABS_FORMATS)
    blend = p["BlendingValue"] if p["BlendingEnable"] else 0
    return (f'{cmd}("{fmt}",{pose_text(p["TargetPosition"])},{p["Speed"]},{p["AccelTime"]},{blend},'
            f'{"false" if p["PrecisePositioning"] else "true"})')


def line_abs(**kw):
    """A Line to a reachable Cartesian point (the simulator's home TCP region) unless overridden."""
    base = dict(MovementCommand="Line", DataFormat="CPP_Abs",
                TargetPosition=dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90))
    base.update(kw)
    return move_abs(**base)


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
def test_move_absolute_numbers(lib, values, code):
    lib.set_struct("MoveParam", values)
    res = command(lib, "mover", "MoveExec")
    if code is not None:
        refused(res, code)
    else:
        sent(res, abs_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [
    ("MovementCommand", -1, 0x1010), ("MovementCommand", 2, 0x1010), ("MovementCommand", 32767, 0x1010),
    ("DataFormat", -1, 0x1011), ("DataFormat", 7, 0x1011), ("DataFormat", 255, 0x1011),
    ("RobotPose.Pose1", 2, 0x1019), ("RobotPose.Pose2", -1, 0x1019), ("RobotPose.Pose3", 9, 0x1019),
    ("BufferMode", 2, 0x1030), ("BufferMode", -1, 0x1030),
])
def test_move_absolute_undefined_enumeration_values_are_refused(lib, member, raw, code):
    lib.set_struct("MoveParam", move_abs(MovementCommand="PTP", DataFormat="CPP_Abs", RobotPoseEnable=True,
                                         RobotPose=dict(Pose1="Righty", Pose2="Above", Pose3="NoFlip"),
                                         TargetPosition=dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90)))
    lib.write("mover.BufferMode" if member == "BufferMode" else f"MoveParam.{member}", raw, raw=True)
    refused(command(lib, "mover", "MoveExec"), code)


def test_move_absolute_d_format_on_tmflow_1_is_refused(lib):
    lib.write("Cobot.RobotSoftware", "TMflow1x")
    lib.set_struct("MoveParam", line_abs(DataFormat="CDP_Abs"))
    refused(command(lib, "mover", "MoveExec"), 0x1027)


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


def rel_call(p: dict) -> str:
    cmd = "PTP" if p["MovementCommand"] in (1, "PTP") else "Line"
    fmt = fmt_name(p["DataFormat"], REL_FORMATS)
    blend = p["BlendingValue"] if p["BlendingEnable"] else 0
    return (f'Move_{cmd}("{fmt}",{pose_text(p["TargetPosition"])},{p["Speed"]},{p["AccelTime"]},{blend},'
            f'{"false" if p["PrecisePositioning"] else "true"})')


@pytest.mark.parametrize("values,code", [c[1:] for c in REL_CASES], ids=[c[0] for c in REL_CASES])
def test_move_relative_numbers(lib, values, code):
    lib.set_struct("RelParam", values)
    res = command(lib, "rel", "RelExec")
    if code is not None:
        refused(res, code)
    else:
        sent(res, rel_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [
    ("MovementCommand", 2, 0x1010), ("MovementCommand", -1, 0x1010),
    ("DataFormat", 14, 0x1012), ("DataFormat", -1, 0x1012), ("BufferMode", 3, 0x1030)])
def test_move_relative_undefined_enumeration_values_are_refused(lib, member, raw, code):
    lib.set_struct("RelParam", rel())
    lib.write("rel.BufferMode" if member == "BufferMode" else f"RelParam.{member}", raw, raw=True)
    refused(command(lib, "rel", "RelExec"), code)


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


def circle_call(p: dict) -> str:
    blend = p["BlendingValue"] if p["BlendingEnable"] else 0
    fmt = fmt_name(p["DataFormat"], CIRCLE_FORMATS)
    return (f'Circle("{fmt}",{pose_text(p["ArcPoint"])},{pose_text(p["EndPoint"])},{p["Speed"]},'
            f'{p["AccelTime"]},{blend},{p["ArcAngle"]},{"false" if p["PrecisePositioning"] else "true"})')


@pytest.mark.parametrize("values,code", [c[1:] for c in CIRCLE_CASES], ids=[c[0] for c in CIRCLE_CASES])
def test_move_circle_numbers(lib, values, code):
    lib.set_struct("CircParam", values)
    res = command(lib, "circ", "CircExec")
    if code is not None:
        refused(res, code)
    else:
        sent(res, circle_call(values), motion=not values["BlendingEnable"])


@pytest.mark.parametrize("member,raw,code", [("DataFormat", 3, 0x101C), ("DataFormat", 4, 0x101C),
                                             ("DataFormat", -1, 0x101C), ("BufferMode", 2, 0x1030)])
def test_move_circle_undefined_enumeration_values_are_refused(lib, member, raw, code):
    lib.set_struct("CircParam", circ())
    lib.write("circ.BufferMode" if member == "BufferMode" else f"CircParam.{member}", raw, raw=True)
    refused(command(lib, "circ", "CircExec"), code)


# ---- CBT_ChangeBase, CBT_ChangeTCP ------------------------------------------------------------------------------
ZERO_POSE = dict(X=0, Y=0, Z=0, RX=0, RY=0, RZ=0)


@pytest.mark.parametrize("member,value,code", [
    ("X", 100000.0, None), ("Y", -100000.0, None), ("Z", NEG_ZERO, None), ("RX", TINY, None),
    ("RY", -99999.992, None), ("RZ", 0.0015, None),
    ("X", past(100000.0, True), 0x101E), ("Y", past(-100000.0, False), 0x101E), ("Z", NAN, 0x101E),
    ("RX", NAN_PAYLOAD, 0x101E), ("RY", INF, 0x101E), ("RZ", NEG_INF, 0x101E), ("X", -MAX_REAL, 0x101E)])
def test_change_base_numbers(lib, member, value, code):
    pose = {**ZERO_POSE, member: value}
    lib.set_struct("BaseParam.Transformation", pose)
    res = command(lib, "base", "BaseExec")
    if code is not None:
        refused(res, code)
        return
    sent(res, f"ChangeBase({pose_text(pose)})")
    assert res.done
    assert lib.events("setting")[-1]["pose"] == pytest.approx(tuple(f32(pose[k]) for k in pose), abs=5e-4)


def tcp_values(**kw):
    p = dict(TCPOffset=dict(ZERO_POSE, Z=120.5), Weight=1.5, MomentOfInertia=dict(Ixx=0, Iyy=0, Izz=0),
             MassCenter=dict(ZERO_POSE, Z=60.25))
    for key, value in kw.items():
        part, _, member = key.partition("__")
        if member:
            p[part] = {**p[part], member: value}
        else:
            p[part] = value
    return p


def tcp_call(p: dict) -> str:
    inertia = p["MomentOfInertia"]
    return (f'ChangeTCP({pose_text(p["TCPOffset"])},{num(p["Weight"])},{num(inertia["Ixx"])},{num(inertia["Iyy"])},'
            f'{num(inertia["Izz"])},{pose_text(p["MassCenter"])})')


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
def test_change_tcp_numbers(lib, kw, code):
    values = tcp_values(**kw)
    lib.set_struct("TcpParam", values)
    res = command(lib, "tcp", "TcpExec")
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
def test_set_output_module_and_channel(lib, module, channel, code):
    lib.write("OutParam.Module", module, raw=isinstance(module, int))
    lib.write("OutParam.Channel", channel)
    lib.write("OutParam.Value", True)
    res = command(lib, "dout", "OutExec")
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
def test_stop_modes(lib, mode, script):
    lib.write("StopParam.Mode", mode, raw=isinstance(mode, int))
    res = command(lib, "stop", "StopExec")
    if isinstance(script, int):
        refused(res, script)
        assert not lib.read("Cobot.Stopping")
    else:
        assert res.done and res.scripts == [script]


@pytest.mark.parametrize("cmd,expected", [("Pause", "Pause()"), ("Resume", "Resume()"),
                                          (-1, 0x1022), (2, 0x1022), (200, 0x1022)])
def test_program_control_commands(lib, cmd, expected):
    lib.write("PrgParam.Command", cmd, raw=isinstance(cmd, int))
    res = command(lib, "prg", "PrgExec")
    if isinstance(expected, int):
        refused(res, expected)
    else:
        assert res.done and res.scripts == [expected]


# ---- CBT_ReadVariable, CBT_WriteVariable: names, types, counts, texts, floats (Ethernet Slave) -------------------
SPECS = ["g_text:string", "g_texts:string[2]", "g_f:float", "g_fs:float[2]", "g_n:int",
         "g_" + "x" * 30 + ":int"]                                  # a name of 32 characters


@pytest.fixture
def var():
    r = Rig(program="Main_Var.st", svr_port=0, svr_options={"variables": [table.parse_variable(s) for s in SPECS]})
    assert r.until(lambda: r.read("Cobot.Status.SlaveLink"), 1)
    yield r
    r.close()


def svr_writes(rig) -> list:
    return [e for e in rig.robot.events if e["kind"] == "svr_write"]


def set_variable(rig, path, name, kind, count=1, member=None, values=()):
    rig.write(f"{path}.Name", name)
    rig.write(f"{path}.DataType", kind, raw=isinstance(kind, int))
    rig.write(f"{path}.Count", count)
    for k, value in enumerate(values, start=1):
        rig.write(f"{path}.{member}[{k}]", value)


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
LONG_JOB = "J" * 32                                                  # the longest job name TMflow takes


@pytest.fixture
def vis():
    from tmsim.robot.camera import camera_of
    r = Rig(program="Main_Vision.st")
    camera = camera_of(r.robot.session.robot)
    for job in ("job1", LONG_JOB):
        camera.define(job, objects=[[417.5, -122.3, 300, 0, 0, 0]], seconds=0.1)
    yield r
    r.close()


def vision_call(job: str, mode: str, speed: int, accel: int) -> str:
    call = {"VisionAtPosition": f'Vision_DoJob("{job}")', "VisionPTP": f'Vision_DoJob_PTP("{job}",{speed},{accel})',
            "VisionLine": f'Vision_DoJob_Line("{job}",{speed})'}[mode]
    return f'ListenSend(90,GetString(Vision_IsJobAvailable("{job}")))\r\nListenSend(91,GetString({call}))'


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
def test_read_actual_position_period(lib, period_ms, ok):
    lib.write("ReadPeriod", period_ms * 1_000_000)                    # TIME in ns
    lib.write("ReadEnable", True)
    assert lib.until(lambda: lib.read("rd.Valid") or lib.read("rd.Error"), 1)
    if ok:
        assert lib.read("rd.Valid") and not lib.read("rd.Error")
    else:
        before = len(script_frames(lib))
        lib.scans(300)
        assert lib.read("rd.Error") and lib.read("rd.ErrorID") == 0x1004
        assert lib.read("rd.ErrorDescrip") == ERRORS[0x1004][:80]
        assert len(script_frames(lib)) == before                      # nothing asked of the robot
    lib.write("ReadEnable", False)
    lib.scans(2)
    assert not lib.read("rd.Error")


@pytest.mark.parametrize("raw", [-1, 3, 255])
def test_project_control_undefined_command(lib, raw):
    lib.write("ProjCmd", raw, raw=True)
    refused(command(lib, "proj", "ProjExec"), 0x1026)


@pytest.fixture
def cell():
    r = Rig(program="Main_Cell.st", svr_port=0)
    r.write("StatusEnable", True)
    assert r.until(lambda: r.read("status.Valid"), 1)
    yield r
    r.close()


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


# ---- PLCopen: Execute held, pulsed, re-raised; inputs changed while Busy; two FBs in one scan ---------------------
SLOW = dict(TargetPosition={**HOME_JOINTS, "RZ": 60.0}, Speed=20)         # about 1 s of motion


def setup_command(rig, fb: str) -> tuple[str, str]:
    """Valid parameters for one FB of Main_Lib.st; (instance, Execute variable)."""
    if fb == "mover":
        rig.set_struct("MoveParam", move_abs(**SLOW))
        return "mover", "MoveExec"
    if fb == "rel":
        rig.set_struct("RelParam", rel())
        return "rel", "RelExec"
    if fb == "circ":
        rig.set_struct("CircParam", circ())
        return "circ", "CircExec"
    if fb == "base":
        rig.set_struct("BaseParam.Transformation", dict(ZERO_POSE, X=10.5))
        return "base", "BaseExec"
    if fb == "tcp":
        rig.set_struct("TcpParam", tcp_values())
        return "tcp", "TcpExec"
    if fb == "dout":
        rig.set_struct("OutParam", dict(Module="EndModule", Channel=2, Value=True))
        return "dout", "OutExec"
    if fb == "prg":
        rig.write("PrgParam.Command", "Resume")
        return "prg", "PrgExec"
    rig.write("StopParam.Mode", "StopNormal")
    return "stop", "StopExec"


FBS = ["mover", "rel", "circ", "base", "tcp", "dout", "prg", "stop"]
OUTS = ("Done", "Busy", "Error", "CommandAborted")


def trace(rig, fb: str, scans: int, on_scan=None) -> list[dict]:
    """The FB's outputs after each of ``scans`` scans."""
    rows = []
    for n in range(scans):
        if on_scan:
            on_scan(n)
        rig.scans(1)
        rows.append({o: rig.read(f"{fb}.{o}") for o in OUTS})
    return rows


@pytest.mark.parametrize("fb", FBS)
def test_execute_held_sends_once_and_done_stays_until_it_falls(lib, fb):
    inst, execute = setup_command(lib, fb)
    lib.write(execute, True)
    rows = trace(lib, inst, 3000)                                        # 3 s held
    first = next(i for i, r in enumerate(rows) if r["Done"])
    assert all(r["Done"] and not r["Busy"] and not r["Error"] for r in rows[first:])
    assert all(r["Busy"] and not r["Done"] for r in rows[:first])
    assert len(script_frames(lib)) == 1
    if inst in ("mover", "rel"):
        assert len(lib.events("motion_end")) == 1
    lib.write(execute, False)
    lib.scans(1)
    assert not any(lib.read(f"{inst}.{o}") for o in OUTS)
    lib.scans(500)
    assert len(script_frames(lib)) == 1


@pytest.mark.parametrize("fb", FBS)
def test_execute_pulsed_for_one_scan_sends_once_and_shows_done_for_one_scan(lib, fb):
    inst, execute = setup_command(lib, fb)
    rows = trace(lib, inst, 3000, on_scan=lambda n: lib.write(execute, n == 0))
    assert [r["Done"] for r in rows].count(True) == 1, "Done must show for exactly one scan"
    assert not any(r["Error"] or r["CommandAborted"] for r in rows)
    done_at = next(i for i, r in enumerate(rows) if r["Done"])
    assert all(r["Busy"] for r in rows[:done_at]) and not any(r["Busy"] for r in rows[done_at:])
    assert len(script_frames(lib)) == 1
    if inst in ("mover", "rel"):
        assert len(lib.events("motion_end")) == 1


@pytest.mark.parametrize("fb,member,raw,code", [("mover", "MoveParam.Speed", 0, 0x1013),
                                                ("base", "BaseParam.Transformation.X", NAN, 0x101E),
                                                ("dout", "OutParam.Channel", 99, 0x1025),
                                                ("stop", "StopParam.Mode", 9, 0x1023)])
def test_a_refused_pulse_shows_error_for_one_scan(lib, fb, member, raw, code):
    inst, execute = setup_command(lib, fb)
    lib.write(member, raw, raw=isinstance(raw, int) and fb == "stop")
    rows = trace(lib, inst, 5, on_scan=lambda n: lib.write(execute, n == 0))
    assert [r["Error"] for r in rows] == [True, False, False, False, False]
    assert not any(r["Busy"] or r["Done"] for r in rows)
    assert script_frames(lib) == []


def test_execute_re_raised_while_busy_starts_one_new_command_per_edge(lib):
    """R5: the new edge replaces the running command; the first motion was sent and runs (it is the robot's), the
    second is sent once, and Done comes when the robot finished the second."""
    inst, execute = setup_command(lib, "mover")
    lib.write(execute, True)
    assert lib.until(lambda: lib.read("mover.Active"), 1)
    lib.write(execute, False)
    lib.scans(1)
    lib.set_struct("MoveParam.TargetPosition", {**HOME_JOINTS, "RZ": -30.0})
    lib.write(execute, True)
    lib.scans(1)
    assert lib.read("mover.Busy") and not lib.read("mover.Done")
    assert lib.until(lambda: lib.read("mover.Done") or lib.read("mover.Error"), 10)
    assert lib.read("mover.Done"), lib.read("mover.ErrorDescrip")
    ends = [round(e["joints"][5]) for e in lib.events("motion_end")]
    assert ends == [60, -30], ends                                     # both ran, in order, Done after the second
    scripts = script_frames(lib)
    assert len(scripts) == 2 and "60" in scripts[0].split(",")[6] and "-30" in scripts[1].split(",")[6]
    lib.write(execute, False)
    lib.scans(500)
    assert len(script_frames(lib)) == 2


def test_inputs_changed_while_busy_are_not_taken(lib):
    """R4: the parameters are latched at the edge: what the robot gets and where it ends are the edge's values."""
    inst, execute = setup_command(lib, "mover")
    lib.write(execute, True)
    lib.scans(1)
    lib.set_struct("MoveParam", move_abs(TargetPosition={**HOME_JOINTS, "RZ": -45.0}, Speed=100, DataFormat="CPR_Abs"))
    lib.write("mover.BufferMode", "Aborting")
    assert lib.until(lambda: lib.read("mover.Done") or lib.read("mover.Error"), 10)
    assert lib.read("mover.Done"), lib.read("mover.ErrorDescrip")
    assert [round(e["joints"][5]) for e in lib.events("motion_end")] == [60]
    scripts = script_frames(lib)
    assert len(scripts) == 1 and scripts[0].split("\r\n")[0] == abs_call(move_abs(**SLOW)), scripts


def test_write_variable_text_changed_while_busy_is_not_taken(var):
    set_variable(var, "WrVar", "g_text", "VarString", 1, "StringValue", ["first"])
    var.write("WrExec", True)
    var.scans(1)
    var.write("WrVar.StringValue[1]", "second")
    var.write("WrVar.Name", "g_n")
    assert var.until(lambda: var.read("wr.Done") or var.read("wr.Error"), 3)
    assert var.read("wr.Done") and var.robot.svr.variables["g_text"] == "first"
    assert [w["items"] for w in svr_writes(var)] == [{"g_text": "first"}]


def test_execute_re_raised_while_a_write_is_busy_is_ignored(var):
    set_variable(var, "WrVar", "g_text", "VarString", 1, "StringValue", ["one"])
    var.write("WrExec", True)
    var.scans(1)
    assert var.read("wr.Busy")
    var.write("WrExec", False)
    var.scans(1)
    var.write("WrExec", True)
    assert var.until(lambda: var.read("wr.Done") or var.read("wr.Error"), 3)
    var.write("WrExec", False)
    var.scans(100)
    assert len(svr_writes(var)) == 1


def test_every_fb_started_in_the_same_scan_sends_once_each_in_call_order(lib):
    """Main_Lib.st calls mover, rel, circ, base, tcp, prg, stop, dout, ..., movers[1..4]: every one started in one
    scan goes out once, in that order, and each ends Done (the stop last would abort the motions: left out)."""
    started = [setup_command(lib, fb) for fb in ("mover", "base", "tcp", "dout")]
    for k in (1, 2):
        lib.set_struct(f"MParam[{k}]", move_abs(TargetPosition={**HOME_JOINTS, "RZ": 10.0 * k}))
        started.append((f"movers[{k}]", f"MExec[{k}]"))
    for _, execute in started:
        lib.write(execute, True)
    assert lib.until(lambda: all(lib.read(f"{i}.Done") or lib.read(f"{i}.Error") for i, _ in started), 20)
    assert all(lib.read(f"{i}.Done") for i, _ in started), {i: lib.read(f"{i}.ErrorDescrip") for i, _ in started}
    heads = [s.split("(")[0] for s in script_frames(lib)]
    assert heads == ["PTP", "ChangeBase", "ChangeTCP", 'IO["EndModule"].DO[2]=1', "PTP", "PTP"], heads
    assert len(lib.events("motion_end")) == 3



# ---- the link lost at each step of a command ---------------------------------------------------------------------
def lose_link(rig) -> None:
    rig.robot.inject("disconnect")


STEPS = ["before_the_edge", "in_the_edge_scan", "reply_held_back", "while_moving", "after_done"]


@pytest.mark.parametrize("fb,step", [(fb, step) for fb in ("mover", "base", "dout") for step in STEPS
                                     if fb == "mover" or step != "while_moving"])
def test_link_lost_at_each_step_never_reports_what_the_robot_did_not_do(lib, fb, step):
    """At most one frame; the FB ends (never Busy for good); Done only if the robot did it, else Error with a
    documented ErrorID and its text. A command refused before the edge sends nothing."""
    inst, execute = setup_command(lib, fb)
    if step == "before_the_edge":
        lose_link(lib)
        assert lib.until(lambda: not lib.read("Cobot.Connected"), 2)
    if step == "reply_held_back":
        lib.robot.inject("reply_delay", seconds=0.3, count=1)
    lib.write(execute, True)
    if step == "in_the_edge_scan":
        lose_link(lib)
    lib.scans(1)
    if step == "reply_held_back":
        assert lib.until(lambda: len(script_frames(lib)) == 1, 1)
        lose_link(lib)
    if step == "while_moving":
        assert lib.until(lambda: lib.read(f"{inst}.Active") or lib.read(f"{inst}.Done"), 2)
        lose_link(lib)
    if step == "after_done":
        assert lib.until(lambda: lib.read(f"{inst}.Done"), 10)
        lose_link(lib)
    assert lib.until(lambda: not lib.read(f"{inst}.Busy"), 12), f"{inst} still Busy"
    done, error_id = lib.read(f"{inst}.Done"), lib.read(f"{inst}.ErrorID")
    lib.scans(3000)                                             # CBT_Connect reconnects; nothing is sent again
    scripts = script_frames(lib)
    assert len(scripts) <= 1, scripts
    if step == "before_the_edge":
        assert scripts == [] and error_id in (0x2001, 0x200C), hex(error_id)
    if done:
        assert len(scripts) == 1
        if inst == "mover":
            assert len(lib.events("motion_end")) == 1
        elif inst == "base":
            assert lib.events("setting")
    else:
        assert lib.read(f"{inst}.Error") and error_id in ERRORS, hex(error_id)
        assert lib.read(f"{inst}.ErrorDescrip") == ERRORS[error_id][:80]


# ---- the Ethernet Slave channel: two FBs started close together, in a user's call order ------------------------
SVR_FBS = {"proj": ("ProjExec", "svr_write", {"Stick_Pause": 1}),
           "ovr": ("OvrExec", "svr_write", {"Project_Speed": 30}),
           "wr": ("WrExec", "svr_write", {"g_n": 7}), "rd": ("RdExec", "svr_read", ["g_n"])}


@pytest.mark.parametrize("gap", range(0, 7))
@pytest.mark.parametrize("first,second", [(a, b) for a in SVR_FBS for b in SVR_FBS if a != b])
def test_ethernet_slave_fbs_started_close_together_send_each_request_once(first, second, gap):
    """tests/lib/st/Main_SvrOrder.st calls CBT_ProjectControl, CBT_SetOverride, CBT_WriteVariable, CBT_ReadVariable
    in that order; ``second`` starts ``gap`` scans after ``first``, so at some gap its first call sees the answer
    to ``first``'s request before ``first`` took it. Each request reaches the robot exactly once and both FBs end
    Done (before: CBT_ProjectControl, and CBT_SetOverride in its edge scan, took the channel over an answer its
    owner had not taken yet, and the owner sent its request a second time)."""
    r = Rig(program="Main_SvrOrder.st", svr_port=0,
            svr_options={"variables": [table.parse_variable("g_n:int=0")]})
    try:
        assert r.until(lambda: r.read("status.Valid"), 1)
        r.write("ProjCmd", "ProjectPause")
        r.write("OvrValue", 30)
        set_variable(r, "WrVar", "g_n", "VarInt", 1, "IntValue", [7])
        set_variable(r, "RdVar", "g_n", "VarInt", 1)
        before = len(r.robot.events)
        r.write(SVR_FBS[first][0], True)
        r.scans(gap)
        r.write(SVR_FBS[second][0], True)
        assert r.until(lambda: all(r.read(f"{fb}.Done") or r.read(f"{fb}.Error") for fb in (first, second)), 10)
        assert r.read(f"{first}.Done") and r.read(f"{second}.Done"), \
            [r.read(f"{fb}.ErrorDescrip") for fb in (first, second)]
        requests = [(e["kind"], e["items"]) for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        expected = [SVR_FBS[fb][1:] for fb in (first, second)]
        assert sorted(map(repr, requests)) == sorted(map(repr, expected)), requests
    finally:
        r.close()


SVR_STEPS = ["before_the_edge", "in_the_edge_scan", "request_unanswered", "after_done"]


@pytest.mark.parametrize("step", SVR_STEPS)
@pytest.mark.parametrize("fb", ["proj", "ovr", "wr", "rd"])
def test_ethernet_slave_link_lost_at_each_step(fb, step):
    """The Ethernet Slave link lost around one request: at most one request reaches the robot, the FB ends, Done
    only when the robot answered it (a write: the robot's value changed), else a documented ErrorID and its text;
    nothing is sent again once the link is back."""
    r = Rig(program="Main_SvrOrder.st", svr_port=0, svr_options={"variables": [table.parse_variable("g_n:int=0")]})
    try:
        assert r.until(lambda: r.read("status.Valid"), 1)
        r.write("ProjCmd", "ProjectPause")
        r.write("OvrValue", 30)
        set_variable(r, "WrVar", "g_n", "VarInt", 1, "IntValue", [7])
        set_variable(r, "RdVar", "g_n", "VarInt", 1)
        execute, kind, items = SVR_FBS[fb]
        before = len(r.robot.events)
        if step == "before_the_edge":                                  # a silent Ethernet Slave: link down
            r.robot.svr.inject("stall")
            assert r.until(lambda: not r.read("Cobot.Status.SlaveLink"), 3)
        if step == "request_unanswered":
            r.robot.svr.inject("stall")
        r.write(execute, True)
        if step == "in_the_edge_scan":
            r.robot.svr.inject("disconnect")
        r.scans(1)
        if step == "request_unanswered":
            r.scans(50)
            r.robot.svr.inject("disconnect")
            r.robot.svr.clear_faults()
        if step == "after_done":
            assert r.until(lambda: r.read(f"{fb}.Done"), 10)
            r.robot.svr.inject("disconnect")
        assert r.until(lambda: not r.read(f"{fb}.Busy"), 10), f"{fb} still Busy"
        done, error_id = r.read(f"{fb}.Done"), r.read(f"{fb}.ErrorID")
        r.until(lambda: False, 3)                                      # the link comes back; nothing is resent
        requests = [(e["kind"], e["items"]) for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(requests) <= 1, requests
        if step == "before_the_edge":                                  # refused in the edge scan, not sent
            assert requests == [] and not done and error_id in (0x2011, 0x2020, 0x2021), hex(error_id)
            assert r.read("Cobot.SvrCmdState") != "SvrCmdSent"
        if done:
            assert requests == [(kind, items)]
            if fb == "wr":
                assert r.robot.svr.variables["g_n"] == 7
        else:
            assert r.read(f"{fb}.Error") and error_id in ERRORS
            assert r.read(f"{fb}.ErrorDescrip") == ERRORS[error_id][:80]
    finally:
        r.close()


# ---- the whole script of the options: arm configuration, Aborting, ExitNode, InstantDO ---------------------------
CPP_TARGET = dict(X=417.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90)


@pytest.mark.parametrize("pose,text", [(("Righty", "Above", "NoFlip"), "0,2,4"), (("Lefty", "Below", "Flip"), "1,3,5"),
                                       (("Lefty", "Above", "Flip"), "1,2,5"), (("Righty", "Below", "NoFlip"), "0,3,4")])
def test_move_absolute_arm_configuration_is_the_three_pose_integers(lib, pose, text):
    """TMscript 2.24 §13.8 PTP Syntax 2: Config1 0/1, Config2 2/3, Config3 4/5 after the precise-positioning flag."""
    values = move_abs(DataFormat="CPP_Abs", TargetPosition=CPP_TARGET, RobotPoseEnable=True,
                      RobotPose=dict(Pose1=pose[0], Pose2=pose[1], Pose3=pose[2]))
    lib.set_struct("MoveParam", values)
    res = command(lib, "mover", "MoveExec")
    assert res.scripts and res.scripts[0].split("\r\n")[0] == abs_call(values)[:-1] + f",{text})", res.scripts


@pytest.mark.parametrize("fb,param,values,tail", [
    ("mover", "MoveParam", move_abs(ExitNode=True), "QueueTag(1)\r\nScriptExit()"),
    ("rel", "RelParam", rel(ExitNode=True, BlendingEnable=True, BlendingValue=50), "ScriptExit()"),
    ("circ", "CircParam", circ(ExitNode=True), "QueueTag(1)\r\nScriptExit()")])
def test_exit_node_is_the_last_line_after_the_queue_tag(lib, fb, param, values, tail):
    lib.set_struct(param, values)
    res = command(lib, fb, {"mover": "MoveExec", "rel": "RelExec", "circ": "CircExec"}[fb])
    assert len(res.scripts) == 1 and res.scripts[0].split("\r\n", 1)[1] == tail, res.scripts


@pytest.mark.parametrize("fb,param,values,call", [
    ("mover", "MoveParam", move_abs(), abs_call(move_abs())),
    ("rel", "RelParam", rel(), rel_call(rel())),
    ("circ", "CircParam", circ(), circle_call(circ()))])
def test_aborting_is_one_script_stop_and_clear_then_the_motion(lib, fb, param, values, call):
    """TMscript 2.24 §13.4: StopAndClearBuffer() first, in the same script, so nothing runs in between."""
    lib.set_struct(param, values)
    lib.write(f"{fb}.BufferMode", "Aborting")
    res = command(lib, fb, {"mover": "MoveExec", "rel": "RelExec", "circ": "CircExec"}[fb])
    assert len(res.scripts) == 1 and res.scripts[0].split("\r\n")[:2] == ["StopAndClearBuffer()", call], res.scripts
    assert res.done


@pytest.mark.parametrize("immediate,value,text", [(True, True, 'IO["ControlBox"].InstantDO[15]=1'),
                                                  (True, False, 'IO["ControlBox"].InstantDO[15]=0'),
                                                  (False, False, 'IO["ControlBox"].DO[15]=0')])
def test_set_output_immediate_and_value(lib, immediate, value, text):
    lib.set_struct("OutParam", dict(Module="ControlBox", Channel=15, Value=value, Immediate=immediate))
    res = command(lib, "dout", "OutExec")
    assert res.done and res.scripts == [text], res.scripts


# ---- CBT_Teach: the entry selected at the edge, also when the selection changes while Busy ------------------------
@pytest.mark.parametrize("svr", [False, True], ids=["listen_node", "ethernet_slave"])
def test_teach_page_example_stores_into_the_entry_selected_at_the_edge(svr, tmp_path):
    """CBT_Teach.md's example holds the index while Busy: the operator selecting entry 2 in the scan after pressing
    Teach on entry 1 leaves entry 2 untouched (Point is an in-out, written in the scan the reading arrives; the
    plain TeachTable[TeachIndex] wrote the position into entry 2)."""
    from doc_steps import example_of, on_simulator, simulator

    from vplc.api import load_plc
    code, _ = example_of("CBT_Teach")
    if svr:
        code = code.replace("Time_Out := 30);", "Time_Out := 30, SvrPort := SVRPORT);")
    srv = simulator() if not svr else None
    if svr:
        from tmsim.net.server import SimServer
        srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, svr_port=0)
    srv.start()
    try:
        source = tmp_path / "teach_example.st"
        source.write_text(on_simulator(code, srv).replace("SVRPORT", str(srv.robots[0].svr_port)), encoding="utf-8")
        plc = load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(source)], task="Main@1ms")
        pump = lambda now_ns: srv.poll(now_ns / 1e9)  # noqa: E731
        assert plc.run_until(lambda: plc.read("Teach_Example.fbConnect.Connected"), 5_000_000_000, on_scan=pump)
        plc.write("Teach_Example.TeachIndex", 1)
        plc.write("Teach_Example.TeachButton", True)
        plc.scan(plc.now_ns + plc.period_ns)
        assert plc.read("Teach_Example.fbTeach.Busy") or plc.read("Teach_Example.fbTeach.Done")
        plc.write("Teach_Example.TeachIndex", 2)
        assert plc.run_until(lambda: plc.read("Teach_Example.fbTeach.Done"), 2_000_000_000, on_scan=pump)
        assert plc.read("Teach_Example.TeachTable[1].Taught") and plc.read("Teach_Example.TeachTable[1].Name") == "Pick"
        assert not plc.read("Teach_Example.TeachTable[2].Taught") and plc.read("Teach_Example.TeachTable[2].Name") == ""
        plc.close()
    finally:
        srv.close()


# ---- Execute re-raised while Busy: one command per accepted edge, each reaching the robot once -----------------
def reraise(rig, execute: str, busy: str, scans_after: int) -> None:
    rig.write(execute, True)
    assert rig.until(lambda: rig.read(busy), 1)
    rig.scans(scans_after)
    rig.write(execute, False)
    rig.scans(1)
    assert rig.read(busy), "ended before the second edge: not a re-raise while Busy"
    rig.write(execute, True)


@pytest.mark.parametrize("after", [0, 5, 60])
def test_vision_job_re_raised_while_busy_runs_the_job_once_per_edge(vis, after):
    """R5 (the command core): the second edge replaces the first, which the robot still runs; Done is the second's."""
    vis.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    reraise(vis, "VisExec", "vis.Busy", after)
    assert vis.until(lambda: vis.read("vis.Done") or vis.read("vis.Error"), 5)
    assert vis.read("vis.Done") and vis.read("vis.Found"), vis.read("vis.ErrorDescrip")
    vis.write("VisExec", False)
    vis.scans(2000)
    assert sum("Vision_DoJob" in s for s in script_frames(vis)) == 2


@pytest.mark.parametrize("fb,after,requests", [("ovr", 0, 1), ("ovr", 3, 1), ("rd", 0, 1), ("wr", 0, 1),
                                               ("proj", 0, 2), ("proj", 3, 2)])
def test_ethernet_slave_fb_re_raised_while_busy(fb, after, requests):
    """CBT_SetOverride, CBT_ReadVariable and CBT_WriteVariable ignore an edge while Busy (the request under way
    ends first: one request); CBT_ProjectControl takes it as a new command (R5: two requests, each once)."""
    r = Rig(program="Main_SvrOrder.st", svr_port=0, svr_options={"variables": [table.parse_variable("g_n:int=0")]})
    try:
        assert r.until(lambda: r.read("status.Valid"), 1)
        r.write("ProjCmd", "ProjectPause")
        r.write("OvrValue", 30)
        set_variable(r, "WrVar", "g_n", "VarInt", 1, "IntValue", [7])
        set_variable(r, "RdVar", "g_n", "VarInt", 1)
        before = len(r.robot.events)
        reraise(r, SVR_FBS[fb][0], f"{fb}.Busy", after)
        assert r.until(lambda: r.read(f"{fb}.Done") or r.read(f"{fb}.Error"), 10)
        assert r.read(f"{fb}.Done"), r.read(f"{fb}.ErrorDescrip")
        r.write(SVR_FBS[fb][0], False)
        r.until(lambda: False, 2)
        sent = [e for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(sent) == requests, sent
    finally:
        r.close()


def test_stop_re_raised_while_busy_sends_one_stop_per_edge_and_releases_stopping(lib):
    lib.write("StopParam.Mode", "StopNormal")
    lib.robot.inject("reply_delay", seconds=0.2, count=1)
    reraise(lib, "StopExec", "stop.Busy", 2)
    assert lib.until(lambda: lib.read("stop.Done") or lib.read("stop.Error"), 3)
    assert lib.read("stop.Done") and lib.read("Cobot.Stopping")
    lib.write("StopExec", False)
    lib.scans(300)
    assert script_frames(lib) == ["StopAndClearBuffer()", "StopAndClearBuffer()"]
    assert not lib.read("Cobot.Stopping") and lib.read("Cobot.StopHolders") == 0


@pytest.mark.parametrize("path,value", [("JogAxis", 1), ("JogFrame", "JogTool"), ("JogVelocity", 100),
                                        ("JogAxis", 0), ("JogVelocity", 0)])
def test_jog_inputs_changed_while_held_are_not_taken(path, value):
    """Frame, Axis and Velocity are taken at the press: changed while the button is held (even to an invalid
    value) the robot keeps getting the pressed axis's increments, and nothing else."""
    r = Rig(program="Main_Jog.st")
    try:
        r.write("JogFrame", "JogBase")
        r.write("JogAxis", 3)
        r.write("JogVelocity", 10)
        r.write("JogFwd", True)
        assert r.until(lambda: r.read("jog.Active"), 1)
        pressed = script_frames(r)[-1].split("\r\n")[0]
        before = len(script_frames(r))
        r.write(path, value, raw=path == "JogFrame" and isinstance(value, int))
        r.scans(400)
        later = [s.split("\r\n")[0] for s in script_frames(r)[before:]]
        assert later and set(later) == {pressed}, later
        assert r.read("jog.Active") and not r.read("jog.Error")
    finally:
        r.close()


@pytest.mark.parametrize("hold", [True, False], ids=["held", "pulsed"])
def test_wait_queue_sends_one_tag_and_is_done_only_after_the_queued_motion(cell, hold):
    """CBT_WaitQueue (an empty script with a queue tag, TMscript 2.24 §15.3 QueueTag): one frame per edge, Done
    when the robot reached the tag, so after the motion queued before it finished."""
    cell.set_struct("MoveParam", move_abs(**SLOW))
    cell.write("MoveExec", True)
    assert cell.until(lambda: cell.read("mover.Active"), 1)
    before = len(script_frames(cell))
    res = command(cell, "wait", "WaitExec", seconds=10, hold=hold)
    assert res.done and res.motion_ends == 1, res
    assert len(script_frames(cell)) - before == 1 and script_frames(cell)[-1].startswith("QueueTag(")


@pytest.mark.parametrize("fb", ["proj", "ovr", "wr", "rd"])
def test_ethernet_slave_fb_pulsed_for_one_scan_shows_done_for_one_scan(fb):
    r = Rig(program="Main_SvrOrder.st", svr_port=0, svr_options={"variables": [table.parse_variable("g_n:int=0")]})
    try:
        assert r.until(lambda: r.read("status.Valid"), 1)
        r.write("ProjCmd", "ProjectPause")
        r.write("OvrValue", 30)
        set_variable(r, "WrVar", "g_n", "VarInt", 1, "IntValue", [7])
        set_variable(r, "RdVar", "g_n", "VarInt", 1)
        before = len(r.robot.events)
        execute = SVR_FBS[fb][0]
        rows = []
        for n in range(2500):
            r.write(execute, n == 0)
            r.scans(1)
            rows.append((r.read(f"{fb}.Done"), r.read(f"{fb}.Busy"), r.read(f"{fb}.Error")))
        assert [d for d, _, _ in rows].count(True) == 1 and not any(e for _, _, e in rows), rows[:5]
        done_at = [d for d, _, _ in rows].index(True)
        assert all(b for _, b, _ in rows[:done_at]) and not any(b for _, b, _ in rows[done_at:])
        sent = [e for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(sent) == 1, sent
    finally:
        r.close()


def test_vision_job_and_teach_pulsed_for_one_scan_show_done_for_one_scan(vis):
    vis.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    rows = trace(vis, "vis", 1500, on_scan=lambda n: vis.write("VisExec", n == 0))
    assert [r["Done"] for r in rows].count(True) == 1 and not any(r["Error"] for r in rows)
    assert sum("Vision_DoJob" in s for s in script_frames(vis)) == 1
    r = Rig(program="Main_Jog.st")
    try:
        done = []
        for n in range(300):
            r.write("TeachExec", n == 0)
            r.scans(1)
            done.append(r.read("teach.Done"))
        assert done.count(True) == 1 and r.read("Table[1].Taught")
    finally:
        r.close()
