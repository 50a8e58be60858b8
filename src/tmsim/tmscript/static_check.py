"""Static check of a TM script, as the robot does before running it.

A script is accepted only when every line passes: known function, a matching overload (arity and
value types), a data-format string valid for that function, declared variables, no redeclaration,
writable targets, no call without a value (``void``: Sleep, WaitQueueTag()) inside an expression. Lines
that pass but lose information (float into an int parameter, unquoted IO module name) are *warnings*
(``OK;lines``). Argument *values* (speed 500 %, tag 99, Sleep(1e30) ...) are not checked here: like on
the robot they fail at run time.
"""
from __future__ import annotations

from tmsim.tmscript import functions as table
from tmsim.tmscript import parser as ast

F, I, S, B, FA, IA, ANY, VOID = "float", "int", "string", "bool", "float[]", "int[]", "any", "void"  # noqa: E741 (as functions.py)


class CheckError(Exception):
    """A rule violation on one line."""


def check_script(lines: list[ast.Line], variables: dict[str, str], version: str = table.V224) -> dict[str, str]:
    """Check every line in place (sets ``line.error`` / ``line.warnings``) against the function set of
    TMflow ``version`` (tmsim.tmscript.functions: a function, format or attribute of another version is unknown).

    ``variables`` are the node-session variables (name -> type). Returns the variables the script
    would declare; the caller adds them only if the script runs.
    """
    checker = ScriptChecker(variables, version)
    for line in lines:
        checker.check(line)
    return checker.declared


class ScriptChecker:
    """``check_script`` one line at a time, in script order (the session spreads a long script's checking
    over several turns of the scheduler)."""

    def __init__(self, variables: dict[str, str], version: str = table.V224):
        self.variables = variables
        self.version = version
        self.scope = dict(variables)
        self.declared: dict[str, str] = {}

    def check(self, line: ast.Line) -> None:
        if line.error:
            return
        checker = _LineChecker(self.scope, line.warnings, self.version)
        try:
            checker.statement(line.stmt)
        except CheckError as exc:
            line.error = str(exc)
        if isinstance(line.stmt, ast.Decl) and line.stmt.name not in self.variables:
            var_type = line.stmt.type + ("[]" if line.stmt.is_array else "")
            self.scope[line.stmt.name] = var_type
            self.declared[line.stmt.name] = var_type


def _assignable(target: str, value: str) -> str | None:
    """'' when assignable, 'warn' for a lossy conversion, None when not assignable."""
    if target in (ANY, value) or value == ANY:
        return ""
    numeric = ("int", "float", "byte")
    if target in numeric and value in numeric:
        return "warn" if (target in ("int", "byte") and value == "float") else ""
    if target.endswith("[]") and value.endswith("[]"):
        return _assignable(target[:-2], value[:-2])
    return None


class _LineChecker:
    def __init__(self, scope, warnings, version):
        self.scope = scope
        self.warnings = warnings
        self.version = version

    def warn(self, text):
        if text not in self.warnings:
            self.warnings.append(text)

    def statement(self, stmt):
        if isinstance(stmt, ast.Empty):
            return
        if isinstance(stmt, ast.Decl):
            if stmt.name in self.scope:
                raise CheckError(f"variable '{stmt.name}' is already declared")
            if stmt.init is not None:
                self.convert(stmt.type + ("[]" if stmt.is_array else ""), self.expr(stmt.init), "initial value")
            return
        if isinstance(stmt, ast.Assign):
            target = self.target(stmt.target)
            value = self.expr(stmt.value)
            if stmt.op != "=" and target not in ("int", "float", "byte", "string"):
                raise CheckError(f"operator '{stmt.op}' needs a numeric variable")
            self.convert(target, value, "assigned value")
            return
        if isinstance(stmt, ast.IncDec):
            if self.target(stmt.target) not in ("int", "float", "byte"):
                raise CheckError(f"'{stmt.op}' needs a numeric variable")
            return
        if isinstance(stmt, ast.ExprStmt):
            if not isinstance(stmt.expr, ast.Call):
                raise CheckError("a statement must be a function call, a declaration or an assignment")
            self.call(stmt.expr)                 # the one place a call without a value may stand
            return
        raise CheckError("unsupported statement")

    def convert(self, target, value, what):
        result = _assignable(target, value)
        if result is None:
            raise CheckError(f"{what} of type {value} does not fit type {target}")
        if result == "warn":
            self.warn(f"{what}: {value} truncated to {target}")

    def target(self, node):
        if isinstance(node, ast.Name):
            if node.id not in self.scope:
                raise CheckError(f"variable '{node.id}' is not declared")
            return self.scope[node.id]
        io = self.io_point(node)
        if io is not None:
            member, kind = io
            if not table.IO_POINTS[member][1]:
                raise CheckError(f"IO point {member} is read-only")
            return kind
        if self.io_array(node) is not None:
            raise CheckError(f"IO[...].{node.name} as a whole is read-only: write one point, e.g. {node.name}[0]")
        if isinstance(node, ast.Member) and _is_robot(node.obj):
            kind, writable = self.robot_member(node.name)
            if not writable:
                raise CheckError(f"Robot[0].{node.name} is read-only")
            return kind
        if isinstance(node, ast.Index) and isinstance(node.obj, ast.Name):
            base = self.target(node.obj)
            if not base.endswith("[]"):
                raise CheckError(f"variable '{node.obj.id}' is not an array")
            self.index(node.index)
            return base[:-2]
        raise CheckError("this expression cannot be assigned to")

    def robot_member(self, name):
        """(type, writable) of Robot[0].name in this version (TMscript 2.24 §11.6)."""
        entry = table.ROBOT.get(name)
        if entry is None or self.version not in entry[2]:
            raise CheckError(f"unknown Robot member '{name}'")
        return entry[0], entry[1]

    def io_array(self, node):
        """Element type of a whole IO array IO["Module"].MEMBER (2.x, read only), else None."""
        if not (isinstance(node, ast.Member) and isinstance(node.obj, ast.Index)
                and isinstance(node.obj.obj, ast.Name) and node.obj.obj.id == "IO"):
            return None
        if self.version not in table.IO_WHOLE_ARRAYS:
            raise CheckError(f"IO[...].{node.name} needs an index in TMflow {self.version}")
        self.io_module(node.obj.index)
        if node.name not in table.IO_POINTS:
            raise CheckError(f"unknown IO member '{node.name}'")
        return table.IO_POINTS[node.name][0]

    def io_module(self, module):
        if isinstance(module, ast.Name):
            self.warn("IO module name without quotes")
            name = module.id
        elif isinstance(module, ast.Str):
            name = module.value
        else:
            raise CheckError("IO module must be a name such as \"ControlBox\"")
        if name not in table.IO_MODULES:
            raise CheckError(f"unknown IO module '{name}'")
        return name

    def io_point(self, node):
        """(member, type) for IO["Module"].MEMBER[n], else None."""
        if not (isinstance(node, ast.Index) and isinstance(node.obj, ast.Member)):
            return None
        member = node.obj
        if not (isinstance(member.obj, ast.Index) and isinstance(member.obj.obj, ast.Name)
                and member.obj.obj.id == "IO"):
            return None
        self.io_module(member.obj.index)
        if member.name not in table.IO_POINTS:
            raise CheckError(f"unknown IO member '{member.name}'")
        self.index(node.index)
        return member.name, table.IO_POINTS[member.name][0]

    def index(self, node):
        if self.expr(node) not in ("int", "byte"):
            raise CheckError("an index must be an integer")

    def expr(self, node) -> str:
        if isinstance(node, ast.Num):
            return F if node.is_float else I
        if isinstance(node, ast.Str):
            return S
        if isinstance(node, ast.Bool):
            return B
        if isinstance(node, ast.Name):
            if node.id in ("IO", "Robot"):
                raise CheckError(f"'{node.id}' must be indexed")
            if node.id not in self.scope:
                raise CheckError(f"variable '{node.id}' is not declared")
            return self.scope[node.id]
        if isinstance(node, ast.Array):
            kinds = [self.expr(item) for item in node.items]
            if any(k.endswith("[]") for k in kinds):
                raise CheckError("arrays cannot be nested")
            if kinds and all(k == S for k in kinds):
                return "string[]"
            if any(k in (S, B) for k in kinds):
                raise CheckError("array elements must all be numbers")
            return FA if F in kinds else IA
        if isinstance(node, ast.Call):
            kind = self.call(node)
            if kind == VOID:                     # [MAN 2.24 §13.2 syntax 3] "void WaitQueueTag()": no return
                raise CheckError(f"{node.name}() returns no value: it cannot be used in an expression, "
                                 f"an argument or an assignment")
            return kind
        if isinstance(node, ast.Unary):
            kind = self.expr(node.operand)
            if node.op == "!":
                return B
            if kind not in (I, F, "byte"):
                raise CheckError("'-' needs a number")
            return kind
        if isinstance(node, ast.Binary):
            return self.binary(node)
        io = self.io_point(node)
        if io is not None:
            return io[1]
        element = self.io_array(node)
        if element is not None:
            return element + "[]"
        if isinstance(node, ast.Member) and _is_robot(node.obj):
            return self.robot_member(node.name)[0]
        if isinstance(node, ast.Index):
            base = self.expr(node.obj)
            if not base.endswith("[]") and base != S:
                raise CheckError("only arrays can be indexed")
            self.index(node.index)
            return base[:-2] if base.endswith("[]") else S
        raise CheckError("unsupported expression")

    def binary(self, node):
        left, right = self.expr(node.left), self.expr(node.right)
        if node.op in ("&&", "||"):
            return B
        if node.op in ("==", "!=", "<", ">", "<=", ">="):
            return B
        if node.op == "+" and S in (left, right):
            return S
        if left not in (I, F, "byte") or right not in (I, F, "byte"):
            raise CheckError(f"operator '{node.op}' needs numbers")
        return F if F in (left, right) else I

    def call(self, node):
        overloads = table.overloads(node.name, self.version)
        if overloads is None:
            raise CheckError(f"unknown function '{node.name}'")
        arg_types = []
        for arg in node.args:                    # literals inline: motion lines are all literals
            kind = type(arg)
            if kind is ast.Num:
                arg_types.append(F if arg.is_float else I)
            elif kind is ast.Str:
                arg_types.append(S)
            elif kind is ast.Bool:
                arg_types.append(B)
            else:
                arg_types.append(self.argument(arg))
        candidates = [(params, ret) for params, ret in overloads if len(params) == len(arg_types)]
        if not candidates:
            counts = sorted({len(p) for p, _ in overloads})
            raise CheckError(f"{node.name} takes {' or '.join(map(str, counts))} arguments, "
                             f"{len(arg_types)} given")
        problem = None
        for params, ret in candidates:
            lossy = []
            for position, (param, arg) in enumerate(zip(params, arg_types, strict=False), start=1):
                result = _assignable(param, arg)
                if result is None:
                    problem = f"{node.name} argument {position} must be {param}, got {arg}"
                    break
                if result == "warn":
                    lossy.append(f"{node.name} argument {position}: {arg} truncated to {param}")
            else:
                for text in lossy:
                    self.warn(text)
                self.format(node, params)
                return ret
        raise CheckError(problem)

    def argument(self, node):
        """Type of a call argument; an undeclared bare name is an unquoted string constant (warning)."""
        if isinstance(node, ast.Name) and node.id not in self.scope and node.id not in ("IO", "Robot"):
            self.warn(f"unquoted string constant {node.id}")
            return S
        return self.expr(node)

    def format(self, node, params):
        allowed = table.formats(node.name, self.version)
        if allowed is None or not node.args:
            return
        first = node.args[0]
        value = first.value if isinstance(first, ast.Str) else (
            first.id if isinstance(first, ast.Name) and first.id not in self.scope else None)
        if value is not None:
            if value not in allowed:
                raise CheckError(f"{node.name} data format \"{value}\" is not one of {', '.join(allowed)}")
            if node.name == "PTP" and value == "JPP" and len(params) in (7, 14):
                raise CheckError("PTP arm configuration is only allowed with Cartesian targets (\"CPP\")")


def _is_robot(node):
    return isinstance(node, ast.Index) and isinstance(node.obj, ast.Name) and node.obj.id == "Robot"
