"""AST of IEC 61131-3 Structured Text (with the Omron Sysmac dialect).

Every node has a ``span`` (see :mod:`vplc.frontend.source`). Spans and checker annotations are excluded from
equality, so two parses of equivalent text compare equal (used by the printer round-trip test).

Checker annotations (set by :mod:`vplc.checker`, ``None`` before checking), documented in
docs/toolchain/frontend_api.md:

* every :class:`Expr` gets ``ty`` (its resolved :mod:`vplc.frontend.types` type) and ``conv`` (the type it is
  implicitly widened to by its context, or ``None``); ``sysmac_ty`` is Sysmac's integer type of an expression
  vplc computes in LREAL (W501 6-106), or ``None``;
* :class:`Name` gets ``sym`` (a :mod:`vplc.checker.symbols` symbol);
* :class:`Call` gets ``binding`` (a :class:`vplc.checker.symbols.CallBinding`).
"""
from __future__ import annotations

from collections.abc import Iterator
from dataclasses import KW_ONLY, dataclass, field
from typing import Any

from .source import Span


def _ann(default: Any = None) -> Any:
    return field(default=default, compare=False, repr=False)


@dataclass(eq=True)
class Node:
    """Base of all nodes."""


class InNamespace:
    """A top-level item the parser found inside NAMESPACE blocks: ``declared_namespace`` is their names joined
    with backslashes (None outside any). Not a dataclass field: it takes no part in equality or the AST dumps."""
    declared_namespace: str | None = None


class ArrayOutputMark:
    """Set by the checker on ``instance.Output`` when that output is an array: ``fb_array_output`` names it
    (``FbType.Output``) for the rule on indexing it (ST1008). Not a dataclass field."""
    fb_array_output: str | None = None


class LoadedFrom:
    """Where the loader (vplc.project) found a file: ``in_prelude`` for the prelude every project sees,
    ``vendor`` for its Sysmac files (their objects are the vendor's). Not dataclass fields."""
    in_prelude: bool = False
    vendor: bool = False


# ----------------------------------------------------------------------------------------------
# Names and type references
# ----------------------------------------------------------------------------------------------

@dataclass(eq=True)
class QualName(Node):
    """``Name``, ``Ns\\Name`` or ``\\\\Ns\\\\Name``: ``namespace`` holds the qualifier parts."""
    name: str
    namespace: tuple[str, ...] = ()
    span: Span = _ann()

    def text(self) -> str:
        return "\\".join((*self.namespace, self.name))


@dataclass(eq=True)
class TypeRef(Node):
    """Base of the syntactic type specifications."""


@dataclass(eq=True)
class NamedTypeRef(TypeRef):
    """An elementary, user or library type by name (``INT``, ``stCBT_Connection``, ``Ns\\T``)."""
    name: QualName
    span: Span = _ann()


@dataclass(eq=True)
class StringTypeRef(TypeRef):
    """``STRING``, ``STRING[n]``, ``STRING(n)``, ``WSTRING[n]``; ``length`` is None when not given."""
    wide: bool
    length: Expr | None
    span: Span = _ann()


@dataclass(eq=True)
class DimRange(Node):
    """One array dimension ``lo..hi``; both None for an open dimension ``*``."""
    lo: Expr | None
    hi: Expr | None
    span: Span = _ann()


@dataclass(eq=True)
class ArrayTypeRef(TypeRef):
    dims: list[DimRange]
    element: TypeRef
    span: Span = _ann()


@dataclass(eq=True)
class SubrangeTypeRef(TypeRef):
    """``INT(0..100)``."""
    base: TypeRef
    lo: Expr
    hi: Expr
    span: Span = _ann()


@dataclass(eq=True)
class EnumValueDecl(Node):
    name: str
    value: Expr | None
    span: Span = _ann()

    @property
    def name_span(self) -> Span:
        """Span of the declared name only (diagnostics point here)."""
        return Span(self.span.file, self.span.start, self.span.start + len(self.name))


@dataclass(eq=True)
class EnumTypeRef(TypeRef):
    """``(A, B := 5, C)`` optionally followed by a base type (``(A, B) INT`` / ``INT (A, B)``)."""
    values: list[EnumValueDecl]
    base: TypeRef | None = None
    span: Span = _ann()


@dataclass(eq=True)
class StructTypeRef(TypeRef):
    """STRUCT ... END_STRUCT, or UNION ... END_UNION (``union``: the members share one memory image, W501)."""
    fields: list[VarDecl]
    span: Span = _ann()
    union: bool = False


# ----------------------------------------------------------------------------------------------
# Expressions
# ----------------------------------------------------------------------------------------------

@dataclass(eq=True)
class Expr(Node):
    _: KW_ONLY
    span: Span = _ann()
    ty: Any = _ann()     # resolved type (vplc.frontend.types.Type), set by the checker
    conv: Any = _ann()   # implicit conversion target type, or None
    sysmac_ty: Any = _ann()   # Sysmac's type of an expression vplc computes in LREAL (W501 6-106), or None


@dataclass(eq=True)
class Literal(Expr):
    """A literal. ``kind`` is one of int, real, bool, string, wstring, time, ltime, date, tod, dt.

    ``value``: int/float/bool/str; durations are int nanoseconds; DATE/DT are int seconds since
    1970-01-01 (DT may carry a fraction: nanoseconds in an int); TOD is int nanoseconds since midnight.
    ``type_prefix`` is the typed-literal prefix (``INT`` in ``INT#5``) or None. ``text`` is the source text.
    """
    kind: str
    value: Any
    type_prefix: str | None = None
    text: str = ""


@dataclass(eq=True)
class Name(Expr):
    """A (possibly namespace-qualified) name: variable, global, POU, or bare enum value."""
    name: QualName
    sym: Any = _ann()


@dataclass(eq=True)
class EnumLiteral(Expr):
    """``Type#Value`` or ``Ns\\Type#Value``; ``type_name`` is None for ``#Value`` forms never produced."""
    type_name: QualName
    value: str
    sym: Any = _ann()


@dataclass(eq=True)
class Member(Expr, ArrayOutputMark):
    """``base.member``."""
    base: Expr
    member: str
    sym: Any = _ann()


@dataclass(eq=True)
class BitAccess(Expr):
    """``base.3`` (bit of an integer / bit-string variable)."""
    base: Expr
    bit: int


@dataclass(eq=True)
class Index(Expr):
    """``base[i, j]``."""
    base: Expr
    indices: list[Expr]


@dataclass(eq=True)
class Unary(Expr):
    """``op`` is '-', '+' or 'NOT'."""
    op: str
    operand: Expr


@dataclass(eq=True)
class Binary(Expr):
    """``op`` is one of OR XOR AND = <> < > <= >= + - * / MOD ** ('&' is normalised to AND)."""
    op: str
    left: Expr
    right: Expr


@dataclass(eq=True)
class Arg(Node):
    """One call argument: ``value`` (non-formal), ``name := value``, ``name => value`` (output=True),
    ``NOT name => value`` (negated output)."""
    name: str | None
    value: Expr | None
    output: bool = False
    negated: bool = False
    span: Span = _ann()


@dataclass(eq=True)
class Call(Expr):
    """A function call, or an FB instance call when used as a statement (:class:`CallStmt`)."""
    callee: Expr
    args: list[Arg]
    binding: Any = _ann()


@dataclass(eq=True)
class ArrayInit(Expr):
    """``[1, 2, 3(0)]``: items are :class:`InitItem`."""
    items: list[InitItem]


@dataclass(eq=True)
class InitItem(Node):
    """One array-initializer element, ``repeat(value)`` when ``repeat`` is set (``3(0)``, ``2()``)."""
    value: Expr | None
    repeat: Expr | None = None
    span: Span = _ann()


@dataclass(eq=True)
class StructInit(Expr):
    """``(X := 1.0, Y := 2.0)``."""
    fields: list[FieldInit]


@dataclass(eq=True)
class FieldInit(Node):
    name: str
    value: Expr
    span: Span = _ann()


# ----------------------------------------------------------------------------------------------
# Statements
# ----------------------------------------------------------------------------------------------

@dataclass(eq=True)
class Stmt(Node):
    _: KW_ONLY
    span: Span = _ann()


@dataclass(eq=True)
class Assign(Stmt):
    target: Expr
    value: Expr


@dataclass(eq=True)
class CallStmt(Stmt):
    call: Call


@dataclass(eq=True)
class IfBranch(Node):
    cond: Expr
    body: list[Stmt]
    span: Span = _ann()


@dataclass(eq=True)
class If(Stmt):
    branches: list[IfBranch]       # IF then ELSIFs, in order
    else_body: list[Stmt] | None = None


@dataclass(eq=True)
class CaseRange(Node):
    """A case label ``lo..hi``."""
    lo: Expr
    hi: Expr
    span: Span = _ann()


@dataclass(eq=True)
class CaseBranch(Node):
    labels: list[Expr | CaseRange]
    body: list[Stmt]
    span: Span = _ann()


@dataclass(eq=True)
class Case(Stmt):
    selector: Expr
    branches: list[CaseBranch]
    else_body: list[Stmt] | None = None


@dataclass(eq=True)
class For(Stmt):
    var: Name
    start: Expr
    end: Expr
    step: Expr | None
    body: list[Stmt]


@dataclass(eq=True)
class While(Stmt):
    cond: Expr
    body: list[Stmt]


@dataclass(eq=True)
class Repeat(Stmt):
    body: list[Stmt]
    cond: Expr


@dataclass(eq=True)
class Exit(Stmt):
    pass


@dataclass(eq=True)
class Continue(Stmt):
    pass


@dataclass(eq=True)
class Return(Stmt):
    pass


@dataclass(eq=True)
class Empty(Stmt):
    """A lone ``;``."""


# ----------------------------------------------------------------------------------------------
# Declarations
# ----------------------------------------------------------------------------------------------

SECTION_KINDS = ("VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL",
                 "VAR_EXTERNAL", "VAR_STAT")


@dataclass(eq=True)
class VarDecl(Node):
    """One declared name (``a, b : INT`` yields two VarDecls sharing ``type``)."""
    name: str
    type: TypeRef
    init: Expr | None = None
    at: str | None = None          # ``AT %MW10`` location text, kept but not interpreted
    span: Span = _ann()
    sym: Any = _ann()

    @property
    def name_span(self) -> Span:
        """Span of the declared name only (diagnostics point here)."""
        return Span(self.span.file, self.span.start, self.span.start + len(self.name))


@dataclass(eq=True)
class VarSection(Node):
    kind: str                      # one of SECTION_KINDS
    vars: list[VarDecl]
    constant: bool = False
    retain: bool = False
    persistent: bool = False
    span: Span = _ann()


@dataclass(eq=True)
class TypeDecl(Node):
    """``Name : <spec> [:= init];`` inside TYPE ... END_TYPE."""
    name: str
    spec: TypeRef
    init: Expr | None = None
    span: Span = _ann()
    namespace: str | None = _ann()   # set by the loader from the library folder

    @property
    def name_span(self) -> Span:
        """Span of the declared name only (diagnostics point here)."""
        return Span(self.span.file, self.span.start, self.span.start + len(self.name))


@dataclass(eq=True)
class TypeBlock(Node, InNamespace):
    decls: list[TypeDecl]
    span: Span = _ann()


@dataclass(eq=True)
class Pou(Node, InNamespace):
    """FUNCTION, FUNCTION_BLOCK or PROGRAM."""
    kind: str                      # 'FUNCTION' | 'FUNCTION_BLOCK' | 'PROGRAM'
    name: str
    return_type: TypeRef | None
    sections: list[VarSection]
    body: list[Stmt]
    pragmas: list[str] = field(default_factory=list)
    span: Span = _ann()
    name_span: Span = _ann()
    namespace: str | None = _ann()   # set by the loader from the library folder
    native: bool = _ann(False)       # True when implemented in Python by the runtime (prelude {native})
    sym: Any = _ann()


@dataclass(eq=True)
class GlobalVarList(Node, InNamespace):
    """Top-level VAR_GLOBAL sections of a file (a global variable list); ``name`` is the file stem."""
    sections: list[VarSection]
    name: str | None = None
    span: Span = _ann()
    namespace: str | None = _ann()


@dataclass(eq=True)
class TaskDecl(Node):
    """``TASK Name(INTERVAL := T#10ms, PRIORITY := 1, SINGLE := x);``; ``props`` maps upper-case keys."""
    name: str
    props: list[FieldInit]
    span: Span = _ann()


@dataclass(eq=True)
class ProgramInstance(Node):
    """``PROGRAM Inst WITH Task : ProgType (args);``."""
    name: str
    task: str | None
    program: QualName
    args: list[Arg] = field(default_factory=list)
    span: Span = _ann()
    binding: Any = _ann()     # CallBinding of the args (kind 'program'), set by the checker


@dataclass(eq=True)
class Resource(Node):
    name: str | None               # None: the implicit resource of a configuration without RESOURCE
    on: str | None
    sections: list[VarSection]
    tasks: list[TaskDecl]
    programs: list[ProgramInstance]
    span: Span = _ann()


@dataclass(eq=True)
class Configuration(Node, InNamespace):
    """CONFIGURATION ... END_CONFIGURATION. Programs/tasks written directly in the configuration
    (without RESOURCE) are put in one implicit resource with ``name`` None."""
    name: str
    sections: list[VarSection]
    resources: list[Resource]
    span: Span = _ann()


Item = TypeBlock | Pou | GlobalVarList | Configuration


@dataclass(eq=True)
class CompilationUnit(Node, LoadedFrom):
    """One source file. ``comments``: (style, start, end) of every comment, style "(*", "/*" or "//"."""
    items: list[Item]
    span: Span = _ann()
    namespace: str | None = _ann()
    comments: list = _ann(None)


def iter_children(node: Node) -> Iterator[Node]:
    """Yield the direct child nodes of ``node`` (used by generic walkers)."""
    for name in node.__dataclass_fields__:
        if name in ("span", "ty", "conv", "sym", "binding", "name_span"):
            continue
        value = getattr(node, name)
        if isinstance(value, Node):
            yield value
        elif isinstance(value, list):
            for v in value:
                if isinstance(v, Node):
                    yield v


def walk(node: Node) -> Iterator[Node]:
    """Depth-first pre-order walk, iterative (safe on very deep trees)."""
    stack = [node]
    while stack:
        n = stack.pop()
        yield n
        children = list(iter_children(n))
        stack.extend(reversed(children))
