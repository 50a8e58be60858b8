"""ST2004 (warning, only with ``--portable``) — an enumeration value with an explicit number.

IEC 61131-3 2nd edition enumerations list names only (`(A, B, C)`); `A := 0` is 3rd edition. Declare the
values in number order instead: every compiler, Sysmac Studio included, numbers them 0, 1, 2, ... so a value
keeps its number (write the number in a comment if an HMI maps it).

Passing (portable)::

    TYPE eMode : (Idle, Running, Stopped); END_TYPE      (* 0, 1, 2 *)

Failing (portable)::

    TYPE eMode : (Idle := 0, Running := 1, Stopped := 2); END_TYPE   (* ST2004 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from .context import Context


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.EnumTypeRef):
            explicit = [v for v in node.values if v.value is not None]
            in_order = all(v.value is not None and isinstance(v.value, A.Literal) and v.value.value == i
                           for i, v in enumerate(node.values))
            for v in explicit:
                fix = (f"write `{v.name}` without `:= ...`; the values are already in number order from 0"
                       if in_order else "declare the values in number order from 0 without `:= ...`")
                ctx.diags.warning(codes.PORTABLE_ENUM_NUMBER,
                                  f"enumeration value `{v.name}` has an explicit number, which is IEC "
                                  f"61131-3 3rd edition only; {fix}", v.span)
