"""``python3 -m vplc draw FILE... --pou NAME -o rung.svg``: draw a ladder POU as SVG (docs/toolchain/ladder.md).

The sources are loaded and checked first (a ladder with errors is not drawn). Exit codes: 0 written,
1 errors in the sources, 2 usage error (one line on stderr).
"""
from __future__ import annotations

import argparse
import os
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "draw", help="draw a ladder (LD) POU as SVG",
        description="Check the sources, then draw the ladder body of one POU as an SVG file: rails, contacts, "
                    "coils, blocks with pin names, variable names and rung comments. Exit 0 written, 1 errors "
                    "in the sources, 2 usage error.")
    p.add_argument("paths", nargs="+", metavar="PATH",
                   help="XML file with the ladder, plus the .st files or folders it uses")
    p.add_argument("--pou", required=True, metavar="NAME", help="the POU to draw")
    p.add_argument("-o", "--output", required=True, metavar="FILE.svg", help="SVG file to write")
    p.set_defaults(handler=run_draw)


def run_draw(args: argparse.Namespace) -> int:
    from ..frontend.diagnostics import ERROR
    from ..ladder.svg import svg_document
    from ..project import load_project

    missing = [p for p in args.paths if not os.path.exists(p)]
    if missing:
        return _usage(f"file or folder `{missing[0]}` does not exist")
    parent = os.path.dirname(os.path.abspath(args.output))
    if not args.output.lower().endswith(".svg"):
        return _usage(f"`{args.output}`: the drawing is SVG, give a file name ending in .svg")
    if os.path.isdir(args.output) or not os.path.isdir(parent):
        return _usage(f"cannot write `{args.output}`: give a file name in an existing folder")
    proj = load_project(args.paths)
    errors = [d for d in proj.diagnostics if d.severity == ERROR]
    if errors:
        for d in errors:
            print(d.render(), file=sys.stderr)
        print(f"vplc draw: {len(errors)} error(s) in the sources; nothing drawn", file=sys.stderr)
        return 1
    pt = proj.lookup_pou(args.pou)
    if pt is None or pt.pou is None:
        return _usage(f"no POU named `{args.pou}` in the sources")
    ladder = getattr(pt.pou, "ladder", None)
    if ladder is None:
        return _usage(f"`{args.pou}` is written in Structured Text, not as a ladder; only LD POUs can be drawn")
    try:
        with open(args.output, "w", encoding="utf-8") as fh:
            fh.write(svg_document(ladder))
    except OSError as exc:
        return _usage(f"cannot write `{args.output}`: {exc.strerror or exc}")
    print(f"{args.output}: {args.pou}, {len(ladder.rungs)} rung(s)")
    return 0


def _usage(msg: str) -> int:
    print(f"vplc draw: error: {msg}", file=sys.stderr)
    return 2
