"""The one range table, docs/library/ranges.tsv, agrees with what the library's ST checks: every row is run on the
virtual PLC (no robot connected, so a command whose parameters pass ends with 16#2001 "not connected" and one
that fails them with the row's ErrorID): both limits accepted, one step outside refused, every allowed
enumeration value accepted and every other one refused. The generated types.md and cbt_hmi/pages/ranges.json are
current."""
from __future__ import annotations

import importlib.util
import struct
import sys

import pytest
from rig import ROOT, Rig

DOCS = ROOT / "docs" / "library"
NOT_CONNECTED = 0x2001
# struct -> (FB instance, parameter variable, Execute variable) in tests/lib/st/Main_Lib.st
FB_OF = {"stCBT_MovAbsParam": ("mover", "MoveParam", "MoveExec"), "stCBT_MovRelParam": ("rel", "RelParam", "RelExec"),
         "stCBT_MovCircleParam": ("circ", "CircParam", "CircExec"),
         "stCBT_BaseParam": ("base", "BaseParam", "BaseExec"), "stCBT_TCParam": ("tcp", "TcpParam", "TcpExec"),
         "stCBT_OutputParam": ("dout", "OutParam", "OutExec")}
CONNECT_INPUT = {"Time_Out": "TimeOut", "IPPort": "Port"}
# an FB input of a motion FB: written on the instance itself (Main_Lib.st does not pass it, so it keeps the value)
FB_INPUT = {"CBT_MoveAbsolute": "stCBT_MovAbsParam", "CBT_MoveRelative": "stCBT_MovRelParam",
            "CBT_MoveCircle": "stCBT_MovCircleParam"}
POSE = {"stCBT_Transformation": "X", "stCBT_MomentOfInertia": "Ixx"}      # the member written for a structure
VALID = {"stCBT_MovAbsParam": dict(MovementCommand="Line", DataFormat="CPP_Abs", Speed=50, AccelTime=200),
         "stCBT_MovRelParam": dict(MovementCommand="Line", DataFormat="CPP_Rel", Speed=50, AccelTime=200),
         "stCBT_MovCircleParam": dict(DataFormat="CPP_Circle", Speed=50, AccelTime=200),
         "stCBT_OutputParam": dict(Module="ControlBox", Channel=0)}


def load(name):
    spec = importlib.util.spec_from_file_location(name, DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module                      # dataclasses look their module up while it loads
    spec.loader.exec_module(module)
    return module


MT = load("make_types")
# CBT_SetOverride's row (an FB input of a program of its own) is run, every value of its type, by
# tests/lib/test_lib_set_override.py; the rows of CBT_ReadVariable / CBT_WriteVariable (members of their in-out
# Variable) by tests/lib/test_lib_variables.py; CBT_Jog's (FB inputs, no Execute) by tests/lib/test_lib_jog.py
# and CBT_VisionJob's (members of its Parameters, a program of its own) by tests/lib/test_lib_vision_job.py
OWN_TESTS = ("CBT_SetOverride", "CBT_ReadVariable", "CBT_WriteVariable", "CBT_Jog", "CBT_VisionJob")
ROWS = [r for r in MT.read_ranges() if r.error and r.struct not in OWN_TESTS]


@pytest.fixture(scope="module")
def rig():
    r = Rig(connect=False)
    yield r
    r.close()


def member_path(rig, row) -> tuple[str, str]:
    """(variable path written, its ST type) of the row's member."""
    if row.struct == "CBT_Connect":
        return CONNECT_INPUT[row.member], rig.plc.var_type(f"Main.{CONNECT_INPUT[row.member]}")
    if row.struct in FB_INPUT:
        path = f"{FB_OF[FB_INPUT[row.struct]][0]}.{row.member}"
        return path, rig.plc.var_type(f"Main.{path}").rsplit("\\", 1)[-1]
    _, param, _ = FB_OF[row.struct]
    path = f"{param}.{row.member}"
    ty = rig.plc.var_type(f"Main.{path}").rsplit("\\", 1)[-1]
    if ty in POSE:
        path += f".{POSE[ty]}"
    return path, ty


def condition_sets(row) -> list[dict]:
    """Every combination the row's condition names (each DataFormat listed), with a MovementCommand that takes
    the format (joint formats are PTP only)."""
    sets = [{}]
    for key, values in row.when.items():
        sets = [{**s, key: v} for s in sets for v in values]
    for s in sets:
        if s.get("DataFormat", "").startswith("J"):
            s["MovementCommand"] = "PTP"
    return sets


def outcome(rig, row, value) -> int:
    """ErrorID of one command with the member at ``value``, the same for every condition set of the row."""
    results = {outcome_when(rig, row, value, when) for when in condition_sets(row)}
    assert len(results) == 1, f"{row.struct}.{row.member} = {value}: differs between conditions {results}"
    return results.pop()


def outcome_when(rig, row, value, when: dict) -> int:
    if row.struct == "CBT_Connect":
        rig.write("Ip", "127.0.0.1")
        rig.write("TimeOut", 30)
        rig.write("Port", 1)
        rig.write(CONNECT_INPUT[row.member], value)
        rig.write("ConnExec", True)
        rig.scans(2)
        err = rig.read("conn.ErrorID")
        rig.write("ConnExec", False)
        rig.scans(3)
        return err if 0x1000 <= err < 0x2000 else NOT_CONNECTED
    struct_name = FB_INPUT.get(row.struct, row.struct)
    fb, param, execute = FB_OF[struct_name]
    rig.set_struct(param, VALID.get(struct_name, {}))
    for key, text in when.items():
        rig.write(f"{param}.{key}", {"TRUE": True, "FALSE": False}.get(text, text))
    rig.write(member_path(rig, row)[0], value)
    rig.write(execute, True)
    rig.scans(2)
    err = rig.read(f"{fb}.ErrorID")
    rig.write(execute, False)
    rig.scans(2)
    rig.write(member_path(rig, row)[0], 0 if not isinstance(value, str) else value)
    return err


def step_outside(ty: str, value, up: bool):
    """The nearest value beyond the limit that the member's type holds (REAL: the next 32-bit float)."""
    if ty in ("REAL", "stCBT_Transformation", "stCBT_MomentOfInertia"):
        bits = struct.unpack("<i", struct.pack("<f", float(value)))[0]
        if value == 0:
            return 1.4e-45 if up else -1.4e-45
        bits += 1 if (up == (value > 0)) else -1
        return struct.unpack("<f", struct.pack("<i", bits))[0]
    return value + (1 if up else -1)


@pytest.mark.parametrize("row", ROWS, ids=lambda r: f"{r.struct}.{r.member}:{r.line}")
def test_range_row_matches_the_st_check(rig, row):
    code = int(row.error[3:], 16)
    path, ty = member_path(rig, row)
    if row.allowed is not None:
        enum = next(t for t in MT.read_types() if t.name == ty)
        for value in (v.name for v in enum.members):
            expected = NOT_CONNECTED if value in row.allowed else code
            assert outcome(rig, row, value) == expected, (value, hex(expected))
        return
    assert outcome(rig, row, row.low) == NOT_CONNECTED, f"{row.low} must be accepted"
    assert outcome(rig, row, row.high) == NOT_CONNECTED, f"{row.high} must be accepted"
    for up, limit in ((False, row.low), (True, row.high)):
        beyond = step_outside(ty, limit, up)
        if ty.startswith("U") and beyond < 0 or ty == "UINT" and beyond > 65535:
            continue                                   # the type itself cannot hold it
        assert outcome(rig, row, beyond) == code, f"{beyond} must be refused with {row.error}"


def test_generated_type_reference_and_hmi_limits_are_current():
    assert MT.main(["--check"]) == 0, "run python3 docs/library/make_types.py"


def test_every_public_type_is_in_the_reference():
    text = (DOCS / "types.md").read_text(encoding="utf-8")
    for path in (ROOT / "lib" / "CBT_Commands_Lib" / "types").glob("*.st"):
        assert f"### {path.stem}\n" in text, path.stem
