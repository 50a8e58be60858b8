"""Load ST files into a checked project: ``load_project(paths) -> Project`` (docs/toolchain/frontend_api.md)."""
from __future__ import annotations

import contextlib
import gc
import os
import threading
from collections.abc import Iterable, Iterator
from typing import Any

from .checker import calls, recursion, sysmac_identifiers
from .checker import portable as portable_rule
from .checker.body import BodyChecker
from .checker.context import Context, Unit
from .checker.declare import Declarer
from .checker.exprs import ExprChecker
from .checker.scope import Ambiguous, Tables
from .frontend import ast as A
from .frontend import codes
from .frontend import types as T
from .frontend.diagnostics import Diagnostic, DiagnosticBag, render_all, sort_key
from .frontend.parser import parse, parse_kept
from .frontend.source import MAX_SOURCE_BYTES, FileRefused, SourceFile, Span, read_file_bytes
from .ladder.load import attach_ladders, check_operands, is_project_xml, is_xml, read_xml

Paths = str | os.PathLike[str] | Iterable[str | os.PathLike[str]]    # one file or folder, or several

PRELUDE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "prelude")
VENDOR_PRELUDE = ("sysmac_types.st", "sysmac_decl.st", "sysmac_sysvars.st", "sysmac_motion.st", "sysmac_control.st")


class Project:
    def __init__(self, dialect: str) -> None:
        self.dialect = dialect
        self.units: list[A.CompilationUnit] = []
        self.pous: dict[str, T.PouType] = {}
        self.types: dict[str, T.Type] = {}
        self.globals: dict = {}
        self.global_lists: list[A.GlobalVarList] = []
        self.configurations: list[A.Configuration] = []
        self.programs: list[T.PouType] = []
        self.diagnostics: list[Diagnostic] = []
        self.files: list[str] = []        # the user's files: those passed, and those found in the folders passed
        self._tables: Tables | None = None

    @property
    def has_errors(self) -> bool:
        return any(d.is_error for d in self.diagnostics)

    def render_diagnostics(self, context: bool = True) -> str:
        return render_all(self.diagnostics, context)

    def _lookup(self, table: str, text: str, from_ns: str | None) -> Any:
        parts = [p for p in text.replace("\\\\", "\\").split("\\") if p]
        if not parts or self._tables is None:
            return None
        try:
            return getattr(self._tables, table).lookup(parts[-1], tuple(parts[:-1]), from_ns)
        except Ambiguous:
            return None

    def lookup_pou(self, text: str, from_ns: str | None = None) -> T.PouType | None:
        return self._lookup("pous", text, from_ns)

    def lookup_type(self, text: str, from_ns: str | None = None) -> T.Type | None:
        return self._lookup("types", text, from_ns)


# ---- files ---------------------------------------------------------------------------------------

def namespace_of(path: str) -> str | None:
    """The innermost folder whose name ends in ``Lib`` (a library folder), or None."""
    parts = os.path.normpath(os.path.abspath(path)).split(os.sep)[:-1]
    for part in reversed(parts):
        if part.endswith("Lib"):
            return part
    return None


def collect_files(paths: Iterable[str | os.PathLike[str]], diags: DiagnosticBag) -> list[str]:
    files: list[str] = []
    for p in paths:
        p = str(p)
        if os.path.isdir(p):
            found = []
            for root, dirs, names in os.walk(p):
                dirs.sort()
                found += [os.path.join(root, n) for n in sorted(names)
                          if n.lower().endswith(".st") or (is_xml(n) and is_project_xml(os.path.join(root, n)))]
            if not found:
                diags.warning(codes.FILE_EMPTY,
                              f"folder `{p}` contains no .st or .xml files", Span(SourceFile(p, ""), 0, 0))
            files += found
        elif os.path.exists(p):
            files.append(p)
        elif os.path.islink(p):                # the link is there, what it names is not (or it names itself)
            diags.error(codes.FILE_NOT_FOUND, f"`{p}` is a symbolic link to nothing: what it names does not exist "
                        f"or the links loop", Span(SourceFile(p, ""), 0, 0))
        else:
            diags.error(codes.FILE_NOT_FOUND, f"file or folder `{p}` does not exist", Span(SourceFile(p, ""), 0, 0))
    seen, out = set(), []
    for f in files:
        key = os.path.abspath(f)
        if key not in seen:
            seen.add(key)
            out.append(f)
    return out


def read_source(path: str, diags: DiagnosticBag) -> SourceFile | None:
    empty = Span(SourceFile(path, ""), 0, 0)
    try:
        data = read_file_bytes(path, MAX_SOURCE_BYTES)
    except OSError as exc:
        diags.error(codes.FILE_UNREADABLE, f"cannot read `{path}`: {exc.strerror or exc}", empty)
        return None
    except FileRefused as exc:
        diags.error(codes.FILE_UNREADABLE, f"cannot read `{path}`: it {exc}", empty)
        return None
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        diags.error(codes.FILE_NOT_UTF8, f"`{path}` is UTF-16 text; save the file as UTF-8", empty)
        return None
    if b"\x00" in data[:8192]:
        diags.error(codes.FILE_BINARY, f"`{path}` is a binary file, not Structured Text source", empty)
        return None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        diags.error(codes.FILE_NOT_UTF8,
                    f"`{path}` is not valid UTF-8 (invalid byte 0x{data[exc.start]:02X} on line {line}); "
                    "save the file as UTF-8", empty)
        return None
    src = SourceFile(path, text)
    if not text.strip():
        diags.error(codes.FILE_EMPTY, f"`{path}` is empty; it declares nothing", Span(src, 0, 0))
        return None
    return src


# ---- loading -------------------------------------------------------------------------------------

def load_project(paths: Paths, *, dialect: str = "sysmac", include_prelude: bool = True,
                 portable: bool = False) -> Project:
    """Read, parse and check ``paths`` (files or folders, recursively ``*.st`` and ``*.xml``: PLCopen XML and
    IEC 61131-10 projects, see :mod:`vplc.ladder`) plus the prelude."""
    with gc_paused():
        return _load(paths, dialect, include_prelude, portable)


@contextlib.contextmanager
def gc_paused(long_lived: bool = True) -> Iterator[None]:
    """The cyclic garbage collector paused for the block; with ``long_lived`` what the block built then goes to
    the permanent generation (LongLived). The front end and the code generator allocate many small long-lived
    objects and free almost nothing: the collector would only re-scan them (making large files quadratic-ish, and a
    compile in a process that already holds compiled programs 15-40 % slower)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            if long_lived:
                LONG_LIVED.keep()
            gc.enable()


class LongLived:
    """What a load or a compile builds lives long (a checked project, a compiled program), so at the end of each it
    goes to the collector's permanent generation (``gc.freeze``) instead of through the young generations and into
    every later full collection; with it goes whatever else the process holds at that moment, its garbage too, which
    then waits for the next collection of the permanent generation (``gc.collect()`` does not look there;
    ``LONG_LIVED.reclaim()`` does). Python collects the oldest generation when it has grown by a quarter; the
    permanent one is collected here (``reclaim``) when the objects frozen since its last collection are as many as
    that collection kept, and at least ``RECLAIM_MIN``: a process that loads once never pays for it, and one that
    loads and drops many projects (a test suite) holds at most about twice its live objects, or its live objects and
    ``RECLAIM_MIN`` more, whichever is larger. A controller's construction pauses the collector but freezes nothing
    (``gc_paused(long_lived=False)``): a dropped PLC goes with the next collection, and its engine's collector
    callback with it. Measured (27 Nov 2026, 2-core machine): three test files of hundreds of controllers and
    compiles in one process 28.3 -> 22.5 CPU-s, peak memory 227 -> 300 MB; the whole test suite 305 -> 280 CPU-s,
    each worker's peak memory 240-329 -> 276-399 MB."""

    RECLAIM_MIN = 1_000_000

    def __init__(self) -> None:
        self.kept = 0           # objects the last collection of the permanent generation left in it
        self.since = 0          # objects frozen since then (counted when frozen, not all still alive)
        self.lock = threading.Lock()

    def keep(self) -> None:
        """Freeze every object the collector tracks now; collect the permanent generation once it has doubled."""
        with self.lock:
            self.since += gc.get_count()[0] + len(gc.get_objects(1)) + len(gc.get_objects(2))
            gc.freeze()
            if self.since > max(self.kept, self.RECLAIM_MIN):
                self.reclaim()

    def reclaim(self) -> None:
        """Collect everything, the permanent generation included, and freeze what is left."""
        gc.unfreeze()
        gc.collect()
        gc.freeze()
        self.kept, self.since = gc.get_freeze_count(), 0


LONG_LIVED = LongLived()


def _load(paths: Paths, dialect: str, include_prelude: bool, portable: bool) -> Project:
    diags = DiagnosticBag()
    ctx = Context(dialect, diags)
    proj = Project(dialect)
    user_files = collect_files([paths] if isinstance(paths, (str, os.PathLike)) else paths, diags)
    prelude_files = sorted(os.path.join(PRELUDE_DIR, n) for n in os.listdir(PRELUDE_DIR) if n.endswith(".st")) \
        if include_prelude and os.path.isdir(PRELUDE_DIR) else []
    prelude_abs = {os.path.abspath(f) for f in prelude_files}
    user_files = [f for f in user_files if os.path.abspath(f) not in prelude_abs]
    proj.files = user_files
    for path in prelude_files + user_files:
        if is_xml(path):
            for src, namespace in read_xml(path, diags):
                unit = parse(src, diags)
                unit.namespace = namespace or namespace_of(path)
                attach_ladders(unit)
                proj.units.append(unit)
            continue
        source = read_source(path, diags)
        if source is None:
            continue
        in_prelude = os.path.abspath(path) in prelude_abs
        unit = parse_kept(source, diags) if in_prelude else parse(source, diags)
        unit.namespace = None if in_prelude else namespace_of(path)
        unit.in_prelude = in_prelude
        unit.vendor = unit.in_prelude and os.path.basename(path) in VENDOR_PRELUDE
        proj.units.append(unit)
    check_units(ctx, proj)
    check_operands(ctx, proj.units)
    if portable:
        for unit in proj.units:
            portable_rule.check_unit(ctx, unit)
    proj.diagnostics = sorted(diags.items, key=sort_key)
    return proj


def check_units(ctx: Context, proj: Project) -> None:
    dec = Declarer(ctx)
    for file_unit in proj.units:
        dec.register(file_unit)
    for _decl, shell, unit in ctx.type_decls:
        if getattr(unit, "vendor", False):
            ctx.vendor_objects.add(id(shell))
    for pou, unit in ctx.pou_units:
        if getattr(unit, "vendor", False):
            ctx.vendor_objects.add(id(pou.sym))
    dec.complete_types()
    dec.complete_pous()
    for gl, unit in ctx.global_lists:
        dec.declare_globals(gl.sections, unit, gl.name)
        if not getattr(unit, "in_prelude", False):      # the user's lists (system-defined variables are not)
            proj.global_lists.append(gl)
    for cfg, unit in ctx.configurations:
        dec.declare_globals(cfg.sections, unit, cfg.name)
        for res in cfg.resources:
            dec.declare_globals(res.sections, unit, res.name or cfg.name)
        proj.configurations.append(cfg)
    # initial values of type declarations and globals
    for decl, shell, unit in ctx.type_decls:
        ck = ExprChecker.for_unit(ctx, unit)
        if decl.init is not None:
            ck.initial_value(decl.init, shell, f"initial value of {decl.name}")
        if isinstance(shell, T.StructType):
            for f in shell.fields.values():
                if f.init is not None:
                    ck.initial_value(f.init, f.type, f"initial value of {f.name}")
    with_globals: list[tuple[A.GlobalVarList | A.Configuration, Unit]] = [*ctx.global_lists, *ctx.configurations]
    for holder, unit in with_globals:
        ck = ExprChecker.for_unit(ctx, unit)
        for section in holder.sections:
            for d in section.vars:
                if d.init is not None and d.sym is not None:
                    ck.initial_value(d.init, d.sym.type, f"initial value of {d.name}")
    edges: dict = {}
    for pou, unit in ctx.pou_units:
        body = BodyChecker.for_pou(ctx, pou, unit)
        body.check_pou()
        pt = pou.sym
        edges.setdefault(pt, []).extend(
            [(callee, span) for callee, span in body.exprs.calls_made if callee.kind != "fb" or callee is pt])
        edges[pt].extend(recursion.instance_edges(pt, [d for s in pou.sections if s.kind in ("VAR", "VAR_STAT")
                                                       for d in s.vars]))
        if pou.kind == "PROGRAM" and not getattr(unit, "in_prelude", False):
            proj.programs.append(pt)
    recursion.check(ctx, edges)
    sysmac_identifiers.check(ctx)
    for cfg, unit in ctx.configurations:
        check_configuration(ctx, cfg, unit)
    proj._tables = ctx.tables
    for (ns, name), obj in ctx.tables.pous.entries.items():
        proj.pous[f"{ns}\\{name}" if ns else name] = obj
    for (ns, name), ty in ctx.tables.types.entries.items():
        proj.types[f"{ns}\\{name}" if ns else name] = ty
    proj.globals = dict(ctx.tables.globals)


def check_configuration(ctx: Context, cfg: A.Configuration, unit: Unit) -> None:
    ck = ExprChecker.for_unit(ctx, unit)
    for res in cfg.resources:
        tasks = {}
        for task in res.tasks:
            if task.name.upper() in tasks:
                ctx.diags.error(codes.DUPLICATE_NAME, f"task `{task.name}` is declared more than once", task.span)
            tasks[task.name.upper()] = task
            for prop in task.props:
                want = {"INTERVAL": T.TIME, "PRIORITY": T.UINT, "SINGLE": T.BOOL}.get(prop.name)
                if want is None:
                    ctx.diags.error(codes.UNKNOWN_TASK_PROPERTY,
                                    f"unknown task property `{prop.name}`; use INTERVAL, PRIORITY or SINGLE",
                                    prop.span)
                    continue
                have = ck.expr(prop.value, want)
                ck.coerce(prop.value, have, want, f"task property {prop.name}")
        for inst in res.programs:
            if inst.task is not None and inst.task.upper() not in tasks:
                ctx.diags.error(codes.UNDECLARED, f"task `{inst.task}` is not declared in this resource", inst.span)
            pt = None
            with contextlib.suppress(Ambiguous):
                pt = ctx.tables.pous.lookup(inst.program.name, inst.program.namespace, unit.namespace)
            if pt is None or pt.kind != "program":
                ctx.diags.error(codes.UNDECLARED, f"`{inst.program.text()}` is not a PROGRAM", inst.span)
                continue
            call = A.Call(A.Name(inst.program, span=inst.program.span), inst.args, span=inst.span)
            calls.bind_pou(ck, call, pt, "program", None)
            inst.binding = call.binding
