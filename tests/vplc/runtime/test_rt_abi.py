"""runtime/abi.py is the whole contract between generated code and the runtime: the code generator emits no
reserved name (``_x``, ``N_x``, ``NF_x``, ``G``, attribute ``i__x``) that the module does not declare, and the
namespace a loaded program runs in holds only declared names besides the ones the generated module defines."""
import ast
import pathlib

import pytest

from vplc.api import Plc, compile_program
from vplc.runtime import abi, natives, stdlib
from vplc.runtime.program import HELPERS

ROOT = pathlib.Path(__file__).resolve().parents[3]

# what the library and the examples do not use: unions, memory areas, scalar VAR_IN_OUT, loops, faults
EXTRA = """TYPE
    uWord : UNION
        W : WORD;
        Bytes : ARRAY[0..1] OF BYTE;
    END_UNION;
    sPair : STRUCT a : INT; b : ARRAY[1..3] OF REAL; END_STRUCT;
END_TYPE
VAR_GLOBAL
    Lamp AT %W480.00 : BOOL;
    Word480 AT %W480 : WORD;
    Count : DINT;
END_VAR
FUNCTION Bump : INT
VAR_IN_OUT x : INT; END_VAR
VAR_INPUT k : INT; END_VAR
x := x + k; Bump := x / k MOD 7;
END_FUNCTION
PROGRAM Main
VAR_EXTERNAL Lamp : BOOL; Word480 : WORD; Count : DINT; END_VAR
VAR u : uWord; p, q : sPair; i, n : INT := 1; r : REAL; arr : ARRAY[1..10] OF INT; s : STRING[20]; END_VAR
u.W := Word480; Lamp := NOT Lamp; q := p; p.b[2] := r / 3.0;
FOR i := 1 TO n DO arr[i] := Bump(x := n, k := i); END_FOR;
WHILE n < 3 DO n := n + 1; END_WHILE;
s := CONCAT(LEFT(s, 3), INT_TO_STRING(n)); r := SQRT(EXPT(r, 2.0)); Count := Count + 1;
END_PROGRAM
"""


def _undeclared(source: str) -> list[str]:
    wrong = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Name) and not abi.is_declared(node.id):
            wrong.add(node.id)
        elif isinstance(node, ast.Attribute) and node.attr.startswith("i__") and node.attr not in abi.ATTRIBUTES:
            wrong.add("." + node.attr)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)) and node.name.startswith("i__") \
                and node.name not in abi.ATTRIBUTES:
            wrong.add(node.name)
    return sorted(wrong)


@pytest.fixture(scope="module")
def extra_program(tmp_path_factory):
    path = tmp_path_factory.mktemp("abi") / "extra.st"
    path.write_text(EXTRA)
    return compile_program([str(path)], count_statements=True)


def test_the_library_and_the_examples_compile_to_declared_names_only():
    program = compile_program([str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")],
                              count_statements=True)
    assert _undeclared(program.source) == []
    uses = {n.id for n in ast.walk(ast.parse(program.source)) if isinstance(n, ast.Name)}
    assert {abi.DEADLINE, abi.STATEMENTS, abi.WATCHDOG, abi.PERF_COUNTER, abi.NEW} <= uses   # the scan is checked


def test_unions_memory_areas_and_references_compile_to_declared_names_only(extra_program):
    assert _undeclared(extra_program.source) == []
    assert abi.UNION_CELL in extra_program.source and abi.MEMORY in extra_program.source


def test_a_name_of_reserved_shape_outside_the_contract_is_caught():
    assert _undeclared("_secret[0] += 1\nx.i__hidden = NF_Foo(G)\n_t3 = _k2") == [".i__hidden", "_secret"]


def test_every_name_the_runtime_puts_into_a_program_namespace_is_declared(extra_program):
    plc = Plc(extra_program, task="Main@1ms")
    try:
        generated = {n.id for n in ast.walk(ast.parse(extra_program.source))
                     if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        generated |= {n.name for n in ast.walk(ast.parse(extra_program.source))
                      if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        provided = set(plc.module.namespace) - generated - set(extra_program.consts) - {"__builtins__"}
        assert sorted(n for n in provided if not abi.is_declared(n)) == []
        assert set(HELPERS) == abi.HELPER_NAMES
        assert {n for n in stdlib.NAMESPACE if not n.startswith(abi.STDLIB_MATH_PREFIX)} <= abi.STDLIB_NAMES
        assert set(plc.module.namespace) >= abi.NAMESPACE_CELLS | abi.BOUND_NAMES
        assert all(abi.NATIVE_FB + name in plc.module.namespace for name in natives.NATIVE_FBS)
        assert all(abi.NATIVE_FUNCTION + name in plc.module.namespace for name in natives.NATIVE_FUNCTIONS)
        plc.scan(0)
        assert plc.read("Count") == 1
    finally:
        plc.close()
