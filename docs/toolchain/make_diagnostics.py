"""Generates the named diagnostic codes and the docs table from the one table of codes (one fact, one home).

    python3 docs/toolchain/make_diagnostics.py           # rewrite the generated files
    python3 docs/toolchain/make_diagnostics.py --check   # exit 1 and name the files that are out of date

src/vplc/frontend/diagnostic_codes.tsv has one row per code: code (ST followed by four digits, ascending), name
(the constant every emitter uses: UPPER_CASE, unique), severity, meaning, failing (an example that gets the code)
and fixed (the same example corrected). A code kept free for a finding no longer emitted has the severity
`reserved`; it stays in the table so that it is never given another meaning. Generated from it:
  src/vplc/frontend/codes.py        one constant per code (`codes.UNDECLARED == "ST1001"`), imported by every
                                    module of vplc that emits or tests a code (no code is written as a literal)
  docs/toolchain/diagnostics.md     the table between the BEGIN / END markers
tests/vplc/frontend/test_fe_codes.py checks that both are up to date and that the table and the emitters agree.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
TABLE = ROOT / "src" / "vplc" / "frontend" / "diagnostic_codes.tsv"
CODES_PY = ROOT / "src" / "vplc" / "frontend" / "codes.py"
DOC = HERE / "diagnostics.md"
COLUMNS = ["code", "name", "severity", "meaning", "failing", "fixed"]
CODE = re.compile(r"ST[0-9]{4}")
NAME = re.compile(r"[A-Z][A-Z0-9_]{2,39}")
RESERVED = "reserved"
BEGIN = "<!-- BEGIN table generated from src/vplc/frontend/diagnostic_codes.tsv by make_diagnostics.py -->"
END = "<!-- END table -->"


class TableError(Exception):
    """diagnostic_codes.tsv is malformed; the message names the line and what is wrong."""


def load(path: Path = TABLE) -> dict[str, dict[str, str]]:
    """Reads and checks the table: {"ST0001": {column: value}}, in ascending code order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    if not lines or lines[0].split("\t") != COLUMNS:
        raise TableError(f"{path.name}:1: the header must be the columns {' '.join(COLUMNS)}, tab separated")
    rows: dict[str, dict[str, str]] = {}
    names: dict[str, str] = {}
    for number, line in enumerate(lines[1:], start=2):
        where = f"{path.name}:{number}"
        fields = line.split("\t")
        if len(fields) != len(COLUMNS):
            raise TableError(f"{where}: {len(fields)} fields, expected {len(COLUMNS)} separated by tabs")
        row = dict(zip(COLUMNS, (f.strip() for f in fields), strict=False))
        code, name = row["code"], row["name"]
        if not CODE.fullmatch(code):
            raise TableError(f"{where}: code {code!r} is not ST followed by four digits")
        if code in rows:
            raise TableError(f"{where}: code {code} appears twice")
        if rows and code < list(rows)[-1]:
            raise TableError(f"{where}: code {code} is out of ascending order")
        if not NAME.fullmatch(name):
            raise TableError(f"{where}: {code}: name {name!r} is not UPPER_CASE letters, digits and `_` (3 to 40)")
        if name in names:
            raise TableError(f"{where}: {code}: name {name} is already the name of {names[name]}")
        for column in COLUMNS[2:]:
            if not row[column]:
                raise TableError(f"{where}: {code} has no {column}")
            if "|" in row[column]:
                raise TableError(f"{where}: {code}: '|' in {column} would break the docs table")
        rows[code] = row
        names[name] = code
    return rows


def codes_module(rows: dict[str, dict[str, str]]) -> str:
    """The text of src/vplc/frontend/codes.py."""
    out = ['"""The diagnostic codes of vplc by name, generated from diagnostic_codes.tsv by',
           "docs/toolchain/make_diagnostics.py: edit the table and run the script, never this file.",
           "",
           "Every module that emits or tests a code uses these names (`codes.UNDECLARED`), never a literal; the",
           "meaning and the examples of each code are in docs/toolchain/diagnostics.md.",
           '"""', "from __future__ import annotations", ""]
    for code, row in rows.items():
        mark = "  # reserved: no longer emitted" if row["severity"] == RESERVED else ""
        out.append(f'{row["name"]} = "{code}"{mark}')
    out += ["", "# name -> code, in code order", "BY_NAME: dict[str, str] = {"]
    out += [f'    "{row["name"]}": {row["name"]},' for row in rows.values()]
    out += ["}", ""]
    return "\n".join(out)


def docs_table(rows: dict[str, dict[str, str]]) -> str:
    """The Markdown table that stands between the markers of diagnostics.md."""
    out = ["| Code | Severity | Meaning | Failing example | Fixed example |", "|---|---|---|---|---|"]
    for code, row in rows.items():
        out.append(f"| {code} | {row['severity']} | {row['meaning']} | {row['failing']} | {row['fixed']} |")
    return "\n".join(out)


def with_table(doc: str, table: str) -> str:
    """diagnostics.md with its generated table replaced; the prose around it is hand-written."""
    start, end = doc.find(BEGIN), doc.find(END)
    if start < 0 or end < start:
        raise TableError(f"{DOC.name}: the markers {BEGIN!r} and {END!r} are missing or out of order")
    return doc[:start + len(BEGIN)] + "\n" + table + "\n" + doc[end:]


def generated(rows: dict[str, dict[str, str]]) -> dict[Path, str]:
    """{file: its full text} for every generated file."""
    return {CODES_PY: codes_module(rows), DOC: with_table(DOC.read_text(encoding="utf-8"), docs_table(rows))}


def main(argv: list[str]) -> int:
    check = "--check" in argv
    try:
        files = generated(load())
    except TableError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    stale = []
    for path, text in files.items():
        current = path.read_text(encoding="utf-8") if path.exists() else None
        if text != current:
            stale.append(str(path.relative_to(ROOT)))
            if not check:
                path.write_text(text, encoding="utf-8")
    if check and stale:
        print("out of date (run python3 docs/toolchain/make_diagnostics.py): " + ", ".join(stale), file=sys.stderr)
        return 1
    for name in stale:
        print(f"wrote {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
