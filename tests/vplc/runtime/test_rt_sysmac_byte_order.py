"""ToAryByte / AryByteTo byte order and array arguments, against the examples of the NJ-series Instructions
Reference Manual (W502): ToAryByte 2-453 .. 2-455, AryByteTo 2-459 .. 2-461 (issue 24, deliverable 5)."""
from __future__ import annotations

import pytest
from rt_helpers import run1


def test_a_one_byte_value_with_high_low_lands_in_the_second_element(tmp_path):
    # W502 2-455, "When the Data Type of In Is One Byte", _HIGH_LOW, not an array: In is stored in AryOut[1] and
    # 16#00 in AryOut[0]
    for decl in ("x : BYTE := 16#7F;", "x : USINT := 127;", "x : SINT := 127;"):
        plc = run1(tmp_path, "n := ToAryByte(In := x, Order := _HIGH_LOW, AryOut := b[0]);",
                   decl + " b : ARRAY[0..3] OF BYTE := [4(16#EE)]; n : UINT;")
        assert plc.read("Main.b") == [0x00, 0x7F, 0xEE, 0xEE] and plc.read("Main.n") == 2, decl
    plc = run1(tmp_path, "n := ToAryByte(In := x, Order := _LOW_HIGH, AryOut := b[0]);",
               "x : BYTE := 16#7F; b : ARRAY[0..3] OF BYTE := [4(16#EE)]; n : UINT;")
    assert plc.read("Main.b") == [0x7F, 0xEE, 0xEE, 0xEE] and plc.read("Main.n") == 1


def test_a_sint_array_is_written_element_by_element_and_swapped_two_by_two_with_high_low(tmp_path):
    # W502 2-455: In = SINT#1, SINT#2, SINT#3. _LOW_HIGH: AryOut = 16#01 16#02 16#03, Out = UINT#3.
    # _HIGH_LOW: In[i] with i even to AryOut[i+1], odd to AryOut[i-1], 16#00 completing the odd count:
    # AryOut = 16#02 16#01 16#00 16#03, Out = UINT#4
    decls = "a : ARRAY[0..2] OF SINT := [1, 2, 3]; lh, hl : ARRAY[0..4] OF BYTE := [5(16#EE)]; n1, n2 : UINT;"
    plc = run1(tmp_path, """n1 := ToAryByte(In := a, Order := _LOW_HIGH, AryOut := lh[0]);
        n2 := ToAryByte(In := a, Order := _HIGH_LOW, AryOut := hl[0]);""", decls)
    assert plc.read("Main.lh") == [0x01, 0x02, 0x03, 0xEE, 0xEE] and plc.read("Main.n1") == 3
    assert plc.read("Main.hl") == [0x02, 0x01, 0x00, 0x03, 0xEE] and plc.read("Main.n2") == 4


def test_a_dword_array_is_written_word_by_word(tmp_path):
    # W502 2-454/2-455: In = DWORD#16#01234567, DWORD#16#89ABCDEF, DWORD#16#CCDDEEFF, Out = UINT#12
    decls = ("d : ARRAY[0..2] OF DWORD := [16#01234567, 16#89ABCDEF, 16#CCDDEEFF]; lh, hl : ARRAY[0..11] OF BYTE; "
             "n : UINT;")
    plc = run1(tmp_path, """n := ToAryByte(In := d, Order := _LOW_HIGH, AryOut := lh[0]);
        ToAryByte(In := d, Order := _HIGH_LOW, AryOut := hl[0]);""", decls)
    assert plc.read("Main.n") == 12
    assert plc.read("Main.lh") == [0x67, 0x45, 0x23, 0x01, 0xEF, 0xCD, 0xAB, 0x89, 0xFF, 0xEE, 0xDD, 0xCC]
    assert plc.read("Main.hl") == [0x45, 0x67, 0x01, 0x23, 0xCD, 0xEF, 0x89, 0xAB, 0xEE, 0xFF, 0xCC, 0xDD]


def test_a_bool_output_takes_bit_0_of_the_first_byte_in_the_order_asked(tmp_path):
    # W502 2-461, "When OutVal Is BOOL Data", not an array: _LOW_HIGH takes bit 0 of In[0], _HIGH_LOW bit 0 of In[1]
    plc = run1(tmp_path, """AryByteTo(In := b[0], Size := 2, Order := _LOW_HIGH, OutVal := lh);
        AryByteTo(In := b[0], Size := 2, Order := _HIGH_LOW, OutVal := hl);
        AryByteTo(In := c[0], Size := 1, Order := _LOW_HIGH, OutVal := even);""",
               "b : ARRAY[0..1] OF BYTE := [16#02, 16#01]; c : ARRAY[0..0] OF BYTE := [16#FE]; lh, hl, even : BOOL;")
    assert plc.read("Main.lh") is False           # 16#02: bit 0 is 0, though the byte is not zero
    assert plc.read("Main.hl") is True            # bit 0 of In[1] = 16#01
    assert plc.read("Main.even") is False


def test_a_bool_array_takes_every_bit_first_byte_first(tmp_path):
    # W502 2-461: OutVal a BOOL array with 21 elements, Size UINT#3, In = BYTE#16#89, BYTE#16#45, BYTE#16#04,
    # _LOW_HIGH: In[0] into OutVal[0] .. OutVal[7], In[1] into OutVal[8] .. OutVal[15], ...; remaining bits discarded.
    # _HIGH_LOW: In[0] into OutVal[8] .. OutVal[15], In[1] into OutVal[0] .. OutVal[7], the same for the next pair
    plc = run1(tmp_path, """AryByteTo(In := b[0], Size := 3, Order := _LOW_HIGH, OutVal := lh);
        AryByteTo(In := b[0], Size := 3, Order := _HIGH_LOW, OutVal := hl);""",
               "b : ARRAY[0..2] OF BYTE := [16#89, 16#45, 16#04]; lh, hl : ARRAY[0..20] OF BOOL;")
    lh = plc.read("Main.lh")
    assert [i for i, v in enumerate(lh) if v] == [0, 3, 7, 8, 10, 14, 18] and len(lh) == 21
    assert [i for i, v in enumerate(plc.read("Main.hl")) if v] == [0, 2, 6, 8, 11, 15]


def test_array_outputs_of_wider_elements_and_a_round_trip(tmp_path):
    plc = run1(tmp_path, """n := ToAryByte(In := w, Order := _HIGH_LOW, AryOut := b[0]);
        AryByteTo(In := b[0], Size := n, Order := _HIGH_LOW, OutVal := back);
        AryByteTo(In := b[0], Size := 3, Order := _LOW_HIGH, OutVal := part);""",
               "w : ARRAY[0..2] OF INT := [-2, 300, 16#1234]; back : ARRAY[0..2] OF INT; "
               "part : ARRAY[0..2] OF INT := [7, 7, 7]; b : ARRAY[0..9] OF BYTE; n : UINT;")
    assert plc.read("Main.n") == 6 and plc.read("Main.back") == [-2, 300, 0x1234]
    assert plc.read("Main.b")[:6] == [0xFF, 0xFE, 0x01, 0x2C, 0x12, 0x34]
    # 3 bytes fill one INT (16#FEFF read low byte first: -257); the elements the bytes do not reach keep theirs
    assert plc.read("Main.part") == [-257, 7, 7]


def test_one_byte_output_with_high_low_reads_the_second_byte(tmp_path):
    # the inverse of 2-455: what ToAryByte wrote with _HIGH_LOW comes back with _HIGH_LOW
    plc = run1(tmp_path, """ToAryByte(In := x, Order := _HIGH_LOW, AryOut := b[0]);
        AryByteTo(In := b[0], Size := 2, Order := _HIGH_LOW, OutVal := y);""",
               "x : USINT := 200; y : USINT; b : ARRAY[0..1] OF BYTE;")
    assert plc.read("Main.b") == [0, 200] and plc.read("Main.y") == 200


@pytest.mark.parametrize("call, message", [
    ("ToAryByte(In := p, Order := _LOW_HIGH, AryOut := b[0]);",
     "where ANY_ELEMENTARY or an array of it is expected"),
    ("AryByteTo(In := b[0], Size := 2, Order := _LOW_HIGH, OutVal := p);",
     "ANY_ELEMENTARY or an array of it"),
])
def test_a_structure_is_refused_with_the_types_accepted(tmp_path, call, message):
    from vplc.api import LoadError
    with pytest.raises(LoadError) as exc:
        run1(tmp_path, call, "p : stP; b : ARRAY[0..9] OF BYTE;",
             extra="TYPE stP : STRUCT x : INT; END_STRUCT; END_TYPE\n")
    assert message in str(exc.value)
