"""Reading IEC 61131-10 as Sysmac Studio writes it (Omron's schemas IEC61131_10_Ed1_0_Spc1_0.xsd and
IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd): every element and attribute that changes what the program does is
either run with its meaning or refused with an error naming it — never read with another meaning. One test
per attribute; files of earlier vplc exports keep loading with warning ST2108."""
from __future__ import annotations

import pytest
from ld_run import Run
from ld_xml import IEC10_HEAD, iec10_program

from vplc.api import load_plc
from vplc.project import load_project

SMC = 'name="https://www.ia.omron.com/Smc IEC61131_10_Ed1_0_SmcExt1_0_Spc1_0.xsd" handleUnknown="discard"'
RAIL = '<LdObject xsi:type="LeftPowerRail"><ConnectionPointOut connectionPointOutId="1"/></LdObject>'


def cin(*ids) -> str:
    return "<ConnectionPointIn>" + "".join(f'<Connection refConnectionPointOutId="{i}"/>' for i in ids) + \
        "</ConnectionPointIn>"


def contact(var, src, out, **attrs) -> str:
    a = "".join(f' {k}="{v}"' for k, v in attrs.items())
    return (f'<LdObject xsi:type="Contact" operand="{var}"{a}>{cin(src)}'
            f'<ConnectionPointOut connectionPointOutId="{out}"/></LdObject>')


def coil(var, src, **attrs) -> str:
    a = "".join(f' {k}="{v}"' for k, v in attrs.items())
    return f'<LdObject xsi:type="Coil" operand="{var}"{a}>{cin(src)}</LdObject>'


def doc(inner: str) -> str:
    return IEC10_HEAD + inner + "</GlobalNamespace></Types><Instances/></Project>\n"


def write(tmp_path, text: str, name="sysmac.xml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def diagnostics(*paths):
    proj = load_project([str(p) for p in paths])
    return [d for d in proj.diagnostics if d.severity in ("error", "warning")]


def refused(path, *words):
    errors = [d for d in diagnostics(path) if d.severity == "error"]
    assert errors, "the construct must be refused"
    text = errors[0].location() + ": " + errors[0].message
    for w in words:
        assert w in text, text
    return errors[0]


def test_latch_set_and_reset_coils_hold_their_value(tmp_path):
    rungs = [RAIL + contact("A", 1, 2) + coil("Q", 2, latch="set"),
             RAIL + contact("B", 1, 2) + coil("Q", 2, latch="reset")]
    r = Run(write(tmp_path, iec10_program({"A": "BOOL", "B": "BOOL", "Q": "BOOL"}, rungs)))
    assert r.scan(A=True)["Q"] is True
    assert r.scan(A=False)["Q"] is True, "latch=set holds without power"
    assert r.scan(B=True)["Q"] is False
    assert r.scan(B=False)["Q"] is False, "latch=reset holds"
    assert diagnostics(tmp_path / "sysmac.xml") == []


def test_edge_contacts_and_edge_block_inputs_keep_their_edge(tmp_path):
    rungs = [RAIL + contact("A", 1, 2, edge="rising") + coil("P", 2),
             RAIL + contact("A", 1, 2, edge="falling") + coil("N", 2)]
    r = Run(write(tmp_path, iec10_program({"A": "BOOL", "P": "BOOL", "N": "BOOL"}, rungs)))
    seen = [(r.scan(A=a)["P"], r["N"]) for a in (True, True, False, False)]
    assert seen == [(True, False), (False, False), (False, True), (False, False)]


def test_edge_detection_on_an_input_variable_is_refused_by_name(tmp_path):
    fb = ('<FunctionBlock name="Edge"><Parameters><InputVars><Variable name="Go" orderWithinParamSet="0" '
          'edgeDetection="rising"><Type><TypeName>BOOL</TypeName></Type></Variable></InputVars></Parameters>'
          '<MainBody><BodyContent xsi:type="ST"><ST>;</ST></BodyContent></MainBody></FunctionBlock>')
    refused(write(tmp_path, doc(fb)), "Edge:variable Go", 'edgeDetection="rising"', "not modelled")


@pytest.mark.parametrize("value, closed", [("true", True), ("1", True), ("false", False), ("0", False)])
def test_negated_contact_is_a_normally_closed_contact(tmp_path, value, closed):
    rungs = [RAIL + contact("A", 1, 2, negated=value) + coil("Q", 2)]
    r = Run(write(tmp_path, iec10_program({"A": "BOOL", "Q": "BOOL"}, rungs)))
    assert r.scan(A=False)["Q"] is closed and r.scan(A=True)["Q"] is (not closed)


def test_negated_with_a_value_that_is_not_a_boolean_is_refused(tmp_path):
    rungs = [RAIL + contact("A", 1, 2, negated="yes") + coil("Q", 2)]
    refused(write(tmp_path, iec10_program({"A": "BOOL", "Q": "BOOL"}, rungs)), "contact A", 'negated="yes"')


def test_a_union_is_read_as_a_union_its_members_sharing_memory(tmp_path):
    """overlap="true" is Sysmac's union (W501 6-3-6): writing W changes B, its low byte."""
    t = ('<DataTypeDecl name="uWord"><UserDefinedTypeSpec xsi:type="StructTypeSpec" overlap="true">'
         '<Member name="W"><Type><TypeName>WORD</TypeName></Type></Member>'
         '<Member name="B"><Type><TypeName>BYTE</TypeName></Type></Member></UserDefinedTypeSpec></DataTypeDecl>')
    st = tmp_path / "use.st"
    st.write_text("PROGRAM Main\nVAR u : uWord; b : BYTE; END_VAR\nu.W := 16#1234; b := u.B;\nEND_PROGRAM\n")
    xml = write(tmp_path, doc(t))
    assert diagnostics(xml, st) == []
    plc = load_plc([str(xml), str(st)], task="Main@1ms")
    plc.scan(0)
    assert plc.read("Main.b") == 0x34


@pytest.mark.parametrize("offset, ok", [("NJ", True), ("CJ", True), ("User", True), ("PLC", False)])
def test_struct_member_offsets_are_read_and_kept_by_the_export(tmp_path, offset, ok):
    """W501 6-43: offset type CJ or User changes the members' memory layout; no behaviour of vplc depends on it
    (a structure is refused wherever its memory image is read), so it is read and written back on export."""
    t = ('<DataTypeDecl name="stPair"><UserDefinedTypeSpec xsi:type="StructTypeSpec">'
         '<Member name="A"><Type><TypeName>INT</TypeName></Type></Member>'
         f'<AddData><Data {SMC}><smcext:StructTypeSpecAdditionalProperties offsetType="{offset}"/></Data></AddData>'
         '</UserDefinedTypeSpec></DataTypeDecl>')
    path = write(tmp_path, doc(t))
    if not ok:
        refused(path, "data type stPair", f'offsetType="{offset}"')
        return
    assert diagnostics(path) == []
    from vplc.cli.main import main
    out = tmp_path / "again.xml"
    assert main(["export", str(path), "--format", "iec61131-10", "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert (f'offsetType="{offset}"' in text) is (offset != "NJ")
    assert diagnostics(out) == []


def _inline(st: str, src=1, out=None) -> str:
    """smcext:InlineST as Sysmac Studio writes it: its connection points and ST in the Omron namespace."""
    cout = f'<smcext:ConnectionPointOut connectionPointOutId="{out}"/>' if out else ""
    return (f'<LdObject xsi:type="smcext:InlineST" xmlns:smcext="https://www.ia.omron.com/Smc">'
            f'<smcext:ConnectionPointIn><Connection refConnectionPointOutId="{src}"/></smcext:ConnectionPointIn>'
            f'{cout}<smcext:ST><ST>{st}</ST></smcext:ST></LdObject>')


def test_inline_st_runs_while_the_rung_gives_it_power_and_passes_the_power_on(tmp_path):
    rungs = [RAIL + contact("Go", 1, 2) + _inline("N := N + 1;\nIF N &gt; 2 THEN Big := TRUE; END_IF;", 2, 3)
             + coil("After", 3)]
    r = Run(write(tmp_path, iec10_program({"Go": "BOOL", "N": "INT", "Big": "BOOL", "After": "BOOL"}, rungs)))
    assert r.scan(Go=False)["N"] == 0 and r.scan(Go=False)["After"] is False
    r.scan(Go=True)
    r.scan(Go=True)
    out = r.scan(Go=True)
    assert out["N"] == 3 and out["Big"] is True and out["After"] is True


@pytest.mark.parametrize("st", ["END_PROGRAM PROGRAM Evil", "IF Go THEN", "VAR X : INT; END_VAR", "Q := ;"])
def test_inline_st_that_is_not_whole_statements_is_refused_at_its_rung(tmp_path, st):
    rungs = [RAIL + _inline(st)]
    refused(write(tmp_path, iec10_program({"Q": "BOOL", "Go": "BOOL"}, rungs)), "Main:rung 1", "smcext:InlineST")


def test_jump_with_target_network_label_skips_to_the_labelled_rung(tmp_path):
    jump = '<FbdObject xsi:type="Jump" targetNetworkLabel="Later">' + cin(2) + "</FbdObject>"
    rungs = [RAIL + contact("Skip", 1, 2) + jump, RAIL + contact("A", 1, 2) + coil("Mid", 2),
             RAIL + contact("A", 1, 2) + coil("End", 2)]
    text = iec10_program({"Skip": "BOOL", "A": "BOOL", "Mid": "BOOL", "End": "BOOL"}, rungs)
    text = text.replace('<Rung evaluationOrder="3">', '<Rung evaluationOrder="3" label="Later">')
    r = Run(write(tmp_path, text))
    r.scan(Skip=True, A=True)
    assert (r["Mid"], r["End"]) == (False, True)
    r.scan(Skip=False)
    assert r["Mid"] is True


FUNCTION_EN = ('<Function name="Twice"><ResultType><TypeName>INT</TypeName></ResultType><Parameters>'
               '<InputVars><Variable name="EN" orderWithinParamSet="0"><Type><TypeName>BOOL</TypeName></Type>'
               '<InitialValue><SimpleValue value="TRUE"/></InitialValue></Variable>'
               '<Variable name="X" orderWithinParamSet="1"><Type><TypeName>INT</TypeName></Type></Variable></InputVars>'
               '<OutputVars><Variable name="ENO" orderWithinParamSet="2"><Type><TypeName>BOOL</TypeName></Type>'
               '</Variable></OutputVars></Parameters>'
               '<MainBody><BodyContent xsi:type="ST"><ST>Twice := X * 2;</ST></BodyContent></MainBody></Function>')


def test_a_functions_en_and_eno_are_the_implicit_ones(tmp_path):
    src = write(tmp_path, doc(FUNCTION_EN), "twice.xml")
    (tmp_path / "Main.st").write_text("PROGRAM Main\nVAR Y : INT; END_VAR\nY := Twice(21);\nEND_PROGRAM\n",
                                      encoding="utf-8")
    r = Run(src, extra=[tmp_path / "Main.st"])
    assert r.scan()["Y"] == 42, "a positional call does not see EN: Sysmac's EN is vplc's implicit EN"


def _param_fb(props: str, list_attrs: str = "") -> str:
    return ('<FunctionBlock name="Fb"><Parameters>'
            f'<InputVars{list_attrs}><Variable name="Limit" orderWithinParamSet="0">{props}'
            '<Type><TypeName>INT</TypeName></Type><InitialValue><SimpleValue value="5"/></InitialValue></Variable>'
            '</InputVars><InputVars><Variable name="Go" orderWithinParamSet="1"><Type><TypeName>BOOL</TypeName>'
            '</Type></Variable></InputVars></Parameters>'
            '<MainBody><BodyContent xsi:type="ST"><ST>Limit := 7;</ST></BodyContent></MainBody></FunctionBlock>')


def test_constant_parameter_is_constant(tmp_path):
    props = (f'<AddData><Data {SMC}><smcext:ParameterSetVariableAdditionalProperties constant="true"/></Data>'
             '</AddData>')
    d = refused(write(tmp_path, doc(_param_fb(props))), "`Limit` is a CONSTANT and cannot be written")
    assert d.code == "ST1301"
    assert diagnostics(write(tmp_path, doc(_param_fb("")), "plain.xml")) == [], "without it the input is writable"


def test_retain_stays_on_its_own_parameter_list(tmp_path):
    proj = load_project([str(write(tmp_path, doc(_param_fb("", ' retain="true"'))))])
    assert not proj.has_errors, proj.render_diagnostics()
    fb = next(i for u in proj.units for i in getattr(u, "items", []) if getattr(i, "name", "") == "Fb")
    inputs = [(s.retain, [d.name for d in s.vars]) for s in fb.sections if s.kind == "VAR_INPUT"]
    assert inputs == [(True, ["Limit"]), (False, ["Go"])], "RETAIN does not spread to the next list"


def test_unknown_sysmac_extension_element_is_an_error_naming_it(tmp_path):
    fb = _param_fb(f'<AddData><Data {SMC}><smcext:FutureThing mode="x"/></Data></AddData>')
    refused(write(tmp_path, doc(fb)), "smcext:FutureThing")
    other = _param_fb('<AddData><Data name="https://example.com/tool" handleUnknown="discard"><Note/></Data></AddData>')
    assert diagnostics(write(tmp_path, doc(other), "other.xml")) == [], "another vendor's data is discarded"


def test_nested_namespaces_are_read_with_their_full_name(tmp_path):
    """Sysmac nests namespaces (Omron's sample: Namespace1\\Namespace1); a type of the inner one is Outer\\Inner\\eX."""
    t = ('<NamespaceDecl name="Outer"><NamespaceDecl name="Inner"><DataTypeDecl name="eX">'
         '<UserDefinedTypeSpec xsi:type="EnumTypeWithNamedValueSpec"><Enumerator name="A" value="0"/>'
         '<Enumerator name="B" value="7"/>'
         '<BaseType>DINT</BaseType></UserDefinedTypeSpec></DataTypeDecl></NamespaceDecl></NamespaceDecl>')
    st = tmp_path / "use.st"
    st.write_text("PROGRAM Main\nVAR x : Outer\\Inner\\eX := Outer\\Inner\\eX#B; n : DINT; END_VAR\n"
                  "n := EnumToNum(x);\nEND_PROGRAM\n")
    xml = write(tmp_path, doc(t))
    assert diagnostics(xml, st) == []
    plc = load_plc([str(xml), str(st)], task="Main@1ms")
    plc.scan(0)
    assert plc.read("Main.n") == 7


def test_enumeration_base_type_is_the_schemas_text_and_dint(tmp_path):
    t = ('<DataTypeDecl name="eX"><UserDefinedTypeSpec xsi:type="EnumTypeWithNamedValueSpec">'
         '<Enumerator name="A" value="0"/><Enumerator name="B" value="70000"/><BaseType>DINT</BaseType>'
         '</UserDefinedTypeSpec></DataTypeDecl>')
    assert diagnostics(write(tmp_path, doc(t))) == []
    refused(write(tmp_path, doc(t.replace("<BaseType>DINT", "<BaseType>eY")), "bad.xml"), "eY")


def test_ld_body_of_a_function_block_runs(tmp_path):
    fb = ('<FunctionBlock name="Pass"><Parameters><InputVars><Variable name="I" orderWithinParamSet="0"><Type>'
          '<TypeName>BOOL</TypeName></Type></Variable></InputVars><OutputVars><Variable name="O" '
          'orderWithinParamSet="1"><Type><TypeName>BOOL</TypeName></Type></Variable></OutputVars></Parameters>'
          '<MainBody><BodyContent xsi:type="LD"><Rung evaluationOrder="1">' + RAIL + contact("I", 1, 2)
          + coil("O", 2) + '<FbdObject xsi:type="DataSink" identifier=""/></Rung></BodyContent></MainBody>'
          '</FunctionBlock>')
    src = write(tmp_path, doc(fb), "pass.xml")
    (tmp_path / "Main.st").write_text("PROGRAM Main\nVAR P : Pass; A : BOOL; Q : BOOL; END_VAR\nP(I := A, O => Q);\n"
                                      "END_PROGRAM\n", encoding="utf-8")
    r = Run(src, extra=[tmp_path / "Main.st"])
    assert r.scan(A=True)["Q"] is True and r.scan(A=False)["Q"] is False


def test_files_of_earlier_exports_load_with_a_warning_naming_the_rule(tmp_path):
    old_jump = '<FbdObject xsi:type="Jump" label="Later">' + cin(2) + "</FbdObject>"
    rungs = [RAIL + contact("A", 1, 2) + coil("Q", 2, storage="set"), RAIL + contact("Skip", 1, 2) + old_jump,
             RAIL + contact("A", 1, 2) + coil("Mid", 2), RAIL + contact("A", 1, 2) + coil("End", 2)]
    text = iec10_program({"A": "BOOL", "Skip": "BOOL", "Q": "BOOL", "Mid": "BOOL", "End": "BOOL"}, rungs)
    text = text.replace('<Rung evaluationOrder="4">', '<Rung evaluationOrder="4" label="Later">')
    path = write(tmp_path, text)
    found = diagnostics(path)
    assert all(d.severity == "warning" and d.code == "ST2108" for d in found)
    messages = " | ".join(d.message for d in found)
    assert 'latch="set"' in messages and "targetNetworkLabel" in messages
    r = Run(path)
    r.scan(A=True, Skip=True)
    assert (r["Q"], r["Mid"], r["End"]) == (True, False, True), "storage=set is a set coil; the jump skips"
    assert r.scan(A=False, Skip=False)["Q"] is True and r["Mid"] is False


def test_malformed_sysmac_attributes_are_errors_with_their_place_never_a_traceback(tmp_path):
    bad = {
        "order": (doc(_param_fb("").replace('orderWithinParamSet="0"', 'orderWithinParamSet="x"')),
                  'Fb:variable Limit: orderWithinParamSet="x" is not an integer'),
        "rung": (iec10_program({"A": "BOOL"}, [RAIL]).replace('<Rung evaluationOrder="1"',
                                                              '<Rung evaluationOrder="1st"'),
                 'Main:rung: evaluationOrder="1st" is not an integer'),
        "body": (iec10_program({"A": "BOOL"}, [RAIL]).replace('name="S" evaluationOrder="1"',
                                                              'name="S" evaluationOrder="?"'),
                 'Main:body S: evaluationOrder="?" is not an integer'),
        "latch": (iec10_program({"A": "BOOL", "Q": "BOOL"}, [RAIL + contact("A", 1, 2) + coil("Q", 2, latch="on")]),
                  'Main:rung 1:coil Q: latch="on" is not one of none, set, reset'),
        "both": (iec10_program({"A": "BOOL", "Q": "BOOL"},
                               [RAIL + contact("A", 1, 2) + coil("Q", 2, latch="set", storage="reset")]),
                 'latch="set" and storage="reset" contradict each other'),
        "jump": (iec10_program({"A": "BOOL"}, [RAIL + contact("A", 1, 2) + '<FbdObject xsi:type="Jump">' + cin(2)
                                               + "</FbdObject>"]), "a Jump without targetNetworkLabel"),
        "using": (doc(FUNCTION_EN.replace("<ResultType>", "<UsingDirective>A</UsingDirective><UsingDirective>B"
                                          "</UsingDirective><ResultType>")), "UsingDirective A, B"),
    }
    for name, (text, message) in bad.items():
        d = refused(write(tmp_path, text, f"{name}.xml"), message)
        assert "internal error" not in d.message, name


def test_old_export_declarations_load_with_one_warning_per_rule(tmp_path):
    old = ('<DataTypeDecl name="eOld"><UserDefinedTypeSpec xsi:type="EnumTypeWithNamedValueSpec">'
           '<Enumerator name="A" value="0"/><Enumerator name="B" value="1"/><BaseType><TypeName>DINT</TypeName>'
           '</BaseType></UserDefinedTypeSpec></DataTypeDecl>'
           '<FunctionBlock name="Old"><Parameters><InputVars constant="true">'
           '<Variable name="K" orderWithinParamSet="0">'
           '<Type><TypeName>INT</TypeName></Type><InitialValue><SimpleValue value="3"/></InitialValue></Variable>'
           '</InputVars><InOutVars><Variable name="Buf" orderWithinParamSet="1"><Type><InstantlyDefinedType '
           'xsi:type="ArrayTypeSpec"><BaseType><TypeName>BYTE</TypeName></BaseType><DimensionSpec dimensionNumber="1"/>'
           '</InstantlyDefinedType></Type></Variable></InOutVars></Parameters>'
           '<MainBody><BodyContent xsi:type="ST"><ST>Buf[0] := INT_TO_BYTE(K);</ST></BodyContent></MainBody>'
           '</FunctionBlock>')
    found = diagnostics(write(tmp_path, doc(old)))
    assert {d.severity for d in found} == {"warning"} and {d.code for d in found} == {"ST2108"}
    text = " | ".join(d.message for d in found)
    for rule in ("spelt InoutVars", "per variable", "BaseType>DINT</BaseType>", "IndexRange or VariableLength"):
        assert rule in text, rule
    assert len(found) == 4, "one warning per rule"


def test_using_directive_outside_a_pou_is_refused(tmp_path):
    fb = _param_fb("").replace("<Type><TypeName>BOOL</TypeName>",
                               "<UsingDirective>Other</UsingDirective><Type><TypeName>BOOL</TypeName>", 1)
    text = doc(fb)
    refused(write(tmp_path, text), "Variable Go", "UsingDirective Other")


def test_namespace_declarations_nested_too_deep_are_refused(tmp_path):
    t = '<NamespaceDecl name="N">' * 40 + '</NamespaceDecl>' * 40
    refused(write(tmp_path, doc(t)), "deeper than 32")


def _pin_in(name, src) -> str:
    return f'<InputVariable parameterName="{name}">{cin(src)}</InputVariable>'


def _pin_out(name, out, **attrs) -> str:
    a = "".join(f' {k}="{v}"' for k, v in attrs.items())
    return (f'<OutputVariable parameterName="{name}"{a}><ConnectionPointOut connectionPointOutId="{out}"/>'
            '</OutputVariable>')


def _source(var, out) -> str:
    return (f'<FbdObject xsi:type="DataSource" identifier="{var}">'
            f'<ConnectionPointOut connectionPointOutId="{out}"/></FbdObject>')


def _sink(var, src) -> str:
    return f'<FbdObject xsi:type="DataSink" identifier="{var}">{cin(src)}</FbdObject>'


def _block(type_name, inputs, outputs) -> str:
    return (f'<FbdObject xsi:type="Block" typeName="{type_name}"><InputVariables>{inputs}</InputVariables>'
            f'<OutputVariables>{outputs}</OutputVariables></FbdObject>')


def test_an_in_out_drawn_as_an_input_and_an_output_of_the_same_name_is_the_in_out(tmp_path):
    # W502 draws Inc with InOut on both sides of the box (IEC 61131-3's graphical VAR_IN_OUT); a file that lists
    # it under InputVariables and OutputVariables passes the variable: the output is the counter after the call,
    # the unnamed output the BOOL result (it was read as the result and refused as BOOL := UDINT)
    inc = _block("Inc", _pin_in("EN", 2) + _pin_in("InOut", 3),
                 _pin_out("ENO", 4) + _pin_out("InOut", 5) + _pin_out("", 6))
    rungs = [RAIL + contact("Go", 1, 2) + _source("Count", 3) + inc + _sink("Count", 5) + coil("Ran", 6)]
    r = Run(write(tmp_path, iec10_program({"Go": "BOOL", "Ran": "BOOL", "Count": "UDINT"}, rungs)))
    assert r.scan(Go=True)["Count"] == 1 and r["Ran"] is True
    assert r.scan(Go=True)["Count"] == 2, "the output is the in-out's variable, not a second increment"
    assert r.scan(Go=False)["Count"] == 2, "without EN the instruction does not run"
    assert diagnostics(tmp_path / "sysmac.xml") == []


TOGGLE = """FUNCTION Toggle : BOOL
VAR_IN_OUT X : BOOL; END_VAR
X := NOT X;
Toggle := FALSE;
END_FUNCTION
"""


def test_an_in_out_output_of_the_same_name_is_never_read_as_the_functions_result(tmp_path):
    # the silent misread this prevents: Q took Toggle's result (always FALSE) instead of X after the call
    (tmp_path / "Toggle.st").write_text(TOGGLE, encoding="utf-8")
    rungs = [RAIL + _source("B", 3) + _block("Toggle", _pin_in("EN", 1) + _pin_in("X", 3),
                                              _pin_out("ENO", 4) + _pin_out("X", 5)) + _sink("Q", 5)]
    r = Run(write(tmp_path, iec10_program({"B": "BOOL", "Q": "BOOL"}, rungs)), extra=[tmp_path / "Toggle.st"])
    assert r.scan()["B"] is True and r["Q"] is True
    assert r.scan()["B"] is False and r["Q"] is False


def test_a_negated_in_out_drawn_on_both_sides_is_refused_by_name(tmp_path):
    (tmp_path / "Toggle.st").write_text(TOGGLE, encoding="utf-8")
    rungs = [RAIL + _source("B", 3) + _block("Toggle", _pin_in("EN", 1) + _pin_in("X", 3),
                                              _pin_out("ENO", 4) + _pin_out("X", 5, negated="true")) + _sink("Q", 5)]
    write(tmp_path, iec10_program({"B": "BOOL", "Q": "BOOL"}, rungs))
    err = refused(tmp_path / "sysmac.xml", "rung 1", "block Toggle", "in-out `X`", "negated")
    assert err.severity == "error"


def _fb_section(fb_name: str, proj, kind: str) -> list:
    fb = next(i for u in proj.units for i in getattr(u, "items", []) if getattr(i, "name", "") == fb_name)
    return [s for s in fb.sections if s.kind == kind]


def test_list_and_member_booleans_are_xsd_booleans_1_as_true(tmp_path):
    # retain, constant and overlap are xsd:boolean: "1" means true (read as false before: RETAIN lost silently)
    proj = load_project([str(write(tmp_path, doc(_param_fb("", ' retain="1"'))))])
    assert not proj.has_errors, proj.render_diagnostics()
    assert [s.retain for s in _fb_section("Fb", proj, "VAR_INPUT")] == [True, False]
    props = (f'<AddData><Data {SMC}><smcext:ParameterSetVariableAdditionalProperties constant="1"/></Data>'
             '</AddData>')
    refused(write(tmp_path, doc(_param_fb(props)), "const.xml"), "`Limit` is a CONSTANT and cannot be written")
    refused(write(tmp_path, doc(_param_fb("", ' retain="yes"')), "bad.xml"),
            "Fb", 'retain="yes" is not a boolean')


def test_array_dimensions_are_read_by_their_dimension_number(tmp_path):
    # DimensionSpec dimensionNumber names the dimension; a file listing dimension 2 first is still ARRAY[1..2, 0..4]
    from vplc.export.model import type_text
    fb = ('<FunctionBlock name="Grid"><Vars accessSpecifier="private"><Variable name="Cells"><Type>'
          '<InstantlyDefinedType xsi:type="ArrayTypeSpec"><BaseType><TypeName>INT</TypeName></BaseType>'
          '<DimensionSpec dimensionNumber="2"><IndexRange lower="0" upper="4"/></DimensionSpec>'
          '<DimensionSpec dimensionNumber="1"><IndexRange lower="1" upper="2"/></DimensionSpec>'
          '</InstantlyDefinedType></Type></Variable></Vars>'
          '<MainBody><BodyContent xsi:type="ST"><ST>Cells[2, 4] := 1;</ST></BodyContent></MainBody></FunctionBlock>')
    proj = load_project([str(write(tmp_path, doc(fb)))])
    assert not proj.has_errors, proj.render_diagnostics()
    [cells] = _fb_section("Grid", proj, "VAR")[0].vars
    assert type_text(cells.type).replace(" ", "") == "ARRAY[1..2,0..4]OFINT"
    refused(write(tmp_path, doc(fb.replace('dimensionNumber="1"', 'dimensionNumber="one"')), "bad.xml"),
            "Grid", 'dimensionNumber="one" is not an integer')
