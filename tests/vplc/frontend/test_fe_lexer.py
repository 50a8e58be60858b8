"""Lexer: token kinds and literal values for the grammar corners; errors at the right place."""
from __future__ import annotations

import pytest

from vplc.frontend.diagnostics import DiagnosticBag
from vplc.frontend.lexer import decode_string, tokenize
from vplc.frontend.source import SourceFile


def toks(text: str):
    d = DiagnosticBag()
    out = [(t.kind, t.text) for t in tokenize(SourceFile("t.st", text), d)][:-1]
    return out, [x.code for x in d.items]


@pytest.mark.parametrize("text,kind", [
    ("16#FF", "BASED"), ("8#17", "BASED"), ("2#1010_1010", "BASED"), ("1_000", "INT"),
    ("1.5e3", "REAL"), ("2E-3", "REAL"), ("T#1h2m3s4ms", "TIME"), ("TIME#-5s", "TIME"), ("LTIME#5ns", "TIME"),
    ("t#1.5s", "TIME"), ("D#2024-02-29", "DATE"), ("DATE#2024-1-1", "DATE"), ("TOD#12:30:15.5", "TOD"),
    ("TIME_OF_DAY#23:59:59", "TOD"), ("DT#2024-01-01-12:00:00", "DT"), ("DATE_AND_TIME#2024-01-01-00:00", "DT"),
    ("'it$'s'", "STRING"), ('"wide"', "WSTRING"), ("%MW10", "ADDRESS"),
])
def test_single_token_literal_kinds(text, kind):
    tokens, errors = toks(text)
    assert tokens == [(kind, text)] and errors == []


def test_typed_literal_and_enum_prefixes_split_into_prefix_and_value():
    assert toks("BYTE#16#41")[0] == [("TYPED", "BYTE#"), ("BASED", "16#41")]
    assert toks("Ns\\eColor#Red")[0] == [("IDENT", "Ns"), ("OP", "\\"), ("TYPED", "eColor#"), ("IDENT", "Red")]


def test_nested_block_comments_line_comments_and_pragmas():
    tokens, errors = toks("a (* x (* nested *) y *) b // rest\n c /* c-style */ {attribute 'x'} d")
    assert tokens == [("IDENT", "a"), ("IDENT", "b"), ("IDENT", "c"), ("PRAGMA", "{attribute 'x'}"), ("IDENT", "d")]
    assert errors == []


def test_range_dots_do_not_make_a_real():
    assert toks("1..5")[0] == [("INT", "1"), ("OP", ".."), ("INT", "5")]


@pytest.mark.parametrize("text,code", [("x := 'abc", "ST0103"), ("(* open", "ST0102"), ("a ? b", "ST0101"),
                                       ("{ pragma", "ST0105")])
def test_lexical_errors_are_reported_with_their_code(text, code):
    assert code in toks(text)[1]


@pytest.mark.parametrize("body,value", [
    ("$$", "$"), ("$'", "'"), ('$"', '"'), ("$L", "\n"), ("$N", "\n"), ("$P", "\f"), ("$R", "\r"), ("$T", "\t"),
    ("$0D$0a", "\r\n"), ("$$TMSTA,2,00,*41$R$L", "$TMSTA,2,00,*41\r\n"), ("$l$r$t", "\n\r\t"),
])
def test_every_dollar_escape_decodes(body, value):
    assert decode_string(body, wide=False) == (value, None)


def test_invalid_escape_is_named():
    value, err = decode_string("a$Qb", wide=False)
    assert err is not None and "$Q" in err


def test_wide_string_uses_four_hex_digits():
    assert decode_string("$00E9", wide=True) == ("é", None)


def spans(text: str):
    d = DiagnosticBag()
    tokens = [(t.kind, t.start, t.end) for t in tokenize(SourceFile("t.st", text), d)]
    return tokens, [(x.code, x.span.start, x.span.end, x.message.split(" (U+")[0]) for x in d.items]


def test_names_beside_a_hash_or_a_port_address_are_read_as_the_longer_token():
    """A name is an IDENT unless "#" or "://" follows it: then a typed or time literal, or an I/O port address."""
    assert toks("T#5s Tx#5 INT#5 TIME")[0] == [("TIME", "T#5s"), ("TYPED", "Tx#"), ("INT", "5"),
                                               ("TYPED", "INT#"), ("INT", "5"), ("IDENT", "TIME")]
    assert toks("ECAT://node#1 Other://x")[0][0] == ("IOPORT", "ECAT://node#1 Other")
    assert toks("Other://x")[0] == [("IDENT", "Other"), ("OP", ":")]          # and a line comment
    assert toks("a_1:=b2;")[0] == [("IDENT", "a_1"), ("OP", ":="), ("IDENT", "b2"), ("OP", ";")]


def test_offsets_and_comments_after_whitespace_and_bad_characters_split_by_it():
    tokens, errors = spans("  a\t(* c *)\n  b ?? ?\n")
    assert tokens == [("IDENT", 2, 3), ("IDENT", 14, 15), ("EOF", 21, 21)]
    assert errors == [("ST0101", 16, 18, "unexpected character '?'"), ("ST0101", 19, 20, "unexpected character '?'")]
    comments: list = []
    tokenize(SourceFile("t.st", " // one\n\t(* two *) x"), DiagnosticBag(), comments)
    assert comments == [("//", 1, 7), ("(*", 9, 18)]
    assert spans("x ?")[1] == [("ST0101", 2, 3, "unexpected character '?'")]
    assert spans("   ")[0] == [("EOF", 3, 3)]


def test_keywords_and_units_are_ascii_only():
    """Unicode case folding made TıME# (dotless i) a TIME keyword and ſ (long s) the unit s; IEC 61131-3 letters
    are ASCII."""
    assert toks("TıME#1s")[1] == ["ST0101"]
    assert toks("T#1ſ")[1] == ["ST0101"] and toks("T#1s")[0] == [("TIME", "T#1s")]
