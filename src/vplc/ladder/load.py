"""Front-end entry for XML project files: ``read_xml(path, diags)`` gives the generated ST sources (one per
namespace of the file) that :mod:`vplc.project` parses and checks with the ``.st`` files, and
``check_operands`` adds the ladder-only type rule after the checker ran.

Diagnostic codes ST2101-ST2108 (docs/toolchain/diagnostics.md).
"""
from __future__ import annotations

import re

from ..frontend import ast as A
from ..frontend import codes
from ..frontend.source import FileRefused, SourceFile, Span, read_file_bytes
from . import iec10_read, plcopen_read
from .decls import FormatError
from .translate import LadderSource, unit_source
from .xmlsafe import XmlError
from .xmlsafe import read as read_safely

XML_SUFFIXES = (".xml",)
PLCOPEN_NS = "http://www.plcopen.org/xml/tc6"


def is_xml(path: str) -> bool:
    return path.lower().endswith(XML_SUFFIXES)


def is_project_xml(path: str) -> bool:
    """Whether an XML file found in a folder is a project to load: its root element is ``project`` (PLCopen)
    or ``Project`` (IEC 61131-10). Other XML files in a source folder (test reports, settings) are not
    sources; a file named on the command line is always loaded, and refused with a reason if it is not one."""
    try:
        head = read_file_bytes(path, 4096, head=True)
    except (OSError, FileRefused):
        return True                                      # the loader reports why it cannot be read
    return re.search(rb"<(?:[A-Za-z_][\w.-]*:)?[pP]roject[\s>/]", head) is not None


def read_xml(path: str, diags) -> list[tuple[LadderSource, str | None]]:
    """(generated source, namespace or None) per namespace of the file; [] after reporting an error."""
    try:
        text, root = read_safely(path)
    except XmlError as exc:
        src = SourceFile(path, _raw_text(path))
        diags.error(codes.XML_REFUSED, f"`{path}` cannot be loaded: {exc}", Span(src, exc.offset, exc.offset + 1))
        return []
    if root.tag == "project":
        reader = plcopen_read.read
    elif root.tag == "Project":
        reader = iec10_read.read
    else:
        diags.error(codes.XML_REFUSED,
                    f"`{path}` is not a PLCopen XML (TC6) or IEC 61131-10 project: its root element is "
                    f"<{root.tag}>", Span(SourceFile(path, text), 0, 1))
        return []
    try:
        out = []
        warnings: list = []
        units = iec10_read.read(root, warnings) if reader is iec10_read.read else reader(root)
        rules: dict[str, list[str]] = {}
        for where, message in warnings:                  # spellings of earlier vplc exports, read as meant
            rules.setdefault(message, []).append(where)
        for message, places in rules.items():            # one warning per rule, at its first place
            more = f" ({len(places)} places)" if len(places) > 1 else ""
            place = LadderSource(path, "", [(0, 1, places[0] or "project")])
            diags.warning(codes.XML_OLD_SPELLING,
                          f"{message}{more}; this spelling of an earlier vplc export breaks Omron's "
                          "schema: export the file again", Span(place, 0, 1))
        for unit in units:
            src = unit_source(path, unit)
            for bad in src.errors:                           # rungs that could not be translated, all of them
                place = LadderSource(path, "", [(0, 1, bad.where)])
                diags.error(bad.code, bad.message, Span(place, 0, 1))
            out.append((src, unit.namespace))
        return out
    except FormatError as exc:
        place = LadderSource(path, "", [(0, 1, exc.where or "project")])
        diags.error(exc.code, exc.message, Span(place, 0, 1))
        return []
    except (ValueError, TypeError, AttributeError) as exc:      # numbers or attributes malformed in the file
        place = LadderSource(path, "", [(0, 1, "project")])
        diags.error(codes.LADDER_UNKNOWN_ELEMENT, f"the XML does not follow the format: {exc}", Span(place, 0, 1))
        return []
    except RecursionError:
        place = LadderSource(path, "", [(0, 1, "project")])
        diags.error(codes.XML_REFUSED, "the XML is nested too deeply to be a project file", Span(place, 0, 1))
        return []
    except Exception as exc:  # noqa: BLE001 - a loader defect must not show a traceback
        place = LadderSource(path, "", [(0, 1, "project")])
        diags.error(codes.LADDER_UNKNOWN_ELEMENT,
                    f"internal error of the ladder loader ({type(exc).__name__}: {exc}); please report it "
                    "with the XML file", Span(place, 0, 1))
        return []


def attach_ladders(unit: A.CompilationUnit) -> None:
    """Give every POU generated from a ladder its model (``pou.ladder``): the drawing, the HMI and the
    export read it."""
    src = unit.span.file if unit.span is not None else None
    ladders = {lad.pou.upper(): lad for lad in getattr(src, "ladders", ())}
    layouts = getattr(src, "layouts", None) or {}
    for item in unit.items:
        if isinstance(item, A.Pou) and item.name.upper() in ladders:
            item.ladder = ladders[item.name.upper()]  # type: ignore[attr-defined]  # rides on the node, read by getattr
        elif isinstance(item, A.TypeBlock) and layouts:
            for decl in item.decls:             # Sysmac's member layout (CJ, User), written back by the export
                decl.offset_type = layouts.get(decl.name.upper())  # type: ignore[attr-defined]  # read by the export


def _raw_text(path: str) -> str:
    try:
        return read_file_bytes(path, 1 << 20, head=True).decode("utf-8", "replace")
    except (OSError, FileRefused):
        return ""


def check_operands(ctx, units) -> None:
    """ST2105: a contact's operand must be BOOL. Other errors the checker reported inside the same
    generated statement are dropped: they are consequences of the wrong operand."""
    bad_statements = []
    for unit in units:
        src = unit.span.file if unit.span is not None else None
        if not isinstance(src, LadderSource) or not src.checks:
            continue
        wanted = {(s, e): (where, operand) for s, e, where, operand in src.checks}
        for node in A.walk(unit):
            if isinstance(node, A.Expr) and node.span is not None and (node.span.start, node.span.end) in wanted:
                ty = node.ty
                if ty is None or getattr(ty, "name", "?") == "BOOL" or getattr(ty, "name", "?").startswith(("?", "<")):
                    continue
                where, operand = wanted.pop((node.span.start, node.span.end))
                stmt = next(((s, e) for s, e in src.statements if s <= node.span.start < e), None)
                if stmt is not None:
                    bad_statements.append((src, stmt))
                ctx.diags.error(codes.LADDER_PIN_TYPE,
                                f"the {operand}'s operand `{node.span.file.text[node.span.start:node.span.end]}`"
                                f" is {ty.name}; a {operand} needs a BOOL variable", node.span)
    if bad_statements:
        ctx.diags.items = [d for d in ctx.diags.items if d.code == codes.LADDER_PIN_TYPE or not any(
            d.span.file is src and s <= d.span.start < e for src, (s, e) in bad_statements)]
