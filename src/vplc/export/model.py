"""What an export contains: the user's data types and POUs, taken from a checked project.

``collect(project)`` returns an :class:`ExportSet` in dependency order (see :mod:`vplc.export.order`).
Each item keeps its AST node, its namespace and the text the writers need and the AST does not carry:
the header comment above it, the comment at the end of each declaration line and, for POUs, the body
text exactly as written between the last ``END_VAR`` and ``END_FUNCTION_BLOCK`` (comments included).
"""
from __future__ import annotations

import bisect
import re
from collections.abc import Iterator
from dataclasses import dataclass, field

from ..frontend import ast as A
from ..frontend import printer
from ..project import Project
from .order import dependency_order


class ExportError(Exception):
    """The sources are valid ST but use something the chosen export format cannot express."""


@dataclass
class TypeItem:
    decl: A.TypeDecl
    namespace: str | None
    comment: str
    source_text: str                 # the TYPE ... END_TYPE block as written
    path: str
    member_comments: dict[int, str] = field(default_factory=dict)   # id(VarDecl | EnumValueDecl) -> comment

    @property
    def name(self) -> str:
        return self.decl.name

    @property
    def kind(self) -> str:
        spec = self.decl.spec
        if isinstance(spec, A.StructTypeRef):
            return "STRUCT"
        if isinstance(spec, A.EnumTypeRef):
            return "ENUM"
        if isinstance(spec, A.ArrayTypeRef):
            return "ARRAY"
        return "ALIAS"


@dataclass
class PouItem:
    pou: A.Pou
    namespace: str | None
    comment: str
    body: str
    path: str
    var_comments: dict[int, str] = field(default_factory=dict)      # id(VarDecl) -> comment

    @property
    def name(self) -> str:
        return self.pou.name

    @property
    def kind(self) -> str:
        return self.pou.kind


@dataclass
class GlobalItem:
    gvl: A.GlobalVarList
    path: str
    var_comments: dict[int, str] = field(default_factory=dict)


@dataclass
class ExportSet:
    types: list[TypeItem]            # dependency order: every type after the types it uses
    pous: list[PouItem]              # dependency order: every POU after the POUs it calls or instantiates
    globals: list[GlobalItem]
    namespaces: list[str]            # library namespaces present, sorted
    title: str | None = None         # content name chosen by the caller (export --only of one object)

    @property
    def items(self) -> list:
        return [*self.types, *self.pous]

    @property
    def name(self) -> str:
        """Content name: the caller's title, the library namespace when there is exactly one, else ``Project``."""
        if self.title:
            return self.title
        return self.namespaces[0] if len(self.namespaces) == 1 else "Project"


# ---- comments ------------------------------------------------------------------------------------

def comment_text(raw: str) -> str:
    """Text of one comment without its delimiters, whitespace folded to single spaces."""
    if raw.startswith("//"):
        raw = raw[2:]
    elif raw[:2] in ("(*", "/*"):
        raw = raw[2:-2]
    return " ".join(raw.split())


class _Comments:
    """The comments of one file, sorted by where they start: a lookup finds its first candidate by bisection, so
    the comments of a file's declarations cost O(log n) each instead of a pass over every comment of the file."""

    def __init__(self, unit: A.CompilationUnit) -> None:
        self.text = unit.span.file.text
        self.spans = sorted((s, e) for _style, s, e in (unit.comments or []))
        self.starts = [s for s, _e in self.spans]

    def starting(self, start: int, stop: int) -> Iterator[tuple[int, int]]:
        """(start, end) of each comment that starts in ``[start, stop)``, in order."""
        spans = self.spans
        for i in range(bisect.bisect_left(self.starts, start), len(spans)):
            if spans[i][0] >= stop:
                return
            yield spans[i]

    def between(self, start: int, end: int) -> str:
        """All comments fully inside ``[start, end)``, joined."""
        parts = [comment_text(self.text[s:e]) for s, e in self.starting(start, end) if e <= end]
        return " ".join(p for p in parts if p)

    def line_end(self, offset: int) -> int:
        """The end of the line holding ``offset`` (a declaration's own line comment ends before it)."""
        end = self.text.find("\n", offset)
        return len(self.text) if end < 0 else end

    def trailing(self, end: int) -> str:
        """The comments on the rest of the line after offset ``end`` (a declaration's line comment)."""
        line_end = self.line_end(end)
        parts = []
        for s, e in self.starting(end, line_end):
            if s >= end and not self.text[end:s].strip(" \t,;\r"):
                parts.append(comment_text(self.text[s:e]))
                end = e
        return " ".join(p for p in parts if p)


# ---- POU body ------------------------------------------------------------------------------------

def body_text(pou: A.Pou) -> str:
    """The statement part of ``pou`` exactly as written (comments kept, line ends normalised to LF).

    It runs from the line after the last declaration (``END_VAR`` or the header) to the line before
    ``END_FUNCTION`` / ``END_FUNCTION_BLOCK`` / ``END_PROGRAM``; leading blank lines and trailing white
    space are dropped.
    """
    text = pou.span.file.text
    ret_span = getattr(pou.return_type, "span", None)         # every type specification has one
    header_end = max([pou.name_span.end]
                     + ([ret_span.end] if ret_span else [])
                     + [s.span.end for s in pou.sections if s.span is not None])
    tail = text[header_end:pou.span.end]
    ends = list(re.finditer(r"(?i)\bEND_" + pou.kind + r"\b", tail))
    stop = header_end + (ends[-1].start() if ends else len(tail))
    raw = text[header_end:stop].replace("\r\n", "\n").replace("\r", "\n")
    first_nl = raw.find("\n")
    if first_nl >= 0 and not raw[:first_nl].strip():
        raw = raw[first_nl + 1:]
    lines = raw.split("\n")
    while lines and not lines[0].strip():
        lines.pop(0)
    return "\n".join(lines).rstrip()


# ---- collection ----------------------------------------------------------------------------------

def collect(project: Project) -> ExportSet:
    """The exportable content of ``project`` (which must have no errors), prelude excluded."""
    types: list[TypeItem] = []
    pous: list[PouItem] = []
    globals_: list[GlobalItem] = []
    namespaces: set[str] = set()
    for unit in project.units:
        if getattr(unit, "in_prelude", False):
            continue
        comments = _Comments(unit)
        path = unit.span.file.path
        prev_end = 0
        for item in unit.items:
            header = comments.between(prev_end, item.span.start)
            prev_end = item.span.end
            if isinstance(item, A.TypeBlock):
                block_text = unit.span.file.text[item.span.start:item.span.end]
                inside = item.span.start                     # comments inside the block, above a declaration
                for i, decl in enumerate(item.decls):
                    ns = decl.namespace                      # the file's, or its NAMESPACE block's
                    own = comments.between(inside, decl.span.start)
                    doc = " ".join(c for c in (header if i == 0 else "", own) if c)
                    inside = comments.line_end(decl.span.end)
                    t = TypeItem(decl, ns, doc, block_text, path)
                    spec = decl.spec
                    if isinstance(spec, A.StructTypeRef):
                        t.member_comments = {id(f): comments.trailing(f.span.end) for f in spec.fields}
                    elif isinstance(spec, A.EnumTypeRef):
                        t.member_comments = {id(v): comments.trailing(v.span.end) for v in spec.values}
                    types.append(t)
                    if ns:
                        namespaces.add(ns)
            elif isinstance(item, A.Pou):
                p = PouItem(item, item.namespace, header, body_text(item), path,
                            {id(d): comments.trailing(d.span.end) for s in item.sections for d in s.vars})
                pous.append(p)
                if item.namespace:
                    namespaces.add(item.namespace)
            elif isinstance(item, A.GlobalVarList):
                globals_.append(GlobalItem(item, path, {id(d): comments.trailing(d.span.end)
                                                        for s in item.sections for d in s.vars}))
    types = dependency_order(types, lambda t: _type_deps(project, t), key=lambda t: (t.namespace, t.name.upper()))
    pous = dependency_order(pous, lambda p: _pou_deps(project, p), key=lambda p: (p.namespace, p.name.upper()))
    return ExportSet(types, pous, globals_, sorted(namespaces))


def _named_refs(ref: A.TypeRef):
    """Every named type referenced by a type specification."""
    if isinstance(ref, A.NamedTypeRef):
        yield ref.name.text()
    elif isinstance(ref, A.ArrayTypeRef):
        yield from _named_refs(ref.element)
    elif isinstance(ref, (A.SubrangeTypeRef, A.EnumTypeRef)) and ref.base is not None:
        yield from _named_refs(ref.base)
    elif isinstance(ref, A.StructTypeRef):
        for f in ref.fields:
            yield from _named_refs(f.type)


def _type_deps(project: Project, item: TypeItem):
    for name in _named_refs(item.decl.spec):
        t = project.lookup_type(name, item.namespace)
        if t is not None:
            yield getattr(t, "namespace", None), t.name.upper()


def _pou_deps(project: Project, item: PouItem):
    pou = item.pou
    for section in pou.sections:
        for d in section.vars:
            for name in _named_refs(d.type):
                pt = project.lookup_pou(name, item.namespace)
                if pt is not None:
                    yield pt.namespace, pt.name.upper()
    for node in (n for stmt in pou.body for n in A.walk(stmt)):
        if isinstance(node, A.Call):
            callee = getattr(getattr(node, "binding", None), "pou", None)
            if callee is not None:
                yield callee.namespace, callee.name.upper()


def enum_values(project: Project, item: TypeItem) -> dict[str, int]:
    """Value of every enumerator (implicit values counted on from the previous one, as the checker does)."""
    t = project.lookup_type(item.decl.name, item.namespace)
    known = {k.upper(): v for k, v in getattr(t, "values", {}).items()}
    spec = item.decl.spec
    if not isinstance(spec, A.EnumTypeRef):
        raise TypeError(f"enum_values: {item.decl.name} is not an enumeration")
    out, nxt = {}, 0
    for v in spec.values:
        value = known.get(v.name.upper(), nxt)
        out[v.name.upper()] = value
        nxt = value + 1
    return out


def type_text(ref: A.TypeRef) -> str:
    """A type specification as Sysmac Studio's tables show it (``STRING[80]``, ``ARRAY[1..6] OF REAL``)."""
    return printer.type_ref(ref)


def expr_text(e: A.Expr) -> str:
    return printer.expr(e)
