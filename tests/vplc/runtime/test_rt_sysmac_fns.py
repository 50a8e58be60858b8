"""Sysmac byte/string/time instructions: pinned behaviour (see docs/toolchain/runtime_sysmac.md)."""
import struct

from rt_helpers import run1


def test_to_ary_byte_low_high_is_little_endian(tmp_path):
    plc = run1(tmp_path, "n := ToAryByte(In := d, Order := _LOW_HIGH, AryOut := b[0]);",
               "d : DINT := 16#11223344; b : ARRAY[0..3] OF BYTE; n : UINT;")
    assert plc.read("Main.b") == [0x44, 0x33, 0x22, 0x11] and plc.read("Main.n") == 4


def test_to_ary_byte_high_low_swaps_inside_each_word_low_word_first(tmp_path):
    plc = run1(tmp_path, "ToAryByte(In := d, Order := _HIGH_LOW, AryOut := b[0]);",
               "d : DINT := 16#11223344; b : ARRAY[0..3] OF BYTE;")
    assert plc.read("Main.b") == [0x33, 0x44, 0x11, 0x22]


def test_to_ary_byte_of_real_writes_the_ieee_image(tmp_path):
    plc = run1(tmp_path, "ToAryByte(In := r, Order := _LOW_HIGH, AryOut := b[0]);",
               "r : REAL := 1.5; b : ARRAY[0..3] OF BYTE;")
    assert bytes(plc.read("Main.b")) == struct.pack("<f", 1.5)


def test_ary_byte_to_is_the_inverse_of_to_ary_byte(tmp_path):
    plc = run1(tmp_path, """ToAryByte(In := d, Order := _HIGH_LOW, AryOut := b[1]);
        AryByteTo(In := b[1], Size := 4, Order := _HIGH_LOW, OutVal := back);
        ToAryByte(In := w, Order := _LOW_HIGH, AryOut := b[5]);
        AryByteTo(In := b[5], Size := 2, Order := _LOW_HIGH, OutVal := wback);""",
               "d : DINT := -123456; back : DINT; w : UINT := 500; wback : UINT; b : ARRAY[0..9] OF BYTE;")
    assert plc.read("Main.back") == -123456 and plc.read("Main.wback") == 500


def test_string_to_ary_and_ary_to_string_round_trip(tmp_path):
    plc = run1(tmp_path, "n := StringToAry(In := 'Hi TM', AryOut := b[2]); s := AryToString(In := b[2], Size := n);",
               "b : ARRAY[0..19] OF BYTE; n : UINT; s : STRING[20];")
    assert plc.read("Main.n") == 5 and plc.read("Main.s") == "Hi TM"
    assert plc.read("Main.b")[2:7] == list(b"Hi TM")


def test_ary_to_string_positional_call_takes_in_then_size(tmp_path):
    """W502 AryToString: In, Size (the order Sysmac code uses in positional calls)."""
    plc = run1(tmp_path, "n := StringToAry('Hi TM', b[2]); s := AryToString(b[2], n);",
               "b : ARRAY[0..19] OF BYTE; n : UINT; s : STRING[20];")
    assert plc.read("Main.s") == "Hi TM"


def test_real_to_format_string_parameters_of_w502_2_269(tmp_path):
    """W502 2-269: In, Exponent, Sign, MinLen, DecPlace; the last four can be omitted."""
    plc = run1(tmp_path, """a := RealToFormatString(In := 3.14159, Exponent := FALSE, Sign := FALSE, MinLen := 8,
                                                   DecPlace := 2);
        b := RealToFormatString(In := 2.25, Exponent := FALSE, Sign := TRUE, MinLen := 4, DecPlace := 1);
        c := RealToFormatString(In := 1234.5, Exponent := TRUE, Sign := FALSE, MinLen := 3, DecPlace := 3);
        d := RealToFormatString(In := 42.0, Exponent := FALSE, Sign := TRUE, MinLen := 1, DecPlace := 0);
        e := LrealToFormatString(12.75);
        f := RealToFormatString(7.5, FALSE, FALSE, 5, 2);""",
               "a, b, c, d, e, f : STRING[30];")
    assert [plc.read(f"Main.{v}") for v in "abcdef"] == ["    3.14", "+2.2", "1.234e+03", "+42", "13", " 7.50"]


def test_real_to_format_string_rounds_half_to_even_as_w502_2_269_shows(tmp_path):
    plc = run1(tmp_path, """a := RealToFormatString(In := 1.49); b := RealToFormatString(In := 1.5);
        c := RealToFormatString(In := 2.5); d := RealToFormatString(In := 1.51);""", "a, b, c, d : STRING[10];")
    assert [plc.read(f"Main.{v}") for v in "abcd"] == ["1", "2", "2", "2"]


def test_real_to_format_string_with_dec_place_above_min_len_keeps_out_as_w502_2_269_says(tmp_path):
    """W502 2-269: DecPlace greater than MinLen is an error, ENO FALSE and Out does not change: the assigned
    variable keeps its value, the controller goes on, and the error is recorded with its ST line."""
    plc = run1(tmp_path, """a := RealToFormatString(In := 1.25, MinLen := 1, DecPlace := 2);
        b := LrealToFormatString(In := lr, DecPlace := 3);
        c := LrealToFormatString(In := lr, MinLen := 6, DecPlace := 3);
        n := n + 1;""", "a : STRING[10] := 'before'; b : STRING[10] := 'kept'; c : STRING[10]; lr : LREAL := 2.5;"
               " n : INT;")
    assert plc.read("Main.a") == "before" and plc.read("Main.b") == "kept" and plc.read("Main.c") == " 2.500"
    assert plc.read("Main.n") == 1
    count, messages = plc.instruction_errors
    assert count == 2
    assert messages[0].endswith("main.st:5: instruction error in Main: RealToFormatString: DecPlace 2 is greater than "
                                "MinLen 1 (W502 2-269); Out is not changed")
    assert "LrealToFormatString: DecPlace 3 is greater than MinLen 1" in messages[1]


def test_format_string_longer_than_the_variable_on_out_keeps_it_as_w502_2_269_says(tmp_path):
    """W502 2-269: a result with more bytes than the variable connected to Out is an error; Out does not change.
    Inside a larger expression the call has no Out variable of its own: it gives ''."""
    plc = run1(tmp_path, """s := LrealToFormatString(In := 3.14159, MinLen := 8, DecPlace := 3);
        t := CONCAT('x=', LrealToFormatString(In := 3.14159, DecPlace := 3));""",
               "s : STRING[5] := 'old'; t : STRING[10];")
    assert plc.read("Main.s") == "old" and plc.read("Main.t") == "x="
    count, messages = plc.instruction_errors
    assert count == 2 and "the result has 8 characters, more than the 4 the variable connected to Out holds" \
        in messages[0]


def test_time_instructions(tmp_path):
    plc = run1(tmp_path, """dt1 := SecToDt(In := 86400); s := DtToSec(In := DT#1970-01-02-00:00:10);
        t := NanoSecToTime(In := 1500000); ns := TimeToNanoSec(In := T#2ms); now := GetTime();""",
               "dt1 : DT; s : LINT; t : TIME; ns : LINT; now : DT;", clock_base_ns=1_700_000_000_000_000_000)
    assert plc.read("Main.dt1") == 86400 * 10**9
    assert plc.read("Main.s") == 86410
    assert plc.read("Main.t") == 1_500_000 and plc.read("Main.ns") == 2_000_000
    assert plc.read("Main.now") == 1_700_000_000_000_000_000


SYSVARS = """
IF P_First_RunMode THEN firsts := firsts + 1; END_IF;
IF P_First_Run THEN runs := runs + 1; END_IF;
IF P_0_1s AND NOT prev THEN pulses := pulses + 1; END_IF;
prev := P_0_1s;
on := P_On AND NOT P_Off;
"""


def test_system_defined_variables_first_scan_flags_and_clock_pulses(tmp_path):
    from rt_helpers import plc_from
    plc = plc_from(tmp_path, SYSVARS, "firsts, runs, pulses : INT; prev, on : BOOL;")
    for n in range(1000):                                   # 1 s of 1 ms scans
        plc.scan(n * 1_000_000)
    assert plc.read("Main.firsts") == 1 and plc.read("Main.runs") == 1
    assert plc.read("Main.pulses") == 10                   # 100 ms period: 10 rising edges in 1 s
    assert plc.read("Main.on") is True
    plc.scan(1_060_000_000)                                 # 60 ms into a 100 ms period, 60 ms into a 1 s period
    assert plc.read("P_0_1s") is False and plc.read("P_1s") is True and plc.read("P_1min") is True


def test_first_run_flag_is_per_task(tmp_path):
    from rt_helpers import plc_from
    config = """PROGRAM Slow
VAR firsts : INT; END_VAR
IF P_First_RunMode THEN firsts := firsts + 1; END_IF;
END_PROGRAM
CONFIGURATION Cfg
    RESOURCE R ON PLC
        TASK Fast (INTERVAL := T#1ms, PRIORITY := 1);
        TASK Periodic (INTERVAL := T#10ms, PRIORITY := 2);
        PROGRAM A WITH Fast : Main;
        PROGRAM B WITH Periodic : Slow;
    END_RESOURCE
END_CONFIGURATION
"""
    plc = plc_from(tmp_path, "IF P_First_RunMode THEN firsts := firsts + 1; END_IF;", "firsts : INT;", config)
    for n in range(50):
        plc.scan(n * 1_000_000)
    assert plc.read("A.firsts") == 1 and plc.read("B.firsts") == 1


def test_system_defined_variables_are_read_only_and_vendor(tmp_path):
    from vplc.project import load_project
    src = tmp_path / "w.st"
    src.write_text("PROGRAM Main\nVAR x : BOOL; END_VAR\nP_On := FALSE;\nx := P_1s;\nEND_PROGRAM\n")
    proj = load_project([str(src)], portable=True)
    messages = [(d.code, d.message) for d in proj.diagnostics]
    assert ("ST1301", "`P_On` is a Sysmac system-defined variable and is read-only; use a variable of your own") \
        in messages
    assert any(code == "ST2001" and "`P_1s` is an Omron Sysmac system-defined variable" in m for code, m in messages)


def test_every_prelude_entry_has_a_row_in_the_manual_table():
    """docs/toolchain/runtime_sysmac.md section 4: each instruction, type and system-defined variable the virtual
    controller provides (prelude/sysmac_*.st, prelude/iec_fbs.st) is named in the first column of the table."""
    import pathlib
    import re

    from vplc.frontend import ast as A
    from vplc.frontend.diagnostics import DiagnosticBag
    from vplc.frontend.parser import parse
    from vplc.frontend.source import SourceFile

    root = pathlib.Path(__file__).resolve().parents[3]
    prelude = root / "src" / "vplc" / "prelude"
    names = set()
    for path in sorted(prelude.glob("sysmac_*.st")) + [prelude / "iec_fbs.st"]:
        unit = parse(SourceFile(str(path), path.read_text(encoding="utf-8")), DiagnosticBag())
        for item in unit.items:
            if isinstance(item, A.Pou):
                names.add(item.name)
            elif isinstance(item, A.TypeBlock):
                names |= {d.name for d in item.decls}
            elif isinstance(item, A.GlobalVarList):
                names |= {v.name for section in item.sections for v in section.vars}
    assert {"TON", "SktTCPRcv", "_sSOCKET", "P_1min", "VPLC_ScanTime"} <= names
    doc = (root / "docs" / "toolchain" / "runtime_sysmac.md").read_text(encoding="utf-8")
    section = doc[doc.index("## 4."):]
    first_cells = [line.split("|")[1] for line in section.splitlines() if line.startswith("| ")]
    listed = {n for cell in first_cells for n in re.findall(r"[A-Za-z_][A-Za-z_0-9]*", cell)}
    assert sorted(names - listed) == []
