"""Variable access by path for the API, CLI and traces: ``Main.mover.Done``, ``GVL.Cobot.Connected``,
``Main.buf[3]``. Values cross the boundary as bool/int/float/str; structures as dicts, arrays as lists,
enumeration values as their name. Writes are type-checked."""
from __future__ import annotations

import re

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


def type_text(t) -> str:
    u = T.unalias(t) if not isinstance(t, T.AliasType) else t
    ns = getattr(u, "namespace", None)
    name = getattr(u, "qualified_name", None) or u.name
    return f"{ns}\\{u.name}" if ns and "\\" not in name else name


class Resolver:
    def __init__(self, plc) -> None:
        self.plc = plc
        gl = plc.project.global_lists
        self.list_names = {g.name.upper() for g in gl if g.name}

    def _locate(self, path: str):
        """-> (container, key, type) of the variable at ``path``."""
        segs = path.strip().split(".")
        if not segs or not segs[0]:
            raise PathError(f"empty variable path {path!r}")
        plc = self.plc
        first = _SEG.fullmatch(segs[0])
        if first is None:
            raise PathError(f"`{segs[0]}` is not a variable name (in {path!r})")
        head = first.group(1).upper()
        obj, ty, rest = None, None, segs
        if head in plc.type_named_instances and not first.group(2):
            names = " and ".join(f"`{n}`" for n in plc.type_named_instances[head])
            tail = ".".join(segs[1:])
            example = f"{plc.type_named_instances[head][0]}.{tail}" if tail else plc.type_named_instances[head][0]
            raise PathError(f"`{segs[0]}` is a PROGRAM type; the configuration runs it as the instance {names}: "
                            f"use `{example}`")
        if head in plc.instances and not first.group(2):
            obj, ty, rest = plc.instances[head], plc.instances[head].i__type, segs[1:]
        elif head in self.list_names and not first.group(2) and len(segs) > 1:
            obj, ty, rest = plc.globals, None, segs[1:]
        else:
            obj, ty = plc.globals, None
        container, key, cur_t = None, None, ty
        for seg in rest:
            m = _SEG.fullmatch(seg)
            if m is None:
                raise PathError(f"`{seg}` is not a variable name (in {path!r})")
            value = obj if container is None else container[key]
            info = getattr(type(value), "i__vars", None)
            if info is None:
                raise PathError(f"`{seg}`: {path!r} goes into a value that has no members")
            ent = info.get(m.group(1).upper())
            if ent is None:
                where = getattr(value, "i__path", None) or getattr(getattr(value, "i__type", None), "name", "value")
                raise PathError(f"`{m.group(1)}` is not a variable of {where} (in {path!r})")
            attr, cur_t = ent
            container, key = value.__dict__, attr
            if key + "__r" in container:                 # scalar VAR_IN_OUT: follow the reference
                container, key = container[key + "__r"], container[key + "__k"]
            for idx_text in re.findall(r"\[([^\]]*)\]", m.group(2)):
                at = T.unalias(cur_t)
                if not isinstance(at, T.ArrayType):
                    raise PathError(f"`{seg}` is not an array (in {path!r})")
                try:
                    idx = tuple(int(x) for x in idx_text.split(","))
                except ValueError:
                    raise PathError(f"index [{idx_text}] is not a list of integers (in {path!r})") from None
                arr = container[key]
                try:
                    off = iec.ixo(idx[0], arr) if at.open else iec.ixn(idx, tuple(at.dims))
                except iec.RuntimeFaultError as exc:
                    raise PathError(f"{exc} (in {path!r})") from None
                container, key, cur_t = arr, off, at.element
        if container is None:
            raise PathError(f"{path!r} names a program instance, not a variable")
        return container, key, cur_t

    def read(self, path: str):
        c, k, t = self._locate(path)
        return to_python(c[k], t)

    def type_text(self, path: str) -> str:
        return type_text(self._locate(path)[2])

    def write(self, path: str, value, raw: bool = False) -> None:
        c, k, t = self._locate(path)
        c[k] = from_python(value, t, path, raw)


def to_python(v, t):
    u = T.base_of(t)
    if isinstance(u, T.EnumType):
        for name, val in u.values.items():
            if val == v:
                return name
        return v
    if isinstance(u, T.ArrayType):
        return [to_python(x, u.element) for x in v]
    if isinstance(u, (T.StructType, T.PouType)):
        info = getattr(type(v), "i__vars", {})
        return {attr: to_python(getattr(v, attr), ft) for attr, ft in info.values() if hasattr(v, attr)}
    return v


def from_python(value, t, path: str, raw: bool = False):
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
        if isinstance(T.unalias(t), T.SubrangeType):
            lo, hi = T.unalias(t).lo, T.unalias(t).hi
        if not lo <= value <= hi:
            raise PathError(f"{value} is outside the range {lo}..{hi} of {path} ({tn})")
        return value
    raise PathError(f"{path} is a {tn}; write its elementary members one by one")
