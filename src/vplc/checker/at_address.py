"""ST1110 — an AT address in a Sysmac memory area that vplc cannot place the variable at (and the reading of
those addresses for the runtime's memory model).

Sysmac AT specifications (W501, AT specification of variables: the CJ-series memory areas of the controller) put
a global variable at a word of the CIO (`%100`), Work (`%W480`), Holding (`%H300`), DM (`%D4`) or EM (`%E0_100`,
bank 0) area; a BOOL at a bit of a word (`%W480.00`, bits 00..15). Variables at the same words share them: vplc
keeps one memory of 16-bit words per area, a variable of several words takes them low word first (and a BYTE the
low byte of its word), an array one element after the other (BOOL elements one bit each, BYTE elements two per
word, low byte first). Addresses of IEC 61131-3 (`%IX0.0`, `%MW10`) keep their
meaning of before: kept, not interpreted.

Passing::

    VAR_GLOBAL
        Flags AT %W480 : WORD;
        Lamp AT %W480.00 : BOOL;        (* bit 0 of Flags *)
        Total AT %D4 : DINT;            (* D4 low word, D5 high word *)
    END_VAR

Failing::

    VAR_GLOBAL
        Lamp AT %W480 : BOOL;           (* ST1110: a BOOL needs a bit address, %W480.00 *)
        Name AT %D10 : STRING[8];       (* ST1110: STRING is not placed in a memory area by vplc *)
    END_VAR
"""
from __future__ import annotations

import re

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from .context import Context

# words per area (the CJ-compatible sizes of the NJ's memory for CJ units: CIO 6,144, W 512, H 1,536, D and each EM
# bank 32,768 words; W501)
AREA_WORDS = {"CIO": 6144, "W": 512, "H": 1536, "D": 32768, "E": 32768}
EM_BANKS = 25
Layout = tuple[str, int, int | None]      # how the value lies in the words: types.union_layout()
_RE = re.compile(r"%(?:(?P<area>[WHDA])|E(?P<bank>[0-9A-F]{1,2})_)?(?P<word>[0-9]+)(?:\.(?P<bit>[0-9]+))?$", re.I)


def parse(text: str) -> tuple[str, int, int, int | None] | None:
    """(area, bank, word, bit or None) of a Sysmac memory-area address, or None for another address."""
    m = _RE.match(text)
    if m is None:
        return None
    area = (m.group("area") or ("E" if m.group("bank") is not None else "CIO")).upper()
    bank = int(m.group("bank"), 16) if m.group("bank") is not None else 0
    bit = int(m.group("bit")) if m.group("bit") is not None else None
    return area, bank, int(m.group("word")), bit


def check_global(ctx: Context, decl: A.VarDecl, vt: T.Type) -> tuple[str, int, int, int, Layout, int] | None:
    """The address of a global in a Sysmac area as (area, bank, word, bit, layout, words in the area), or None;
    reports ST1110."""
    if decl.at is None:
        return None
    addr = parse(decl.at)
    if addr is None:
        return None
    area, bank, word, bit = addr
    where = f"`{decl.name}` AT {decl.at}"
    if T.is_error(vt):
        return None
    if area == "A":
        ctx.diags.error(codes.AT_ADDRESS, f"{where}: the Auxiliary Area is not modelled by vplc", decl.name_span)
        return None
    layout = T.union_layout(vt)
    if layout is None:
        ctx.diags.error(codes.AT_ADDRESS,
                        f"{where}: a variable of type {vt.name} is not placed in a memory area by vplc "
                        "(BOOL, bit strings, integers, REAL/LREAL, TIME and one-dimensional arrays of them are)",
                        decl.name_span)
        return None
    is_bool = layout[0] == "bool"
    if is_bool and bit is None:
        ctx.diags.error(codes.AT_ADDRESS, f"{where}: a BOOL is placed at a bit of a word; write the bit "
                        f"(`{decl.at}.00`)", decl.name_span)
        return None
    if not is_bool and bit is not None:
        ctx.diags.error(codes.AT_ADDRESS, f"{where}: only a BOOL is placed at a bit; write the word "
                        f"(`{decl.at.split('.')[0]}`)", decl.name_span)
        return None
    if bit is not None and bit > 15:
        ctx.diags.error(codes.AT_ADDRESS, f"{where}: bit {bit} of a word; the bits are 00 to 15", decl.name_span)
        return None
    if area == "E" and bank >= EM_BANKS:
        ctx.diags.error(codes.AT_ADDRESS,
                        f"{where}: EM bank {bank:X}; the banks are 0 to {EM_BANKS - 1:X}", decl.name_span)
        return None
    kind, bits, count = layout
    span_bits = (bit or 0) + (count or 1) * (1 if is_bool else bits)
    last = word + -(-span_bits // 16) - 1
    if last >= AREA_WORDS[area]:
        ctx.diags.error(codes.AT_ADDRESS, f"{where}: reaches word {last} of the {area} area, which has "
                        f"{AREA_WORDS[area]} words (0 to {AREA_WORDS[area] - 1})", decl.name_span)
        return None
    ctx.note_edition3(f"AT {decl.at} (a Sysmac memory area)", decl.name_span)
    return area, bank, word, bit or 0, layout, AREA_WORDS[area]


def check_local(ctx: Context, decl: A.VarDecl) -> None:
    """vplc places global variables in memory areas; an AT of a Sysmac area on a POU's variable is refused."""
    if decl.at is not None and parse(decl.at) is not None:
        ctx.diags.error(codes.AT_ADDRESS,
                        f"`{decl.name}` AT {decl.at}: vplc places only global variables in memory areas; "
                        "declare it in VAR_GLOBAL (and VAR_EXTERNAL where it is used)", decl.name_span)
