"""Declaration pass: data types, POU interfaces and global variables into the symbol tables.

Runs before any body is checked, so declarations may appear in any order and any file.
"""
from __future__ import annotations

from collections.abc import Mapping

from ..frontend import ast as A
from ..frontend import codes
from ..frontend import types as T
from ..frontend.builtins import default_string
from . import at_address, data_size, duplicates, undeclared, union_member
from .consteval import const_int
from .context import Context, NamespaceView, Unit
from .scope import GENERIC_TYPES, Ambiguous
from .symbols import VarSymbol

PARAM_DIRECTION = {"VAR_INPUT": "in", "VAR_OUTPUT": "out", "VAR_IN_OUT": "inout"}


class Declarer:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.tables = ctx.tables
        self.meter = data_size.Meter(ctx)

    # ---- pass 1: names --------------------------------------------------------------------------
    def register(self, file_unit: A.CompilationUnit) -> None:
        views: dict[str, NamespaceView] = {}
        unit: A.CompilationUnit | NamespaceView
        for item in file_unit.items:
            inner = getattr(item, "declared_namespace", None)
            if inner:
                # an item of a NAMESPACE block: its namespace is nested in the file's (a library folder's)
                self.ctx.note_edition3("NAMESPACE (3rd edition)", getattr(item, "name_span", None) or item.span)
                full = f"{file_unit.namespace}\\{inner}" if file_unit.namespace else inner
                unit = views.get(full) or views.setdefault(full, NamespaceView(file_unit, full))
            else:
                unit = file_unit
            ns = unit.namespace
            if isinstance(item, A.TypeBlock):
                for decl in item.decls:
                    decl.namespace = ns
                    shell = self.shell_type(decl, ns)
                    prev = self.tables.types.add(ns, decl.name, shell)
                    if prev is not None or decl.name.upper() in T.ELEMENTARY:
                        duplicates.report(self.ctx, "data type", decl.name, decl.name_span, prev)
                    else:
                        self.ctx.type_decls.append((decl, shell, unit))
            elif isinstance(item, A.Pou):
                item.namespace = ns
                kind = {"FUNCTION": "function", "FUNCTION_BLOCK": "fb", "PROGRAM": "program"}[item.kind]
                pt = T.PouType(item.name, kind, pou=item, native=item.native, namespace=ns)
                item.sym = pt
                prev = self.tables.pous.add(ns, item.name, pt)
                if prev is not None:
                    duplicates.report(self.ctx, item.kind, item.name, item.name_span or item.span, prev)
                elif self.tables.types.entries.get(((ns or "").upper(), item.name.upper())) is not None:
                    duplicates.report(self.ctx, item.kind, item.name, item.name_span or item.span, None)
                self.ctx.pou_units.append((item, unit))
            elif isinstance(item, A.GlobalVarList):
                item.namespace = ns
                self.ctx.global_lists.append((item, unit))
            elif isinstance(item, A.Configuration):
                self.ctx.configurations.append((item, unit))

    def shell_type(self, decl: A.TypeDecl, ns: str | None) -> T.Type:
        spec = decl.spec
        if isinstance(spec, A.StructTypeRef):
            return T.StructType(decl.name, decl=decl, namespace=ns, kind="union" if spec.union else "struct")
        if isinstance(spec, A.EnumTypeRef):
            return T.EnumType(decl.name, decl=decl, namespace=ns)
        return T.AliasType(decl.name, decl=decl, namespace=ns)

    # ---- pass 2: bodies of type declarations -------------------------------------------------
    def complete_types(self) -> None:
        for decl, shell, unit in self.ctx.type_decls:
            if isinstance(shell, T.EnumType) and isinstance(decl.spec, A.EnumTypeRef):      # see shell_type()
                self.fill_enum(shell, decl.spec, unit)
        for decl, shell, unit in self.ctx.type_decls:
            if isinstance(shell, T.StructType) and isinstance(decl.spec, A.StructTypeRef):
                self.fill_struct(shell, decl.spec, unit)
            elif isinstance(shell, T.AliasType):
                shell.target = self.resolve(decl.spec, unit, None)
                if isinstance(decl.spec, A.SubrangeTypeRef) and isinstance(shell.target, T.SubrangeType):
                    shell.target.alias = decl.name
        self.struct_cycles()
        for decl, shell, _unit in self.ctx.type_decls:   # alias cycles
            if isinstance(shell, T.AliasType):
                seen: set[int] = set()
                t: T.Type = shell
                while isinstance(t, T.AliasType):
                    if id(t) in seen:
                        self.ctx.diags.error(codes.UNKNOWN_TYPE, f"data type {decl.name} is defined in terms of itself",
                                             decl.name_span)
                        shell.target = T.ERROR
                        break
                    seen.add(id(t))
                    t = t.target

    def fill_enum(self, enum: T.EnumType, spec: A.EnumTypeRef, unit: Unit) -> None:
        if spec.base is not None:
            base = self.resolve(spec.base, unit, None)
            if T.is_int(base):
                enum.base = T.base_of(base)
        next_value = 0
        for v in spec.values:
            if v.value is not None:
                val = const_int(v.value, self.ctx, None)
                if val is None:
                    self.ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                         f"the value of {v.name} must be a constant integer", v.value.span)
                else:
                    next_value = val
            if enum.lookup(v.name) is not None:
                duplicates.report(self.ctx, "enumeration value", v.name, v.span, None)
                continue
            enum.values[v.name] = next_value
            next_value += 1
        self.tables.add_enum(enum)

    def struct_cycles(self) -> None:
        """ST1004 for structures that contain themselves through other structures or arrays (A has a B, B has an
        A): such a value would be infinitely large. Reported once per cycle, at the member that closes it."""
        def contained(t: T.Type) -> T.StructType | None:
            t = T.unalias(t)
            while isinstance(t, T.ArrayType):
                t = T.unalias(t.element)
            return t if isinstance(t, T.StructType) else None

        reported = set()
        for _decl, shell, _unit in self.ctx.type_decls:
            if not isinstance(shell, T.StructType) or id(shell) in reported:
                continue
            path, stack, visited = [shell], [iter(list(shell.fields.values()))], {id(shell)}
            while stack:
                f = next(stack[-1], None)
                if f is None:
                    stack.pop()
                    path.pop()
                    continue
                inner = contained(f.type)
                if inner is None:
                    continue
                if inner is shell:
                    names = " → ".join(t.name for t in path + [shell])
                    self.ctx.diags.error(codes.UNKNOWN_TYPE, f"structure {shell.name} contains itself ({names}, member "
                                         f"{f.name}); a value of it would be infinitely large", f.decl.name_span)
                    for t in path:
                        reported.add(id(t))
                    f.type = T.ERROR
                    break
                if id(inner) not in visited:
                    visited.add(id(inner))
                    path.append(inner)
                    stack.append(iter(list(inner.fields.values())))

    def fill_struct(self, st: T.StructType, spec: A.StructTypeRef, unit: Unit) -> None:
        for f in spec.fields:
            ftype = self.resolve(f.type, unit, None)
            if ftype is st:
                self.ctx.diags.error(codes.UNKNOWN_TYPE,
                                     f"structure {st.name} cannot contain itself (member {f.name})", f.name_span)
                ftype = T.ERROR
            if st.field(f.name) is not None:
                duplicates.report(self.ctx, "member", f.name, f.span, None)
                continue
            st.fields[f.name.upper()] = T.StructField(f.name, ftype, f.init, f)
            if st.kind == "union":
                union_member.check(self.ctx, st, f, ftype)
        if st.kind == "union":
            self.ctx.note_edition3("UNION (a Sysmac extension)", spec.span)

    # ---- type references ----------------------------------------------------------------------
    def resolve(self, ref: A.TypeRef, unit: Unit, scope: Mapping[str, VarSymbol | None] | None) -> T.Type:
        """Turn a syntactic type into a semantic type; unknown names are reported (ST1004)."""
        ctx = self.ctx
        if isinstance(ref, A.NamedTypeRef):
            name = ref.name
            up = name.name.upper()
            if not name.namespace:
                if up in T.ELEMENTARY:
                    if up.startswith("L") and up not in ("LINT", "LREAL", "LWORD"):
                        ctx.note_edition3(f"the type {name.name}", ref.span)
                    return T.ELEMENTARY[up]
                if up in GENERIC_TYPES and unit is not None and getattr(unit, "in_prelude", False):
                    return GENERIC_TYPES[up]
            try:
                found = self.tables.types.lookup(name.name, name.namespace, unit.namespace if unit else None)
                if found is None:
                    found = self.tables.pous.lookup(name.name, name.namespace, unit.namespace if unit else None)
                    if found is not None and found.kind == "function":
                        ctx.diags.error(codes.UNKNOWN_TYPE, f"{found.name} is a FUNCTION, not a type; only function "
                                        "blocks can be instantiated", ref.span)
                        return T.ERROR
            except Ambiguous as amb:
                undeclared.report_ambiguous(ctx, name.text(), amb.candidates, ref.span)
                return T.ERROR
            if found is None:
                undeclared.report_type(ctx, name.text(), ref.span)
                return T.ERROR
            ctx.note_vendor(found, ref.span)
            return found
        if isinstance(ref, A.StringTypeRef):
            if ref.length is None:
                return default_string(ctx.dialect, ref.wide)
            n = const_int(ref.length, ctx, scope)
            if n is None or n < 1:
                ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                "the string length must be a positive constant integer", ref.length.span)
                return default_string(ctx.dialect, ref.wide)
            cap = n - 1 if ctx.dialect == "sysmac" else n
            return T.StringType(n, ref.wide, capacity=cap)
        if isinstance(ref, A.ArrayTypeRef):
            dims: list[tuple[int | None, int | None]] = []
            for d in ref.dims:
                if d.lo is None:
                    ctx.note_edition3("an open array bound `ARRAY[*]`", d.span)
                    dims.append((None, None))
                    continue
                lo, hi = const_int(d.lo, ctx, scope), const_int(d.hi, ctx, scope)
                if lo is None or hi is None:
                    ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE, "array bounds must be constant integers", d.span)
                    lo, hi = 0, 0
                elif hi < lo:
                    ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                    f"array upper bound {hi} is below the lower bound {lo}", d.span)
                    hi = lo
                dims.append((lo, hi))
            return T.ArrayType(dims, self.resolve(ref.element, unit, scope))
        if isinstance(ref, A.SubrangeTypeRef):
            base = T.base_of(self.resolve(ref.base, unit, scope))
            lo, hi = const_int(ref.lo, ctx, scope), const_int(ref.hi, ctx, scope)
            if not isinstance(base, T.ElementaryType) or not T.is_int(base) or lo is None or hi is None or hi < lo:
                ctx.diags.error(codes.CONSTANT_OUT_OF_RANGE,
                                "a subrange needs an integer base type and constant bounds lo..hi",
                                ref.span)
                return base if T.is_int(base) else T.ERROR
            return T.SubrangeType(base, lo, hi)
        if isinstance(ref, A.EnumTypeRef):
            enum = T.EnumType("(" + ", ".join(v.name for v in ref.values) + ")")
            self.fill_enum(enum, ref, unit)
            return enum
        if isinstance(ref, A.StructTypeRef):
            st = T.StructType("UNION" if ref.union else "STRUCT", kind="union" if ref.union else "struct")
            self.fill_struct(st, ref, unit)
            return st
        return T.ERROR

    # ---- pass 3: POU interfaces and globals ---------------------------------------------------
    def complete_pous(self) -> None:
        for pou, unit in self.ctx.pou_units:
            pt: T.PouType = pou.sym
            if pou.kind == "FUNCTION":
                pt.ret = self.resolve(pou.return_type, unit, None) if pou.return_type else T.VOID
            else:
                pt.ret = T.VOID
            index = 0
            consts = {d.name.upper(): VarSymbol(d.name, T.ERROR, s.kind, constant=True, decl=d)
                      for s in pou.sections if s.constant for d in s.vars}
            for section in pou.sections:
                direction = PARAM_DIRECTION.get(section.kind)
                for decl in section.vars:
                    vt = self.resolve(decl.type, unit, consts)
                    sym = VarSymbol(decl.name, vt, section.kind, pt, decl, section.constant, section.retain)
                    decl.sym = sym
                    at_address.check_local(self.ctx, decl)
                    if direction:
                        pt.params.append(T.Param(decl.name, direction, vt, index, decl.init, decl))
                        index += 1
        self.meter.check_pous([pou.sym for pou, _unit in self.ctx.pou_units])

    def declare_globals(self, sections: list[A.VarSection], unit: Unit, list_name: str | None) -> None:
        for section in sections:
            if section.kind != "VAR_GLOBAL":
                self.ctx.diags.error(codes.STRAY_TEXT,
                                     f"{section.kind} is not allowed here; only VAR_GLOBAL sections may "
                                     "appear outside a POU", section.span)
                continue
            for decl in section.vars:
                vt = self.resolve(decl.type, unit, None)
                sym = VarSymbol(decl.name, vt, "VAR_GLOBAL", None, decl, section.constant, section.retain,
                                global_list=list_name)
                decl.sym = sym
                sym.at_address = at_address.check_global(self.ctx, decl, vt)
                self.meter.check_global(decl, sym)
                if getattr(unit, "vendor", False):           # Sysmac system-defined variables (P_On ...)
                    self.ctx.vendor_objects.add(id(sym))
                prev = self.tables.globals.get(decl.name.upper())
                if prev is not None:
                    duplicates.report(self.ctx, "global variable", decl.name, decl.name_span, prev)
                    continue
                self.tables.globals[decl.name.upper()] = sym
