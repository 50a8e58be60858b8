"""ST2005 (warning, only with ``--portable``) — an IEC 61131-3 keyword used as a name.

vplc (like Sysmac Studio) accepts `Step`, `Task` or `On` as names, but IEC 61131-3 reserves the words of the
sequential function chart (STEP, TRANSITION, ACTION, ...) and configuration (RESOURCE, TASK, ON, WITH, ...)
grammar, EN/ENO, R_EDGE/F_EDGE and the elementary data type names (2nd edition, Annex C); other compilers
reject them as variable, type, field, enumeration value or POU names.

Passing (portable)::

    VAR ConnStep : eConnStep; END_VAR

Failing (portable)::

    VAR Step : eConnStep; END_VAR          (* ST2005: STEP is an SFC keyword *)
"""
from __future__ import annotations

from collections.abc import Iterator

from ..frontend import ast as A
from ..frontend import codes
from ..frontend.source import Span
from .context import Context

SFC = ["STEP", "END_STEP", "INITIAL_STEP", "TRANSITION", "END_TRANSITION", "FROM", "ACTION", "END_ACTION"]
CONFIG = ["TASK", "ON", "WITH", "READ_ONLY", "READ_WRITE", "SINGLE", "INTERVAL", "PRIORITY", "AT", "VAR_ACCESS"]
OTHER = ["EN", "ENO", "R_EDGE", "F_EDGE"]
TYPES = ["BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "TIME", "DATE",
         "TIME_OF_DAY", "TOD", "DATE_AND_TIME", "DT", "BYTE", "WORD", "DWORD", "LWORD"]
KIND = {**{w: "a keyword of the sequential function chart (SFC)" for w in SFC},
        **{w: "a keyword of the configuration grammar" for w in CONFIG},
        **{w: "a reserved IEC 61131-3 keyword" for w in OTHER},
        **{w: "an elementary data type name" for w in TYPES}}


def _names(node: A.Node) -> Iterator[tuple[str, Span]]:
    if isinstance(node, (A.VarDecl, A.TypeDecl, A.EnumValueDecl)):
        yield node.name, node.name_span
    elif isinstance(node, A.Pou):
        yield node.name, node.name_span or node.span


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        for name, span in _names(node):
            kind = KIND.get(name.upper())
            if kind is not None:
                ctx.diags.warning(codes.PORTABLE_KEYWORD,
                                  f"`{name}` is {kind} in IEC 61131-3 and cannot be a name in other "
                                  "compilers; rename it (e.g. with a prefix that says what it is)", span)
