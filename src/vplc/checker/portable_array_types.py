"""ST2011 (warning, only with ``--portable``) — a whole array passed between two separately written ARRAY types.

`ARRAY[0..4095] OF BYTE` written in two declarations is two different types for an IEC 61131-3 2nd edition
compiler, so passing one to the other (in-out or input parameter, assignment) does not compile there. Declare
the buffer once as a named type and use the name on both sides; for Sysmac Studio, which registers no array
data types, wrap the array in a structure.

Passing (portable)::

    TYPE stBuffer : STRUCT Bytes : ARRAY[0..4095] OF BYTE; END_STRUCT; END_TYPE
    ... VAR_IN_OUT Buf : stBuffer; END_VAR ...      Encode(Buf := TxBuf);      (* TxBuf : stBuffer *)

Failing (portable)::

    ... VAR_IN_OUT Buf : ARRAY[0..4095] OF BYTE; END_VAR ...
    Encode(Buf := TxBuf);                        (* TxBuf : ARRAY[0..4095] OF BYTE -> ST2011 *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from ..frontend.source import Span
from .context import Context


def _anonymous_array(t: T.Type) -> bool:
    return isinstance(t, T.ArrayType)


def _warn(ctx: Context, span: Span, what: str) -> None:
    ctx.diags.warning(codes.PORTABLE_ARRAY_TYPES,
                      f"{what}: two separately written ARRAY types are different types in IEC 61131-3 "
                      "2nd edition; declare the array once as a named type (a STRUCT member for Sysmac Studio) "
                      "and use it on both sides", span)


def check_unit(ctx: Context, unit: A.CompilationUnit) -> None:
    for node in A.walk(unit):
        if isinstance(node, A.Call) and node.binding is not None and node.binding.kind in ("function", "fb"):
            for ba in node.binding.args:
                if ba.from_element or ba.expr is None or ba.expr.ty is None:
                    continue
                if isinstance(T.unalias(ba.param.type), T.ArrayType) and (
                        _anonymous_array(ba.param.type) or _anonymous_array(ba.expr.ty)):
                    _warn(ctx, ba.expr.span, f"array passed to `{ba.param.name}` of {node.binding.pou.name}")
        elif isinstance(node, A.Assign) and node.target.ty is not None and node.value.ty is not None and \
                isinstance(T.unalias(node.target.ty), T.ArrayType) and (
                    _anonymous_array(node.target.ty) or _anonymous_array(node.value.ty)):
            _warn(ctx, node.span, "whole array assigned")
