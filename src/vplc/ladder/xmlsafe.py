"""Parse an XML project file with the standard library only, safely.

The graphical exchange formats need no document type declaration, so any ``<!DOCTYPE`` or ``<!ENTITY``
is refused before the parser sees it: that rules out entity-expansion bombs ("billion laughs") and
external entities (file or network access) in one check. Files larger than ``MAX_BYTES`` are refused
before they are read whole. Namespaces are stripped from tag names after parsing; ``xsi:type`` stays
reachable with :func:`xsi_type`.
"""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET

from ..frontend.source import FileRefused, read_file_bytes

MAX_BYTES = 64 * 1024 * 1024
XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"
_DTD = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.I)


class XmlError(Exception):
    """The file is not a safe, well-formed XML document; ``offset`` is the character offset when known."""

    def __init__(self, message: str, offset: int = 0) -> None:
        super().__init__(message)
        self.offset = offset


def read(path: str) -> tuple[str, ET.Element]:
    """The decoded text and the namespace-free root element of ``path``; XmlError with the reason."""
    try:
        size = os.path.getsize(path)
        if size > MAX_BYTES:
            raise XmlError(f"the file is {size / 1048576:.0f} MiB; XML project files are limited to "
                           f"{MAX_BYTES // 1048576} MiB")
        data = read_file_bytes(path, MAX_BYTES)
    except OSError as exc:
        raise XmlError(f"cannot read the file: {exc.strerror or exc}") from None
    except FileRefused as exc:
        raise XmlError(f"the file {exc}") from None
    return parse_bytes(data)


def parse_bytes(data: bytes) -> tuple[str, ET.Element]:
    if len(data) > MAX_BYTES:
        raise XmlError(f"the document is larger than {MAX_BYTES // 1048576} MiB")
    found = _DTD.search(data)
    if found:
        what = found.group(1).decode().upper()
        raise XmlError(f"the document contains a <!{what} declaration; document type declarations and "
                       "entities are refused (they can expand without limit or read other files)",
                       _char_offset(data, found.start()))
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise XmlError(f"the file is not valid UTF-8 (invalid byte 0x{data[exc.start]:02X})") from None
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line, col = exc.position
        message = str(exc).split(":")[0]
        raise XmlError(f"not well-formed XML: {message}", _line_col_offset(text, line, col)) from None
    for el in root.iter():
        if isinstance(el.tag, str) and el.tag.startswith("{"):
            el.tag = el.tag.split("}", 1)[1]
    return text, root


def _char_offset(data: bytes, byte_offset: int) -> int:
    return len(data[:byte_offset].decode("utf-8", "replace"))


def _line_col_offset(text: str, line: int, col: int) -> int:
    offset = 0
    for _ in range(line - 1):
        nl = text.find("\n", offset)
        if nl < 0:
            return len(text)
        offset = nl + 1
    return min(offset + col, len(text))


def xsi_type(el: ET.Element) -> str:
    """``xsi:type`` without a namespace prefix (``smcext:LdSection`` -> ``LdSection``)."""
    return el.get(XSI_TYPE, "").split(":")[-1]


def text_of(el: ET.Element | None) -> str:
    """All text below ``el`` (a formatted text: plain, or XHTML paragraphs)."""
    if el is None:
        return ""
    return "".join(el.itertext()).strip()
