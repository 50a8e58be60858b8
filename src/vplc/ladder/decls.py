"""What an XML project file declares, as Structured Text pieces both readers fill in and
:mod:`vplc.ladder.translate` turns into one ST text the front end parses.

Readers convert each XML type reference and initial value to its ST spelling (``STRING[80]``,
``ARRAY[0..9] OF INT``, ``(X := 1.0)``), so the checker sees exactly what a ``.st`` file would declare.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..frontend import codes
from .model import Element, LadderBody


@dataclass
class VarText:
    name: str
    type: str
    init: str | None = None
    comment: str = ""
    at: str | None = None


@dataclass
class SectionText:
    kind: str                       # VAR, VAR_INPUT, ... as in ST
    vars: list[VarText] = field(default_factory=list)
    constant: bool = False
    retain: bool = False


@dataclass
class TypeText:
    name: str
    spec: str                       # ST text after ``Name :``
    init: str | None = None
    comment: str = ""
    offset_type: str = "NJ"         # Sysmac's member layout of a structure (StructTypeSpecAdditionalProperties)


@dataclass
class PouText:
    kind: str                       # PROGRAM | FUNCTION_BLOCK | FUNCTION
    name: str
    return_type: str | None = None
    sections: list[SectionText] = field(default_factory=list)
    st_body: str | None = None
    ladder: LadderBody | None = None
    comment: str = ""


@dataclass
class XmlUnit:
    """The declarations of one namespace of an XML file (None: the global namespace)."""
    namespace: str | None
    types: list[TypeText] = field(default_factory=list)
    pous: list[PouText] = field(default_factory=list)
    globals: list[SectionText] = field(default_factory=list)


class FormatError(Exception):
    """The XML is well formed but describes something we cannot run; ``where`` names the place, ``code`` is
    the diagnostic code (docs/toolchain/diagnostics.md, ST21xx)."""

    def __init__(self, where: str, message: str, code: str = codes.LADDER_UNKNOWN_ELEMENT) -> None:
        super().__init__(f"{where}: {message}" if where else message)
        self.where = where
        self.message = message
        self.code = code


def join_inouts(e: Element, where: str) -> None:
    """Both readers: a block's input and output of the same name are its in-out (``Element``'s method says why);
    a negated or edge-detected one is refused at ``where``."""
    bad = e.join_inouts_drawn_on_both_sides()
    if bad is not None:
        raise FormatError(where, f"in-out `{bad}` (an input and an output of the same name) is negated or "
                                 "edge-detected; an in-out passes the variable itself")
