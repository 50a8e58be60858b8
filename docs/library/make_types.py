"""Generates the data-type reference and the HMI's parameter limits from the sources (one fact, one home).

    python3 docs/library/make_types.py           # rewrite the generated files
    python3 docs/library/make_types.py --check   # exit 1 and name the files that are out of date

Read: lib/CBT_Commands_Lib/types/*.st (every public structure and enumeration: members, types, comments) and
ranges.tsv, the one table of parameter ranges (one row per checked range: struct or FB, member, condition, min,
max or the allowed enumeration values, unit, the ErrorID the FB raises outside it; rows without an ErrorID only
document a unit). tests/lib/test_lib_ranges.py runs every row against the library's ST on the virtual PLC, so
the table cannot drift from what the FBs check.
Written:
  docs/library/types.md    member, type, range, unit and description of every structure; values of every enum
  src/cbt_hmi/pages/ranges.json          the same ranges per parameter and condition, for the HMI's limits and hints
"""
from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
TYPES_DIR = ROOT / "lib" / "CBT_Commands_Lib" / "types"
TABLE = HERE / "ranges.tsv"
DOC_FILE = HERE / "types.md"
HMI_FILE = ROOT / "src" / "cbt_hmi" / "pages" / "ranges.json"
COLUMNS = ["struct", "member", "when", "min", "max", "unit", "error"]

_COMMENT = re.compile(r"\(\*(.*?)\*\)", re.S)
_MEMBER = re.compile(r"(\w+)[ \t]*:[ \t]*([^;:=]+?)\s*(?::=\s*([^;]+))?;[ \t]*(?:\(\*(.*?)\*\))?", re.S)
_ENUM_VALUE = re.compile(r"(\w+)[ \t]*(?::=[ \t]*(\d+))?[ \t]*,?[ \t]*(?:\(\*(.*?)\*\))?", re.S)


class SourceError(Exception):
    """A type file or a table row the generator cannot read; the message names the file and line."""


@dataclass
class Member:
    name: str
    type: str
    comment: str
    init: str | None = None


@dataclass
class DataType:
    name: str
    kind: str                        # struct / enum
    header: str
    members: list[Member] = field(default_factory=list)


@dataclass
class Range:
    struct: str
    member: str
    when: dict[str, list[str]]
    low: float | None
    high: float | None
    allowed: list[str] | None
    unit: str
    error: str
    line: int


def _clean(text: str) -> str:
    return " ".join(text.split())


def read_type(path: Path) -> DataType:
    text = path.read_text(encoding="utf-8")
    head = _COMMENT.match(text.strip())
    header = _clean(head.group(1)) if head else ""
    m = re.search(r"\bTYPE\s+(\w+)\s*:\s*(STRUCT|\()(.*?)(END_STRUCT|\))\s*;\s*END_TYPE", text, re.S)
    if m is None:
        raise SourceError(f"{path}: expected one TYPE with a STRUCT or an enumeration")
    dt = DataType(m.group(1), "struct" if m.group(2) == "STRUCT" else "enum", header)
    body = m.group(3)
    item = _MEMBER if dt.kind == "struct" else _ENUM_VALUE
    pos, number = 0, 0
    while True:                                  # declarations, each with the comment after it (one or more lines)
        blank = re.compile(r"\s*").match(body, pos)
        pos = blank.end()
        if pos >= len(body):
            break
        if body.startswith("(*", pos):           # a comment on its own: a section title, not a member
            pos = body.index("*)", pos) + 2
            continue
        mm = item.match(body, pos)
        if mm is None:
            raise SourceError(f"{path}: cannot read {body[pos:].splitlines()[0].strip()!r}")
        pos = mm.end()
        if dt.kind == "struct":
            dt.members.append(Member(mm.group(1), _clean(mm.group(2)), _clean(mm.group(4) or ""), mm.group(3)))
        else:
            number = int(mm.group(2)) if mm.group(2) else number
            dt.members.append(Member(mm.group(1), str(number), _clean(mm.group(3) or "")))
            number += 1
    return dt


def read_types() -> list[DataType]:
    return [read_type(p) for p in sorted(TYPES_DIR.glob("*.st"))]


def _number(text: str) -> float | int:
    value = float(text)
    return int(value) if value.is_integer() else value


def read_ranges(path: Path = TABLE) -> list[Range]:
    lines = path.read_text(encoding="utf-8").splitlines()
    if not lines or lines[0].split("\t") != COLUMNS:
        raise SourceError(f"{path}:1: the header must be {' / '.join(COLUMNS)} (tab separated)")
    out = []
    for n, line in enumerate(lines[1:], 2):
        cells = line.split("\t")
        if len(cells) != len(COLUMNS):
            raise SourceError(f"{path}:{n}: {len(cells)} cells, expected {len(COLUMNS)}")
        struct, member, when, low, high, unit, error = cells
        conditions = {}
        if when != "*":
            for part in when.split(";"):
                key, _, values = part.partition("=")
                conditions[key.strip()] = [v.strip() for v in values.split(",")]
        allowed = None
        try:
            lo = _number(low) if low else None
        except ValueError:
            lo, allowed = None, low.split()
        hi = _number(high) if high else None
        if error and not re.fullmatch(r"16#[0-9A-F]{4}", error):
            raise SourceError(f"{path}:{n}: ErrorID {error!r} is not of the form 16#XXXX")
        out.append(Range(struct, member, conditions, lo, hi, allowed, unit, error, n))
    return out


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def range_text(r: Range) -> str:
    if r.allowed is not None:
        body = ", ".join(r.allowed)
    elif r.low is None:
        return ""
    else:
        body = f"{_fmt(r.low)}..{_fmt(r.high)}"
    when = "; ".join(f"{k} = {', '.join(v)}" for k, v in r.when.items())
    return f"{body} ({when})" if when else body


_ELEMENTARY = {"BOOL": "TRUE / FALSE", "USINT": "0..255", "UINT": "0..65535", "UDINT": "0..4294967295",
               "INT": "-32768..32767", "DINT": "-2147483648..2147483647", "BYTE": "16#00..16#FF",
               "WORD": "16#0000..16#FFFF", "REAL": "finite REAL", "LREAL": "finite LREAL"}


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _type_range(m: Member, by_name: dict[str, DataType]) -> str:
    t = m.type
    if t in _ELEMENTARY:
        return _ELEMENTARY[t]
    target = by_name.get(t)
    if target is not None and target.kind == "enum":
        return " / ".join(v.name for v in target.members)
    if target is not None:
        return f"see [{t}](#{t.lower()})"
    return "—"


def render_doc(types: list[DataType], ranges: list[Range]) -> str:
    by_name = {t.name: t for t in types}
    rows: dict[tuple[str, str], list[Range]] = {}
    for r in ranges:
        rows.setdefault((r.struct, r.member), []).append(r)
    out = ["# Data types of CBT_Commands_Lib", "",
           "<!-- generated by docs/library/make_types.py from lib/CBT_Commands_Lib/types/*.st and ranges.tsv: "
           "do not edit; run python3 docs/library/make_types.py -->", "",
           "Every public structure and enumeration of the library (`lib/CBT_Commands_Lib/types/`). *Range* is what "
           "the command FBs check (the ErrorID they raise outside it, see [errors.md](errors.md)), else the values "
           "the type allows; members of structures marked library internal are shared state, not to be written.",
           "", "## Structures", ""]
    for t in (t for t in types if t.kind == "struct"):
        out += [f"### {t.name}", "", _cell(t.header), "", "| Member | Type | Range | Unit | Description |",
                "|---|---|---|---|---|"]
        for m in t.members:
            own = rows.get((t.name, m.name), [])
            checked = [f"{range_text(r)} → {r.error}" if r.error else range_text(r) for r in own if range_text(r)]
            rng = "<br>".join(checked) or _type_range(m, by_name)
            unit = " / ".join(dict.fromkeys(r.unit for r in own if r.unit and r.unit != "—")) or "—"
            desc = m.comment + (f" (default {m.init.strip()})" if m.init else "")
            out.append(f"| {m.name} | {m.type} | {rng} | {unit} | {_cell(desc)} |")
        out.append("")
    out += ["## Enumerations", ""]
    for t in (t for t in types if t.kind == "enum"):
        out += [f"### {t.name}", "", t.header, "", "| Value | Number | Description |", "|---|---|---|"]
        out += [f"| {v.name} | {v.type} | {_cell(v.comment)} |" for v in t.members]
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def render_hmi(ranges: list[Range]) -> str:
    doc: dict[str, dict[str, list[dict]]] = {}
    for r in ranges:
        if not r.error:
            continue
        entry: dict = {"when": r.when, "unit": r.unit, "error": r.error}
        if r.allowed is not None:
            entry["allowed"] = r.allowed
        else:
            entry.update(min=r.low, max=r.high)
        doc.setdefault(r.struct, {}).setdefault(r.member, []).append(entry)
    head = {"_comment": "generated by docs/library/make_types.py from docs/library/ranges.tsv: do not edit"}
    return json.dumps({**head, **doc}, indent=1, ensure_ascii=False) + "\n"


def outputs() -> dict[Path, str]:
    types, ranges = read_types(), read_ranges()
    names = {t.name for t in types} | {p.stem for p in TYPES_DIR.parent.glob("CBT_*.st")}      # or an FB input
    for r in ranges:
        if r.struct not in names:
            raise SourceError(f"{TABLE}:{r.line}: no structure named {r.struct}")
        t = next((t for t in types if t.name == r.struct), None)
        if t is not None and r.member not in {m.name for m in t.members}:
            raise SourceError(f"{TABLE}:{r.line}: {r.struct} has no member {r.member}")
    return {DOC_FILE: render_doc(types, ranges), HMI_FILE: render_hmi(ranges)}


def main(argv: list[str]) -> int:
    try:
        files = outputs()
    except SourceError as exc:
        print(f"make_types: error: {exc}", file=sys.stderr)
        return 2
    stale = [p for p, text in files.items() if not p.exists() or p.read_text(encoding="utf-8") != text]
    if "--check" in argv:
        for p in stale:
            print(f"{p.relative_to(ROOT)} is out of date (run python3 docs/library/make_types.py)", file=sys.stderr)
        return 1 if stale else 0
    for p in stale:
        p.write_text(files[p], encoding="utf-8")
        print(f"wrote {p.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
