"""Turn what an XML file declares into Structured Text the front end parses, checks and compiles like any
``.st`` file; ladder bodies become ST statements in the documented LD evaluation order
(docs/toolchain/ladder.md):

* rungs run top to bottom; in a rung, elements run in power-flow order (an element after everything
  wired into it), elements that do not depend on each other top to bottom, left to right;
* a contact passes power ``in AND var`` (NC: ``AND NOT var``; P / N contacts: on the change of ``var``
  since the rung's previous evaluation); wires meeting at one input are an OR;
* a coil writes its power to ``var`` (negated, set, reset, P / N coils as IEC 61131-3 defines them) and
  passes it on unchanged;
* a block is called once; with an ``EN`` input only while EN has power (its outputs then keep their
  values); ``ENO`` carries EN's power;
* a jump with power skips the rungs down to its label; RETURN with power leaves the POU.

Hidden helper variables (edge memories, shared power of a branch point, jump flags) are BOOLs named
``_ld…`` in an extra VAR section. The text carries regions: every diagnostic inside a region is reported
as ``file:POU:rung N:element`` instead of a line of the generated text.
"""
from __future__ import annotations

import heapq

from ..frontend import codes
from ..frontend.source import SourceFile
from .decls import FormatError, PouText, SectionText, XmlUnit
from .model import Conn, Element, LadderBody, Pin, Rung

TRUE = "TRUE"
SERIES_MARKS = 128        # marked ranges in one series expression before a helper variable carries its power on
COMPARE = {"GT": ">", "GE": ">=", "EQ": "=", "LT": "<", "LE": "<=", "NE": "<>"}   # IEC comparison blocks
# Sysmac names its comparison and arithmetic blocks by their symbols (W502 2-87, 2-89: `=`, `<>`, `<`, `<=`, `>`,
# `>=`; `+`, `-`, `*`, `/`): the same instructions as IEC's EQ ... DIV
SYMBOL_BLOCKS = {"=": "EQ", "<>": "NE", "<": "LT", "<=": "LE", ">": "GT", ">=": "GE", "+": "ADD", "-": "SUB",
                 "*": "MUL", "/": "DIV"}


class LadderSource(SourceFile):
    """The ST text generated from an XML file; ``where(offset)`` names the XML element behind it."""

    __slots__ = ("regions", "statements", "checks", "ladders", "errors", "layouts")

    def __init__(self, path: str, text: str, regions=(), statements=(), checks=(), ladders=(), errors=()) -> None:
        super().__init__(path, text)
        self.errors = errors            # FormatError of each rung that could not be translated (reported by load)
        self.layouts: dict = {}         # structure name (upper) -> Sysmac offsetType other than NJ, kept for export
        self.regions = regions          # (start, end, label), any order
        self.statements = statements    # (start, end) of each generated statement
        self.checks = checks            # (start, end, label, operand): contact operands that must be BOOL
        self.ladders = ladders          # LadderBody of every LD POU of the text

    def where(self, offset: int) -> str:
        best = None
        for start, end, label in self.regions:
            if start <= offset < end and (best is None or end - start < best[1] - best[0]):
                best = (start, end, label)
        return best[2] if best else "declarations"


class Txt:
    """Generated text with marked sub-ranges ``(start, end, label)``; ``prec`` is 3 atom, 2 AND, 1 OR."""

    __slots__ = ("text", "marks", "prec")

    def __init__(self, text: str, marks=(), prec: int = 3) -> None:
        self.text = text
        self.marks = list(marks)
        self.prec = prec

    def __add__(self, other: Txt | str) -> Txt:
        if isinstance(other, str):
            return Txt(self.text + other, self.marks, min(self.prec, 3))
        n = len(self.text)
        return Txt(self.text + other.text, self.marks + [(s + n, e + n, lab) for s, e, lab in other.marks])

    def __radd__(self, other: str) -> Txt:
        n = len(other)
        return Txt(other + self.text, [(s + n, e + n, lab) for s, e, lab in self.marks])

    def marked(self, label: str) -> Txt:
        return Txt(self.text, self.marks + [(0, len(self.text), label)], self.prec)

    def at_least(self, prec: int) -> Txt:
        return self if self.prec >= prec else ("(" + self + ")").with_prec(3)

    def with_prec(self, prec: int) -> Txt:
        self.prec = prec
        return self


def _joined(parts: list[Txt], sep: str, prec: int) -> Txt:
    """``parts`` joined by ``sep`` in one pass (adding them one by one would copy the text once per part)."""
    texts: list[str] = []
    marks: list[tuple[int, int, str]] = []
    n = 0
    for i, t in enumerate(parts):
        if i:
            texts.append(sep)
            n += len(sep)
        texts.append(t.text)
        marks.extend((s + n, e + n, lab) for s, e, lab in t.marks)
        n += len(t.text)
    return Txt("".join(texts), marks, prec)


class Writer:
    """Accumulates the ST text of one XML unit with its regions."""

    def __init__(self) -> None:
        self.parts: list[str] = []
        self.size = 0
        self.regions: list[tuple[int, int, str]] = []
        self.statements: list[tuple[int, int]] = []
        self.checks: list[tuple[int, int, str, str]] = []

    def put(self, text: Txt | str, label: str | None = None, statement: bool = False) -> None:
        t = text if isinstance(text, Txt) else Txt(text)
        base = self.size
        for s, e, lab in t.marks:
            if lab.startswith("check:"):
                _, operand, where = lab.split(":", 2)
                self.checks.append((base + s, base + e, where, operand))
            else:
                self.regions.append((base + s, base + e, lab))
        if label is not None:
            self.regions.append((base, base + len(t.text), label))
        if statement:
            self.statements.append((base, base + len(t.text)))
        self.parts.append(t.text)
        self.size += len(t.text)

    def text(self) -> str:
        return "".join(self.parts)


def unit_source(path: str, unit: XmlUnit) -> LadderSource:
    w = Writer()
    ladders, errors = [], []
    for t in unit.types:
        init = f" := {t.init}" if t.init is not None else ""
        w.put(f"TYPE\n{_comment(t.comment)}{t.name} : {t.spec}{init};\nEND_TYPE\n\n", f"data type {t.name}")
    if unit.globals:
        for section in unit.globals:
            _section(w, section, "global variables")
        w.put("\n")
    functions = {p.name.upper(): _function_outputs(p) for p in unit.pous if p.kind == "FUNCTION"}
    for pou in unit.pous:
        errors += _pou(w, pou, functions)
        if pou.ladder is not None:
            pou.ladder.path = path
            ladders.append(pou.ladder)
    src = LadderSource(path, w.text(), w.regions, w.statements, w.checks, ladders, errors)
    src.layouts = {t.name.upper(): t.offset_type for t in unit.types if t.offset_type != "NJ"}
    return src


def _comment(text: str) -> str:
    return f"(* {text.replace('(*', '( *').replace('*)', '* )')} *)\n" if text else ""


def _section(w: Writer, s: SectionText, owner: str) -> None:
    quals = (" CONSTANT" if s.constant else "") + (" RETAIN" if s.retain else "")
    w.put(f"{s.kind}{quals}\n")
    for v in s.vars:
        at = f" AT {v.at}" if v.at else ""
        init = f" := {v.init}" if v.init is not None else ""
        w.put(f"    {v.name}{at} : {v.type}{init};", f"{owner}:variable {v.name}")
        w.put(f" {_comment(v.comment)}" if v.comment else "\n")
    w.put("END_VAR\n")


def _function_outputs(pou: PouText) -> dict[str, str]:
    """Output name (upper; ``""`` for the result) -> declared type of a FUNCTION of the unit."""
    outs = {v.name.upper(): v.type for s in pou.sections if s.kind == "VAR_OUTPUT" for v in s.vars}
    if pou.return_type:
        outs[""] = pou.return_type
    return outs


def _pou(w: Writer, pou: PouText, functions: dict[str, dict[str, str]] | None = None) -> list[FormatError]:
    """Write one POU; returns the wiring errors of its rungs (each rung with one is left out of the ST text)."""
    errors = []
    w.put(_comment(pou.comment))
    head = f"{pou.kind} {pou.name}" + (f" : {pou.return_type}" if pou.return_type else "")
    w.put(head + "\n", f"{pou.name}")
    for s in pou.sections:
        _section(w, s, pou.name)
    if pou.ladder is not None:
        names = {v.name.upper() for s in pou.sections for v in s.vars}
        compiler = RungCompiler(w, pou, names, functions or {})
        compiler.body(pou.ladder)
        errors = compiler.errors
    else:
        w.put((pou.st_body or "") + "\n", f"{pou.name}:ST body")
    w.put(f"END_{pou.kind}\n\n")
    return errors


def _error(where: str, message: str, code: str) -> FormatError:
    return FormatError(where, message, code)


class RungCompiler:
    """Compiles the rungs of one POU; collects the hidden variables it needs."""

    def __init__(self, w: Writer, pou: PouText, names: set[str],
                 functions: dict[str, dict[str, str]] | None = None) -> None:
        self.w = w
        self.pou = pou.name
        self.functions = functions or {}      # output types of the unit's own functions (typed carriers)
        self.hidden_types: dict[str, str] = {}      # helper name -> its type when not BOOL
        prefix = "_ld"
        while any(n.startswith(prefix.upper()) for n in names):
            prefix += "x"
        self.prefix = prefix
        self.hidden: list[str] = []
        self.lines: list[tuple] = []          # (Txt | str, label | None, statement)
        self.errors: list[FormatError] = []   # every rung's wiring errors, not only the first

    def new(self, kind: str, type_name: str | None = None) -> str:
        name = f"{self.prefix}{kind}{len(self.hidden) + 1}"
        self.hidden.append(name)
        if type_name is not None:
            self.hidden_types[name] = type_name
        return name

    def emit(self, text, label: str | None = None, indent: str = "") -> None:
        self.lines.append((indent + text if isinstance(text, Txt) else indent + text, label))

    # ---- the body ---------------------------------------------------------------------------
    def body(self, ladder: LadderBody) -> None:
        labels: dict[str, int] = {}
        for n, rung in enumerate(ladder.rungs):
            if rung.label:
                if rung.label.upper() in labels:
                    self.errors.append(_error(f"{self.pou}:rung {n + 1}", f"label `{rung.label}` is defined twice",
                                              codes.LADDER_BAD_JUMP))
                labels.setdefault(rung.label.upper(), n)
        self.jump_flags: dict[int, str] = {}
        for n, rung in enumerate(ladder.rungs):
            for el in rung.elements:
                if el.kind == "jump":
                    target = labels.get(el.var.upper())
                    where = f"{self.pou}:rung {n + 1}:jump {el.var}"
                    if target is None:
                        self.errors.append(_error(where, f"jump to label `{el.var}`, which no rung of {self.pou} "
                                                         "has", codes.LADDER_BAD_JUMP))
                    elif target <= n:
                        self.errors.append(_error(where, f"jump back to label `{el.var}` (rung {target + 1}); a "
                                                         "jump may only skip rungs below it, so a scan always ends",
                                                  codes.LADDER_BAD_JUMP))
                    else:
                        self.jump_flags[id(el)] = self.new("J")
        for flag in self.jump_flags.values():
            self.emit(f"{flag} := FALSE;\n")
        flags_by_rung: dict[int, list[str]] = {}
        for n, rung in enumerate(ladder.rungs):
            for el in rung.elements:
                if id(el) in self.jump_flags:
                    flag = self.jump_flags[id(el)]
                    target = labels[el.var.upper()]
                    for skipped in range(n + 1, target):
                        flags_by_rung.setdefault(skipped, []).append(flag)
        for n, rung in enumerate(ladder.rungs):
            guard = flags_by_rung.get(n)
            if rung.comment:
                self.emit(f"(* rung {n + 1}: {rung.comment.replace('(*', '( *').replace('*)', '* )')} *)\n")
            if guard:
                self.emit(f"IF NOT ({' OR '.join(guard)}) THEN\n")
            self.rung(rung, n + 1, "    " if guard else "")
            if guard:
                self.emit("END_IF;\n")
        w = self.w
        ladder.helpers = list(self.hidden)
        if self.hidden:
            w.put("VAR (* ladder helper variables *)\n")
            for name in self.hidden:
                w.put(f"    {name} : {self.hidden_types.get(name, 'BOOL')};\n", f"{self.pou}:ladder helper variables")
            w.put("END_VAR\n")
        for text, label in self.lines:
            w.put(text, label, statement=label is not None)

    # ---- one rung ---------------------------------------------------------------------------
    def rung(self, rung: Rung, number: int, indent: str) -> None:
        """Translate one rung. Its wiring errors are collected (every missing or wrong connection, and a loop
        among the rest), not only the first; a rung with one is replaced by checks of its contacts' and coils'
        operands, so an undeclared or non-BOOL variable in it is still reported."""
        self.where = f"{self.pou}:rung {number}"
        self.indent = indent
        self.by_id = {e.id: e for e in rung.elements}
        self.out: dict[tuple[str, str | None], Txt] = {}
        self.guard: dict[str, Txt] = {}
        consumers: dict[tuple[str, str | None], int] = {}
        readers: dict[tuple[str, str | None], list[tuple[Element, Pin]]] = {}
        deps: dict[str, set[str]] = {e.id: set() for e in rung.elements}
        users: dict[str, list[str]] = {e.id: [] for e in rung.elements}
        problems: list[FormatError] = []
        for e in rung.elements:
            if e.kind in ("left_rail", "right_rail"):
                continue
            for pin in [*e.inputs, *e.inouts]:
                for c in pin.conns:
                    src = self.by_id.get(c.ref)
                    try:
                        if src is None:
                            raise _error(f"{self.where}:{e.describe()}",
                                         f"input `{pin.name or 'power'}` is connected to element "
                                         f"{c.ref.lstrip('?')}, which is not in this rung",
                                         codes.LADDER_MISSING_CONNECTION)
                        if src.kind == "right_rail":
                            raise _error(f"{self.where}:{e.describe()}", "a wire starts at the right power rail",
                                         codes.LADDER_MISSING_CONNECTION)
                        key = (src.id, self._pin_name(src, c, e))
                    except FormatError as exc:
                        problems.append(exc)
                        continue
                    consumers[key] = consumers.get(key, 0) + 1
                    readers.setdefault(key, []).append((e, pin))
                    if src.kind != "left_rail":
                        deps[e.id].add(src.id)
                        users[src.id].append(e.id)
        self.consumers = consumers
        self.readers = readers
        self.carried: set[int] = set()        # output-variable elements a function call writes directly
        order, stuck = self._order(rung, deps, users)
        if stuck:
            problems.append(_error(self.where, "the rung is wired in a loop (" + ", ".join(stuck[:6])
                                   + "); power must flow from the left rail to the right without coming back",
                                   codes.LADDER_LOOP))
        mark, hidden = len(self.lines), len(self.hidden)
        bad_jump = any(e.kind == "jump" and id(e) not in self.jump_flags for e in rung.elements)   # reported above
        if not problems and not bad_jump:
            try:
                for eid in order:
                    self.element(self.by_id[eid])
                return
            except FormatError as exc:
                problems.append(exc)
                del self.lines[mark:], self.hidden[hidden:]
        self.errors.extend(problems)
        for e in rung.elements:
            if e.kind in ("contact", "coil") and e.var:
                lab = self.label(e)
                var = Txt(e.var, [(0, len(e.var), f"check:{e.kind}:{lab}")]).marked(lab)
                self.stmt("IF FALSE THEN " + self.new("C") + " := " + var + "; END_IF;", lab)

    @staticmethod
    def _order(rung: Rung, deps: dict, users: dict) -> tuple[list[str], list[str]]:
        """Evaluation order of the elements (power flow, then top to bottom and left to right as drawn) and the
        elements left over because they are wired in a loop."""
        index = {e.id: i for i, e in enumerate(rung.elements)}
        rank = {e.id: ((e.pos[1], e.pos[0]) if e.pos else (0.0, 0.0), index[e.id]) for e in rung.elements}
        waiting = {k: len(v) for k, v in deps.items()}
        ready = [(rank[k], k) for k, n in waiting.items() if n == 0]
        heapq.heapify(ready)
        order = []
        while ready:
            _, eid = heapq.heappop(ready)
            order.append(eid)
            for u in users[eid]:
                waiting[u] -= 1
                if waiting[u] == 0:
                    heapq.heappush(ready, (rank[u], u))
        by_id = {e.id: e for e in rung.elements}
        return order, [by_id[k].describe() for k, n in waiting.items() if n > 0]

    def _pin_name(self, src: Element, c: Conn, user: Element) -> str | None:
        if src.kind != "block":
            return None
        names = [p.name for p in src.outputs] + [p.name for p in src.inouts]
        if c.pin is None:
            first = next((p.name for p in src.outputs if p.name.upper() != "ENO"), None)
            if first is None:
                raise _error(f"{self.where}:{user.describe()}", f"is wired to {src.describe()}, which has no output",
                             codes.LADDER_MISSING_CONNECTION)
            return first
        if c.pin.upper() not in (n.upper() for n in names):
            raise _error(f"{self.where}:{user.describe()}",
                         f"is wired to output `{c.pin}` of {src.describe()}, which has no such pin",
                         codes.LADDER_MISSING_CONNECTION)
        return next(n for n in names if n.upper() == c.pin.upper())

    def label(self, e: Element) -> str:
        return f"{self.where}:{e.describe()}"

    def source(self, e: Element, c: Conn) -> Txt:
        src = self.by_id[c.ref]
        if src.kind == "left_rail":
            return Txt(TRUE)
        pin = self._pin_name(src, c, e)
        if src.id in self.guard and (pin or "").upper() != "ENO" and e.kind not in ("out_var", "inout_var"):
            raise _error(self.label(e), f"reads the result of {src.describe()}, a function with EN; wire the "
                                        "result to a variable and read the variable", codes.LADDER_FUNCTION_WIRING)
        value = self.out.get((src.id, pin))
        if value is None:
            raise _error(self.label(e), f"is wired to {src.describe()}, which has no output to read",
                         codes.LADDER_MISSING_CONNECTION)
        return value

    def power(self, e: Element, pin: Pin | None) -> Txt:
        if pin is None or not pin.conns:
            raise _error(self.label(e), "nothing is connected to its input" if pin is None or pin.name == "" else
                         f"input `{pin.name}` is not connected", codes.LADDER_MISSING_CONNECTION)
        terms = [self.source(e, c) for c in pin.conns]
        if any(t.text == TRUE for t in terms):
            return Txt(TRUE)
        if len(terms) == 1:
            return terms[0]
        return _joined([t.at_least(2) for t in terms], " OR ", 1)

    def materialize(self, value: Txt, kind: str = "P") -> Txt:
        if value.text == TRUE or (value.prec == 3 and value.text.startswith(self.prefix)):
            return value
        name = self.new(kind)
        self.stmt(name + " := " + value + ";")
        return Txt(name)

    def stmt(self, text: Txt | str, label: str | None = None) -> None:
        self.emit((text if isinstance(text, Txt) else Txt(text)) + "\n", label or self.where, self.indent)

    def shared(self, e: Element, value: Txt, pin: str | None = None) -> Txt:
        """An output read by several elements is evaluated once."""
        return self.materialize(value) if self.consumers.get((e.id, pin), 0) > 1 else value

    # ---- elements ---------------------------------------------------------------------------
    def element(self, e: Element) -> None:
        getattr(self, "el_" + e.kind)(e)

    def el_left_rail(self, e: Element) -> None:
        pass

    def el_right_rail(self, e: Element) -> None:
        pass

    def el_contact(self, e: Element) -> None:
        inp = self.power(e, e.power_in)
        lab = self.label(e)
        var = Txt(e.var, [(0, len(e.var), f"check:contact:{lab}")]).marked(lab)
        if e.edge != "none":
            mem = self.new("M")
            test = (var + " AND NOT " + mem) if e.edge == "rising" else ("NOT " + var + " AND " + mem)
            value = test if inp.text == TRUE else inp.at_least(2) + " AND " + test
            out = self.new("P")
            self.stmt(out + " := " + value + ";", lab)
            self.stmt(mem + " := " + var + ";", lab)
            self.out[(e.id, None)] = Txt(out)
            return
        op = ("NOT " + var).with_prec(3) if e.negated else var
        if len(inp.marks) > SERIES_MARKS:      # a long series of contacts: carried on by a helper every ~60
            inp = self.materialize(inp)        # contacts, so no expression (and no copy of one) grows with it
        value = op if inp.text == TRUE else (inp.at_least(2) + " AND " + op).with_prec(2)
        self.out[(e.id, None)] = self.shared(e, value.marked(lab))

    def el_coil(self, e: Element) -> None:
        lab = self.label(e)
        inp = self.power(e, e.power_in)
        if self.consumers.get((e.id, None), 0) or e.edge != "none":
            inp = self.materialize(inp)
        var = Txt(e.var).marked(lab)
        if e.edge != "none":
            mem = self.new("M")
            test = (inp + " AND NOT " + mem) if e.edge == "rising" else ("NOT " + inp + " AND " + mem)
            self.stmt(var + " := " + test + ";", lab)
            self.stmt(mem + " := " + inp + ";", lab)
        elif e.storage != "none":
            value = "TRUE" if e.storage == "set" else "FALSE"
            if inp.text == TRUE:
                self.stmt(var + f" := {value};", lab)
            else:
                self.stmt("IF " + inp + " THEN " + var + f" := {value}; END_IF;", lab)
        elif e.negated:
            self.stmt(var + " := NOT " + inp.at_least(3) + ";", lab)
        else:
            self.stmt(var + " := " + inp + ";", lab)
        self.out[(e.id, None)] = inp

    def el_in_var(self, e: Element) -> None:
        lab = self.label(e)
        value = Txt(e.var).marked(lab)
        self.out[(e.id, None)] = ("NOT " + value.at_least(3)).marked(lab) if e.negated else value

    def el_out_var(self, e: Element) -> None:
        lab = self.label(e)
        if id(e) in self.carried:              # the function call wrote the variable itself
            if e.kind == "inout_var":
                self.out[(e.id, None)] = Txt(e.var).marked(lab)
            return
        value = self.power(e, e.power_in)
        var = Txt(e.var).marked(lab)
        line = var + " := " + (("NOT " + value.at_least(3)) if e.negated else value) + ";"
        conns = e.power_in.conns if e.power_in is not None else []
        guards = {self.guard[c.ref].text: self.guard[c.ref] for c in conns if c.ref in self.guard}
        if guards:
            line = "IF " + " OR ".join(guards) + " THEN " + line + " END_IF;"
        self.stmt(line, lab)
        if e.kind == "inout_var":
            self.out[(e.id, None)] = var

    def el_inout_var(self, e: Element) -> None:
        if e.power_in is not None and e.power_in.conns:
            self.el_out_var(e)
        else:
            self.el_in_var(e)

    def el_inline_st(self, e: Element) -> None:
        """Sysmac's inline ST: its statements run while the rung gives the element power; the power goes on
        unchanged to what is wired after it."""
        lab = self.label(e)
        inp = self.power(e, e.power_in)
        if self.consumers.get((e.id, None), 0):
            inp = self.materialize(inp)
        body = Txt(e.var).marked(lab)
        self.stmt(body if inp.text == TRUE else "IF " + inp + " THEN\n" + body + "\nEND_IF;", lab)
        self.out[(e.id, None)] = inp

    def el_jump(self, e: Element) -> None:
        lab = self.label(e)
        self.stmt(self.jump_flags[id(e)] + " := " + self.power(e, e.power_in) + ";", lab)

    def el_return(self, e: Element) -> None:
        lab = self.label(e)
        inp = self.power(e, e.power_in)
        self.stmt("RETURN;" if inp.text == TRUE else "IF " + inp + " THEN RETURN; END_IF;", lab)

    def comparison(self, e: Element, values: list[Txt], lab: str) -> Txt:
        """GT, GE, EQ, LT, LE, NE blocks are ST operators: ``IN1 > IN2 AND IN2 > IN3 ...``."""
        if len(values) < 2:
            raise _error(lab, f"a {e.type_name.upper()} block needs at least two connected inputs",
                         codes.LADDER_MISSING_CONNECTION)
        op = COMPARE[e.type_name.upper()]
        terms = [("(" + a + f" {op} " + b + ")") for a, b in zip(values, values[1:], strict=False)]
        out = terms[0]
        for t in terms[1:]:
            out = out + " AND " + t
        return out.with_prec(3 if len(terms) == 1 else 2).marked(lab)

    def el_block(self, e: Element) -> None:
        lab = self.label(e)
        e.type_name = SYMBOL_BLOCKS.get(e.type_name.strip(), e.type_name)
        en = None
        args: list[Txt] = []
        values: list[Txt] = []
        for pin in e.inputs:
            if pin.name.upper() == "EN":
                en = self.power(e, pin) if pin.conns else None
                continue
            if not pin.conns:
                continue
            value = self.power(e, pin)
            if pin.negated:
                value = "NOT " + value.at_least(3)
            if pin.edge != "none":
                mem = self.new("M")
                value = self.materialize(value)
                edge = (value + " AND NOT " + mem) if pin.edge == "rising" else ("NOT " + value + " AND " + mem)
                out = self.new("P")
                self.stmt(out + " := " + edge + ";", lab)
                self.stmt(mem + " := " + value + ";", lab)
                value = Txt(out)
            args.append(pin.name + " := " + value)
            values.append(value)
        inouts = {}
        for pin in e.inouts:
            if pin.conns:
                value = self.power(e, pin)
                inouts[pin.name] = value
                args.insert(len(inouts) - 1, pin.name + " := " + value)
        if en is not None and en.text != TRUE and self.consumers.get((e.id, "ENO"), 0):
            en = self.materialize(en)
        call_args = Txt("")
        for i, a in enumerate(args):
            call_args = call_args + (", " if i else "") + a
        for pin in e.outputs:
            if pin.name.upper() == "ENO":
                self.out[(e.id, pin.name)] = en if en is not None else Txt(TRUE)
        for name, value in inouts.items():
            self.out[(e.id, name)] = value
        if not e.instance:
            self.function(e, en, call_args, values, lab)
            return
        call = (e.instance + "(" + call_args + ");").marked(lab)
        if en is None or en.text == TRUE:
            self.stmt(call, lab)
        else:
            self.stmt("IF " + en + " THEN " + call + " END_IF;", lab)
        for pin in e.outputs:
            if pin.name.upper() != "ENO":
                value = Txt(f"{e.instance}.{pin.name}")      # the wire belongs to the element reading it
                self.out[(e.id, pin.name)] = ("NOT " + value).with_prec(3) if pin.negated else value

    # ---- functions --------------------------------------------------------------------------
    POWER_READERS = frozenset({"contact", "coil", "jump", "return", "inline_st"})

    def function(self, e: Element, en: Txt | None, call_args: Txt, values: list[Txt], lab: str) -> None:
        """A function box. Its result read by one element is an expression in that element (``Q := F(..)``,
        ``IF F(..) AND ...``). Sysmac also wires a function like a function block (W502: each output pin of the
        box is a wire): its result to several elements, its other outputs, its result behind EN to a contact.
        The function is then called once, in its place in the power flow, and each wired output lands in a
        carrier the readers read: an output variable wired to it (written by the call itself), a BOOL helper
        when only contacts, coils and other power readers read it, or a helper of the output's declared type
        for a function of the same file."""
        result = next((p for p in e.outputs if p.name.upper() != "ENO"), None)
        wired = [p for p in e.outputs if p.name.upper() != "ENO" and self.consumers.get((e.id, p.name), 0)]
        guarded = en is not None and en.text != TRUE
        simple = all(p is result for p in wired) and (
            result is None or self.consumers.get((e.id, result.name), 0) <= 1 and not (
                guarded and any(r.kind not in ("out_var", "inout_var")
                                for r, _pin in self.readers.get((e.id, result.name), []))))
        if not wired and any(pin.conns for pin in e.inouts) and e.type_name.upper() not in COMPARE:
            # nothing reads an output, but the function works on an in-out (W502 Inc, ClearString, AryMove ...):
            # the box runs where the rung gives it power, its result discarded
            call = (e.type_name + "(" + call_args + ");").marked(lab)
            self.stmt(("IF " + en + " THEN " + call + " END_IF;") if guarded and en is not None else call, lab)
            return
        if simple:
            if result is not None:
                call = (self.comparison(e, values, lab) if e.type_name.upper() in COMPARE
                        else (e.type_name + "(" + call_args + ")").marked(lab))
                self.out[(e.id, result.name)] = ("NOT " + call) if result.negated else call
                if guarded and en is not None:
                    self.guard[e.id] = en
            return
        carriers = {p.name: self._carrier(e, p, p is result, lab) for p in wired}
        extra = [f"{p.name} => {carriers[p.name]}" for p in wired if p is not result]
        if e.type_name.upper() in COMPARE:
            call = self.comparison(e, values, lab)
        else:
            sep = ", " if call_args.text and extra else ""
            call = (e.type_name + "(" + call_args + sep + ", ".join(extra) + ")").marked(lab)
        line = (carriers[result.name] + " := " + call + ";") if result is not None and result.name in carriers \
            else call + ";"
        self.stmt(("IF " + en + " THEN " + line + " END_IF;") if guarded and en is not None else line, lab)
        for p in wired:
            value = Txt(carriers[p.name])
            self.out[(e.id, p.name)] = ("NOT " + value).with_prec(3) if p.negated else value

    def _carrier(self, e: Element, pin: Pin, is_result: bool, lab: str) -> str:
        readers = self.readers.get((e.id, pin.name), [])
        if not pin.negated:
            for r, _rpin in readers:
                if r.kind in ("out_var", "inout_var") and not r.negated and id(r) not in self.carried:
                    self.carried.add(id(r))
                    return r.var
        if all(r.kind in self.POWER_READERS or (r.kind == "block" and rpin.name.upper() == "EN")
               for r, rpin in readers):
            return self.new("F")
        declared = self.functions.get(e.type_name.upper(), {}).get("" if is_result else pin.name.upper())
        if declared is not None and not pin.negated:
            return self.new("V", declared)
        reader = next(r for r, rpin in readers if r.kind not in self.POWER_READERS)
        raise _error(lab, f"output `{pin.name}` of the function feeds {reader.describe()} but no variable; wire it "
                          "to a variable as well (vplc cannot tell the type of a helper for the output of a "
                          f"function declared elsewhere)", codes.LADDER_FUNCTION_WIRING)
