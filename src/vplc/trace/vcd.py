"""Value Change Dump (IEEE 1364) writer; timescale 1 ns. BOOL -> 1-bit wire, integers and bit strings -> n-bit
vectors, REAL/LREAL -> real, STRING and enumerations -> GTKWave string variables."""
from __future__ import annotations

import datetime


def _ident(i: int) -> str:
    chars = [chr(c) for c in range(33, 127)]
    out = ""
    i += 1
    while i:
        i, r = divmod(i - 1, len(chars))
        out = chars[r] + out
    return out


def _value(kind: str, bits: int, v, ident: str) -> str:
    if kind == "bool":
        return f"{1 if v else 0}{ident}"
    if kind == "real":
        return f"r{float(v)!r} {ident}"
    if kind in ("int", "bits"):
        return f"b{int(v) & ((1 << bits) - 1):b} {ident}"
    return f"s{str(v).replace(' ', '_') or '_'} {ident}"


def write_vcd(rec, filename: str) -> None:
    lines = [f"$date {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M:%S} UTC $end",
             "$version vplc virtual PLC $end", "$timescale 1ns $end", "$scope module plc $end"]
    for i, (p, (kind, bits)) in enumerate(zip(rec.paths, rec.kinds, strict=False)):
        vtype = {"bool": "wire", "int": "wire", "bits": "wire", "real": "real", "text": "string"}[kind]
        width = {"bool": 1, "int": bits, "bits": bits, "real": 64, "text": 1}[kind]
        lines.append(f"$var {vtype} {width} {_ident(i)} {p.replace(' ', '_')} $end")
    lines += ["$upscope $end", "$enddefinitions $end"]
    events: dict[int, list[str]] = {}
    for i, (kind, bits) in enumerate(rec.kinds):
        for t, v in rec.changes[i]:
            events.setdefault(t, []).append(_value(kind, bits, v, _ident(i)))
    for t in sorted(events):
        lines.append(f"#{t}")
        lines.extend(events[t])
    lines.append(f"#{rec.end_ns}")
    with open(filename, "w", encoding="ascii", errors="replace") as f:
        f.write("\n".join(lines) + "\n")
