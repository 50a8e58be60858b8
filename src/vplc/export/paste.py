"""Paste kit: the library as clipboard-ready pieces for Sysmac Studio without the XML import.

Layout of the output folder::

    ORDER.txt                 creation order: data types (dependency order), then POUs (call order)
    <DataType>/members.tsv    structure: Name, Data Type, Initial Value, Comment
                              enumeration: Name, Value, Comment
    <DataType>/declaration.st the TYPE ... END_TYPE block as written
    <POU>/variables.tsv       every variable, declaration order: Name, Data Type, Initial Value, AT,
                              Retain, Constant, Comment (Sysmac variable-table columns)
    <POU>/Inputs.tsv ...      the same rows split by the tab of Sysmac's variable table they belong in
                              (Inputs, Outputs, InOuts, Internals, Externals)
    <POU>/body.st             the ST body exactly as written

TSV files have no header row (a pasted header would become a variable), fields are separated by one
TAB, lines end in CRLF (Windows clipboard convention). Files are written only when they have rows.
"""
from __future__ import annotations

import os
import shutil

from .. import __version__
from ..frontend import ast as A
from ..project import Project
from .model import ExportSet, PouItem, TypeItem, enum_values, expr_text, type_text

VAR_COLUMNS = ("Name", "Data Type", "Initial Value", "AT", "Retain", "Constant", "Comment")
TAB_OF_SECTION = {"VAR_INPUT": "Inputs", "VAR_OUTPUT": "Outputs", "VAR_IN_OUT": "InOuts", "VAR": "Internals",
                  "VAR_STAT": "Internals", "VAR_TEMP": "Internals", "VAR_EXTERNAL": "Externals"}
TABS = ("Inputs", "Outputs", "InOuts", "Internals", "Externals")
KIND_LABEL = {"STRUCT": "STRUCT", "ENUM": "ENUM", "ARRAY": "ARRAY", "ALIAS": "TYPE",
              "FUNCTION": "FUNCTION", "FUNCTION_BLOCK": "FUNCTION_BLOCK", "PROGRAM": "PROGRAM"}
MARKER = "ORDER.txt"


class PasteTargetError(Exception):
    """The output folder exists and was not written by this command."""


def _cell(text: str) -> str:
    return " ".join(str(text).replace("\t", " ").split())


def _tsv(rows) -> str:
    return "".join("\t".join(_cell(c) for c in row) + "\r\n" for row in rows)


def variable_row(d: A.VarDecl, section: A.VarSection, comment: str) -> tuple:
    """One row of Sysmac's variable table for declaration ``d``."""
    return (d.name, type_text(d.type), expr_text(d.init) if d.init is not None else "", d.at or "",
            "True" if section.retain else "False", "True" if section.constant else "False", comment)


def pou_files(item: PouItem) -> dict[str, str]:
    """File name -> content for one POU folder."""
    rows_by_tab: dict[str, list] = {t: [] for t in TABS}
    rows = []
    for section in item.pou.sections:
        for d in section.vars:
            row = variable_row(d, section, item.var_comments.get(id(d), ""))
            rows.append(row)
            rows_by_tab[TAB_OF_SECTION.get(section.kind, "Internals")].append(row)
    files = {"variables.tsv": _tsv(rows), "body.st": item.body + "\n"}
    for tab in TABS:
        if rows_by_tab[tab]:
            files[f"{tab}.tsv"] = _tsv(rows_by_tab[tab])
    return files


def type_files(item: TypeItem, values: dict[str, int] | None) -> dict[str, str]:
    spec = item.decl.spec
    files = {"declaration.st": item.source_text.replace("\r\n", "\n").rstrip() + "\n"}
    if isinstance(spec, A.StructTypeRef):
        files["members.tsv"] = _tsv((f.name, type_text(f.type), expr_text(f.init) if f.init is not None else "",
                                     item.member_comments.get(id(f), "")) for f in spec.fields)
    elif isinstance(spec, A.EnumTypeRef):
        files["members.tsv"] = _tsv((v.name, str((values or {}).get(v.name.upper(), "")),
                                     item.member_comments.get(id(v), "")) for v in spec.values)
    return files


def folder_names(export: ExportSet) -> dict[int, str]:
    """Folder of each item: its name, qualified with the namespace only when two items share a name."""
    count: dict[str, int] = {}
    for it in export.items:
        count[it.name.upper()] = count.get(it.name.upper(), 0) + 1
    return {id(it): (f"{it.namespace}.{it.name}" if count[it.name.upper()] > 1 and it.namespace else it.name)
            for it in export.items}


def order_text(export: ExportSet, folders: dict[int, str], flat: bool) -> str:
    ns = ", ".join(export.namespaces) if export.namespaces and not flat else "(none)"
    lines = [
        f"# {export.name}: creation order for Sysmac Studio (paste kit written by vplc {__version__})",
        "# Create the objects from top to bottom; every object uses only objects listed above it.",
        "# Data types: Data > Data Types (Structures / Enumerations); paste members.tsv into the member table.",
        "# POUs: Programming > POUs (Functions / Function Blocks / Programs); paste each <Tab>.tsv into that",
        "#   tab of the variable table, then body.st into the ST editor.",
        f"# Namespace: {ns}",
        "#",
        "# No.  Kind            Name                             Folder                           Returns",
    ]
    for n, it in enumerate(export.items, start=1):
        ret = getattr(it, "pou", None) and it.pou.return_type
        folder = folders[id(it)] + "/"
        line = f"{n:>4}  {KIND_LABEL[it.kind]:<15} {it.name:<32} {folder:<32} {type_text(ret) if ret else ''}"
        lines.append(line.rstrip())
    return "\n".join(lines) + "\n"


def write(export: ExportSet, project: Project, out_dir: str, *, flat: bool = False) -> int:
    """Write the kit into ``out_dir``; returns the number of objects. A folder that holds anything other
    than an earlier kit (recognised by its ORDER.txt) is never touched."""
    if os.path.exists(out_dir):
        if not os.path.isdir(out_dir):
            raise PasteTargetError(f"`{out_dir}` exists and is not a folder")
        if os.listdir(out_dir) and not os.path.isfile(os.path.join(out_dir, MARKER)):
            raise PasteTargetError(f"`{out_dir}` is not empty and holds no {MARKER}; "
                                   "choose an empty or new folder")
        shutil.rmtree(out_dir)
    os.makedirs(out_dir)
    folders = folder_names(export)
    for it in export.items:
        if isinstance(it, TypeItem):
            files = type_files(it, enum_values(project, it) if it.kind == "ENUM" else None)
        else:
            files = pou_files(it)
        target = os.path.join(out_dir, folders[id(it)])
        os.makedirs(target)
        for name, content in files.items():
            with open(os.path.join(target, name), "w", encoding="utf-8", newline="") as fh:
                fh.write(content)
    with open(os.path.join(out_dir, MARKER), "w", encoding="utf-8", newline="\n") as fh:
        fh.write(order_text(export, folders, flat))
    return len(export.items)
