"""Variable access by path for the API, CLI and traces: ``Main.mover.Done``, ``GVL.Cobot.Connected``,
``Main.buf[3]``. Values cross the boundary as bool/int/float/str; structures as dicts, arrays as lists,
enumeration values as their name. Writes are type-checked."""
from __future__ import annotations

import re
from collections.abc import Callable, MutableMapping
from typing import Any, NamedTuple

from ..frontend import types as T
from . import iec


class PathError(ValueError):
    """Unknown variable path, wrong index or a value that does not fit the variable."""


_DUR = re.compile(r"^\s*(-?\d+(?:\.\d+)?)\s*(ns|us|µs|ms|s|m|h)\s*$", re.IGNORECASE)   # the unit is required
_UNIT = {"ns": 1, "us": 1_000, "µs": 1_000, "ms": 1_000_000, "s": 1_000_000_000, "m": 60_000_000_000,
         "h": 3_600_000_000_000}


def parse_duration(text: str) -> int | None:
    """'1ms', '500us', '2s', 'T#10ms' -> nanoseconds (None when not a duration; '5' alone is not one: 5 what?)."""
    t = text.strip()
    if t.upper().startswith("T#"):
        t = t[2:]
    m = _DUR.match(t)
    if not m:
        return None
    return int(float(m.group(1)) * _UNIT[m.group(2).lower()])


_SEG = re.compile(r"([A-Za-z_]\w*)((?:\[[^\]]*\])*)")


def type_text(t: T.Type) -> str:
    u = T.unalias(t) if not isinstance(t, T.AliasType) else t
    ns = getattr(u, "namespace", None)
    name = getattr(u, "qualified_name", None) or u.name
    return f"{ns}\\{u.name}" if ns and "\\" not in name else name


class Slot(NamedTuple):
    """Where a variable's runtime value lives: ``container[key]``, of the declared type ``type``."""

    container: MutableMapping[Any, Any]
    key: Any
    type: T.Type


class Resolver:
    """Reads and writes variables by path. A path is parsed once (names upper-cased, indexes read) and then only
    walked, and each type gets its value converter once: traces and the HMI read the same paths every scan."""

    def __init__(self, plc: Any) -> None:          # a vplc.api.Plc (the API sits above the runtime)
        self.plc = plc
        gl = plc.project.global_lists
        self.list_names = {g.name.upper() for g in gl if g.name}
        self._parsed: dict[str, tuple] = {}

    def _parse(self, path: str) -> tuple:
        """-> (root, steps): root "instance"/"globals" and its key, steps (segment text, NAME, index tuples)."""
        plan = self._parsed.get(path)
        if plan is not None:
            return plan
        segs = path.strip().split(".")
        if not segs or not segs[0]:
            raise PathError(f"empty variable path {path!r}")
        plc = self.plc
        first = _SEG.fullmatch(segs[0])
        if first is None:
            raise PathError(f"`{segs[0]}` is not a variable name (in {path!r})")
        head = first.group(1).upper()
        if head in plc.type_named_instances and not first.group(2):
            names = " and ".join(f"`{n}`" for n in plc.type_named_instances[head])
            tail = ".".join(segs[1:])
            example = f"{plc.type_named_instances[head][0]}.{tail}" if tail else plc.type_named_instances[head][0]
            raise PathError(f"`{segs[0]}` is a PROGRAM type; the configuration runs it as the instance {names}: "
                            f"use `{example}`")
        if head in plc.instances and not first.group(2):
            root, rest = head, segs[1:]
        elif head in self.list_names and not first.group(2) and len(segs) > 1:
            root, rest = None, segs[1:]
        else:
            root, rest = None, segs
        steps = []
        for seg in rest:
            m = _SEG.fullmatch(seg)
            if m is None:
                raise PathError(f"`{seg}` is not a variable name (in {path!r})")
            indexes = []
            for idx_text in re.findall(r"\[([^\]]*)\]", m.group(2)):
                try:
                    indexes.append(tuple(int(x) for x in idx_text.split(",")))
                except ValueError:
                    raise PathError(f"index [{idx_text}] is not a list of integers (in {path!r})") from None
            steps.append((seg, m.group(1).upper(), m.group(1), indexes))
        plan = (root, tuple(steps))
        if len(self._parsed) < 10_000:           # bounded: paths come from programs, traces and the HMI's table
            self._parsed[path] = plan
        return plan

    def _locate(self, path: str) -> tuple[Any, Any, T.Type]:
        """-> (container, key, type) of the variable at ``path``."""
        root, steps = self._parse(path)
        plc = self.plc
        obj = plc.instances[root] if root is not None else plc.globals
        container, key = None, None
        cur_t: T.Type | None = obj.i__type if root is not None else None
        for seg, name, shown, indexes in steps:
            value = obj if container is None else container[key]
            info = getattr(type(value), "i__vars", None)
            if info is None:
                raise PathError(f"`{seg}`: {path!r} goes into a value that has no members")
            ent = info.get(name)
            if ent is None:
                where = getattr(value, "i__path", None) or getattr(getattr(value, "i__type", None), "name", "value")
                raise PathError(f"`{shown}` is not a variable of {where} (in {path!r})")
            attr, step_t = ent
            # a union's members live in its memory image: it lends a mapping view of them (runtime/unions.py)
            container, key = getattr(value, "i__members", None) or value.__dict__, attr
            if key + "__r" in container:                 # scalar VAR_IN_OUT: follow the reference
                container, key = container[key + "__r"], container[key + "__k"]
            elif type(container) is dict and key not in container:     # (a union's view holds all members)
                external = self._external(value, name, shown, path)
                if external is not None:
                    container, key, step_t = external
            for idx in indexes:
                at = T.unalias(step_t)
                if not isinstance(at, T.ArrayType):
                    raise PathError(f"`{seg}` is not an array (in {path!r})")
                arr = container[key]
                try:
                    off = iec.ixo(idx[0], arr) if at.open else iec.ixn(idx, tuple(at.dims))
                except iec.RuntimeFaultError as exc:
                    raise PathError(f"{exc} (in {path!r})") from None
                container, key, step_t = arr, off, at.element
            cur_t = step_t
        if container is None or cur_t is None:        # (every step gives a type: no step, no variable)
            raise PathError(f"{path!r} names a program instance, not a variable")
        return container, key, cur_t

    def _external(self, value: Any, name: str, shown: str, path: str) -> tuple[Any, str, T.Type] | None:
        """A VAR_EXTERNAL of a program or FB instance is the global it names (W501, external variables:
        the POU uses the global itself, it holds no copy), so its path reaches that global: (container, key,
        type) of the global, None when ``name`` is not an external variable of ``value``'s POU."""
        if _section_of(getattr(value, "i__type", None), name) != "VAR_EXTERNAL":
            return None
        g = self.plc.globals
        ent = getattr(type(g), "i__vars", {}).get(name)
        if ent is None or not hasattr(g, ent[0]):
            where = getattr(value, "i__path", None) or "its instance"
            raise PathError(f"`{shown}` is a VAR_EXTERNAL of {where}, but no global variable `{shown}` exists "
                            f"(in {path!r})")
        return getattr(g, "i__members", None) or g.__dict__, ent[0], ent[1]

    def type_of(self, path: str) -> T.Type:
        """The declared type of the variable at ``path``; PathError for a path that names no variable."""
        return self._locate(path)[2]

    def lasting_slot(self, path: str) -> Slot | None:
        """The slot of a variable declared directly in a program instance or a global list (a program's
        VAR_EXTERNAL too: it is the global), which lives as long as the controller; None for anything deeper
        (members, array elements: an assignment may replace their containers). PathError for a bad path."""
        container, key, t = self._locate(path)
        root, steps = self._parse(path)
        plc = self.plc
        owner = plc.instances[root] if root is not None else plc.globals
        lasting = (getattr(owner, "__dict__", None), plc.globals.__dict__)
        if len(steps) == 1 and not steps[0][3] and any(container is d for d in lasting):
            return Slot(container, key, t)
        return None

    def read(self, path: str) -> Any:
        c, k, t = self._locate(path)
        try:
            return converter(t)(c[k])
        except KeyError:              # declared, but its instance holds no value: an error naming it, no traceback
            raise PathError(f"{path!r} holds no value the controller can read") from None

    def type_text(self, path: str) -> str:
        return type_text(self._locate(path)[2])

    def write(self, path: str, value: Any, raw: bool = False) -> None:
        c, k, t = self._locate(path)
        c[k] = from_python(value, t, path, raw)


def _section_of(pou_type: Any, name: str) -> str | None:
    """The section (VAR_EXTERNAL, VAR_TEMP, ...) declaring the upper-case ``name`` in a POU type, or None."""
    pou = getattr(pou_type, "pou", None)
    for sec in getattr(pou, "sections", ()):
        if any(d.name.upper() == name for d in sec.vars):
            return str(sec.kind)
    return None


_CONVERTERS: dict[int, tuple] = {}


def _same(v: Any) -> Any:
    return v


def converter(t: T.Type) -> Callable[[Any], Any]:
    """The function turning a runtime value of type ``t`` into its API value (built once per type)."""
    entry = _CONVERTERS.get(id(t))
    if entry is not None and entry[0] is t:
        return entry[1]
    u = T.base_of(t)
    conv: Callable[[Any], Any]
    if isinstance(u, T.EnumType):
        names: dict[int, str] = {}
        for name, val in u.values.items():
            names.setdefault(val, name)              # the first name declared for a value, as before

        def enum_name(v: Any, names: dict[int, str] = names) -> Any:
            return names.get(v, v)
        conv = enum_name
    elif isinstance(u, T.ArrayType):
        element = u.element

        def elements(v: Any, element: T.Type = element) -> list[Any]:
            each = converter(element)
            return [each(x) for x in v]
        conv = elements
    elif isinstance(u, (T.StructType, T.PouType)):
        def members(v: Any) -> dict[str, Any]:
            info = getattr(type(v), "i__vars", {})
            return {attr: converter(ft)(getattr(v, attr)) for attr, ft in info.values() if hasattr(v, attr)}
        conv = members
    else:
        conv = _same
    if len(_CONVERTERS) > 20_000:                # many programs loaded in one process (tests): start again
        _CONVERTERS.clear()
    _CONVERTERS[id(t)] = (t, conv)               # the type is kept, so its id cannot be reused
    return conv


WATCH_ELEMENTS = 32          # array elements written out in PLC notation; the rest is counted


def plc_text(t: T.Type) -> Callable[[Any], str]:
    """The function writing an API value of type ``t`` (what ``read`` returns) in PLC notation: TRUE/FALSE, bit
    strings in 16#, enumerations by name, durations as T#..., arrays as [a, b, ...] and structures and instances
    as (Member := value, ...). Strings are written as they are at the top level and quoted inside a value."""
    return _text(t, top=True)


def _text(t: T.Type, top: bool = False) -> Callable[[Any], str]:
    u = T.base_of(t)
    if isinstance(u, T.ElementaryType):
        if u.kind == "bool":
            return lambda v: "TRUE" if v else "FALSE"
        if u.kind == "bit":
            bits = u.bits
            return lambda v: T.bits_literal(v, bits) if isinstance(v, int) else str(v)
        if u.kind in ("time", "ltime"):
            return lambda v: duration_literal(v) if isinstance(v, int) else str(v)
        if u.kind == "real":
            return real_literal
        return str
    if isinstance(u, T.StringType):
        return str if top else (lambda v: "'" + str(v).replace("$", "$$").replace("'", "$'") + "'")
    if isinstance(u, T.ArrayType):
        each = _text(u.element)

        def array(v: Any) -> str:
            shown = [each(x) for x in v[:WATCH_ELEMENTS]]
            if len(v) > WATCH_ELEMENTS:
                shown.append(f"… {len(v) - WATCH_ELEMENTS} more")
            return "[" + ", ".join(shown) + "]"
        return array
    if isinstance(u, T.StructType):
        members = [(f.name, _text(f.type)) for f in u.fields.values()]
    elif isinstance(u, T.PouType) and u.pou is not None:
        members = [(d.name, _text(d.sym.type)) for s in u.pou.sections if s.kind in INSTANCE_VISIBLE
                   for d in s.vars if getattr(d, "sym", None) is not None]
    else:
        return str

    def struct(v: Any) -> str:
        if not isinstance(v, dict):
            return str(v)
        parts = []
        for name, text in members:
            key = name if name in v else name + "_"          # members named like a Python keyword get a "_"
            if key in v:
                parts.append(f"{name} := {text(v[key])}")
        return "(" + ", ".join(parts) + ")"
    return struct


INSTANCE_VISIBLE = ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR")


def real_literal(v: Any) -> str:
    """A REAL / LREAL with six significant digits that still reads as a real: 0.0, 1.5, 1e+10, -2.5e-07."""
    if not isinstance(v, float):
        return str(v)
    text = f"{v:.6g}"
    return text if any(c in text for c in ".eni") else text + ".0"


def duration_literal(ns: int) -> str:
    """T#... of a duration in nanoseconds, in the largest unit that keeps it short: T#1.5s, T#-5ms, T#0s."""
    if not ns:
        return "T#0s"
    sign, a = ("-" if ns < 0 else ""), abs(ns)
    for unit, scale in (("s", 10**9), ("ms", 10**6), ("us", 10**3)):
        if a >= scale:
            return f"T#{sign}{a / scale:g}{unit}"
    return f"T#{sign}{a}ns"


def from_python(value: Any, t: T.Type, path: str, raw: bool = False) -> Any:
    """Checked conversion of an API value; ``raw`` lets an enumeration take any integer of its storage
    type, declared or not (what an HMI or a memory copy can put there on the controller)."""
    u = T.base_of(t)
    tn = type_text(t)
    bad = PathError(f"cannot write {value!r} to {path} of type {tn}")
    if isinstance(u, T.EnumType) and raw:
        if isinstance(value, bool) or not isinstance(value, int):
            raise PathError(f"a raw write to {path} ({tn}) takes an integer, not {value!r}")
        return from_python(value, u.base, path)
    if isinstance(u, T.EnumType):
        if isinstance(value, str):
            name = u.lookup(value.split("#")[-1])
            if name is None:
                raise PathError(f"{value!r} is not a value of {tn} (values: {', '.join(u.values)})")
            return u.values[name]
        if isinstance(value, int) and not isinstance(value, bool) and value in u.values.values():
            return value
        raise bad
    if isinstance(u, T.StringType):
        if not isinstance(value, str):
            raise bad
        if len(value) > u.capacity:
            raise PathError(f"{value!r} has {len(value)} characters; {path} ({tn}) holds at most {u.capacity}")
        return value
    if isinstance(u, T.ElementaryType):
        if u.kind == "bool":
            if not isinstance(value, bool):
                raise bad
            return value
        if u.kind == "real":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise bad
            return iec.f32(float(value)) if u.bits == 32 else float(value)
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad
        lo, hi = (u.lo, u.hi) if u.lo is not None else (-(1 << 63), (1 << 63) - 1)
        sub = T.unalias(t)
        if isinstance(sub, T.SubrangeType):
            lo, hi = sub.lo, sub.hi
        if not lo <= value <= hi:
            raise PathError(f"{value} is outside the range {lo}..{hi} of {path} ({tn})")
        return value
    raise PathError(f"{path} is a {tn}; write its elementary members one by one")
