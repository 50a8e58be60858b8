"""LD power flow on the virtual PLC: every element kind and the corner cases of the documented evaluation
order (docs/toolchain/ladder.md), scan by scan on virtual time."""
from __future__ import annotations

import pytest
from ld_run import MS, Run
from ld_xml import block, coil, comment, contact, invar, jump, label, outvar, program, rail, ret, right

from vplc.api import load_plc


def test_series_contacts_and_normally_closed_contact_drive_a_coil(tmp_path):
    r = Run.of(tmp_path, {"A": "BOOL", "B": "BOOL", "Q": "BOOL"},
               [rail(1), contact(2, "A", 1), contact(3, "B", 2, negated="true"), coil(4, "Q", 3), right(5, 4)])
    assert r.scan(A=True, B=False)["Q"] is True
    assert r.scan(B=True)["Q"] is False
    assert r.scan(A=False, B=False)["Q"] is False


def test_parallel_branches_are_a_wired_or(tmp_path):
    # A -+- Q ; B (parallel with A) ; C in series after the join
    r = Run.of(tmp_path, {"A": "BOOL", "B": "BOOL", "C": "BOOL", "Q": "BOOL"},
               [rail(1), contact(2, "A", 1), contact(3, "B", 1, y=20), contact(4, "C", 2, 3), coil(5, "Q", 4),
                right(6, 5)])
    assert r.scan(A=False, B=True, C=True)["Q"] is True
    assert r.scan(A=True, B=False, C=True)["Q"] is True
    assert r.scan(A=True, B=True, C=False)["Q"] is False
    assert r.scan(A=False, B=False, C=True)["Q"] is False


def test_a_branch_point_feeding_two_coils_is_evaluated_once_before_either_coil(tmp_path):
    # contact A fans out to a reset coil of A and a coil Q: Q gets the power A had before the reset
    r = Run.of(tmp_path, {"A": "BOOL", "Q": "BOOL"},
               [rail(1), contact(2, "A", 1), coil(3, "A", 2, storage="reset"), coil(4, "Q", 2, y=20), right(5, 3, 4)])
    r.scan(A=True)
    assert r["Q"] is True and r["A"] is False
    assert r.scan()["Q"] is False


def test_negated_set_and_reset_coils(tmp_path):
    r = Run.of(tmp_path, {"S": "BOOL", "R": "BOOL", "Latch": "BOOL", "N": "BOOL"},
               [rail(1), contact(2, "S", 1), coil(3, "Latch", 2, storage="set"), right(4, 3),
                contact(5, "R", 1, y=40), coil(6, "Latch", 5, y=40, storage="reset"),
                coil(7, "N", 5, y=60, negated="true")])
    assert r.scan(S=True)["Latch"] is True
    assert r.scan(S=False)["Latch"] is True, "a set coil holds without power"
    assert r["N"] is True
    r.scan(R=True)
    assert r["Latch"] is False and r["N"] is False
    assert r.scan(R=False)["Latch"] is False, "a reset coil holds without power"


def test_rising_and_falling_edge_contacts_pass_power_for_one_scan(tmp_path):
    r = Run.of(tmp_path, {"X": "BOOL", "Up": "BOOL", "Down": "BOOL", "Ups": "INT"},
               [rail(1), contact(2, "X", 1, edge="rising"), coil(3, "Up", 2), right(4, 3),
                contact(5, "X", 1, y=40, edge="falling"), coil(6, "Down", 5, y=40)])
    seen = [(r.scan(X=x)["Up"], r["Down"]) for x in (False, True, True, True, False, False, True)]
    assert seen == [(False, False), (True, False), (False, False), (False, False), (False, True), (False, False),
                    (True, False)]


def test_edge_contact_memory_follows_the_variable_even_without_power(tmp_path):
    # IEC 61131-3: the transition is sensed between evaluations of the element, power or not
    r = Run.of(tmp_path, {"En": "BOOL", "X": "BOOL", "Up": "BOOL"},
               [rail(1), contact(2, "En", 1), contact(3, "X", 2, edge="rising"), coil(4, "Up", 3), right(5, 4)])
    r.scan(En=False, X=True)
    assert r.scan(En=True)["Up"] is False, "X rose while the rung had no power: no edge later"


def test_rising_edge_coil_is_on_for_one_scan(tmp_path):
    r = Run.of(tmp_path, {"A": "BOOL", "P": "BOOL"},
               [rail(1), contact(2, "A", 1), coil(3, "P", 2, edge="rising"), right(4, 3)])
    assert [r.scan(A=a)["P"] for a in (False, True, True, False, True)] == [False, True, False, False, True]


def test_function_block_with_en_off_is_not_called_and_keeps_its_outputs(tmp_path):
    body = [rail(1), contact(2, "Run", 1), contact(3, "Start", 1, y=20),
            block(4, "TON", {"EN": 2, "IN": 3, "PT": 5}, ["ENO", "Q", "ET"], instance="T", y=0),
            invar(5, "T#3ms", y=40), coil(6, "Eno", (4, "ENO")), coil(7, "Q", (4, "Q"), y=20),
            outvar(8, "Et", (4, "ET"), y=40),
            right(9, 6, 7)]
    r = Run.of(tmp_path, {"Run": "BOOL", "Start": "BOOL", "Eno": "BOOL", "Q": "BOOL", "Et": "TIME", "T": "TON"}, body)
    r.scan(Run=True, Start=True)
    assert r["Eno"] is True
    r.scan().scan()
    assert r["Et"] == 2 * MS
    r.scan(Run=False)
    frozen = r["Et"]
    r.scan().scan().scan().scan()
    assert r["Et"] == frozen == 2 * MS and r["Eno"] is False, "EN off: the timer is not called"
    r.scan(Run=True)
    assert r["Et"] == 3 * MS and r["Q"] is True


def test_function_result_inline_and_function_with_en_writes_its_variable_only_with_power(tmp_path):
    body = [rail(1), invar(2, "A"), invar(3, "B", y=10), block(4, "ADD", {"IN1": 2, "IN2": 3}, ["OUT"]),
            outvar(5, "Sum", (4, "OUT")),
            contact(6, "Go", 1, y=40), block(7, "MUL", {"EN": 6, "IN1": 2, "IN2": 3}, ["ENO", "OUT"], y=40),
            outvar(8, "Prod", (7, "OUT"), y=40), coil(9, "Did", (7, "ENO"), y=60), right(10, 9),
            invar(11, "A", y=80), invar(12, "B", y=90), block(13, "GT", {"IN1": 11, "IN2": 12}, ["OUT"], y=80),
            coil(14, "Bigger", (13, "OUT"), y=80)]
    r = Run.of(tmp_path, {"A": "INT", "B": "INT", "Sum": "INT", "Prod": "INT", "Go": "BOOL", "Did": "BOOL",
                          "Bigger": "BOOL"}, body)
    r.scan(A=3, B=4)
    assert (r["Sum"], r["Prod"], r["Did"], r["Bigger"]) == (7, 0, False, False)
    r.scan(Go=True, A=5, B=2)
    assert (r["Sum"], r["Prod"], r["Did"], r["Bigger"]) == (7, 10, True, True)


def test_in_out_pin_and_block_output_read_by_a_contact(tmp_path, tmp_path_factory):
    st = tmp_path_factory.mktemp("st") / "Counter.st"
    st.write_text("FUNCTION_BLOCK Bump\nVAR_IN_OUT Value : INT; END_VAR\nVAR_INPUT Go : BOOL; END_VAR\n"
                  "VAR_OUTPUT Big : BOOL; END_VAR\nIF Go THEN Value := Value + 1; END_IF;\nBig := Value > 2;\n"
                  "END_FUNCTION_BLOCK\n", encoding="utf-8")
    body = [rail(1), contact(2, "Go", 1), invar(3, "N", y=20),
            block(4, "Bump", {"Go": 2}, ["Big"], instance="B", inouts={"Value": 3}),
            contact(5, "Ok", (4, "Big")), coil(6, "Q", 5), right(7, 6)]
    r = Run.of(tmp_path, {"Go": "BOOL", "N": "INT", "Ok": "BOOL", "Q": "BOOL", "B": "Bump"}, body, extra=[st])
    r.scan(Go=True, Ok=True)
    r.scan().scan()
    assert r["N"] == 3 and r["Q"] is True, "the in-out wrote N; Big went through the contact"


def test_jump_skips_the_rungs_down_to_its_label_and_return_ends_the_scan(tmp_path):
    body = [rail(1), contact(2, "Skip", 1), jump(3, "Later", 2),
            contact(4, "P_On", 1, y=40), coil(5, "Middle", 4, y=40), right(6, 5),
            label(7, "Later", y=60),
            contact(8, "P_On", 1, y=80), coil(9, "End1", 8, y=80),
            contact(10, "Stop", 1, y=100), ret(11, 10, y=100),
            contact(12, "P_On", 1, y=120), coil(13, "End2", 12, y=120)]
    r = Run.of(tmp_path, {"Skip": "BOOL", "Middle": "BOOL", "End1": "BOOL", "End2": "BOOL", "Stop": "BOOL"}, body)
    r.scan(Skip=True)
    assert (r["Middle"], r["End1"], r["End2"]) == (False, True, True)
    r.scan(Skip=False, Stop=True, End1=False, End2=False)
    assert (r["Middle"], r["End1"], r["End2"]) == (True, True, False)


def test_comment_belongs_to_the_rung_below_and_rungs_run_top_to_bottom(tmp_path):
    # rung at y=100 copies A to B; rung at y=0 copies B to C: C lags B by one scan
    body = [comment(20, "copy B to C", y=-10), rail(1), contact(2, "B", 1), coil(3, "C", 2),
            contact(4, "A", 1, y=100), coil(5, "B", 4, y=100)]
    path = program(tmp_path, {"A": "BOOL", "B": "BOOL", "C": "BOOL"}, body)
    from vplc.project import load_project
    proj = load_project([str(path)])
    ladder = next(u.items[0].ladder for u in proj.units if str(u.span.file.path) == str(path))
    assert [r.comment for r in ladder.rungs] == ["copy B to C", ""]
    r = Run.of(tmp_path, {"A": "BOOL", "B": "BOOL", "C": "BOOL"}, body)
    r.scan(A=True)
    assert (r["B"], r["C"]) == (True, False)
    assert r.scan()["C"] is True


@pytest.mark.parametrize("edge", ["rising", "falling"])
def test_edge_on_a_block_input_pin(tmp_path, edge):
    body = [rail(1), contact(2, "X", 1), block(3, "CTU", {"CU": 2, "PV": 4}, ["Q", "CV"], instance="C"),
            invar(4, "100", y=20), outvar(5, "N", (3, "CV"))]
    body[2] = body[2].replace('formalParameter="CU"', f'formalParameter="CU" edge="{edge}"')
    r = Run.of(tmp_path, {"X": "BOOL", "N": "INT", "C": "CTU"}, body)
    for x in (True, True, False, True, False):
        r.scan(X=x)
    assert r["N"] == (2 if edge == "rising" else 2)


def test_in_out_variable_is_written_and_read_on_in_the_rung(tmp_path):
    from ld_xml import inoutvar
    r = Run.of(tmp_path, {"A": "BOOL", "X": "BOOL", "Q": "BOOL"},
               [rail(1), contact(2, "A", 1), inoutvar(3, "X", 2), contact(4, "P_On", 3), coil(5, "Q", 4), right(6, 5)])
    r.scan(A=True)
    assert (r["X"], r["Q"]) == (True, True)
    r.scan(A=False)
    assert (r["X"], r["Q"]) == (False, False)


def test_sysmac_ladder_shape_runs(tmp_path):
    """IEC 61131-10 with smcext:LdSection (the shape of docs/toolchain/export.md): NC contact, set coil."""
    from ld_xml import iec10_program
    rung = ('<LdObject xsi:type="LeftPowerRail"><ConnectionPointOut connectionPointOutId="1"/></LdObject>'
            '<LdObject xsi:type="Contact" operand="A" negated="true"><ConnectionPointIn><Connection '
            'refConnectionPointOutId="1"/></ConnectionPointIn><ConnectionPointOut connectionPointOutId="2"/></LdObject>'
            '<LdObject xsi:type="Coil" operand="Q" storage="set"><ConnectionPointIn><Connection '
            'refConnectionPointOutId="2"/></ConnectionPointIn><ConnectionPointOut connectionPointOutId="3"/></LdObject>'
            '<LdObject xsi:type="RightPowerRail"><ConnectionPointIn><Connection refConnectionPointOutId="3"/>'
            '</ConnectionPointIn></LdObject>')
    path = tmp_path / "sysmac.xml"
    path.write_text(iec10_program({"A": "BOOL", "Q": "BOOL"}, [rung]), encoding="utf-8")
    plc = load_plc([str(path)], task="Main@1ms")
    plc.write("Main.A", True)
    plc.scan(0)
    assert plc.read("Main.Q") is False
    plc.write("Main.A", False)
    plc.scan(MS)
    plc.write("Main.A", True)
    plc.scan(2 * MS)
    assert plc.read("Main.Q") is True, "a set coil holds"
