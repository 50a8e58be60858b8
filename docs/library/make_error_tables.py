"""Rewrites the "## ErrorIDs" section of every FB page in docs/library/ from the one ErrorID table, errors.md.

    python docs/library/make_error_tables.py           # rewrite the pages
    python docs/library/make_error_tables.py --check   # exit 1 and name the pages that are out of date

Which ErrorIDs an FB raises is read from its page (the ErrorID column of its table; ranges such as
16#3011..16#3015 are expanded on the first run); description, cause and remedy always come from errors.md, so
the two never disagree.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROW = re.compile(r"^\| (16#[0-9A-F]{4}) \| [^|]* \| ([^|]*) \| ([^|]*) \| ([^|]*) \|$")
CODE = re.compile(r"16#([0-9A-F]{4})(?:\.\.16#([0-9A-F]{4}))?")
INTRO = ("Parameter errors (16#1xxx) are raised in the scan of the rising edge and nothing is sent. Every ErrorID "
         "of the library, with the layer it belongs to: [errors.md](errors.md).")


def error_table() -> dict[str, tuple[str, str, str]]:
    rows = {}
    for line in (HERE / "errors.md").read_text(encoding="utf-8").splitlines():
        m = ROW.match(line)
        if m:
            rows[m.group(1)] = (m.group(2).strip(), m.group(3).strip(), m.group(4).strip())
    return rows


def codes_in(section: str, known: dict) -> list[str]:
    found = []
    for m in CODE.finditer(section):
        first = int(m.group(1), 16)
        last = int(m.group(2), 16) if m.group(2) else first
        found += [f"16#{n:04X}" for n in range(first, last + 1) if f"16#{n:04X}" in known]
    return sorted(set(found), key=lambda c: int(c[3:], 16))


def render(codes: list[str], known: dict) -> str:
    lines = ["## ErrorIDs", INTRO, "", "| ErrorID | Description | Cause | Remedy |", "|---|---|---|---|"]
    lines += [f"| {c} | {' | '.join(known[c])} |" for c in codes]
    return "\n".join(lines) + "\n\n"


def rewrite(page: Path, known: dict) -> str:
    text = page.read_text(encoding="utf-8")
    start = text.index("## ErrorIDs")
    end = text.find("\n## ", start + 1)
    end = len(text) if end < 0 else end + 1
    codes = codes_in(text[start:end], known)
    if not codes:
        raise SystemExit(f"{page.name}: the ErrorIDs section names no ErrorID of errors.md")
    return text[:start] + render(codes, known) + text[end:]


def main(argv: list[str]) -> int:
    check = "--check" in argv
    known = error_table()
    stale = []
    for page in sorted(HERE.glob("CBT_*.md")):
        new = rewrite(page, known)
        if new != page.read_text(encoding="utf-8"):
            stale.append(page.name)
            if not check:
                page.write_text(new, encoding="utf-8")
    if check and stale:
        print("ErrorID sections out of date with errors.md: " + ", ".join(stale)
              + " (run python docs/library/make_error_tables.py)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
