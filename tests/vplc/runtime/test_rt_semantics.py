"""IEC value semantics of generated code: widths, REAL rounding, division, strings, time, conversions."""
import math
import struct

import pytest
from rt_helpers import plc_from, run1

from vplc.api import PlcFault


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def test_integer_addition_wraps_at_the_type_width(tmp_path):
    plc = run1(tmp_path, "i := i + 1; u := u + 1; b := b + 1; s := s - 1;",
               "i : INT := 32767; u : UINT := 65535; b : USINT := 255; s : SINT := -128;")
    assert (plc.read("Main.i"), plc.read("Main.u"), plc.read("Main.b"), plc.read("Main.s")) == (-32768, 0, 0, 127)


def test_a_wrapped_signed_result_keeps_its_value_inside_a_larger_expression(tmp_path):
    plc = run1(tmp_path, "r := 1; i := (r - 1) * 16 + 3; j := -(r - 2) * 4; k := (r - 1) * 2 - 5;",
               "r : INT; i : INT; j : INT; k : DINT;")
    assert (plc.read("Main.i"), plc.read("Main.j"), plc.read("Main.k")) == (3, 4, -5)


def test_real_is_rounded_to_32_bits_on_every_store_and_lreal_is_not(tmp_path):
    plc = run1(tmp_path, "r := 1.0 / 3.0; l := 1.0 / 3.0;", "r : REAL; l : LREAL;")
    assert plc.read("Main.r") == f32(1 / 3)
    assert plc.read("Main.l") == 1 / 3


def test_integer_division_truncates_toward_zero_and_mod_takes_the_dividend_sign(tmp_path):
    plc = run1(tmp_path, "q := -7 / 2; m := -7 MOD 2; n := 7 MOD -2;", "q : INT; m : INT; n : INT;")
    assert (plc.read("Main.q"), plc.read("Main.m"), plc.read("Main.n")) == (-3, -1, 1)


def test_shifts_and_rotates_use_the_operand_width(tmp_path):
    plc = run1(tmp_path, "a := SHL(b, 1); c := ROL(b, 1); d := ROR(w, 4); e := SHR(b, 7);",
               "b : BYTE := 16#81; a : BYTE; c : BYTE; w : WORD := 16#1234; d : WORD; e : BYTE;")
    assert (plc.read("Main.a"), plc.read("Main.c"), plc.read("Main.d"), plc.read("Main.e")) == (0x02, 0x03, 0x4123, 1)


def test_string_assignment_truncates_to_the_declared_size(tmp_path):
    plc = run1(tmp_path, "s := CONCAT('abc', 'defgh', 'ij');", "s : STRING[5];")
    assert plc.read("Main.s") == "abcd"            # Sysmac STRING[5] holds 4 characters + NUL


def test_string_functions_follow_iec_positions(tmp_path):
    plc = run1(tmp_path, """a := LEFT('Robot', 3); b := RIGHT('Robot', 2); c := MID('Robot', 2, 2);
        d := INSERT('Rbt', 'o', 1); e := DELETE('Robot', 2, 2); f := REPLACE('Robot', 'XY', 1, 3);
        n := FIND('Robot', 'bo'); k := LEN('Robot');""",
               "a, b, c, d, e, f : STRING[20]; n : UINT; k : UINT;")
    assert [plc.read(f"Main.{v}") for v in "abcdef"] == ["Rob", "ot", "ob", "Robt", "Rot", "RoXYot"]
    assert (plc.read("Main.n"), plc.read("Main.k")) == (3, 5)


def test_time_arithmetic_and_comparison(tmp_path):
    plc = run1(tmp_path, "t := T#1s + T#250ms; d := t - T#2s; later := t > T#1s;",
               "t : TIME; d : TIME; later : BOOL;")
    assert plc.read("Main.t") == 1_250_000_000
    assert plc.read("Main.d") == -750_000_000
    assert plc.read("Main.later") is True


def test_real_to_int_conversion_rounds_to_nearest_even(tmp_path):
    plc = run1(tmp_path, "a := REAL_TO_INT(2.5); b := REAL_TO_INT(3.5); c := REAL_TO_INT(-1.6); d := TRUNC(-1.6);",
               "a, b, c : INT; d : DINT;")
    assert [plc.read(f"Main.{v}") for v in "abcd"] == [2, 4, -2, -1]


def test_conversions_to_and_from_string(tmp_path):
    plc = run1(tmp_path, "s := INT_TO_STRING(-42); i := STRING_TO_INT('123'); b := BOOL_TO_STRING(TRUE);"
                         "t := TIME_TO_STRING(T#1m2s);", "s, b, t : STRING[30]; i : INT;")
    assert (plc.read("Main.s"), plc.read("Main.i"), plc.read("Main.b"), plc.read("Main.t")) == \
        ("-42", 123, "TRUE", "T#1m2s")


def test_numeric_functions(tmp_path):
    plc = run1(tmp_path, "a := SQRT(16.0); b := EXPT(2.0, 10.0); c := LIMIT(0, 15, 10); d := MAX(3, 9, 4);"
                         "e := SEL(TRUE, 1, 2); f := MUX(2, 10, 20, 30); g := ABS(-5);",
               "a, b : LREAL; c, d, e, f, g : INT;")
    assert [plc.read(f"Main.{v}") for v in "abcdefg"] == [4.0, 1024.0, 10, 9, 2, 30, 5]


def test_real_division_by_zero_gives_infinity_not_a_fault(tmp_path):
    plc = run1(tmp_path, "r := 1.0 / z;", "r : LREAL; z : LREAL;")
    assert math.isinf(plc.read("Main.r"))


def test_bit_access_reads_and_writes_single_bits(tmp_path):
    plc = run1(tmp_path, "x := w.3; w.0 := TRUE;", "w : WORD := 8; x : BOOL;")
    assert plc.read("Main.x") is True
    assert plc.read("Main.w") == 9


def test_bit_string_to_string_is_hexadecimal_in_the_sysmac_dialect(tmp_path):
    plc = run1(tmp_path, "a := WORD_TO_STRING(WORD#16#ABCD); b := BYTE_TO_STRING(BYTE#16#41); c := UINT_TO_STRING(65);",
               "a, b, c : STRING[10];")
    assert (plc.read("Main.a"), plc.read("Main.b"), plc.read("Main.c")) == ("abcd", "41", "65")


def test_bcd_conversions_pack_and_unpack_decimal_digits(tmp_path):
    plc = run1(tmp_path, "a := BCD_TO_INT(WORD#16#1234); b := WORD_BCD_TO_UINT(WORD#16#9999); c := INT_TO_BCD(42);"
                         "d := UDINT_TO_BCD_DWORD(12345678); e := BCD_TO_SINT(BYTE#16#99);",
               "a : INT; b : UINT; c : WORD; d : DWORD; e : SINT;")
    assert [plc.read(f"Main.{v}") for v in "abcde"] == [1234, 9999, 0x42, 0x12345678, 99]


@pytest.mark.parametrize("body,message", [
    ("i := BCD_TO_INT(w);", r"BCD_TO_INT: 16#12A4 is not a BCD value \(digit 16#A\)"),
    ("w := INT_TO_BCD(-1);", r"INT_TO_BCD: -1 cannot be written as BCD in 16 bits \(0\.\.9999\)"),
    ("w := UINT_TO_BCD(UINT#10000);", r"UINT_TO_BCD: 10000 cannot be written as BCD"),
    ("s := BCD_TO_SINT(BYTE#16#99); s := BCD_TO_SINT(WORD#16#0128);",
     r"= 128 is out of the result's range \(max 127\)"),
])
def test_a_value_that_is_not_bcd_is_a_runtime_fault(tmp_path, body, message):
    plc = plc_from(tmp_path, body, "w : WORD := WORD#16#12A4; i : INT; s : SINT;")
    with pytest.raises(PlcFault, match=message):
        plc.scan(0)
