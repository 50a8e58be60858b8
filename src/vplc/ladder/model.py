"""The ladder model both XML readers produce and every back end of a ladder reads (translation to ST,
drawing, live monitoring, export).

A POU body is a list of rungs; a rung is a graph of elements joined by connections. A connection goes
from an output point (an element and, for a block, the name of its output or in-out pin) to an input
point; several connections arriving at one input are a wired OR. Element kinds:

=============  =========================================================================================
left_rail      power source of a rung (always energised)
right_rail     power sink (connections into it only close the drawing)
contact        ``var``: normal, ``negated`` (NC), ``edge`` rising / falling (P / N contact)
coil           ``var``: normal, ``negated``, ``storage`` set / reset (S / R coil), ``edge`` rising / falling
block          function block instance (``instance`` set) or function call; pins in ``inputs``,
               ``inouts``, ``outputs``; an ``EN`` input makes the call conditional, ``ENO`` is its power out
in_var         ``var`` is an expression read by the rung (a variable or a literal)
out_var        ``var`` is a variable the rung writes
inout_var      ``var`` is read and written
jump           ``var`` is the label jumped to when the jump has power
label          ``var`` is the label name (marks the rung it stands in)
return         leaves the POU when it has power
=============  =========================================================================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

EDGES = ("none", "rising", "falling")
STORAGES = ("none", "set", "reset")


@dataclass
class Conn:
    """One wire arriving at an input point: from element ``ref`` (its output pin ``pin`` for a block)."""
    ref: str
    pin: str | None = None


@dataclass
class Pin:
    """A block pin, or the single input point of a simple element (``name`` "")."""
    name: str
    conns: list[Conn] = field(default_factory=list)
    negated: bool = False
    edge: str = "none"


@dataclass
class Element:
    id: str
    kind: str
    var: str = ""                   # operand, expression, label name
    negated: bool = False
    edge: str = "none"
    storage: str = "none"
    type_name: str = ""             # blocks
    instance: str = ""              # blocks: the FB instance; "" for a function
    inputs: list[Pin] = field(default_factory=list)
    inouts: list[Pin] = field(default_factory=list)
    outputs: list[Pin] = field(default_factory=list)
    pos: tuple[float, float] | None = None      # (x, y) as drawn by the IDE, when the file has it

    @property
    def power_in(self) -> Pin | None:
        """The input point of a simple element (contact, coil, variable, jump, return)."""
        return self.inputs[0] if self.inputs and self.kind != "block" else None

    def join_inouts_drawn_on_both_sides(self) -> str | None:
        """Read an input and an output of the same name as one in-out; the name of a negated or edge-detected
        one (which cannot be an in-out), else None.

        IEC 61131-3 draws a VAR_IN_OUT on both sides of the box, joined through it, and Omron's instruction
        pages draw their in-outs that way (W560 2-231, ``Inc``: ``InOut`` on the input and on the output side,
        ``Out`` the result; W560 is the NY-series manual of W502's instruction set). Hand-written and generated
        files list such a pin as an input and an output instead of an in-out. A POU's names are unique, so an
        output named like an input can only be the in-out's variable after the call; read as a result it
        would give the function's return value (``Inc``'s BOOL) to whatever the output feeds."""
        inout_names = {p.name.upper() for p in self.inouts}
        inputs = {p.name.upper(): p for p in self.inputs if p.name and p.name.upper() != "EN"}
        for out in list(self.outputs):
            key = out.name.upper()
            pin = inputs.get(key)
            if not key or pin is None or key in inout_names:
                continue
            if out.negated or pin.negated or pin.edge != "none":
                return out.name
            self.inputs.remove(pin)
            self.outputs.remove(out)
            self.inouts.append(Pin(pin.name, pin.conns))
            inout_names.add(key)
        return None

    def describe(self) -> str:
        """How diagnostics and the drawing name the element: ``contact Start``, ``block CBT_MoveAbsolute``."""
        if self.kind == "block":
            return f"block {self.type_name.split(chr(92))[-1]}"
        if self.kind == "inline_st":
            return "inline ST"
        noun = {"left_rail": "left power rail", "right_rail": "right power rail", "in_var": "variable",
                "out_var": "variable", "inout_var": "variable"}.get(self.kind, self.kind)
        return f"{noun} {self.var}".strip()


class WriteError(Exception):
    """A ladder element the target format cannot express (TC6 has no inline ST); the export reports it."""


@dataclass
class Rung:
    elements: list[Element]
    comment: str = ""
    label: str = ""                 # a label standing in this rung (jump target)


@dataclass
class LadderBody:
    """The ladder body of one POU."""
    pou: str
    rungs: list[Rung]
    path: str = ""                  # the XML file it was read from
    helpers: list[str] = field(default_factory=list)   # hidden BOOLs the translation declared (never exported)
