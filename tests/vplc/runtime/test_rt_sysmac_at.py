"""Sysmac AT specifications in the memory areas (W501: CIO, %W, %H, %D, %E): variables at the same words share
them; I/O port names are refused as not modelled."""
from vplc.api import load_plc
from vplc.project import load_project

GLOBALS = """VAR_GLOBAL
    Lamp AT %W480.00 : BOOL;
    Flag AT %W480.15 : BOOL;
    Word480 AT %W480 : WORD;
    Count AT %H300 : INT := -2;
    Total AT %d4 : DINT;
    Lo AT %D4 : UINT;
    Hi AT %D5 : UINT;
    Em AT %E0_100 : UINT;
    Bits AT %W10.00 : ARRAY[0..31] OF BOOL;
    W10 AT %W10 : DWORD;
    Bytes AT %D20 : ARRAY[0..3] OF BYTE;
    D20 AT %D20 : WORD;
    Cio AT %100 : WORD;
END_VAR
"""
MAIN = """PROGRAM Main
VAR_EXTERNAL
    Lamp, Flag : BOOL; Total : DINT; Lo : UINT; Em : UINT; Bits : ARRAY[0..31] OF BOOL; Bytes : ARRAY[0..3] OF BYTE;
END_VAR
    Lamp := TRUE;
    Flag := TRUE;
    Total := 16#12345678;
    Bits[17] := TRUE;
    Bytes[1] := 16#AB;
    Em := Lo;
END_PROGRAM
"""


def plc(tmp_path):
    (tmp_path / "g.st").write_text(GLOBALS)
    (tmp_path / "main.st").write_text(MAIN)
    p = load_plc([str(tmp_path / "g.st"), str(tmp_path / "main.st")], task="Main@1ms")
    p.scan(0)
    return p


def test_variables_at_the_same_words_share_them(tmp_path):
    p = plc(tmp_path)
    assert p.read("Word480") == 0x8001                          # bits 00 and 15 of W480
    assert (p.read("Lo"), p.read("Hi")) == (0x5678, 0x1234)      # a DINT at D4: low word D4, high word D5
    assert p.read("Em") == 0x5678 and p.read("Count") == -2
    assert p.read("W10") == 1 << 17                             # BOOL array elements are bits
    assert p.read("D20") == 0xAB00                              # BYTE elements two per word, low byte first


def test_writing_a_placed_variable_by_name_changes_the_others(tmp_path):
    p = plc(tmp_path)
    p.write("Cio", 7)
    p.write("Word480", 0)
    assert p.read("Lamp") is False and p.read("Flag") is False and p.read("Cio") == 7


def _errors(tmp_path, text):
    (tmp_path / "x.st").write_text(text)
    return [(d.code, d.message) for d in load_project([str(tmp_path / "x.st")]).diagnostics if d.severity == "error"]


def test_addresses_vplc_cannot_place_are_st1110(tmp_path):
    errors = _errors(tmp_path, "VAR_GLOBAL\n    A AT %W480 : BOOL;\n    B AT %W1.00 : INT;\n"
                               "    C AT %D10 : STRING[8];\n    D AT %W511 : DINT;\n    E AT %A100 : WORD;\nEND_VAR\n")
    assert [c for c, _ in errors] == ["ST1110"] * 5
    assert "bit" in errors[0][1] and "512 words" in errors[3][1] and "Auxiliary" in errors[4][1]


def test_a_local_variable_in_a_memory_area_is_st1110(tmp_path):
    errors = _errors(tmp_path, "PROGRAM Main\nVAR X AT %D0 : INT; END_VAR\nX := 1;\nEND_PROGRAM\n")
    assert [c for c, _ in errors] == ["ST1110"]


def test_an_io_port_name_is_refused_as_not_modelled(tmp_path):
    errors = _errors(tmp_path, "VAR_GLOBAL\n    In1 AT ECAT://node#1/Input Bit 00 : BOOL;\nEND_VAR\n")
    assert [c for c, _ in errors] == ["ST1007"] and "I/O ports are not modelled by vplc" in errors[0][1]


def test_iec_addresses_keep_their_meaning_of_before(tmp_path):
    assert _errors(tmp_path, "VAR_GLOBAL\n    Q AT %QX0.1 : BOOL;\n    M AT %MW10 : WORD;\nEND_VAR\n") == []


def test_a_placed_variable_passed_as_in_out_is_written_into_the_area(tmp_path):
    (tmp_path / "g.st").write_text("VAR_GLOBAL\n    Cnt AT %D0 : UINT;\n    Word0 AT %D0 : WORD;\nEND_VAR\n")
    (tmp_path / "main.st").write_text("PROGRAM Main\nVAR_EXTERNAL Cnt : UINT; Word0 : WORD; END_VAR\n"
                                      "Inc(Cnt);\nInc(Cnt);\nEND_PROGRAM\n")
    p = load_plc([str(tmp_path / "g.st"), str(tmp_path / "main.st")], task="Main@1ms")
    p.scan(0)
    assert p.read("Cnt") == 2 and p.read("Word0") == 2
