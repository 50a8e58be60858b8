"""ST1502 — a variable, a POU's instance data or the global variables hold more values than vplc models.

The virtual controller keeps every value of a program in memory. A type is measured in *cells*: one per
elementary value or string, plus one per array, structure and function-block instance that holds them (the
containers cost memory too: ``ARRAY[0..1] OF ARRAY[0..1] OF …`` nested 30 deep is 2^30 values in 2^30 arrays).
A variable may hold at most ``MAX_CELLS``; so may one POU's instance data (all its variables together) and
all global variables together. The limit is vplc's choice (a controller's own limits are per model, in its
memory sizes); it is far above any data an NJ/NX program declares, and it keeps a run within a few hundred
megabytes.

Passing::

    Buffer : ARRAY[0..65535] OF BYTE;

Failing::

    Grid : ARRAY[0..1] OF ARRAY[0..1] OF … (30 levels) … OF INT;    (* ST1502: 2,147,483,647 cells *)
"""
from __future__ import annotations

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from ..frontend.source import Span
from .context import Context
from .symbols import VarSymbol

MAX_CELLS = 4 * 1024 * 1024


def cells(t: T.Type, memo: dict) -> int:
    return T.value_cells(t, MAX_CELLS, memo)


def _report(ctx: Context, what: str, n: int, span: Span) -> None:
    size = f"{n:,} cells" if n <= MAX_CELLS else f"more than {MAX_CELLS:,} cells"
    ctx.diags.error(codes.DATA_TOO_LARGE,
                    f"{what} holds {size} (values plus the arrays, structures and instances that hold "
                    f"them); vplc models at most {MAX_CELLS:,}: make the arrays smaller", span)


class Meter:
    """Measures the declarations of one project as the declaration pass completes them."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.memo: dict = {}
        self.global_total = 0
        self.global_reported = False

    def check_pous(self, pous: list[T.PouType]) -> None:
        """Each variable of each POU (``pous``: PouTypes), then a program's or FB's instance data as a whole."""
        for pt in pous:
            pou = pt.pou
            if pou is None:
                continue
            total, reported = 1, False
            for section in pou.sections:
                if section.kind not in T.INSTANCE_SECTIONS:
                    continue
                for decl in section.vars:
                    sym = getattr(decl, "sym", None)
                    if sym is None:
                        continue
                    n = cells(sym.type, self.memo)
                    if n > MAX_CELLS:
                        _report(self.ctx, f"`{decl.name}`", n, decl.name_span)
                        reported = True
                    total += n
            if total > MAX_CELLS and not reported and pou.kind != "FUNCTION":
                _report(self.ctx, f"the instance data of {pou.kind} `{pou.name}`", total, pou.name_span or pou.span)

    def check_global(self, decl: A.VarDecl, sym: VarSymbol) -> None:
        """One global variable, and the running total of all global variables."""
        n = cells(sym.type, self.memo)
        if n > MAX_CELLS:
            _report(self.ctx, f"`{decl.name}`", n, decl.name_span)
            return
        self.global_total += n
        if self.global_total > MAX_CELLS and not self.global_reported:
            self.global_reported = True
            _report(self.ctx, f"the global variables up to `{decl.name}`", self.global_total, decl.name_span)
