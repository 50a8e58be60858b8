"""Generates every ErrorID text of the project from the one ErrorID table, errors.tsv (one fact, one home).

    python3 docs/library/make_error_tables.py           # rewrite the generated files
    python3 docs/library/make_error_tables.py --check   # exit 1 and name the files that are out of date

errors.tsv has one row per ErrorID: id (16#XXXX), name (ErrXxx: the name every WORD#16#XXXX literal of the
library's ST carries in a comment on its line, tests/lib/test_lib_error_table.py), raised_by, text (the
ErrorDescrip, <= 79 characters), cause, remedy (for the engineer: the FB pages and errors.md), operator (what the
operator does at the panel; it names screens and buttons, never a function block) and hmi ("alarm": the HMI server
raises an alarm when a command ends with it, unless a cause it already shows explains it; "message": a refused
start, nothing happened, the page's message line says it). Generated from it:
  lib/CBT_Commands_Lib/core/CBTi_ErrorText.st   the ST text function (decimal CASE labels, IEC 61131-3 Ed. 2
                                               has no based-number CASE labels; the hex ID in a comment)
  docs/library/errors.md                       the table between the BEGIN / END markers
  docs/library/CBT_*.md                        the "## ErrorIDs" section of every FB page; which IDs an FB
                                               raises is read from its page (ranges such as 16#3011..16#3015
                                               are expanded)
  src/cbt_hmi/pages/errors.json                              text, cause, remedy, operator remedy and alarm/message for
                                               the HMI (pages and the server's alarm system)
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
TABLE = HERE / "errors.tsv"
ST_FILE = ROOT / "lib" / "CBT_Commands_Lib" / "core" / "CBTi_ErrorText.st"
HMI_FILE = ROOT / "src" / "cbt_hmi" / "pages" / "errors.json"
COLUMNS = ["id", "name", "raised_by", "text", "cause", "remedy", "operator", "hmi"]
HMI_KINDS = ("alarm", "message")
FB_NAME = re.compile(r"\bCBT_\w+|\b(?:MoveAbsolute|MoveRelative|MoveCircle|ProgramControl|ProjectControl)\b")
ID = re.compile(r"16#[0-9A-F]{4}")
NAME = re.compile(r"Err[A-Z][A-Za-z0-9]{1,28}")
CODE = re.compile(r"16#([0-9A-F]{4})(?:\.\.16#([0-9A-F]{4}))?")
BEGIN = "<!-- BEGIN table generated from errors.tsv by make_error_tables.py -->"
END = "<!-- END table -->"
INTRO = ("Parameter errors (16#1xxx) are raised in the scan of the rising edge and nothing is sent. Every ErrorID "
         "of the library, with the layer it belongs to: [errors.md](errors.md).")
LAYERS = {"1": "parameter", "2": "connection", "3": "protocol", "4": "robot"}


class TableError(Exception):
    """errors.tsv is malformed; the message names the line and what is wrong."""


def load(path: Path = TABLE) -> dict[str, dict[str, str]]:
    """Reads and checks the table: {"16#XXXX": {column: value}}, in ascending ID order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    if not lines or lines[0].split("\t") != COLUMNS:
        raise TableError(f"{path.name}:1: the header must be the columns {' '.join(COLUMNS)}, tab separated")
    rows: dict[str, dict[str, str]] = {}
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split("\t")
        where = f"{path.name}:{number}"
        if len(fields) != len(COLUMNS):
            raise TableError(f"{where}: {len(fields)} fields, expected {len(COLUMNS)} separated by tabs")
        row = dict(zip(COLUMNS, (f.strip() for f in fields), strict=False))
        code = row["id"]
        if not ID.fullmatch(code) or code[3] not in LAYERS:
            raise TableError(f"{where}: id {code!r} is not 16#1xxx..16#4xxx with four upper-case hex digits")
        if code in rows:
            raise TableError(f"{where}: ErrorID {code} appears twice")
        if rows and int(code[3:], 16) < int(list(rows)[-1][3:], 16):
            raise TableError(f"{where}: ErrorID {code} is out of ascending order")
        for column in COLUMNS[1:]:
            if not row[column]:
                raise TableError(f"{where}: ErrorID {code} has no {column}")
            if "|" in row[column]:
                raise TableError(f"{where}: ErrorID {code}: '|' in {column} would break the docs table")
        if not NAME.fullmatch(row["name"]):
            raise TableError(f"{where}: ErrorID {code}: name {row['name']!r} is not Err followed by a capital "
                             "letter, letters and digits, at most 31 characters")
        twin = next((c for c, r in rows.items() if r["name"] == row["name"]), None)
        if twin:
            raise TableError(f"{where}: ErrorID {code}: name {row['name']} is already the name of {twin}")
        if row["hmi"] not in HMI_KINDS:
            raise TableError(f"{where}: ErrorID {code}: hmi is {row['hmi']!r}, expected alarm or message")
        named = FB_NAME.search(row["operator"])
        if named:
            raise TableError(f"{where}: ErrorID {code}: the operator text names the function block "
                             f"{named.group()}: say what to do at the panel instead")
        if len(row["text"]) > 79:
            raise TableError(f"{where}: ErrorID {code}: text is {len(row['text'])} characters, ErrorDescrip "
                             "holds 79 (STRING[80])")
        rows[code] = row
    return rows


def st_string(text: str) -> str:
    return "'" + text.replace("$", "$$").replace("'", "$'") + "'"


def st_function(rows: dict) -> str:
    out = ["(* The library's ErrorID texts (ErrorDescrip), generated from docs/library/errors.tsv by",
           "   docs/library/make_error_tables.py: edit the table, not this file. 16#1xxx parameter, 16#2xxx",
           "   connection, 16#3xxx protocol, 16#4xxx robot; docs/library/errors.md gives cause and remedy. *)",
           "FUNCTION CBTi_ErrorText : STRING[80]",
           "VAR_INPUT", "    ErrorID : WORD;", "END_VAR",
           "CASE WORD_TO_UINT(ErrorID) OF",
           "0: CBTi_ErrorText := '';"]
    out += [f"{int(code[3:], 16)}: (* {code} {row['name']} *) CBTi_ErrorText := {st_string(row['text'])};"
            for code, row in rows.items()]
    out += ["ELSE", "    CBTi_ErrorText := CONCAT('Unknown ErrorID 16#', WORD_TO_STRING(ErrorID));",
            "END_CASE;", "END_FUNCTION"]
    return "\n".join(out) + "\n"


def errors_md(rows: dict, text: str) -> str:
    if BEGIN not in text or END not in text:
        raise TableError(f"errors.md: the markers {BEGIN} and {END} are missing")
    table = ["| ErrorID | Name | Raised by | Description | Cause | Remedy |", "|---|---|---|---|---|---|"]
    table += [f"| {c} | {r['name']} | {r['raised_by']} | {r['text']} | {r['cause']} | {r['remedy']} |"
              for c, r in rows.items()]
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    return head + BEGIN + "\n" + "\n".join(table) + "\n" + END + tail


def codes_in(section: str, known: dict) -> list[str]:
    found = []
    for m in CODE.finditer(section):
        first = int(m.group(1), 16)
        last = int(m.group(2), 16) if m.group(2) else first
        found += [f"16#{n:04X}" for n in range(first, last + 1) if f"16#{n:04X}" in known]
    return sorted(set(found), key=lambda c: int(c[3:], 16))


def fb_page(page: Path, text: str, rows: dict) -> str:
    start = text.index("## ErrorIDs")
    end = text.find("\n## ", start + 1)
    end = len(text) if end < 0 else end + 1
    codes = codes_in(text[start:end], rows)
    if not codes:
        raise TableError(f"{page.name}: the ErrorIDs section names no ErrorID of errors.tsv")
    lines = ["## ErrorIDs", INTRO, "", "| ErrorID | Description | Cause | Remedy |", "|---|---|---|---|"]
    lines += [f"| {c} | {rows[c]['text']} | {rows[c]['cause']} | {rows[c]['remedy']} |" for c in codes]
    return text[:start] + "\n".join(lines) + "\n\n" + text[end:]


def hmi_json(rows: dict) -> str:
    table = {code: {"layer": LAYERS[code[3]], "text": r["text"], "cause": r["cause"], "remedy": r["remedy"],
                    "operator": r["operator"], "hmi": r["hmi"]} for code, r in rows.items()}
    return json.dumps(table, indent=1, ensure_ascii=False) + "\n"


def generated(rows: dict) -> dict[Path, str]:
    """Every generated file with the text it must have."""
    files = {ST_FILE: st_function(rows), HMI_FILE: hmi_json(rows)}
    md = HERE / "errors.md"
    files[md] = errors_md(rows, md.read_text(encoding="utf-8"))
    for page in sorted(HERE.glob("CBT_*.md")):
        files[page] = fb_page(page, page.read_text(encoding="utf-8"), rows)
    return files


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
        print("Out of date with docs/library/errors.tsv: " + ", ".join(stale)
              + " (run python3 docs/library/make_error_tables.py)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
