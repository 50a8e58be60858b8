"""What the input edge probes (test_lib_input_edges.py, test_lib_command_edges.py) share: the values at the edges
of a REAL (bit patterns), the text the library must send for given parameters (TMscript 2.24 call formats, numbers
as CBTi_FormatReal prints them: up to 3 decimals, no exponent, docs/library/design.md), and one command run on the
rig with what the FB reported and what the robot's own log received."""
from __future__ import annotations

import csv
import struct
from collections.abc import Callable
from dataclasses import dataclass, field

from rig import ROOT, Rig, move_abs

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


def refused_or_sent(res: Outcome, code: int | None, call: Callable[[], str], motion: bool = False) -> None:
    """``refused(res, code)`` when a code is expected, else ``sent`` with the command line ``call()`` gives (called
    only then: a refused value may have no text)."""
    if code is not None:
        refused(res, code)
    else:
        sent(res, call(), motion)


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


def rel_call(p: dict) -> str:
    cmd = "PTP" if p["MovementCommand"] in (1, "PTP") else "Line"
    fmt = fmt_name(p["DataFormat"], REL_FORMATS)
    blend = p["BlendingValue"] if p["BlendingEnable"] else 0
    return (f'Move_{cmd}("{fmt}",{pose_text(p["TargetPosition"])},{p["Speed"]},{p["AccelTime"]},{blend},'
            f'{"false" if p["PrecisePositioning"] else "true"})')


def circle_call(p: dict) -> str:
    blend = p["BlendingValue"] if p["BlendingEnable"] else 0
    fmt = fmt_name(p["DataFormat"], CIRCLE_FORMATS)
    return (f'Circle("{fmt}",{pose_text(p["ArcPoint"])},{pose_text(p["EndPoint"])},{p["Speed"]},'
            f'{p["AccelTime"]},{blend},{p["ArcAngle"]},{"false" if p["PrecisePositioning"] else "true"})')


ZERO_POSE = dict(X=0, Y=0, Z=0, RX=0, RY=0, RZ=0)


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


def svr_writes(rig) -> list:
    return [e for e in rig.robot.events if e["kind"] == "svr_write"]


def set_variable(rig, path, name, kind, count=1, member=None, values=()):
    rig.write(f"{path}.Name", name)
    rig.write(f"{path}.DataType", kind, raw=isinstance(kind, int))
    rig.write(f"{path}.Count", count)
    for k, value in enumerate(values, start=1):
        rig.write(f"{path}.{member}[{k}]", value)


LONG_JOB = "J" * 32                                                  # the longest job name TMflow takes


def vision_call(job: str, mode: str, speed: int, accel: int) -> str:
    call = {"VisionAtPosition": f'Vision_DoJob("{job}")', "VisionPTP": f'Vision_DoJob_PTP("{job}",{speed},{accel})',
            "VisionLine": f'Vision_DoJob_Line("{job}",{speed})'}[mode]
    return f'ListenSend(90,GetString(Vision_IsJobAvailable("{job}")))\r\nListenSend(91,GetString({call}))'


SVR_FBS = {"proj": ("ProjExec", "svr_write", {"Stick_Pause": 1}),
           "ovr": ("OvrExec", "svr_write", {"Project_Speed": 30}),
           "wr": ("WrExec", "svr_write", {"g_n": 7}), "rd": ("RdExec", "svr_read", ["g_n"])}


# ---- rigs of the probes (each test module declares its fixtures from these) --------------------------------------
VAR_SPECS = ["g_text:string", "g_texts:string[2]", "g_f:float", "g_fs:float[2]", "g_n:int",
             "g_" + "x" * 30 + ":int"]                              # a name of 32 characters


def var_rig() -> Rig:
    """Main_Var.st with the robot's Ethernet Slave and the global variables of VAR_SPECS."""
    r = Rig(program="Main_Var.st", svr_port=0,
            svr_options={"variables": [table.parse_variable(s) for s in VAR_SPECS]})
    assert r.until(lambda: r.read("Cobot.Status.SlaveLink"), 1)
    return r


def vision_rig() -> Rig:
    """Main_Vision.st with the vision jobs job1 and LONG_JOB, each locating one object in 0.1 s."""
    from tmsim.robot.camera import camera_of
    r = Rig(program="Main_Vision.st")
    camera = camera_of(r.robot.session.robot)
    for job in ("job1", LONG_JOB):
        camera.define(job, objects=[[417.5, -122.3, 300, 0, 0, 0]], seconds=0.1)
    return r


def cell_rig() -> Rig:
    """Main_Cell.st with the Ethernet Slave and CBT_RobotStatus valid."""
    r = Rig(program="Main_Cell.st", svr_port=0)
    r.write("StatusEnable", True)
    assert r.until(lambda: r.read("status.Valid"), 1)
    return r


def svr_order_rig() -> Rig:
    """Main_SvrOrder.st (CBT_ProjectControl called first, then CBT_SetOverride, CBT_WriteVariable,
    CBT_ReadVariable) with the Ethernet Slave, the variable g_n and each FB's parameters of SVR_FBS set."""
    r = Rig(program="Main_SvrOrder.st", svr_port=0, svr_options={"variables": [table.parse_variable("g_n:int=0")]})
    assert r.until(lambda: r.read("status.Valid"), 1)
    r.write("ProjCmd", "ProjectPause")
    r.write("OvrValue", 30)
    set_variable(r, "WrVar", "g_n", "VarInt", 1, "IntValue", [7])
    set_variable(r, "RdVar", "g_n", "VarInt", 1)
    return r
