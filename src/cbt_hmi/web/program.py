"""Live ladder monitoring for the HMI's Program page, as Sysmac Studio's online monitoring shows it.

    GET /api/program                  {"ok", "programs": [{"pou", "instance", "svg", "rungs"}]}  the drawings (once);
                                      rungs: [{"number", "label", "comment"}], the whole comments
                                      (the drawing cuts long ones; the page wraps them and lists the rungs)
    GET /api/program/state?pou=NAME   {"ok", "on": [ids], "values": {variable text: value text}}

``on`` lists the drawn elements and wires that carry power in the current scan state: power is worked
out from the variable values the same way the translation does (contacts ``in AND var``, NC ``AND NOT``,
coils pass power on, a block's outputs are the instance's outputs, ENO follows EN). Edge contacts show
their variable, as Sysmac's monitor does. Only variables drawn in the ladder are read. Bit strings
(BYTE, WORD, DWORD, LWORD) are written in 16# notation, as Sysmac Studio's monitor and every other HMI page
show them (16390 reads 16#4006).
"""
from __future__ import annotations

import contextlib
from http import HTTPStatus

from vplc.api import PathError

from .mapping import format_dt


class ProgramError(Exception):
    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST):
        super().__init__(message)
        self.status = status


class LadderView:
    """One ladder POU running in the PLC: its drawing and how to read its variables."""

    def __init__(self, plc, program) -> None:
        """program: a vplc.api.LadderProgram of plc."""
        self.plc = plc
        self.name = program.name
        self.ladder = program.ladder
        self.instance = program.instance
        self.locals = program.own_names       # a VAR_EXTERNAL operand is read as the global it names
        self.svg = program.svg()
        names = set()
        for rung in self.ladder.rungs:
            for e in rung.elements:
                if e.kind in ("contact", "coil", "in_var", "out_var", "inout_var") and e.var:
                    names.add(e.var)
        self.names = sorted(names)
        self.types = {}
        for n in self.names:
            with contextlib.suppress(PathError, KeyError, ValueError, TypeError):
                self.types[n] = plc.var_type(self.path(n))

    def path(self, text: str) -> str:
        head = text.split(".", 1)[0].split("[", 1)[0].strip().upper()
        return f"{self.instance}.{text}" if head in self.locals else text

    def read(self, text: str) -> object:
        try:
            return self.plc.read(self.path(text))
        except (PathError, KeyError, ValueError, TypeError):
            return None

    def state(self) -> dict:
        with self.plc.lock:
            raw = {n: self.read(n) for n in self.names}
            on: list[str] = []
            for rung in self.ladder.rungs:
                on += self._rung_power(rung, raw)
        values = {n: _text(v, self.types.get(n)) for n, v in raw.items() if _text(v, self.types.get(n)) is not None}
        return {"ok": True, "on": sorted(set(on)), "values": values}

    def _rung_power(self, rung, raw) -> list[str]:
        by_id = {e.id: e for e in rung.elements}
        power: dict[tuple[str, str | None], bool] = {}
        on = []
        done: set[str] = set()

        def out(ref: str, pin: str | None) -> bool:
            src = by_id.get(ref)
            if src is None:
                return False
            if src.kind == "left_rail":
                return True
            if ref not in done:
                visit(src)
            return bool(power.get((ref, pin), power.get((ref, None), False)))

        def into(pin) -> bool:
            return any([out(c.ref, c.pin) for c in pin.conns])

        def visit(e) -> None:
            done.add(e.id)
            if e.kind == "contact":
                value = raw.get(e.var) is True
                power[(e.id, None)] = into(e.inputs[0]) and (not value if e.negated else value)
            elif e.kind == "coil":
                power[(e.id, None)] = into(e.inputs[0])
            elif e.kind == "in_var":
                power[(e.id, None)] = raw.get(e.var) is True
            elif e.kind == "block":
                en = next((p for p in e.inputs if p.name.upper() == "EN"), None)
                en_on = into(en) if en is not None and en.conns else True
                for p in e.inputs:
                    if p.name.upper() != "EN" and p.conns:
                        into(p)
                for p in e.outputs:
                    if p.name.upper() == "ENO":
                        power[(e.id, p.name)] = en_on
                    elif e.instance:
                        power[(e.id, p.name)] = self.read(f"{e.instance}.{p.name}") is True
                if en is not None and en.conns and en_on:     # a block with EN is lit while it runs
                    on.append(e.id)
            elif e.kind in ("out_var", "inout_var", "jump", "return") and e.inputs:
                power[(e.id, None)] = into(e.inputs[0])
            if power.get((e.id, None)):
                on.append(e.id)

        for e in rung.elements:
            if e.kind == "left_rail":
                on.append(e.id)                       # wires leaving the left rail always carry power
            elif e.id not in done and e.kind != "right_rail":
                visit(e)
        for (eid, pin), p in power.items():
            if p:
                on.append(eid if pin is None or by_id[eid].kind != "block" else f"{eid}:{pin}")
        return on


HEX_DIGITS = {"BYTE": 2, "WORD": 4, "DWORD": 8, "LWORD": 16}


def _text(v, type_name: str | None = None):
    if type_name in ("DATE_AND_TIME", "DT") and isinstance(v, int):
        return format_dt(v)
    if type_name in HEX_DIGITS and isinstance(v, int) and not isinstance(v, bool):
        return f"16#{v:0{HEX_DIGITS[type_name]}X}"
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, (int, float)):
        return f"{v:g}" if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return f"'{v}'" if len(v) <= 40 else f"'{v[:37]}...'"
    return None


class ProgramMonitor:
    """The ladder POUs of the running PLC (none: the page says so)."""

    def __init__(self, plc) -> None:
        self.views: dict[str, LadderView] = {}
        for program in plc.ladder_programs():
            self.views[program.name.upper()] = LadderView(plc, program)

    def page(self) -> dict:
        return {"ok": True, "programs": [{"pou": v.name, "instance": v.instance, "svg": v.svg,
                                          "rungs": [{"number": n, "label": r.label, "comment": r.comment}
                                                    for n, r in enumerate(v.ladder.rungs, start=1)]}
                                         for v in self.views.values()]}

    def state(self, pou: str) -> dict:
        view = self.views.get(pou.upper())
        if view is None:
            raise ProgramError(f"no ladder program named `{pou}` runs in this PLC", HTTPStatus.NOT_FOUND)
        return view.state()
