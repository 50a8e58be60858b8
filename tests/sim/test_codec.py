"""Codec: every worked frame of tm_protocol.md §3/§4 decoded whole, split in two, byte by byte and glued."""
import pytest

from tmsim.limits import FRAME_DATA_MAX
from tmsim.protocol import codec

VECTORS = [
    b"$TMSCT,5,10,OK,*6D\r\n",
    b"$TMSTA,2,00,*41\r\n",
    b'$TMSCT,64,2,ChangeBase("RobotBase")\r\nChangeTCP("NOTOOL")\r\nChangeLoad(10.1),*68\r\n',
    b"$TMSCT,4,1,OK,*5C\r\n", b"$TMSCT,4,2,OK,*5F\r\n", b"$TMSCT,4,3,OK,*5E\r\n",
    b"$TMSCT,8,2,OK;2;3,*52\r\n", b"$TMSCT,13,3,ERROR;1;2;3,*3F\r\n", b"$TMSCT,9,4,ERROR;1,*02\r\n",
    b"$TMSCT,9,0,Listen1,*4C\r\n", b'$TMSCT,25,1,ChangeBase("RobotBase"),*08\r\n',
    b"$TMSCT,40,3,int var_i = 100\r\nvar_i = 1000\r\nvar_i++,*5A\r\n",
    b"$TMSCT,42,4,int var_i = 100\r\nvar_i = 1000\r\nvar_i++\r\n,*58\r\n",
    b'$TMSCT,78,2,ChangeBase("RobotBase")\r\nChangeTCP("NOTOOL")\r\nScriptExit()\r\nChangeLoad(10.1),*6C\r\n',
    b'$TMSCT,86,1,float[] targetP1= {0,0,90,0,90,0}\r\nPTP("JPP",targetP1,10,200,0,false)\r\nQueueTag(1,1),*60\r\n',
    b"$TMSCT,15,2,ScriptExit(0),*55\r\n", b"$TMSCT,23,2,StopAndClearBuffer(0),*55\r\n",
    b"$TMSCT,23,3,StopAndClearBuffer(1),*55\r\n", b"$TMSCT,23,3,StopAndClearBuffer(2),*56\r\n",
    b"$TMSTA,9,00,false,,*37\r\n", b"$TMSTA,15,00,true,Listen1,*79\r\n", b"$TMSTA,5,01,15,*6F\r\n",
    b"$TMSTA,10,01,15,none,*7D\r\n", b"$TMSTA,5,01,88,*6B\r\n", b"$TMSTA,10,01,88,none,*79\r\n",
    b"$TMSTA,10,01,08,true,*6D\r\n", b"$TMSTA,10,01,01,true,*64\r\n", b"$TMSTA,10,01,02,true,*67\r\n",
    b"$TMSTA,14,90,Hello World,*73\r\n",
    b"$CPERR,2,01,*49\r\n", b"$CPERR,2,02,*4A\r\n", b"$CPERR,2,03,*4B\r\n", b"$CPERR,2,04,*4C\r\n",
    b"$CPERR,2,F1,*3F\r\n", b"$TMSCT,8,local,OK,*0C\r\n", b"$TMSCT,12,diag,ERROR;2,*04\r\n",
    b'$TMSCT,55,M1,PTP("JPP",0,0,90,0,90,0,35,200,0,false)\r\nQueueTag(1),*73\r\n',
    b"$TMSCT,5,M1,OK,*10\r\n",
    b'$TMSCT,74,M2,Line("CAR",417.5,-122.3,343.9,180,0,90,100,200,50,false)\r\nQueueTag(2,1),*04\r\n',
    b"$TMSCT,10,M2,ERROR;1,*71\r\n", b"$TMSCT,24,P1,StopAndClearBuffer(0),*01\r\n",
    b"$TMSCT,15,X1,ScriptExit(),*3E\r\n", b"$TMSTA,3,00,,*6c\r\n",
    '$TMSCT,20,7,string s = "Über",*39\r\n'.encode(),
    b"$TMSCT,52,SCTpy0,PTP(\"JPP\",10,-10,10,-10,10,-10,10,200,0,true),*00\r\n",
    b"$TMSTA,5,01,03,*68\r\n",
]


def _feed(chunks):
    buf, out = bytearray(), []
    for chunk in chunks:
        buf += chunk
        out.extend(codec.decode_all(buf))
    assert not buf, "no bytes may stay in the buffer after a complete frame"
    return out


def _frame_parts(raw):
    header, length, rest = raw[1:].split(b",", 2)
    return header.decode(), rest[: int(length)]


@pytest.mark.parametrize("raw", VECTORS, ids=lambda r: r[:24].decode("utf-8", "replace"))
def test_worked_frame_decodes_whole_split_bytewise_and_glued(raw):
    header, data = _frame_parts(raw)
    expected = [codec.Frame(header, data, raw)]
    assert _feed([raw]) == expected
    for cut in range(1, len(raw)):
        assert _feed([raw[:cut], raw[cut:]]) == expected
    assert _feed([raw[i:i + 1] for i in range(len(raw))]) == expected
    glued = _feed([raw + VECTORS[0] + raw])
    assert glued == expected + [codec.Frame("TMSCT", b"10,OK", VECTORS[0])] + expected


@pytest.mark.parametrize("raw", [v for v in VECTORS if v[-4:-2].upper() == v[-4:-2]],
                         ids=lambda r: r[:24].decode("utf-8", "replace"))
def test_encode_reproduces_robot_frames_with_decimal_length_and_upper_case_checksum(raw):
    header, data = _frame_parts(raw)
    assert codec.encode(header, data) == raw


def test_lower_case_checksum_is_accepted():
    item, used = codec.decode(b"$TMSTA,3,00,,*6c\r\n")
    assert isinstance(item, codec.Frame) and item.data == b"00," and used == 18


def test_checksum_covers_comma_before_star_as_in_manual_example():
    assert codec.checksum(b"TMSCT,5,10,OK,") == 0x6D


@pytest.mark.parametrize("raw, code", [
    (b'$TMSCT,-100,1,ChangeBase("RobotBase"),*13\r\n', "01"),
    (b'$TMSCT,25,1,ChangeBase("RobotBase"),*09\r\n', "02"),
    (b'$TMsct,25,1,ChangeBase("RobotBase"),*28\r\n', "03"),
    (b"$TMSCT,abc,1,x,*00\r\n", "01"),
    (b"$TMSCT,5,10,OK,*ZZ\r\n", "01"),
    (b"$TMSCT,6,10,OK,*6D\r\n$TMSTA,2,00,*41\r\n", "01"),   # length too long: seen when more bytes arrive
    (b"$TMSCT,4,10,OK,*6D\r\n", "01"),           # length too short
    (b"$TMSCT,5,10,OK,*6D\n\n", "01"),           # CR LF missing
])
def test_bad_packets_give_the_documented_cperr_code(raw, code):
    item, used = codec.decode(raw)
    assert isinstance(item, codec.BadFrame) and item.code == code
    assert used >= 1


def test_header_error_example_has_correct_checksum_so_code_is_03_not_02():
    raw = b'$TMsct,25,1,ChangeBase("RobotBase"),*28\r\n'
    assert codec.checksum(raw[1:-5]) == 0x28


def test_garbage_before_dollar_is_skipped_and_next_frame_decoded():
    items = _feed([b"\x00\xffnoise\r\n" + VECTORS[1]])
    assert isinstance(items[0], codec.Garbage) and items[0].raw == b"\x00\xffnoise\r\n"
    assert items[1] == codec.Frame("TMSTA", b"00", VECTORS[1])


def test_bad_packet_resynchronises_on_the_next_frame():
    items = _feed([b'$TMSCT,-100,1,ChangeBase("RobotBase"),*13\r\n' + VECTORS[1]])
    assert isinstance(items[0], codec.BadFrame) and items[0].code == "01"
    assert items[-1] == codec.Frame("TMSTA", b"00", VECTORS[1])


def test_oversized_declared_length_is_rejected_without_waiting_for_the_data():
    item, used = codec.decode(b"$TMSCT,%d,1," % (FRAME_DATA_MAX + 1))
    assert isinstance(item, codec.BadFrame) and item.code == "01" and "limit" in item.reason


def test_hex_and_binary_length_notation_is_accepted_on_input():
    body = b"TMSCT,0x5,10,OK,"
    raw = b"$" + body + b"*%02X\r\n" % codec.checksum(body)
    item, _ = codec.decode(raw)
    assert item.data == b"10,OK"
    body = b"TMSTA,0b10,00,"
    item, _ = codec.decode(b"$" + body + b"*%02X\r\n" % codec.checksum(body))
    assert item.data == b"00"


def test_incomplete_frame_needs_more_bytes():
    assert codec.decode(b"$TMSCT,5,10,O") == (None, 0)
    assert codec.decode(b"$TMS") == (None, 0)
    assert codec.decode(b"") == (None, 0)


def test_data_may_contain_dollar_star_comma_and_crlf():
    data = b"1,ListenSend(90,\"$a,*b\r\n\")"
    raw = codec.encode("TMSCT", data)
    assert _feed([raw[:7], raw[7:]]) == [codec.Frame("TMSCT", data, raw)]


def test_length_counts_utf8_bytes():
    raw = codec.encode("TMSCT", '7,string s = "Über"')
    assert raw == '$TMSCT,20,7,string s = "Über",*39\r\n'.encode()


def test_manual_13_3_queue_tag_example_is_172_bytes_with_checksum_49():
    """TMscript 2.24 §13.3 "Motion Function Queue Tag": the packet as printed, with real CR LF bytes."""
    data = ('2,float[] targetP1= {0,0,90,0,90,0}\r\nPTP("JPP",targetP1,10,200,0,false)\r\nQueueTag(1)\r\n'
            'float[] targetP2 = {0,0,90,90,0,0}\r\nPTP("JPP",targetP2,10,200,10,false)\r\nQueueTag(2)\r\n')
    assert len(data.encode()) == 172
    assert codec.encode("TMSCT", data) == b"$TMSCT,172," + data.encode() + b",*49\r\n"
