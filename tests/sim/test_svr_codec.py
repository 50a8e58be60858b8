"""Ethernet Slave framing and encodings: the worked frames of TMscript 2.24 §17.4 decoded whole, split in
two, byte by byte and glued; the data-table encodings reproduce the manual's byte dumps."""
import struct

import pytest

from tmsim.limits import SVR_STRING_MAX
from tmsim.protocol import codec
from tmsim.protocol import svr_table as table
from tmsim.protocol.svr_session import HEADERS
from tmsim.protocol.svr_table import ITEMS, SvrContentError, SvrValueError

TMSVR = HEADERS | {"CPERR"}

# §17.4.2 (mode 1): Robot_Link=0, TCP_Value={1,1,1,0.1,0.2,0.1}, Ctrl_DO0=0 as the robot sends it
MANUAL_BINARY = bytes.fromhex(
    "24544D5356522C" "36392C" "302C312C"                                # $TMSVR, 69, 0,1,
    "0A00" "526F626F745F4C696E6B" "0100" "00"                           # Robot_Link=0
    "0900" "5443505F56616C7565" "1800" + "0000803F" * 3 + "CDCCCC3D" "CDCC4C3E" "CDCCCC3D"   # TCP_Value
    "0800" "4374726C5F444F30" "0100" "00"                               # Ctrl_DO0=0
    "2C2A39360D0A")                                                     # ,*96 CR LF
MANUAL_BINARY_WRITE = bytes.fromhex("24544D5356522C" "31382C" "54312C312C"
                                    "0800" "4374726C5F444F30" "0100" "01" "2C2A37410D0A")
MANUAL_READ_11 = bytes.fromhex("24544D5356522C" "32362C" "51312C31312C"
                               "0800" "4374726C5F444F30" "0800" "5443505F4D617373" "2C2A37460D0A")

VECTORS = [
    b"$TMSVR,15,S0,2,Ctrl_DO0=1,*76\r\n", b"$TMSVR,10,S0,0,00,OK,*18\r\n",
    b"$TMSVR,16,S1,99,Ctrl_DO0=1,*46\r\n", b"$TMSVR,18,S1,0,01,NotSupport,*0E\r\n",
    b"$TMSVR,15,S2,2,Ctrl_DO0=1,*74\r\n", b"$TMSVR,23,S2,0,02,WritePermission,*6A\r\n",
    b"$TMSVR,15,S3,3,Ctrl_DO0=1,*74\r\n", b"$TMSVR,19,S3,0,03,InvalidData,*74\r\n",
    b"$TMSVR,16,S4,2,Ctrl_DO32=1,*40\r\n", b"$TMSVR,26,S4,0,04,NotExist;Ctrl_DO32,*58\r\n",
    b"$TMSVR,17,S5,2,Robot_Link=1,*07\r\n", b"$TMSVR,27,S5,0,05,ReadOnly;Robot_Link,*1E\r\n",
    codec.encode("TMSVR", "T2,2,Ctrl_DO0=0\r\nCtrl_DO1=1"),     # the manual prints length 15 for these 27 bytes
    b"$TMSVR,10,T2,0,00,OK,*1D\r\n",
    codec.encode("TMSVR", "Q2,12,Robot_Link\r\nTCP_Mass"),          # the manual prints length 28 for 26 bytes
    b"$TMSVR,30,Q2,12,Robot_Link=0\r\nTCP_Mass=0,*09\r\n",
    b'$TMSVR,27,Q3,13,[{"Item":"TCP_Mass"}],*3C\r\n', b'$TMSVR,39,Q3,13,[{"Item":"TCP_Mass","Value":0.0}],*40\r\n',
    b"$TMSVR,25,Q2,0,04,NotExist;TCP_MaXX,*17\r\n", b"$TMSVR,10,T1,0,00,OK,*1E\r\n",
    MANUAL_BINARY, MANUAL_BINARY_WRITE, MANUAL_READ_11,
]


def _feed(chunks):
    buf, out = bytearray(), []
    for chunk in chunks:
        buf += chunk
        out.extend(codec.decode_all(buf, TMSVR))
    assert not buf, "no bytes may stay in the buffer after a complete frame"
    return out


@pytest.mark.parametrize("raw", VECTORS, ids=lambda r: r[:22].decode("ascii", "replace"))
def test_manual_17_4_frame_decodes_whole_split_bytewise_and_glued(raw):
    item, used = codec.decode(raw, TMSVR)
    assert used == len(raw) and isinstance(item, codec.Frame) and item.header == "TMSVR"
    expected = [item]
    assert _feed([raw]) == expected
    for cut in range(1, len(raw)):
        assert _feed([raw[:cut], raw[cut:]]) == expected
    assert _feed([raw[i:i + 1] for i in range(len(raw))]) == expected
    other = VECTORS[1]
    assert _feed([raw + other + raw]) == expected + [codec.decode(other, TMSVR)[0]] + expected


def test_listen_node_header_on_the_ethernet_slave_is_a_header_error():
    item, _used = codec.decode(b"$TMSCT,5,10,OK,*6D\r\n", TMSVR)
    assert isinstance(item, codec.BadFrame) and item.code == codec.CPERR_HEADER


def test_manual_17_4_2_binary_content_is_reproduced_byte_for_byte():
    pairs = [(ITEMS["Robot_Link"], 0), (ITEMS["TCP_Value"], [1, 1, 1, 0.1, 0.2, 0.1]), (ITEMS["Ctrl_DO0"], 0)]
    assert codec.encode("TMSVR", b"0,1," + table.encode_binary(pairs)) == MANUAL_BINARY


def test_manual_17_4_2_binary_write_splits_into_item_and_value():
    frame, _ = codec.decode(MANUAL_BINARY_WRITE, TMSVR)
    content = frame.data.split(b",", 2)[2]
    assert table.split_binary(content, True) == [("Ctrl_DO0", b"\x01")]
    assert table.decode_binary_value(ITEMS["Ctrl_DO0"], b"\x01") == 1


def test_manual_17_4_5_binary_read_request_lists_names_without_values():
    frame, _ = codec.decode(MANUAL_READ_11, TMSVR)
    content = frame.data.split(b",", 2)[2]
    assert table.split_binary(content, False) == [("Ctrl_DO0", None), ("TCP_Mass", None)]


def test_manual_17_4_3_string_and_17_4_4_json_contents():
    pairs = [(ITEMS["Robot_Link"], 0), (ITEMS["TCP_Value"], [1, 1, 1, 0.1, 0.2, 0.1]), (ITEMS["Ctrl_DO0"], 1)]
    assert table.encode_string(pairs) == "Robot_Link=0\r\nTCP_Value={1,1,1,0.1,0.2,0.1}\r\nCtrl_DO0=1"
    assert table.encode_json(pairs) == ('[{"Item":"Robot_Link","Value":0},'
                                        '{"Item":"TCP_Value","Value":[1.0,1.0,1.0,0.1,0.2,0.1]},'
                                        '{"Item":"Ctrl_DO0","Value":1}]')


def test_every_item_encodes_in_all_three_formats_and_reads_back():
    samples = {"bool": True, "byte": 7, "int": -123456, "float": 1.5, "string": "Grip ok"}
    for item in ITEMS.values():
        value = [samples[item.type]] * item.size if item.size > 1 else samples[item.type]
        if item.low is not None:
            value = item.high
        raw = table.binary_value(item, value)
        assert table.decode_binary_value(item, raw) == (int(value) if item.type == "bool" else value), item.name
        text = table.string_value(item, value)
        assert table.check_value(item, table.parse_string_value(item, text)) == \
            table.check_value(item, value), item.name


@pytest.mark.parametrize("name, text", [
    ("Ctrl_DO0", "2"), ("Ctrl_DO0", "abc"), ("Project_Speed", "7"), ("Project_Speed", "105"),
    ("Project_Speed", "0"), ("Ctrl_AO0", "nan"), ("Ctrl_AO0", "{1,2}"), ("Project_Name", "NoQuotes"),
    ("Project_Name", '"' + "x" * (SVR_STRING_MAX + 1) + '"'), ("Stick_Play", "3"), ("Camera_Light", "1.5"),
])
def test_value_that_does_not_fit_its_item_is_a_value_error(name, text):
    with pytest.raises(SvrValueError):
        table.check_value(ITEMS[name], table.parse_string_value(ITEMS[name], text))


def test_binary_value_of_the_wrong_size_is_a_value_error():
    with pytest.raises(SvrValueError):
        table.decode_binary_value(ITEMS["Ctrl_AO0"], struct.pack("<d", 1.0))


@pytest.mark.parametrize("kind, content", [
    ("binary", b"\x05\x00Ab"), ("binary", b"\x01"), ("binary", b""), ("string", "Ctrl_DO0"), ("string", "=1"),
    ("json", "Ctrl_DO0=1"), ("json", '[{"Value": 1}]'), ("json", "[" * 60000 + "]" * 60000),
    ("json", '[{"Item": "Ctrl_DO0"}]'), ("json", "[]"),
])
def test_content_that_does_not_match_its_mode_is_invalid_data(kind, content):
    split = {"binary": table.split_binary, "string": table.split_string, "json": table.split_json}[kind]
    with pytest.raises(SvrContentError):
        split(content, True)


def test_docs_item_table_matches_the_data_table():
    """docs/simulator.md lists every item with the type, size and access of tmsim/protocol/svr_table.py (one fact,
    one home)."""
    import pathlib
    import re
    text = (pathlib.Path(__file__).resolve().parents[2] / "docs" / "simulator.md").read_text(encoding="utf-8")
    documented = {}
    for first, last, kind, size, access in re.findall(
            r"^\| `(\w+)`(?: … `(\w+)`)? \| (\w+) \| (\d+) \| (R(?:/W (?:M/A|A))?) \|", text, re.M):
        names = [first]
        if last:
            stem = first.rstrip("0123456789")
            names = [f"{stem}{i}" for i in range(int(first[len(stem):]), int(last[len(stem):]) + 1)]
        for name in names:
            documented[name] = (kind, int(size), access)
    expected = {item.name: (item.type, item.size, {"": "R", "MA": "R/W M/A", "A": "R/W A"}[item.writable])
                for item in ITEMS.values()}
    assert documented == expected
