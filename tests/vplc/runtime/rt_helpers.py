"""Helpers for runtime tests: load a PROGRAM from ST text written to a temporary folder."""
from __future__ import annotations

import textwrap

from vplc.api import load_plc


def plc_from(tmp_path, body: str, decls: str = "", extra: str = "", **kw):
    src = f"PROGRAM Main\nVAR\n{textwrap.dedent(decls)}\nEND_VAR\n{textwrap.dedent(body)}\nEND_PROGRAM\n{extra}"
    return plc_of(tmp_path, src, **kw)


def plc_of(tmp_path, source: str, **kw):
    """A PLC loaded from ``source``, a whole ST file (types, globals, POUs), written to ``tmp_path``/main.st."""
    path = tmp_path / "main.st"
    path.write_text(source, encoding="utf-8")
    return load_plc([str(path)], **kw)


def run1(tmp_path, body: str, decls: str = "", extra: str = "", **kw):
    plc = plc_from(tmp_path, body, decls, extra, **kw)
    plc.scan(0)
    return plc
