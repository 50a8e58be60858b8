"""Bad ladder files get one clear diagnostic naming file, POU, rung and element (never a traceback), and the
ST checker's rules hold for ladder POUs (docs/toolchain/diagnostics.md, ST21xx)."""
from __future__ import annotations

import os

import pytest
from ld_xml import HEAD, block, coil, contact, invar, jump, label, outvar, program, rail

from vplc.ladder import xmlsafe
from vplc.project import load_project


def diags(*paths):
    proj = load_project([str(p) for p in paths])
    return [d for d in proj.diagnostics if d.severity == "error"]


def one(*paths):
    errors = diags(*paths)
    assert len(errors) == 1, [d.render() for d in errors]
    return errors[0]


V = {"A": "BOOL", "B": "BOOL", "Q": "BOOL", "N": "INT", "T": "TON"}


def test_missing_connection_names_the_element_and_the_missing_id(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "A", 77), coil(3, "Q", 2)]))
    assert d.code == "ST2103"
    assert d.render().startswith(f"{tmp_path / 'main.xml'}:Main:rung 1:contact A: error[ST2103]: input `power` is "
                                 "connected to element 77, which is not in this rung")


def test_two_elements_with_one_local_id_are_refused(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(1, "A", 1), coil(3, "Q", 1)]))
    assert d.code == "ST2103" and "localId 1 is used by two elements" in d.message


def test_unconnected_coil_is_reported(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "A", 1), coil(3, "Q")]))
    assert (d.code, d.location().split(":", 1)[1]) == ("ST2103", "Main:rung 2:coil Q")
    assert "nothing is connected to its input" in d.message


def test_cycle_in_a_network_is_reported_with_its_elements(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "A", 1, 3), contact(3, "B", 2), coil(4, "Q", 3)]))
    assert d.code == "ST2104"
    assert "wired in a loop (contact A, contact B" in d.message
    assert d.location().endswith("main.xml:Main:rung 1")


def test_unknown_element_is_refused_with_the_list_of_ladder_elements(tmp_path):
    body = [rail(1), '<step localId="5" name="S1"><position x="0" y="0"/></step>']
    d = one(program(tmp_path, V, body))
    assert d.code == "ST2102" and d.location().endswith("main.xml:Main:element 5")
    assert "unknown element <step> in a ladder body" in d.message and "contact" in d.message


def test_wrong_pin_type_contact_on_an_integer(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "N", 1), coil(3, "Q", 2)]))
    assert d.code == "ST2105"
    assert d.render().splitlines()[0].endswith(
        "main.xml:Main:rung 1:contact N: error[ST2105]: the contact's operand `N` is INT; "
        "a contact needs a BOOL variable")


def test_wrong_pin_type_integer_output_into_a_coil_is_a_type_mismatch(tmp_path):
    body = [rail(1), contact(2, "A", 1), block(3, "TON", {"IN": 2, "PT": 4}, ["Q", "ET"], instance="T"),
            invar(4, "T#1s", y=20), coil(5, "Q", (3, "ET"))]
    d = one(program(tmp_path, V, body))
    assert d.code == "ST1101" and ":Main:rung 1:coil Q:" in d.render()


def test_wire_to_a_block_output_that_does_not_exist(tmp_path):
    body = [rail(1), contact(2, "A", 1), block(3, "TON", {"IN": 2}, ["Q"], instance="T"), coil(5, "Q", (3, "Done"))]
    d = one(program(tmp_path, V, body))
    assert d.code == "ST2103" and "output `Done` of block TON, which has no such pin" in d.message


def test_undeclared_variable_in_a_contact_is_the_st_rule(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "Strat", 1), coil(3, "Q", 2)]))
    assert d.code == "ST1001" and d.location().endswith("main.xml:Main:rung 1:contact Strat")


def test_fb_direction_rule_an_output_wired_as_an_input(tmp_path):
    body = [rail(1), contact(2, "A", 1), block(3, "TON", {"IN": 2, "Q": 2}, ["ET"], instance="T")]
    d = one(program(tmp_path, V, body))
    assert d.code == "ST1203" and d.location().endswith(":Main:rung 1:block TON")


def test_jump_to_a_missing_label_and_backwards(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "A", 1), jump(3, "Nowhere", 2)]))
    assert d.code == "ST2106" and "which no rung of Main has" in d.message
    d = one(program(tmp_path, V, [label(9, "Top", y=-10), rail(1), contact(2, "A", 1), coil(4, "Q", 2),
                                  contact(5, "B", 1, y=50), jump(3, "Top", 5, y=50)]))
    assert d.code == "ST2106" and "jump back to label `Top` (rung 1)" in d.message


def write(tmp_path, text, name="x.xml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_xml_bomb_is_refused_before_parsing(tmp_path):
    bomb = ('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;">]>\n'
            '<project>&lol2;</project>')
    d = one(write(tmp_path, bomb))
    assert d.code == "ST2101" and "<!DOCTYPE declaration" in d.message
    assert d.location().endswith("x.xml:2:1")


def test_external_entity_is_refused(tmp_path):
    xxe = '<?xml version="1.0"?><!DOCTYPE p [<!ENTITY x SYSTEM "file:///etc/passwd">]><project>&x;</project>'
    d = one(write(tmp_path, xxe))
    assert d.code == "ST2101" and "entities are refused" in d.message


def test_huge_document_is_refused_without_reading_it(tmp_path, monkeypatch):
    monkeypatch.setattr(xmlsafe, "MAX_BYTES", 1000)
    d = one(write(tmp_path, HEAD + " " * 2000 + "<types/></project>"))
    assert d.code == "ST2101" and "limited to" in d.message


def test_a_pipe_or_a_device_named_xml_is_refused_at_once(tmp_path):
    """A pipe nobody writes to is not waited on (read, it is empty); a link to /dev/zero is not read (its size
    reads 0)."""
    os.mkfifo(tmp_path / "pipe.xml")
    os.symlink("/dev/zero", tmp_path / "zero.xml")
    [d] = load_project([str(tmp_path / "zero.xml")]).diagnostics
    assert d.code == "ST2101" and "the file is not a regular file or a pipe" in d.message, d.message
    [d] = load_project([str(tmp_path / "pipe.xml")]).diagnostics
    assert d.code == "ST2101", d.message


def test_not_well_formed_xml_points_at_the_line(tmp_path):
    d = one(write(tmp_path, HEAD + "<types>\n<pous>\n</types></project>"))
    assert d.code == "ST2101" and "not well-formed XML: mismatched tag" in d.message
    assert d.location().split(":")[-2] == "7"


def test_a_file_that_is_not_a_project(tmp_path):
    d = one(write(tmp_path, "<svg/>"))
    assert d.code == "ST2101" and "root element is <svg>" in d.message


def test_fbd_body_is_refused(tmp_path):
    text = (HEAD + '<types><dataTypes/><pous><pou name="F" pouType="program"><body><FBD/></body></pou></pous></types>'
            '<instances><configurations/></instances></project>')
    d = one(write(tmp_path, text))
    assert d.code == "ST2102" and "FBD bodies are not supported" in d.message


def test_ladder_and_st_files_mix_in_one_project(tmp_path):
    (tmp_path / "Globals.st").write_text("VAR_GLOBAL\n    Start : BOOL;\n    Lamp : BOOL;\nEND_VAR\n", encoding="utf-8")
    (tmp_path / "Helper.st").write_text("FUNCTION Both : BOOL\nVAR_INPUT a, b : BOOL; END_VAR\nBoth := a AND b;\n"
                                        "END_FUNCTION\n", encoding="utf-8")
    body = [rail(1), invar(2, "Start"), invar(3, "TRUE", y=10), block(4, "Both", {"a": 2, "b": 3}, ["Both"]),
            outvar(5, "Lamp", (4, "Both"))]
    program(tmp_path, {}, body, externals={"Start": "BOOL", "Lamp": "BOOL"})
    from vplc.api import load_plc
    plc = load_plc([str(tmp_path)], task="Main@1ms")
    plc.write("Start", True)
    plc.scan(0)
    assert plc.read("Lamp") is True


@pytest.mark.parametrize("name", ["vplc check", "json"])
def test_cli_check_prints_the_element_location(tmp_path, capsys, name):
    from vplc.cli.main import main
    path = program(tmp_path, V, [rail(1), contact(2, "Strat", 1), coil(3, "Q", 2)])
    args = ["check", str(path)] + (["--format", "json"] if name == "json" else [])
    assert main(args) == 1
    out = capsys.readouterr().out
    if name == "json":
        assert '"element": "Main:rung 1:contact Strat"' in out
    else:
        assert "main.xml:Main:rung 1:contact Strat: error[ST1001]" in out


def test_other_xml_files_in_a_source_folder_are_not_sources(tmp_path):
    (tmp_path / "report.xml").write_text('<?xml version="1.0"?><testsuites><testsuite/></testsuites>', encoding="utf-8")
    program(tmp_path, V, [rail(1), contact(2, "A", 1), coil(3, "Q", 2)])
    assert diags(tmp_path) == []
    d = one(tmp_path / "report.xml")
    assert d.code == "ST2101" and "root element is <testsuites>" in d.message


def test_unknown_object_in_a_sysmac_rung(tmp_path):
    from ld_xml import iec10_program
    rung = ('<LdObject xsi:type="LeftPowerRail"><ConnectionPointOut connectionPointOutId="1"/></LdObject>'
            '<LdObject xsi:type="smcext:InlineFBD"><ConnectionPointIn><Connection refConnectionPointOutId="1"/>'
            '</ConnectionPointIn></LdObject>')
    path = write(tmp_path, iec10_program({"A": "BOOL"}, [rung]))
    d = one(path)
    assert d.code == "ST2102" and d.location().endswith("x.xml:Main:rung 1:element 2")
    assert 'unknown element <LdObject xsi:type="smcext:InlineFBD"> in a rung' in d.message


def test_sysmac_rung_wire_to_a_missing_point(tmp_path):
    from ld_xml import iec10_program
    rung = ('<LdObject xsi:type="LeftPowerRail"><ConnectionPointOut connectionPointOutId="1"/></LdObject>'
            '<LdObject xsi:type="Coil" operand="A"><ConnectionPointIn><Connection refConnectionPointOutId="9"/>'
            '</ConnectionPointIn></LdObject>')
    d = one(write(tmp_path, iec10_program({"A": "BOOL"}, [rung])))
    assert d.code == "ST2103" and "connected to element 9, which is not in this rung" in d.message


def test_wire_from_an_element_without_output(tmp_path):
    d = one(program(tmp_path, V, [rail(1), contact(2, "A", 1), jump(3, "L", 2), coil(4, "Q", 3), label(5, "L", y=50)]))
    assert d.code == "ST2103" and "is wired to jump L, which has no output to read" in d.message


@pytest.mark.slow
def test_damaged_files_give_diagnostics_never_a_traceback(tmp_path):
    """300 seeded mutations of a ladder using every element kind: wires moved, elements deleted, pins,
    modifiers and operands changed. Each load ends in diagnostics (or none), never in an exception."""
    import random
    import re

    from ld_xml import ALL_BODY, ALL_KINDS, document
    base = document(ALL_KINDS, ALL_BODY)
    rnd = random.Random(16)

    def maybe(p, new):
        return lambda m: new(m) if rnd.random() < p else m.group(0)

    mutations = [
        lambda s: re.sub(r'refLocalId="\d+"', maybe(0.2, lambda m: f'refLocalId="{rnd.randint(0, 60)}"'), s),
        lambda s: re.sub(r'formalParameter="\w*"',
                         maybe(0.2, lambda m: f'formalParameter="{rnd.choice(["EN", "ENO", "Q", "X"])}"'), s),
        lambda s: re.sub(r'(edge|storage)="\w+"',
                         maybe(0.3, lambda m: f'{m.group(1)}="{rnd.choice(["none", "set", "odd"])}"'), s),
        lambda s: re.sub(r"<variable>\w+</variable>",
                         maybe(0.2, lambda m: f"<variable>{rnd.choice(['N', 'T', '1', 'A.B'])}</variable>"), s),
        lambda s: "\n".join(line for line in s.split("\n") if rnd.random() > 0.05),
    ]
    path = tmp_path / "m.xml"
    loaded = set()
    for _ in range(300):
        text = base
        for _ in range(rnd.randint(1, 3)):
            text = rnd.choice(mutations)(text)
        if text in loaded:              # the same damage drawn again (11 of the 300): its load was checked already
            continue
        loaded.add(text)
        path.write_text(text, encoding="utf-8")
        for d in load_project([str(path)]).diagnostics:
            assert "internal error" not in d.render()


def test_check_summary_counts_an_xml_file_with_an_error_as_one_file(tmp_path, capsys):
    """The summary counts the files passed or found, not the units read from them (a rung that cannot be read
    gives none, an export with a library gives one per namespace)."""
    from vplc.cli.main import main
    path = program(tmp_path, V, [rail(1), contact(2, "A", 77), coil(3, "Q", 2)])
    assert main(["check", str(path)]) == 1
    assert capsys.readouterr().out.splitlines()[-1].startswith("1 file(s) checked: 1 error(s), ")


@pytest.mark.parametrize("fmt", ["iec61131-10", "plcopen"])
def test_check_summary_counts_one_exported_project_file_as_one_file(tmp_path, capsys, fmt):
    from vplc.cli.main import main
    src = tmp_path / "src"
    (src / "Demo_Lib").mkdir(parents=True)
    (src / "Demo_Lib" / "Both.st").write_text("FUNCTION Both : BOOL\nVAR_INPUT a, b : BOOL; END_VAR\nBoth := a AND b;\n"
                                              "END_FUNCTION\n", encoding="utf-8")
    (src / "Globals.st").write_text("VAR_GLOBAL\n    Start : BOOL;\n    Lamp : BOOL;\nEND_VAR\n", encoding="utf-8")
    program(src, {}, [rail(1), invar(2, "Start"), invar(3, "TRUE", y=10), block(4, "Both", {"a": 2, "b": 3}, ["Both"]),
                      outvar(5, "Lamp", (4, "Both"))], externals={"Start": "BOOL", "Lamp": "BOOL"})
    assert main(["check", str(src)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "3 file(s) checked: 0 error(s), 0 warning(s)"
    out = tmp_path / "project.xml"
    assert main(["export", str(src), "--format", fmt, "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["check", str(out)]) == 0          # both formats write the program's external variables
    assert capsys.readouterr().out.splitlines()[-1] == "1 file(s) checked: 0 error(s), 0 warning(s)"


def test_independent_wiring_problems_are_all_reported_with_the_st_rules_of_the_broken_rung(tmp_path):
    """A missing connection no longer hides the rest: a second missing wire in the same rung, a loop in another
    rung, an undeclared contact in the broken rung (its operands are still checked) and one in a good rung."""
    body = [rail(1), contact(2, "A", 77), contact(3, "Nope", 2), coil(5, "Q", 3, 88),
            rail(10, y=100), contact(11, "A", 10, 12, y=100), contact(12, "B", 11, y=100), coil(13, "Q", 12, y=100),
            rail(20, y=200), contact(21, "Strat", 20, y=200), coil(22, "Q", 21, y=200)]
    found = sorted((d.code, d.location().split("main.xml:", 1)[1], d.message.split(";")[0]) for d in
                   diags(program(tmp_path, V, body)))
    assert found == [
        ("ST1001", "Main:rung 1:contact Nope", "`Nope` is not declared"),
        ("ST1001", "Main:rung 3:contact Strat", "`Strat` is not declared"),
        ("ST2103", "Main:rung 1:coil Q", "input `power` is connected to element 88, which is not in this rung"),
        ("ST2103", "Main:rung 1:contact A", "input `power` is connected to element 77, which is not in this rung"),
        ("ST2104", "Main:rung 2", "the rung is wired in a loop (contact A, contact B, coil Q)"),
    ]


def test_a_contact_on_an_integer_in_a_broken_rung_is_still_the_pin_type_error(tmp_path):
    errors = diags(program(tmp_path, V, [rail(1), contact(2, "N", 77), coil(3, "Q", 2)]))
    assert sorted(d.code for d in errors) == ["ST2103", "ST2105"]
