"""Record chosen variables after every scan (only changes are stored)."""
from __future__ import annotations

from ..frontend import types as T


class Recorder:
    def __init__(self, plc, paths: list[str], labels: list[str] | None = None) -> None:
        self.plc = plc
        self.paths = paths
        self.labels = labels or paths            # row names of the SVG diagram
        self.kinds = []
        for p in paths:
            t = T.base_of(plc.type_of(p))                       # raises PathError for a bad path
            if isinstance(t, T.ElementaryType) and t.kind == "bool":
                self.kinds.append(("bool", 1))
            elif isinstance(t, T.ElementaryType) and t.kind == "real":
                self.kinds.append(("real", t.bits))
            elif isinstance(t, T.ElementaryType) and t.kind == "bit":
                self.kinds.append(("bits", t.bits))            # BYTE .. LWORD: drawn in 16# notation
            elif isinstance(t, T.ElementaryType):
                self.kinds.append(("int", t.bits))
            elif isinstance(t, (T.StringType, T.EnumType)):
                self.kinds.append(("text", 0))
            else:
                raise ValueError(f"{p} is a {t.name}; trace its elementary members instead")
        self.changes: list[list[tuple[int, object]]] = [[] for _ in paths]
        self.end_ns = 0

    def sample(self, now_ns: int | None = None) -> None:
        now = self.plc.now_ns if now_ns is None else now_ns
        for i, p in enumerate(self.paths):
            v = self.plc.read(p)
            ch = self.changes[i]
            if not ch or ch[-1][1] != v:
                ch.append((now, v))
        self.end_ns = now


def write_trace(rec: Recorder, filename: str, window: tuple[int, int] | None = None) -> None:
    """Write ``rec`` as VCD (``.vcd``) or SVG (``.svg``, only ``window`` if given), chosen by the extension."""
    from .svg import write_svg
    from .vcd import write_vcd
    low = filename.lower()
    if low.endswith(".vcd"):
        write_vcd(rec, filename)
    elif low.endswith(".svg"):
        write_svg(rec, filename, window)
    else:
        raise ValueError(f"trace file {filename!r} must end in .vcd or .svg")
