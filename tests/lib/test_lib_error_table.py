"""The one ErrorID table (docs/library/errors.tsv): the files generated from it are up to date, the library raises
only ErrorIDs of the table and names each literal after its row in a comment on its line, every row has a cause and
a remedy, and the ST text function compiled on the virtual PLC returns exactly the table's text for every ID."""
import json
import re
import subprocess
import sys

import pytest
from rig import LIB, ROOT

from docs.library import make_error_tables as tables
from vplc.api import load_plc

LITERAL = re.compile(r"WORD#16#([0-9A-Fa-f]{1,4})\b")
NAMED = re.compile(r"\bErr[A-Z][A-Za-z0-9]*")


def named_literals(text):
    """(line number, ErrorIDs of the line's code in order, Err names its comments give in order) for every line of
    ST text holding a non-zero WORD#16#... literal before its first comment."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        code, _, comment = line.partition("(*")
        codes = [f"16#{int(m.group(1), 16):04X}" for m in LITERAL.finditer(code) if int(m.group(1), 16)]
        if codes:
            found.append((number, codes, NAMED.findall(comment)))
    return found


def misnamed(text, rows):
    """The lines whose ErrorID literals are not named, in order, by their rows' names in the line's comment."""
    return [f"{number}: {', '.join(codes)} named {names or 'nothing'}, the table says "
            f"{[rows[c]['name'] if c in rows else 'no such row' for c in codes]}"
            for number, codes, names in named_literals(text)
            if [rows.get(c, {}).get("name") for c in codes] != names]


def library_literals():
    """Every non-zero WORD#16#... literal of the library outside the generated text function and platform/
    (where Sysmac socket service codes are compared), with the file and line it stands in."""
    found = []
    for path in sorted(LIB.rglob("*.st")):
        if path == tables.ST_FILE or path.parent.name == "platform":
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            for m in LITERAL.finditer(line.split("(*")[0]):
                value = int(m.group(1), 16)
                if value:
                    found.append((f"16#{value:04X}", f"{path.relative_to(ROOT)}:{number}"))
    return found


def test_generated_files_agree_with_the_table():
    result = subprocess.run([sys.executable, str(ROOT / "docs" / "library" / "make_error_tables.py"), "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def test_every_row_has_text_cause_and_remedy():
    rows = tables.load()
    assert len(rows) >= 49
    for code, row in rows.items():
        assert row["text"] and row["cause"] and row["remedy"] and row["raised_by"], code
        assert len(row["text"]) <= 79, code


def test_the_library_raises_only_ids_of_the_table():
    rows = tables.load()
    unknown = [f"{where}: {code}" for code, where in library_literals() if code not in rows]
    assert unknown == [], "ErrorIDs missing from docs/library/errors.tsv:\n" + "\n".join(unknown)


def test_every_errorid_literal_carries_the_name_of_its_table_row():
    rows = tables.load()
    wrong, seen = [], 0
    for path in sorted(LIB.rglob("*.st")):
        if path == tables.ST_FILE or path.parent.name == "platform":
            continue
        text = path.read_text(encoding="utf-8")
        seen += sum(len(codes) for _, codes, _ in named_literals(text))
        wrong += [f"{path.relative_to(ROOT)}:{line}" for line in misnamed(text, rows)]
    assert wrong == [], "ErrorID literals not named as in docs/library/errors.tsv:\n" + "\n".join(wrong)
    assert seen == len(library_literals()) >= 150


@pytest.mark.parametrize("line,complaint", [
    ("Err := WORD#16#2001;", "16#2001 named nothing, the table says ['ErrNotConnected']"),
    ("Err := WORD#16#2001;  (* ErrNotReachable *)", "16#2001 named ['ErrNotReachable']"),
    ("IF E = WORD#16#2004 OR E = WORD#16#2001 THEN  (* ErrNotConnected, ErrUnreachable *)", "in order"),
    ("Err := WORD#16#2FFF;  (* ErrNotConnected *)", "'no such row'"),
])
def test_a_literal_without_its_name_is_found(line, complaint):
    rows = tables.load()
    found = misnamed("x := 1;\n" + line + "\n", rows)
    assert len(found) == 1 and found[0].startswith("2: ")
    if complaint != "in order":
        assert complaint in found[0]
    assert misnamed("Err := WORD#16#2001;  (* ErrNotConnected: why *)\nErr := WORD#16#0;\n", rows) == []


def test_every_id_of_the_table_is_raised_somewhere_in_the_library():
    raised = {code for code, _ in library_literals()}
    assert [code for code in tables.load() if code not in raised] == []


def test_hmi_texts_are_the_table():
    hmi = json.loads((ROOT / "src" / "cbt_hmi" / "pages" / "errors.json").read_text(encoding="utf-8"))
    rows = tables.load()
    assert list(hmi) == list(rows)
    assert all(hmi[c]["text"] == rows[c]["text"] and hmi[c]["remedy"] == rows[c]["remedy"] for c in rows)


def test_st_text_function_returns_the_table_text_for_every_id(tmp_path):
    rows = tables.load()
    n = len(rows)
    ids = ", ".join(f"WORD#{c}" for c in rows)
    (tmp_path / "Texts.st").write_text(f"""PROGRAM Main
VAR
    Ids : ARRAY[1..{n}] OF WORD := [{ids}];
    Texts : ARRAY[1..{n}] OF STRING[80];
    Unknown : STRING[80];
    I : UINT;
END_VAR
FOR I := 1 TO {n} DO
    Texts[I] := CBTi_ErrorText(Ids[I]);
END_FOR;
Unknown := CBTi_ErrorText(WORD#16#4FFF);
END_PROGRAM
""", encoding="utf-8")
    with load_plc([str(LIB), str(tmp_path / "Texts.st")], task="Main@1ms") as plc:
        plc.scan(plc.period_ns)
        got = [plc.read(f"Main.Texts[{i}]") for i in range(1, n + 1)]
        assert got == [row["text"] for row in rows.values()]
        assert plc.read("Main.Unknown") == "Unknown ErrorID 16#4fff"


OPERATOR = "\tPress Execute again.\tmessage"
N = "\tErrTimeOutRange"


@pytest.mark.parametrize("line,message", [
    ("16#1001" + N + "\tCBT_Connect\tText\t\tRemedy" + OPERATOR, "has no cause"),
    ("16#0001" + N + "\tCBT_Connect\tText\tCause\tRemedy" + OPERATOR, "is not 16#1xxx..16#4xxx"),
    ("16#1001" + N + "\tCBT_Connect\t" + "x" * 80 + "\tCause\tRemedy" + OPERATOR, "text is 80 characters"),
    ("16#1001" + N + "\tCBT_Connect\tText\tCause", "5 fields, expected 8"),
    ("16#1001" + N + "\tCBT_Connect\tA | B\tCause\tRemedy" + OPERATOR, "'|' in text"),
    ("16#1001" + N + "\tCBT_Connect\tText\tCause\tRemedy\tPress Execute again.\tevent",
     "hmi is 'event', expected alarm or message"),
    ("16#1001" + N + "\tCBT_Connect\tText\tCause\tRemedy\tExecute CBT_Connect again.\tmessage",
     "the operator text names the function block CBT_Connect"),
    ("16#1001" + N + "\tCBT_Connect\tText\tCause\tRemedy\t\tmessage", "has no operator"),
    ("16#1001\tTimeOutRange\tCBT_Connect\tText\tCause\tRemedy" + OPERATOR, "name 'TimeOutRange' is not Err"),
])
def test_a_malformed_table_is_named_with_its_line(tmp_path, line, message):
    bad = tmp_path / "errors.tsv"
    bad.write_text("\t".join(tables.COLUMNS) + "\n" + line + "\n", encoding="utf-8")
    with pytest.raises(tables.TableError, match=re.escape(message)) as info:
        tables.load(bad)
    assert str(info.value).startswith("errors.tsv:2: ")


def test_two_rows_of_one_name_are_refused(tmp_path):
    bad = tmp_path / "errors.tsv"
    row = "\tErrTimeOutRange\tCBT_Connect\tText\tCause\tRemedy" + OPERATOR
    bad.write_text("\t".join(tables.COLUMNS) + "\n16#1001" + row + "\n16#1002" + row + "\n", encoding="utf-8")
    with pytest.raises(tables.TableError, match="errors.tsv:3: ErrorID 16#1002: name ErrTimeOutRange is already "
                                                "the name of 16#1001"):
        tables.load(bad)
