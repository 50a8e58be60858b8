"""What the HMI takes from the toolchain, through vplc.api only: the IEC integer ranges of its value checks, the
PLC's major fault and the ladder programs of the Program page (docs/toolchain/layout.md, cbt_hmi)."""
from __future__ import annotations

import pathlib

import pytest

from cbt_hmi.web.mapping import INT_RANGES, Leaf, RequestError, validate
from vplc.api import PlcFault, integer_ranges, load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]

# IEC 61131-3 table 10: the integer types by width and sign, the bit strings as unsigned of their width
WIDTHS = {"SINT": 8, "INT": 16, "DINT": 32, "LINT": 64, "USINT": 8, "UINT": 16, "UDINT": 32, "ULINT": 64,
          "BYTE": 8, "WORD": 16, "DWORD": 32, "LWORD": 64}


def test_the_integer_ranges_are_the_iec_ones_and_the_hmi_has_no_copy():
    expected = {name: (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if name in ("SINT", "INT", "DINT", "LINT")
                else (0, (1 << bits) - 1) for name, bits in WIDTHS.items()}
    assert integer_ranges() == expected
    assert expected == INT_RANGES


@pytest.mark.parametrize("type_name,value,accepted", [("INT", 32767, True), ("INT", 32768, False),
                                                      ("USINT", -1, False), ("WORD", 65535, True)])
def test_a_value_outside_its_types_range_is_refused(type_name, value, accepted):
    leaf = Leaf("Some_Value", {"type": type_name}, "rw", "operator")
    if accepted:
        assert validate(leaf, value) == value
    else:
        with pytest.raises(RequestError, match="Some_Value"):
            validate(leaf, value)


@pytest.fixture(scope="module")
def plc():
    with load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")]) as loaded:
        yield loaded


def test_the_ladder_example_is_offered_with_its_instance_and_drawing(plc):
    programs = {p.name: p for p in plc.ladder_programs()}
    assert "Commands_Example" in programs
    ladder = programs["Commands_Example"]
    assert ladder.instance == "Commands" and "FBCONNECT" in ladder.own_names      # the task's instance, its FBs
    assert plc.var_type(f"{ladder.instance}.fbConnect.Connected") == "BOOL"
    assert ladder.svg().startswith("<svg") and len(ladder.ladder.rungs) >= 10
    assert all(p.name != "PnP_Example" for p in programs.values())      # an ST program is not drawn


def test_a_running_plc_has_no_fault_and_a_faulted_one_says_which(plc):
    assert plc.fault is None
    plc.engine.fault = PlcFault("examples/PnP_Example.st:57: major fault in PnP_Example: integer division by zero")
    try:
        assert str(plc.fault).endswith("integer division by zero")
    finally:
        plc.engine.fault = None
