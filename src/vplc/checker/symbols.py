"""Symbols the checker attaches to the AST (``Name.sym``, ``Member.sym``, ``Call.binding``).

Documented for the back end in docs/toolchain/frontend_api.md.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..frontend.types import EnumType, Param, PouType, Type


@dataclass(eq=False)
class VarSymbol:
    """A variable. ``section``: VAR, VAR_INPUT, VAR_OUTPUT, VAR_IN_OUT, VAR_TEMP, VAR_STAT, VAR_GLOBAL,
    VAR_EXTERNAL, or RESULT (the function-result variable named like the function).
    ``owner`` is the PouType declaring it (None for globals). ``global_list`` is the global list name
    (file stem) or configuration/resource name for globals. ``target`` is the VAR_GLOBAL symbol a
    VAR_EXTERNAL refers to."""
    name: str
    type: Type
    section: str
    owner: PouType | None = None
    decl: Any = None
    constant: bool = False
    retain: bool = False
    global_list: str | None = None
    target: VarSymbol | None = None
    used: bool = False
    at_address: Any = None          # a global in a Sysmac memory area (at_address.py):
                                    # (area, bank, word, bit, layout, words)

    @property
    def is_global(self) -> bool:
        return self.section in ("VAR_GLOBAL", "VAR_EXTERNAL")


@dataclass(eq=False)
class EnumValueSymbol:
    enum: EnumType
    name: str
    value: int


@dataclass(eq=False)
class PouSymbol:
    """A FUNCTION / FUNCTION_BLOCK / PROGRAM used by name (call target or type of an instance)."""
    type: PouType


@dataclass(eq=False)
class BuiltinSymbol:
    """A standard function from vplc.frontend.builtins (``builtin`` is a builtins.Builtin)."""
    builtin: Any


@dataclass(eq=False)
class BoundArg:
    """One argument bound to a parameter.

    ``expr`` is the value (inputs, in-outs) or the target that receives the output (``=>``).
    ``from_element`` is True when an array *element* is passed to an array parameter (Sysmac rule: the
    callee sees the array starting at that element; ``expr`` is then an ast.Index).
    """
    param: Param
    expr: Any
    negated: bool = False
    from_element: bool = False


@dataclass(eq=False)
class CallBinding:
    """How a call was resolved.

    kind: 'function' (user or prelude FUNCTION), 'fb' (FB instance call), 'builtin' (vplc.frontend.builtins
    standard function), 'program' (a PROGRAM called from a program).
    ``args`` lists the supplied arguments in parameter-declaration order (for POU calls) or in call order
    (for builtins, where ``param`` is a synthetic Param named IN1..INn). Missing function inputs take the
    parameter's ``default``; missing FB inputs keep their previous value.
    """
    kind: str
    ty: Type
    pou: PouType | None = None
    builtin: Any = None
    instance: Any = None            # ast.Expr of the FB instance for kind 'fb'
    args: list[BoundArg] = field(default_factory=list)
