"""``python3 -m vplc export PATH... --format iec61131-10|paste -o OUT [--flat]``: hand the library to
Sysmac Studio.

* ``iec61131-10`` writes one IEC 61131-10 Ed.1 XML file for Tools > IEC 61131-10 XML > Import
  (:mod:`vplc.export.iec61131_10`);
* ``plcopen`` writes one PLCopen XML TC6 v2.01 file (CODESYS, Beremiz / OpenPLC, …;
  :mod:`vplc.export.plcopen`); ladder POUs keep their rungs in both XML formats;
* ``paste`` writes a folder of clipboard-ready variable tables and bodies plus ORDER.txt for CPU units
  without that menu (:mod:`vplc.export.paste`).

The sources are loaded and checked by the front end first; nothing is written while there are errors.
Exit codes: 0 written, 1 errors in the sources (diagnostics printed), 2 usage error (one-line message).
Documentation: docs/toolchain/export.md.
"""
from __future__ import annotations

import argparse
import errno
import os
import sys
import tempfile

FORMATS = ("iec61131-10", "plcopen", "paste")


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "export", help="export ST sources for Sysmac Studio (IEC 61131-10 XML or paste kit)",
        description="Check the sources, then write them as one IEC 61131-10 XML file (Sysmac Studio: "
                    "Tools > IEC 61131-10 XML > Import), one PLCopen XML TC6 file, or a paste kit folder. Exit 0 "
                    "written, 1 errors in the sources, 2 usage error.")
    p.add_argument("paths", nargs="+", metavar="PATH", help="ST or XML file, or folder (recursive *.st, *.xml)")
    p.add_argument("--format", default="iec61131-10", metavar="FORMAT",
                   help="iec61131-10 (default): one XML file for Sysmac Studio; plcopen: one PLCopen XML TC6 file; "
                        "paste: a folder per data type and POU")
    p.add_argument("-o", "--output", metavar="OUT", help="XML file (iec61131-10, plcopen) or folder (paste); required")
    p.add_argument("--flat", action="store_true",
                   help="write every object in the global namespace (no NamespaceDecl), for importers "
                        "that do not take namespaces")
    p.add_argument("--only", metavar="NAME[,NAME...]",
                   help="write only these data types and POUs (the other sources are loaded to check them), e.g. "
                        "one program for import into a project that has the library already")
    p.add_argument("--device", metavar="MODEL[@VERSION]",
                   help="iec61131-10: name the controller in the file header (smcext:DeviceInfo), e.g. "
                        "NJ501-1500@1.40; without it the file is not tied to a controller model")
    p.add_argument("--dialect", choices=("sysmac", "iec"), default="sysmac", help="language dialect (default: sysmac)")
    p.set_defaults(handler=run_export)


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _usage(msg: str) -> int:
    print(f"vplc export: error: {msg}", file=sys.stderr)
    return 2


def run_export(args: argparse.Namespace) -> int:
    from ..frontend.diagnostics import ERROR, NOTE
    from ..ladder.model import WriteError
    from ..project import load_project
    from .iec61131_10 import render
    from .model import ExportError, collect
    from .paste import PasteTargetError
    from .paste import write as write_paste

    device = None
    if getattr(args, "device", None):
        model, _, version = args.device.partition("@")
        if not model.strip() or "@" in version:
            return _usage(f"--device `{args.device}`: give MODEL or MODEL@VERSION, e.g. NJ501-1500@1.40")
        device = (model.strip(), version.strip())
    if args.format not in FORMATS:
        return _usage(f"unknown format `{args.format}`; use {', '.join(FORMATS[:-1])} or {FORMATS[-1]}")
    if not args.output:
        return _usage("no output given; add -o FILE.xml (iec61131-10, plcopen) or -o FOLDER (paste)")
    missing = [p for p in args.paths if not os.path.exists(p)]
    if missing:
        return _usage(f"file or folder `{missing[0]}` does not exist")
    out = args.output
    if args.format in ("iec61131-10", "plcopen"):
        parent = os.path.dirname(os.path.abspath(out))
        if os.path.isdir(out):
            return _usage(f"output `{out}` is a folder; give a file name such as {os.path.join(out, 'Lib.xml')}")
        if not os.path.isdir(parent):
            return _usage(f"cannot write `{out}`: folder `{parent}` does not exist")

    proj = load_project(args.paths, dialect=args.dialect)
    if args.format in ("iec61131-10", "plcopen") and os.path.exists(out) and any(
            _same_file(out, source) for source in proj.files):
        return _usage(f"output `{out}` is one of the sources; give another file name (the export would replace "
                      "the source)")
    shown = [d for d in proj.diagnostics if d.severity != NOTE]
    errors = sum(1 for d in shown if d.severity == ERROR)
    if shown:
        for d in shown:
            print(d.render(), file=sys.stderr)
    if errors:
        print(f"vplc export: {errors} error(s) in the sources; nothing written", file=sys.stderr)
        return 1
    export = collect(proj)
    if args.only:
        wanted = {n.strip().upper() for n in args.only.split(",") if n.strip()}
        unknown = wanted - {i.name.upper() for i in export.items}
        if unknown:
            return _usage(f"--only: no data type or POU named {', '.join(sorted(unknown))} in the sources")
        export.types = [t for t in export.types if t.name.upper() in wanted]
        export.pous = [p for p in export.pous if p.name.upper() in wanted]
        export.globals = []
        export.namespaces = sorted({i.namespace for i in export.items if i.namespace})
        if len(export.items) == 1:
            export.title = export.items[0].name
    if not export.items:
        return _usage("the sources declare no data type and no POU; nothing to export")
    try:
        if args.format == "iec61131-10":
            data = render(export, proj, flat=args.flat, device=device)
            _write_atomic(out, data)
        elif args.format == "plcopen":
            from .plcopen import render as render_plcopen
            _write_atomic(out, render_plcopen(export, proj))
        else:
            write_paste(export, proj, out, flat=args.flat)
    except (ExportError, WriteError) as exc:
        print(f"vplc export: error: {exc}", file=sys.stderr)
        return 1
    except PasteTargetError as exc:
        return _usage(str(exc))
    except OSError as exc:
        return _usage(f"cannot write `{out}`: {exc.strerror or exc}")
    print(f"{out}: {len(export.types)} data type(s), {len(export.pous)} POU(s)"
          + (f", {sum(len(s.vars) for g in export.globals for s in g.gvl.sections)} global variable(s)"
             if export.globals else "")
          + (" (flat)" if args.flat else ""))
    return 0


def _write_atomic(path: str, data: bytes) -> None:
    """Write next to the target and rename, so a failed run never leaves half a file behind. A target that exists
    and is not a regular file (a device such as /dev/stdout, a pipe) is written in place: renaming over it would
    replace the device with a file and report success for data nobody received."""
    if os.path.exists(path) and not os.path.isfile(path):
        if os.path.isdir(path):
            raise IsADirectoryError(errno.EISDIR, "is a folder; name the file to write")
        with open(path, "wb") as fh:
            fh.write(data)
        return
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".vplc-export-", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
