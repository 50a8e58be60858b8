"""Buffer sizes have one home each (issue 22 step 7): a size is written where the buffer is declared (its ARRAY
or STRING bound) and, where code needs it, once per POU as a VAR CONSTANT that equals the bound of the type
owning it; no statement of the library repeats a buffer size as a bare literal. IEC 61131-3 2nd edition and Sysmac
Studio take only literals as bounds, and a Sysmac library has no global constants (docs/library/design.md)."""
import re

import pytest
from rig import LIB, ROOT

COMMENT = re.compile(r"\(\*.*?\*\)|//[^\n]*|'(?:\$.|[^'$])*'", re.S)     # comments and texts
BLOCK = re.compile(r"^\s*(VAR\w*(?:\s+CONSTANT)?|TYPE)\b(.*?)^\s*END_(?:VAR|TYPE)\b", re.S | re.M)
BYTES = re.compile(r"ARRAY\s*\[\s*0\s*\.\.\s*(\d+)\s*\]\s*OF\s+BYTE", re.I)
STRING = re.compile(r"STRING\s*\[\s*(\d+)\s*\]", re.I)
NUMBER = re.compile(r"(?<![\w#.])\d+(?![\w#.])")
CONSTANT = re.compile(r"^\s*(\w+)\s*:\s*\w+\s*:=\s*(\d+)\s*;", re.M)

# every size constant of the library, with the declaration that owns its value: (file, member, kind, offset)
OWNERS = {
    "BUF_SIZE": ("types/stCBT_ByteBuffer.st", "Bytes", BYTES, 1),    # ARRAY[0..4095]: 4096 bytes
    "RCV_SIZE": ("platform/CBTi_SocketIO.st", "RcvTmp", BYTES, 1),
    "FRAME_DATA": ("core/CBTi_RouteFrame.st", "Data", STRING, 0),
    "SVR_CMD": ("types/stCBT_Connection.st", "SvrCmd", STRING, -1),  # STRING[401]: 400 characters and the mark
}


def source(path):
    return COMMENT.sub(" ", path.read_text(encoding="utf-8"))


def files():
    return sorted(LIB.rglob("*.st"))


def sizes():
    """Every buffer size the library declares: byte arrays of 256 bytes or more, strings of 400 characters or
    more (both the count and the last index, which code compares as often)."""
    found = set()
    for path in files():
        text = source(path)
        found |= {int(n) + k for n in BYTES.findall(text) if int(n) >= 255 for k in (0, 1)}
        found |= {int(n) - k for n in STRING.findall(text) if int(n) >= 400 for k in (0, 1)}
    return found


def body(text):
    """The statements: the text without its declaration blocks and the bounds of a function's result type."""
    return STRING.sub(" ", BYTES.sub(" ", BLOCK.sub(" ", text)))


def bound(file, member, kind, offset):
    text = source(LIB / file)
    m = re.search(rf"\b{member}\s*:\s*([^;]*);", text)
    assert m, f"{file} declares no {member}"
    return int(kind.search(m.group(1)).group(1)) + offset


def test_the_library_declares_its_buffers():
    assert {4096, 2048, 420, 400} <= sizes()


def test_no_statement_repeats_a_buffer_size():
    known = sizes()
    found = [f"{path.relative_to(ROOT)}: {n}" for path in files() for n in NUMBER.findall(body(source(path)))
             if int(n) in known]
    assert found == [], "use the POU's VAR CONSTANT sized from the owning type instead of the literal"


def constants():
    for path in files():
        for block in BLOCK.finditer(source(path)):
            if block.group(1).split()[-1].upper() == "CONSTANT":
                for name, value in CONSTANT.findall(block.group(2)):
                    yield path, name, int(value)


def test_every_size_constant_equals_the_bound_of_its_owner():
    known = sizes()
    seen = [(path, name, value) for path, name, value in constants() if value in known]
    assert {name for _, name, _ in seen} == set(OWNERS)
    wrong = [f"{path.relative_to(ROOT)}: {name} = {value}, owner {OWNERS[name][0]} says {bound(*OWNERS[name])}"
             for path, name, value in seen if value != bound(*OWNERS[name])]
    assert wrong == []


@pytest.mark.parametrize("name", sorted(OWNERS))
def test_each_owner_declares_the_size(name):
    assert bound(*OWNERS[name]) in sizes()
