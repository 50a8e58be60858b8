"""`vplc` run inside the test process: ``vplc.cli.main.main(argv)`` with its output captured, answered as the
``subprocess.CompletedProcess`` a child process gives. For tests of what a command says and returns; a test of the
process itself (start-up, ``python -m``, signals, the interpreter's exit) starts a child (``run_cli`` fixture).
It saves the child's interpreter start and the compile of what it loads: a program compiled once is kept by
vplc.api for the next command of the same test process."""
from __future__ import annotations

import contextlib
import io
import os
import pathlib
import subprocess

from vplc.cli.main import main

ROOT = pathlib.Path(__file__).resolve().parents[1]


def run_in_process(*args, cwd=None) -> subprocess.CompletedProcess:
    """``vplc args...`` from the checkout's root (or ``cwd``): exit status, standard output and error as text."""
    argv = [str(a) for a in args]
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(cwd or ROOT)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:                   # the argument parser's usage errors (exit 2)
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
                if isinstance(exc.code, str):
                    print(exc.code, file=err)
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(["vplc", *argv], code, out.getvalue(), err.getvalue())
