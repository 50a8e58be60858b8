"""Function boxes wired like Sysmac wires them (issue 24): the result read by several elements, a second output
wired, the result of a function with EN read by a contact. The function runs once, in its place in the power
flow; each wired output reaches every element wired to it (docs/toolchain/ladder.md, "Function boxes")."""
from ld_run import Run
from ld_xml import block, coil, contact, document, invar, outvar, program, rail, right

from vplc.project import load_project

SPLIT = """FUNCTION Split : INT
VAR_INPUT X : INT; END_VAR
VAR_OUTPUT Big : BOOL; Half : INT; END_VAR
Split := X * 2;
Big := X > 10;
Half := X / 2;
END_FUNCTION
"""


def _errors(path, extra=()):
    proj = load_project([str(path), *map(str, extra)])
    return [d for d in proj.diagnostics if d.severity == "error"]


def test_a_result_read_by_two_variables_reaches_both(tmp_path):
    body = [invar(1, "N"), invar(2, "7"), block(3, "ADD", {"IN1": 1, "IN2": 2}, ["OUT"]),
            outvar(4, "Sum", (3, "OUT")), outvar(5, "Copy", (3, "OUT"), y=20)]
    r = Run.of(tmp_path, {"N": "INT", "Sum": "INT", "Copy": "INT"}, body)
    r.scan(N=5)
    assert (r["Sum"], r["Copy"]) == (12, 12)


def test_a_second_output_wired_to_a_coil_and_the_result_to_a_variable(tmp_path):
    (tmp_path / "split.st").write_text(SPLIT, encoding="utf-8")
    body = [rail(1), invar(2, "N"), block(3, "Split", {"X": 2}, ["Split", "Big", "Half"]),
            outvar(4, "Twice", (3, "Split")), coil(5, "Q", (3, "Big"), y=20), outvar(6, "H", (3, "Half"), y=40),
            right(7, 5)]
    r = Run.of(tmp_path, {"N": "INT", "Twice": "INT", "Q": "BOOL", "H": "INT"}, body,
               extra=[tmp_path / "split.st"])
    r.scan(N=12)
    assert (r["Twice"], r["Q"], r["H"]) == (24, True, 6)
    r.scan(N=3)
    assert (r["Twice"], r["Q"], r["H"]) == (6, False, 1)


def test_a_bool_result_read_by_a_contact_and_a_coil_is_evaluated_once(tmp_path):
    body = [rail(1), invar(2, "N"), invar(3, "5"), block(4, "GT", {"IN1": 2, "IN2": 3}, ["OUT"]),
            coil(5, "Q1", (4, "OUT")), contact(6, "A", (4, "OUT"), y=20), coil(7, "Q2", 6, y=20), right(8, 5, 7)]
    r = Run.of(tmp_path, {"N": "INT", "A": "BOOL", "Q1": "BOOL", "Q2": "BOOL"}, body)
    r.scan(N=9, A=True)
    assert (r["Q1"], r["Q2"]) == (True, True)
    r.scan(N=1)
    assert (r["Q1"], r["Q2"]) == (False, False)


def test_the_result_of_a_function_with_en_read_by_a_contact_keeps_its_value_while_en_is_off(tmp_path):
    """With EN off the function is not executed: its output keeps the value of its last execution, which the
    contact reads (as the variable wired to an output keeps its value)."""
    body = [rail(1), contact(2, "Run", 1), invar(3, "N"), invar(4, "5"),
            block(5, "GT", {"EN": 2, "IN1": 3, "IN2": 4}, ["ENO", "OUT"]),
            contact(6, "A", (5, "OUT")), coil(7, "Q", 6), right(8, 7)]
    r = Run.of(tmp_path, {"Run": "BOOL", "N": "INT", "A": "BOOL", "Q": "BOOL"}, body)
    r.scan(Run=True, N=9, A=True)
    assert r["Q"] is True
    r.scan(Run=False, N=1)
    assert r["Q"] is True                               # not executed: GT's output is still TRUE
    r.scan(Run=True)
    assert r["Q"] is False


def _with_function(variables, body, function_pou: str) -> str:
    doc = document(variables, body)
    return doc.replace("</pous>", function_pou + "</pous>")


FUNCTION_XML = ('<pou name="Scale" pouType="function"><interface><returnType><INT/></returnType>'
                '<inputVars><variable name="X"><type><INT/></type></variable></inputVars>'
                '<outputVars><variable name="Rest"><type><INT/></type></variable></outputVars></interface>'
                '<body><ST><xhtml:p>Scale := X * 10; Rest := X MOD 3;</xhtml:p></ST></body></pou>')


def test_an_output_of_a_function_of_the_same_file_feeds_another_block_through_a_typed_helper(tmp_path):
    body = [invar(1, "N"), block(2, "Scale", {"X": 1}, ["Scale", "Rest"]), invar(3, "1"),
            block(4, "ADD", {"IN1": (2, "Rest"), "IN2": 3}, ["OUT"], y=20), outvar(5, "R", (4, "OUT"), y=20),
            outvar(6, "S", (2, "Scale"))]
    path = tmp_path / "main.xml"
    path.write_text(_with_function({"N": "INT", "R": "INT", "S": "INT"}, body, FUNCTION_XML), encoding="utf-8")
    r = Run(path)
    r.scan(N=5)
    assert (r["S"], r["R"]) == (50, 3)


def test_an_output_of_a_function_declared_elsewhere_feeding_only_a_block_is_st2107_naming_it(tmp_path):
    (tmp_path / "split.st").write_text(SPLIT, encoding="utf-8")
    body = [invar(1, "N"), block(2, "Split", {"X": 1}, ["Split", "Big", "Half"]), invar(3, "1"),
            block(4, "ADD", {"IN1": (2, "Half"), "IN2": 3}, ["OUT"], y=20), outvar(5, "R", (4, "OUT"), y=20),
            outvar(6, "S", (2, "Split"))]
    errors = _errors(program(tmp_path, {"N": "INT", "R": "INT", "S": "INT"}, body), [tmp_path / "split.st"])
    assert [d.code for d in errors] == ["ST2107"]
    assert "output `Half` of the function feeds block ADD but no variable" in errors[0].message



def test_a_function_with_its_outputs_wired_survives_the_sysmac_export(tmp_path):
    """The same rung written as Sysmac's IEC 61131-10 (vplc export) reads back with the same meaning."""
    from vplc.cli.main import main
    (tmp_path / "split.st").write_text(SPLIT, encoding="utf-8")
    body = [rail(1), invar(2, "N"), block(3, "Split", {"X": 2}, ["Split", "Big", "Half"]),
            outvar(4, "Twice", (3, "Split")), coil(5, "Q", (3, "Big"), y=20), outvar(6, "H", (3, "Half"), y=40),
            outvar(8, "H2", (3, "Half"), y=60), right(7, 5)]
    src = program(tmp_path, {"N": "INT", "Twice": "INT", "Q": "BOOL", "H": "INT", "H2": "INT"}, body)
    out = tmp_path / "sysmac.xml"
    assert main(["export", str(src), str(tmp_path / "split.st"), "--format", "iec61131-10", "-o", str(out)]) == 0
    (tmp_path / "back").mkdir()
    back = tmp_path / "back" / "sysmac.xml"
    back.write_text(out.read_text(encoding="utf-8"), encoding="utf-8")
    r = Run(back)
    r.scan(N=12)
    assert (r["Twice"], r["Q"], r["H"], r["H2"]) == (24, True, 6, 6)


def test_a_function_working_on_an_in_out_runs_though_nothing_reads_its_result(tmp_path):
    """W502 Inc(InOut) in a rung: while the contact gives EN power, each scan adds 1; no output is wired."""
    body = [rail(1), contact(2, "Go", 1), invar(3, "N"),
            block(4, "Inc", {"EN": 2}, ["ENO", "Out"], inouts={"InOut": 3})]
    r = Run.of(tmp_path, {"Go": "BOOL", "N": "INT"}, body)
    r.scan(Go=True)
    r.scan(Go=True)
    r.scan(Go=False)
    assert r["N"] == 2


def test_an_in_out_drawn_as_an_input_and_an_output_of_the_same_name_is_the_in_out(tmp_path):
    """W560 2-231 draws Inc's InOut on both sides of the box; a PLCopen file that lists it as an input and an output
    passes the variable: the InOut output is N after the call, Out the BOOL result (it was taken as the result)."""
    body = [rail(1), contact(2, "Go", 1), invar(3, "N"),
            block(4, "Inc", {"EN": 2, "InOut": 3}, ["ENO", "InOut", "Out"]),
            outvar(5, "Copy", (4, "InOut")), coil(6, "Ran", (4, "Out")), right(7, (4, "ENO"))]
    r = Run.of(tmp_path, {"Go": "BOOL", "N": "INT", "Copy": "INT", "Ran": "BOOL"}, body)
    r.scan(Go=True)
    assert r["N"] == 1 and r["Copy"] == 1 and r["Ran"] is True
    r.scan(Go=True)
    assert r["N"] == 2 and r["Copy"] == 2


def test_a_negated_in_out_drawn_on_both_sides_is_refused_naming_it(tmp_path):
    body = [rail(1), invar(3, "N"), block(4, "Inc", {"EN": 1, "InOut": 3}, ["ENO", "InOut"]),
            outvar(5, "Copy", (4, "InOut"))]
    path = program(tmp_path, {"N": "INT", "Copy": "INT"}, body)
    path.write_text(path.read_text().replace('<variable formalParameter="InOut"><connectionPointOut/>',
                                             '<variable formalParameter="InOut" negated="true"><connectionPointOut/>'))
    errors = _errors(path)
    assert errors and "in-out `InOut`" in errors[0].message and "negated" in errors[0].message
