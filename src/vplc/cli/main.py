"""Command line: ``python3 -m vplc <command> ...``.

Subcommands live in a registry: this module registers ``check``; the back end's modules
``vplc.cli.run`` and ``vplc.cli.test`` register ``run`` and ``test``, the package ``vplc.export`` registers
``export``, each through its ``register(subparsers)`` function when it is importable. Exit codes: 0 success,
1 errors found, 2 usage error.
"""
from __future__ import annotations

import argparse
import errno
import importlib
import os
import sys
from typing import Any, NoReturn

from ..frontend.diagnostics import ERROR, NOTE, WARNING, to_json

EXTENSION_MODULES = ("vplc.cli.run", "vplc.cli.test", "vplc.export", "vplc.cli.draw")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # usage errors: message + hint, exit 2, never a traceback
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}\n")

    def _get_values(self, action: argparse.Action, arg_strings: list[str]) -> Any:
        # an option given an empty value (a script's unset variable: --duration "$T") is a usage error: read as
        # absent, --duration '' ran for ever and --only '' exported everything
        if action.option_strings and any(not text.strip() for text in arg_strings):
            self.error(f"argument {'/'.join(action.option_strings)}: empty value; give one or leave the option out")
        return super()._get_values(action, arg_strings)


def register_check(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "check", help="parse and check Structured Text files",
        description="Check ST files (or folders, searched recursively for *.st) and print every diagnostic as "
                    "path:line:col: severity[CODE]: message. Exit 0 without errors, 1 with errors.")
    p.add_argument("paths", nargs="+", metavar="PATH",
                   help="ST (.st) or PLCopen / IEC 61131-10 (.xml) file, or a folder searched recursively for both")
    p.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")
    p.add_argument("--portable", action="store_true",
                   help="also warn on constructs outside IEC 61131-3 2nd edition (vendor instructions and types, "
                        "namespace qualifiers, 3rd-edition syntax); files below a folder named `platform` are exempt")
    p.add_argument("--warnings-as-errors", action="store_true", help="exit 1 when there is any warning")
    p.add_argument("--dialect", choices=("sysmac", "iec"), default="sysmac", help="language dialect (default: sysmac)")
    p.add_argument("--no-notes", action="store_true", help="do not print notes (e.g. ignored pragmas)")
    p.set_defaults(handler=run_check)


def run_check(args: argparse.Namespace) -> int:
    from ..project import load_project
    proj = load_project(args.paths, dialect=args.dialect, portable=args.portable)
    diags = [d for d in proj.diagnostics if not (args.no_notes and d.severity == NOTE)]
    errors = sum(1 for d in diags if d.severity == ERROR)
    warnings = sum(1 for d in diags if d.severity == WARNING)
    if args.format == "json":
        print(to_json(diags))
    else:
        for d in diags:
            print(d.render())
        print(f"{len(proj.files)} file(s) checked: {errors} error(s), {warnings} warning(s)")
    if errors or (args.warnings_as_errors and warnings):
        return 1
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="vplc", description="Open IEC 61131-3 Structured Text toolchain (virtual PLC).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    register_check(sub)
    for name in EXTENSION_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:
                continue            # that back-end command is not installed: not an error
            print(f"vplc: `{name.rsplit('_', 1)[-1]}` command unavailable: {exc}", file=sys.stderr)
            continue
        except Exception as exc:  # a broken extension must not take `vplc check` down with it
            print(f"vplc: `{name.rsplit('_', 1)[-1]}` command unavailable: {type(exc).__name__}: {exc}",
                  file=sys.stderr)
            continue
        register = getattr(module, "register", None)
        if callable(register):
            register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code = int(args.handler(args) or 0)
        sys.stdout.flush()                  # a full disk must fail the command, not the interpreter's exit
        return code
    except KeyboardInterrupt:
        print("vplc: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _drop_stdout()
        return 0
    except MemoryError:
        print("vplc: error: out of memory; the input is too large for this machine", file=sys.stderr)
        return 1
    except OSError as exc:                  # writing the output failed (a full disk, /dev/full, an I/O error)
        _drop_stdout()
        what = "cannot write the output" if exc.errno in _WRITE_ERRORS else "operating system error"
        target = f" ({exc.filename})" if exc.filename else ""
        print(f"vplc: error: {what}{target}: {exc.strerror or exc}", file=sys.stderr)
        return 1


_WRITE_ERRORS = {errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG, errno.EROFS}


def _drop_stdout() -> None:
    """Forget what could not be written, so the interpreter's exit does not try (and fail) again."""
    try:
        sys.stdout = open(os.devnull, "w", encoding="utf-8")    # noqa: SIM115 - stdout until the process ends
    except OSError:
        sys.stdout = None
