"""Frame codec of the TM Listen Node protocol (pure functions, no I/O).

Wire layout of one packet::

    $ HEADER , LENGTH , DATA , * CS CR LF
      |<------ XOR checksum range ------>|       CS = 2 hex digits of the XOR of every byte
                                                   strictly between '$' and '*'

DATA is length-delimited: exactly LENGTH bytes, it may contain ',' '*' '$' and CR LF.

``decode(buf)`` looks at the front of a receive buffer and returns ``(item, consumed)``:
consumed == 0 means "need more bytes", item is a ``Frame``, a ``Garbage`` (bytes skipped before a
'$') or a ``BadFrame`` carrying the CPERR code the robot answers with.
"""
from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass

from tmsim.limits import FRAME_DATA_MAX

HEADERS = frozenset({"TMSCT", "TMSTA", "CPERR"})
_MAX_HEADER = 8           # characters allowed before the first ',' (real headers have 5)
_MAX_LENGTH_FIELD = 20    # characters allowed in the LENGTH field

CPERR_PACKET = "01"
CPERR_CHECKSUM = "02"
CPERR_HEADER = "03"
CPERR_DATA = "04"
CPERR_NOT_IN_NODE = "F1"


@dataclass(frozen=True)
class Frame:
    header: str
    data: bytes
    raw: bytes


@dataclass(frozen=True)
class Garbage:
    raw: bytes


@dataclass(frozen=True)
class BadFrame:
    code: str          # CPERR code to answer with
    reason: str
    raw: bytes


def checksum(body: bytes) -> int:
    """XOR of all bytes of ``body`` (the bytes between '$' and '*').

    Folds the bytes as one big integer (halving its width each step) so long frames cost
    O(n log n) machine work instead of a Python loop per byte.
    """
    width = len(body)
    value = int.from_bytes(body, "little")
    while width > 1:
        half = (width + 1) // 2
        value = (value & ((1 << (8 * half)) - 1)) ^ (value >> (8 * half))
        width = half
    return value


def encode(header: str, data: bytes | str) -> bytes:
    """Build one packet; decimal length, upper-case checksum."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    body = header.encode("ascii") + b"," + str(len(data)).encode("ascii") + b"," + data + b","
    return b"$" + body + b"*" + f"{checksum(body):02X}".encode("ascii") + b"\r\n"


def parse_length(field: bytes) -> int | None:
    """Decimal, ``0x`` hexadecimal or ``0b`` binary length; None when not a valid non-negative number."""
    text = field.decode("ascii", "replace")
    try:
        if text[:2] in ("0x", "0X"):
            value = int(text[2:], 16) if text[2:] and all(c in "0123456789abcdefABCDEF" for c in text[2:]) else -1
        elif text[:2] in ("0b", "0B"):
            value = int(text[2:], 2) if text[2:] and all(c in "01" for c in text[2:]) else -1
        else:
            value = int(text) if text.isdigit() else -1
    except ValueError:
        return None
    return value if value >= 0 else None


def decode(buf: bytes | bytearray, headers: Collection[str] = HEADERS) -> tuple[Frame | Garbage | BadFrame | None, int]:
    """Decode the packet at the front of ``buf``; ``headers`` are the ones this port serves (the Ethernet
    Slave passes {"TMSVR"}, TMscript 2.24 §17.3); any other is a header error (CPERR 03).

    Resynchronisation: on a packet error only the leading '$' is consumed, so the rest of the
    bad packet is skipped as garbage up to the next '$'.
    """
    start = buf.find(b"$")
    if start < 0:
        return (Garbage(bytes(buf)), len(buf)) if buf else (None, 0)
    if start > 0:
        return Garbage(bytes(buf[:start])), start
    comma1 = buf.find(b",", 1, 2 + _MAX_HEADER)
    if comma1 < 0:
        if len(buf) >= 2 + _MAX_HEADER or buf.find(b"$", 1) > 0:
            return BadFrame(CPERR_PACKET, "header field too long or missing", bytes(buf[:1])), 1
        return None, 0
    comma2 = buf.find(b",", comma1 + 1, comma1 + 2 + _MAX_LENGTH_FIELD)
    if comma2 < 0:
        if len(buf) >= comma1 + 2 + _MAX_LENGTH_FIELD or buf.find(b"$", 1) > 0:
            return BadFrame(CPERR_PACKET, "length field missing or too long", bytes(buf[:1])), 1
        return None, 0
    length = parse_length(bytes(buf[comma1 + 1:comma2]))
    if length is None:
        return BadFrame(CPERR_PACKET, "length is not a non-negative number", bytes(buf[:1])), 1
    if length > FRAME_DATA_MAX:
        return BadFrame(CPERR_PACKET, f"length {length} exceeds the limit of {FRAME_DATA_MAX} bytes", bytes(buf[:1])), 1
    data_end = comma2 + 1 + length
    total = data_end + 6                       # ",*" + 2 checksum digits + CR LF
    if len(buf) < total:
        return None, 0
    tail = bytes(buf[data_end:total])
    if tail[:2] != b",*" or tail[4:] != b"\r\n":
        return BadFrame(CPERR_PACKET, "declared length does not match the data", bytes(buf[:1])), 1
    try:
        received = int(tail[2:4].decode("ascii"), 16)
    except (UnicodeDecodeError, ValueError):
        return BadFrame(CPERR_PACKET, "checksum is not two hex digits", bytes(buf[:1])), 1
    raw = bytes(buf[:total])
    if received != checksum(raw[1:data_end + 1]):
        return BadFrame(CPERR_CHECKSUM, "checksum mismatch", raw), total
    header = raw[1:comma1].decode("ascii", "replace")
    if header not in headers:
        return BadFrame(CPERR_HEADER, f"unknown header {header!r}", raw), total
    return Frame(header, raw[comma2 + 1:data_end], raw), total


def decode_all(buf: bytearray, headers: Collection[str] = HEADERS) -> list[Frame | Garbage | BadFrame]:
    """Decode every complete item at the front of ``buf`` and remove it from the buffer."""
    items: list[Frame | Garbage | BadFrame] = []
    while buf:
        item, used = decode(buf, headers)
        if item is None or not used:        # (decode gives an item exactly when it consumed bytes)
            break
        del buf[:used]
        items.append(item)
    return items
