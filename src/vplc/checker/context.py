"""The state one check of a project shares between its passes and rules.

:class:`Context` holds the dialect, the diagnostics, the symbol tables and what the declaration pass collected
(project.py creates it, declare.py fills it, the body checkers and rules read it); :class:`NamespaceView` is a
NAMESPACE block of a file seen as a unit of its own; :class:`Flow` and :class:`ExprHost` are the seam between
the statement checker (body.py), the expression checker (exprs.py) and the rules they call: a rule module
depends on this description, never on the checkers themselves (no import cycle).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

from ..frontend import ast as A
from ..frontend import types as T
from ..frontend.diagnostics import DiagnosticBag
from ..frontend.source import Span
from .scope import Tables
from .symbols import VarSymbol


class NamespaceView:
    """The items of one NAMESPACE block of a file, seen as a compilation unit of that namespace (names are looked
    up from it as from a library folder's file)."""

    def __init__(self, unit: A.CompilationUnit, namespace: str) -> None:
        self.unit = unit
        self.namespace = namespace

    def __getattr__(self, name: str) -> Any:
        return getattr(self.unit, name)


Unit = A.CompilationUnit | NamespaceView


@dataclass
class Context:
    """One check of a project. The declaration pass records every declaration with the unit declaring it
    (``type_decls``: declaration, its type, unit; ``pou_units``, ``global_lists``, ``configurations``: item,
    unit). ``vendor_objects`` are the ids of the Sysmac prelude's objects; ``vendor_uses`` and
    ``edition3_uses`` the places using them or a 3rd-edition feature (reported by --portable)."""
    dialect: str
    diags: DiagnosticBag
    tables: Tables = field(default_factory=Tables)
    type_decls: list[tuple[A.TypeDecl, T.Type, Unit]] = field(default_factory=list)
    pou_units: list[tuple[A.Pou, Unit]] = field(default_factory=list)
    global_lists: list[tuple[A.GlobalVarList, Unit]] = field(default_factory=list)
    configurations: list[tuple[A.Configuration, Unit]] = field(default_factory=list)
    vendor_objects: set[int] = field(default_factory=set)
    vendor_uses: list[tuple[Span, str, str]] = field(default_factory=list)
    edition3_uses: list[tuple[Span, str]] = field(default_factory=list)
    system_global_names: frozenset[str] | None = None     # the prelude's globals (external_globals.py)

    def note_vendor(self, obj: Any, span: Span | None) -> None:
        """Record a use of a Sysmac system-defined variable, instruction or type (``obj``: its symbol or type)."""
        if id(obj) in self.vendor_objects and span is not None:
            what = "system-defined variable" if getattr(obj, "section", None) == "VAR_GLOBAL" else "instruction or type"
            self.vendor_uses.append((span, obj.name, what))

    def note_edition3(self, what: str, span: Span | None) -> None:
        """Record a use of an IEC 61131-3 3rd-edition-only feature (reported by --portable)."""
        if span is not None:
            self.edition3_uses.append((span, what))


@dataclass
class Flow:
    """What the statements around an expression tell the rules that check a write (assign_target.py): the
    variables of the enclosing FOR loops, which must not be written, and the function block instances already
    called on this path (ST1303). The statement checker (body.py) keeps it; the expression checker reads it
    when a call writes an output or in-out argument."""
    for_vars: list[object] = field(default_factory=list)           # the symbols of the loop variables
    called_instances: set[str] = field(default_factory=set)


class ExprHost(Protocol):
    """What the rules called while typing an expression (calls.py, assign_target.py, array_bounds.py,
    case_labels.py, string_length.py) use of the expression checker (exprs.ExprChecker)."""
    ctx: Context
    ns: str | None
    scope: dict[str, VarSymbol | None]
    result_sym: VarSymbol | None
    flow: Flow
    calls_made: list[tuple[T.PouType, Span]]

    def expr(self, e: A.Expr, expected: T.Type | None = None) -> T.Type: ...

    def coerce(self, value: A.Expr, have: T.Type, want: T.Type, what: str) -> None: ...

    def lookup_var(self, name: str) -> VarSymbol | None: ...

    def needs_context(self, e: A.Expr) -> bool: ...

    def text(self, e: A.Expr | A.CaseRange) -> str: ...
