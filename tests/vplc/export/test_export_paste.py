"""Paste kit (fallback for CPU units without the IEC 61131-10 import): files, columns, order."""
from __future__ import annotations

from tests.vplc.export.conftest import LIB, run
from vplc.frontend import ast as A

STOP_VARIABLES = [
    # Name, Data Type, Initial Value, AT, Retain, Constant, Comment
    ["CBT", "stCBT_Connection", "", "", "False", "False", ""],
    ["Execute", "BOOL", "", "", "False", "False", ""],
    ["Parameters", "stCBT_StopParam", "", "", "False", "False", ""],
    ["Done", "BOOL", "", "", "False", "False", ""],
    ["Busy", "BOOL", "", "", "False", "False", ""],
    ["CommandAborted", "BOOL", "", "", "False", "False", ""],
    ["Error", "BOOL", "", "", "False", "False", ""],
    ["ErrorID", "WORD", "", "", "False", "False", ""],
    ["ErrorDescrip", "STRING[80]", "", "", "False", "False", ""],
    ["CmdID_Ack", "UINT", "", "", "False", "False", ""],
    ["Core", "CBTi_CommandCore", "", "", "False", "False", ""],
    ["P", "stCBT_StopParam", "", "", "False", "False", ""],
    ["Err", "WORD", "", "", "False", "False", ""],
    ["Script", "STRING[256]", "", "", "False", "False", ""],
    ["Mode", "USINT", "", "", "False", "False", "1..4 = eCBT_StopMode + 1"],
    ["Holding", "BOOL", "", "", "False", "False", "this instance holds CBT in the Stopping state"],
]


def _rows(path):
    data = path.read_bytes().decode("utf-8")
    assert data.endswith("\r\n") and "\n" not in data.replace("\r\n", "")
    return [line.split("\t") for line in data.split("\r\n")[:-1]]


def _order(kit):
    return [line.split() for line in (kit / "ORDER.txt").read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.startswith("#")]


def test_cbt_stop_variable_table_line_by_line(lib_paste):
    folder = lib_paste / "CBT_Stop"
    assert sorted(p.name for p in folder.iterdir()) == \
        ["InOuts.tsv", "Inputs.tsv", "Internals.tsv", "Outputs.tsv", "body.st", "variables.tsv"]
    assert _rows(folder / "variables.tsv") == STOP_VARIABLES
    assert _rows(folder / "InOuts.tsv") == STOP_VARIABLES[:1]
    assert _rows(folder / "Inputs.tsv") == STOP_VARIABLES[1:3]
    assert _rows(folder / "Outputs.tsv") == STOP_VARIABLES[3:10]
    assert _rows(folder / "Internals.tsv") == STOP_VARIABLES[10:]


def test_cbt_stop_body_is_the_source_body(lib_paste):
    body = (lib_paste / "CBT_Stop" / "body.st").read_text(encoding="utf-8").splitlines()
    source = (LIB / "CBT_Stop.st").read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(source) if line.startswith("IF Holding AND NOT Execute THEN"))
    assert body == source[start:source.index("END_FUNCTION_BLOCK")]
    assert "    P := Parameters;                                  (* R4: latched at the rising edge *)" in body


def test_data_type_folders_hold_members_and_declaration(lib_paste):
    enum = _rows(lib_paste / "eCBT_StopMode" / "members.tsv")
    assert [r[:2] for r in enum] == [["StopNormal", "0"], ["StopImmediate", "1"], ["StopAbortScript", "2"],
                                     ["StopDiscardAll", "3"]]
    assert enum[0][2].startswith("StopAndClearBuffer()")
    conn = _rows(lib_paste / "stCBT_Connection" / "members.tsv")
    members = {r[0]: r for r in conn}
    assert members["ReplyTimeout"][:3] == ["ReplyTimeout", "TIME", "T#5s"]
    assert members["Req"][:2] == ["Req", "ARRAY[1..16] OF stCBT_Request"]
    decl = (lib_paste / "stCBT_Connection" / "declaration.st").read_text(encoding="utf-8")
    assert decl.startswith("TYPE\n    stCBT_Connection : STRUCT") and decl.endswith("END_TYPE\n")


def test_order_lists_types_then_pous_each_after_what_it_uses(lib_paste, lib_project):
    rows = _order(lib_paste)
    kinds = [r[1] for r in rows]
    n_types = sum(k in ("STRUCT", "ENUM", "ARRAY") for k in kinds)
    assert all(k in ("STRUCT", "ENUM", "ARRAY") for k in kinds[:n_types])
    assert all(k in ("FUNCTION", "FUNCTION_BLOCK", "PROGRAM") for k in kinds[n_types:])
    assert [int(r[0]) for r in rows] == list(range(1, len(rows) + 1))
    assert all(r[3] == r[2] + "/" and (lib_paste / r[2]).is_dir() for r in rows)
    returns = {r[2]: " ".join(r[4:]) for r in rows}
    assert returns["CBTi_HexDigit"] == "BYTE" and returns["CBT_Stop"] == ""
    pos = {r[2].upper(): i for i, r in enumerate(rows)}
    for unit in lib_project.units:
        if getattr(unit, "in_prelude", False):
            continue
        for item in unit.items:
            decls = item.decls if isinstance(item, A.TypeBlock) else [item]
            for d in decls:
                for node in A.walk(d):
                    used = None
                    if isinstance(node, A.NamedTypeRef):
                        used = node.name.name.upper()
                    elif isinstance(node, A.Call) and getattr(node.binding, "pou", None) is not None:
                        used = node.binding.pou.name.upper()
                    if used in pos:
                        assert pos[used] < pos[d.name.upper()], f"{d.name} uses {used}, listed later"


def test_rerun_replaces_an_earlier_kit_but_never_a_foreign_folder(lib_paste, tmp_path, capsys):
    kit = tmp_path / "kit"
    assert run(capsys, "export", str(LIB), "--format", "paste", "-o", str(kit))[0] == 0
    (kit / "CBT_Stop" / "stale.txt").write_text("x")
    assert run(capsys, "export", str(LIB), "--format", "paste", "-o", str(kit))[0] == 0
    assert not (kit / "CBT_Stop" / "stale.txt").exists()
    assert (kit / "ORDER.txt").read_bytes() == (lib_paste / "ORDER.txt").read_bytes()
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    code, _, err = run(capsys, "export", str(LIB), "--format", "paste", "-o", str(foreign))
    assert code == 2 and (foreign / "notes.txt").read_text() == "keep me"
    assert err.count("\n") == 1 and "ORDER.txt" in err
