"""Arrays of BYTE and USINT (and their subranges) live in Python bytearrays (compiler.codegen_expr.holds_bytes):
the elements and every operation on them read as with any other integer array, and the buffers are not objects the
garbage collector walks. Each case here stores, copies or passes such an array the way ST programs do."""
from __future__ import annotations

import gc

from rt_helpers import plc_of, run1


def test_element_stores_wrap_to_the_byte_as_iec_integers_do(tmp_path):
    plc = run1(tmp_path, """
        b[0] := 16#FF; b[0] := b[0] AND 16#0F XOR 16#F0;
        b[1] := NOT b[1];
        b[2] := 16#F0; b[2] := b[2] OR SHR(b[2], 4);
        b[3] := 16#1F; b[3] := SHL(b[3], 4);
        b[4] := 16#81; b[4] := ROL(b[4], 1);
        b[5].7 := TRUE; b[5].0 := TRUE;
        u[0] := 255; u[0] := u[0] + 45;
        u[1] := 200; u[1] := u[1] * 2;
        u[2] := REAL_TO_USINT(254.6);
        u[3] := 10; u[3] := u[3] - 11;
        """, "b : ARRAY[0..5] OF BYTE;\nu : ARRAY[0..3] OF USINT;")
    assert plc.read("Main.b") == [0xFF, 0xFF, 0xFF, 0xF0, 0x03, 0x81]
    assert plc.read("Main.u") == [44, 144, 255, 255]


def test_initial_values_repeats_and_subranges(tmp_path):
    plc = run1(tmp_path, "", """
        b : ARRAY[0..5] OF BYTE := [1, 2, 2(7)];
        s : ARRAY[1..3] OF USINT(5..9);
        m : ARRAY[0..1, 0..2] OF BYTE := [1, 2, 3, 4];""")
    assert plc.read("Main.b") == [1, 2, 7, 7, 0, 0]
    assert plc.read("Main.s") == [5, 5, 5]
    assert plc.read("Main.m") == [1, 2, 3, 4, 0, 0]
    assert plc.read("Main.m[1,0]") == 4


def test_assignment_copies_and_structures_keep_their_own_buffers(tmp_path):
    plc = plc_of(tmp_path, """
TYPE Frame : STRUCT
    Len : UINT;
    Data : ARRAY[0..3] OF BYTE;
END_STRUCT; END_TYPE
PROGRAM Main
VAR
    a, c : ARRAY[0..3] OF BYTE;
    f, g : Frame;
    fs : ARRAY[0..1] OF Frame;
END_VAR
a[0] := 1; a[3] := 4;
c := a;
a[0] := 9;                  (* c is a copy *)
f.Data := c; f.Len := 2;
g := f;
f.Data[1] := 5;             (* g is a copy *)
fs[1] := g;
fs[1].Data[2] := 7;
END_PROGRAM
""")
    plc.scan(0)
    assert plc.read("Main.a") == [9, 0, 0, 4]
    assert plc.read("Main.c") == [1, 0, 0, 4]
    assert plc.read("Main.f.Data") == [1, 5, 0, 4]
    assert plc.read("Main.g") == {"Len": 2, "Data": [1, 0, 0, 4]}
    assert plc.read("Main.fs[1].Data") == [1, 0, 7, 4]
    assert plc.read("Main.fs[0].Data") == [0, 0, 0, 0]


def test_arrays_given_to_function_blocks_and_functions(tmp_path):
    """An input array is a copy; an element given to an array input stands for the array from it on (Sysmac);
    an in-out array (also ARRAY[*]) is the caller's own."""
    plc = plc_of(tmp_path, """
FUNCTION_BLOCK Fill
VAR_INPUT Src : ARRAY[0..3] OF USINT; END_VAR
VAR_OUTPUT Sum : UDINT; Out : ARRAY[0..3] OF USINT; END_VAR
VAR_IN_OUT Buf : ARRAY[*] OF USINT; END_VAR
VAR i : DINT; END_VAR
Sum := 0;
FOR i := 0 TO 3 DO
    Sum := Sum + USINT_TO_UDINT(Src[i]);
    Out[i] := Src[i] + 16#F0;
END_FOR;
FOR i := LOWER_BOUND(Buf, 1) TO UPPER_BOUND(Buf, 1) DO
    Buf[i] := Buf[i] + 1;
END_FOR;
Src[0] := 0;               (* the caller's array is not changed *)
END_FUNCTION_BLOCK
FUNCTION Checksum : BYTE
VAR_IN_OUT Data : ARRAY[*] OF BYTE; END_VAR
VAR i : DINT; END_VAR
Checksum := 0;
FOR i := LOWER_BOUND(Data, 1) TO UPPER_BOUND(Data, 1) DO
    Checksum := Checksum XOR Data[i];
END_FOR;
END_FUNCTION
PROGRAM Main
VAR
    fb : Fill;
    src : ARRAY[0..5] OF USINT := [1, 2, 3, 16#20, 5, 6];
    bytes : ARRAY[0..5] OF BYTE := [1, 2, 3, 16#20, 5, 6];
    buf : ARRAY[0..2] OF USINT := [0, 255, 7];
    x : BYTE;
END_VAR
fb(Src := src[2], Buf := buf);
x := Checksum(Data := bytes);
END_PROGRAM
""")
    plc.scan(0)
    assert plc.read("Main.fb.Sum") == 3 + 0x20 + 5 + 6
    assert plc.read("Main.fb.Out") == [0xF3, 0x10, 0xF5, 0xF6]
    assert plc.read("Main.src") == [1, 2, 3, 0x20, 5, 6]
    assert plc.read("Main.buf") == [1, 0, 8]
    assert plc.read("Main.x") == 1 ^ 2 ^ 3 ^ 0x20 ^ 5 ^ 6


def test_sysmac_array_instructions_read_and_write_byte_arrays(tmp_path):
    """W502: ToAryByte 2-453 .. 2-455, AryByteTo 2-459 .. 2-461 (runtime/sysmac_fns.py), StringToAry, AryToString and
    AryMove, each reading or writing a byte array from an element on."""
    plc = run1(tmp_path, """
        n := ToAryByte(In := w, Order := _LOW_HIGH, AryOut := b[1]);
        ok := AryByteTo(In := b[1], Size := 4, Order := _LOW_HIGH, OutVal := back);
        m := StringToAry(In := 'AB', AryOut := t[0]);
        s := AryToString(In := t[0], Size := 2);
        ok := AryMove(In := b[1], AryOut := c[0], Size := 4);
        """, """
        w : DWORD := 16#11223344;
        back : DWORD;
        b, c, t : ARRAY[0..7] OF BYTE;
        n, m : UINT;
        ok : BOOL;
        s : STRING[8];""")
    assert plc.read("Main.b") == [0, 0x44, 0x33, 0x22, 0x11, 0, 0, 0]
    assert plc.read("Main.back") == 0x11223344
    assert plc.read("Main.c")[:4] == [0x44, 0x33, 0x22, 0x11]
    assert plc.read("Main.t")[:2] == [65, 66] and plc.read("Main.s") == "AB"


def test_writes_from_outside_are_range_checked_and_the_buffers_are_not_walked_by_the_collector(tmp_path):
    import pytest

    from vplc.runtime.values import PathError
    plc = run1(tmp_path, "", "b : ARRAY[0..4095] OF BYTE;\nw : ARRAY[0..3] OF WORD;")
    plc.write("Main.b[4095]", 255)
    assert plc.read("Main.b[4095]") == 255
    with pytest.raises(PathError, match="outside the range 0..255"):
        plc.write("Main.b[0]", 256)
    main = plc.instances["MAIN"]
    assert not gc.is_tracked(main.b)          # 4096 elements the collector never visits
    assert gc.is_tracked(main.w)              # (other arrays are lists of Python integers)
