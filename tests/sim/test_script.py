"""Script parser and checker: ERROR;lines for exactly the offending lines, OK;lines for warnings."""
import pytest

from tmsim.tmscript.parser import Call, Decl, split_lines
from tmsim.tmscript.static_check import check_script


def check(script, variables=None):
    lines = split_lines(script)
    check_script(lines, variables or {})
    return [ln.number for ln in lines if ln.error], [ln.number for ln in lines if ln.warnings and not ln.error], lines


@pytest.mark.parametrize("line", [
    'PTP("JPP",0,0,90,0,90,0,35,200,0,false)',
    'PTP("CPP",400,-100,350,180,0,90,50,200,0,true,0,2,4)',
    'PTP("CPP",{400,-100,350,180,0,90},50,200,0,true,{0,2,4})',
    'Line("CAR",417.5,-122.3,343.9,180,0,90,100,200,50,false)',
    'Line("CPP",{400,-100,350,180,0,90},50,200,0,true)',
    'Circle("CAP",{1,2,3,4,5,6},{7,8,9,10,11,12},100,200,0,0,false)',
    'Circle("CPP",1,2,3,4,5,6,7,8,9,10,11,12,100,200,0,90,false)',
    'PLine("CAP",400,-100,350,180,0,90,100,200,0)', 'PLine("JAP",{0,0,90,0,90,0},100,200,0)',
    'Move_PTP("TPP",0,0,10,0,0,0,50,200,0,false)', 'Move_PTP("JPP",{10,0,0,0,0,0},50,200,0,false)',
    'Move_Line("TAR",0,0,10,0,0,0,100,200,5,false)', 'Move_PLine("TAP",0,0,10,0,0,0,100,200,0)',
    'ChangeBase("RobotBase")', "ChangeBase({0,0,0,0,0,0})", "ChangeBase(1,2,3,4,5,6)",
    'ChangeTCP("NOTOOL")', "ChangeTCP({0,0,100,0,0,0})", "ChangeTCP({0,0,100,0,0,0},1.5)",
    "ChangeTCP({0,0,100,0,0,0},1.5,{1,1,1,0,0,0,0,0,0})", "ChangeTCP(0,0,100,0,0,0,1.5)",
    "ChangeLoad(10.1)", "QueueTag(1)", "QueueTag(2,1)", "WaitQueueTag(1)", "WaitQueueTag(1,-1)",
    "StopAndClearBuffer()", "Pause()", "Resume()", "ScriptExit()",
    'ListenSend(90,"Hello World")', 'ListenSend("127.0.0.1",91,{1.0,2.0})',
    "ListenSend(92, GetString(Robot[0].CoordRobot))", 'IO["ControlBox"].DO[0] = 1',
    'IO["EndModule"].InstantDO[1] = 0', "int x = 3", "float[] p = {0,0,90,0,90,0}", 'string s = "a,b*c$"',
    "bool b = true && !false || 1 < 2", "",
])
def test_valid_lines_pass(line):
    errors, _warnings, _ = check(line)
    assert errors == []


@pytest.mark.parametrize("line, reason", [
    ("Foo()", "unknown function"),
    ('PTP("JPP",0,0,90,0,90,0,35,200,0)', "arguments"),
    ('PTP("XYZ",0,0,90,0,90,0,35,200,0,false)', "data format"),
    ('PTP("CAR",0,0,90,0,90,0,35,200,0,false)', "data format"),
    ('Line("JPP",0,0,90,0,90,0,35,200,0,false)', "data format"),
    ('Circle("CPR",{1,2,3,4,5,6},{7,8,9,10,11,12},100,200,0,0,false)', "data format"),
    ('PLine("CPP",400,-100,350,180,0,90,100,200,0)', "data format"),
    ('Move_PTP("CAR",0,0,10,0,0,0,50,200,0,false)', "data format"),
    ('Move_Line("JPP",0,0,10,0,0,0,100,200,5,false)', "data format"),
    ('PTP("JPP",0,0,90,0,90,0,35,200,0,false,0,2,4)', "arm configuration"),
    ('PTP("JPP",0,0,90,0,90,0,"fast",200,0,false)', "must be int"),
    ("QueueTag(\"a\")", "must be int"),
    ("ChangeLoad(\"heavy\")", "must be float"),
    ("PTP(", "unexpected end"),
    ('ChangeBase("RobotBase"', "expected"),
    ("x = 1", "not declared"),
    ('IO["ControlBox"].DI[0] = 1', "read-only"),
    ('IO["Nowhere"].DO[0] = 1', "unknown IO module"),
    ("Robot[0].Joint = {0,0,0,0,0,0}", "read-only"),
    ('string s = 5', "does not fit"),
    ('"unterminated', "not closed"),
    ("int 3x = 1", "malformed number"),
    ("ListenSend(90)", "arguments"),
])
def test_invalid_line_is_reported_with_a_reason(line, reason):
    errors, _warnings, lines = check(line)
    assert errors == [1]
    assert reason in lines[0].error


def test_error_lines_are_exactly_the_offending_ones():
    script = "\r\n".join(['ChangeBase("RobotBase")', "Foo()", 'PTP("JPP",0,0,90,0,90,0,35,200,0,false)',
                          'Line("XYZ",1,2,3,4,5,6,1,2,3,true)', "QueueTag(1)"])
    errors, _, _ = check(script)
    assert errors == [2, 4]


def test_unquoted_string_constant_argument_is_a_warning():
    errors, warnings, _ = check("ChangeBase(RobotBase)\r\nPTP(JPP,0,0,90,0,90,0,35,200,0,false)")
    assert errors == [] and warnings == [1, 2]
    errors, _, _ = check("PTP(XYZ,0,0,90,0,90,0,35,200,0,false)")
    assert errors == [1]


def test_warnings_for_float_truncation_and_unquoted_io_module():
    errors, warnings, _ = check("QueueTag(1.5)\r\nIO[ControlBox].DO[0]=1\r\nQueueTag(2)")
    assert errors == [] and warnings == [1, 2]


def test_redeclaring_a_node_variable_is_an_error():
    errors, _, _ = check("int var_i = 100", {"var_i": "int"})
    assert errors == [1]


def test_variable_declared_earlier_in_the_packet_can_be_used():
    errors, _, _ = check('float[] targetP1= {0,0,90,0,90,0}\r\nPTP("JPP",targetP1,10,200,0,false)\r\nQueueTag(1,1)')
    assert errors == []


def test_variable_cannot_be_used_in_its_own_declaration():
    errors, _, _ = check("int a = a + 1")
    assert errors == [1]


def test_lf_only_separation_is_an_error_of_that_line():
    errors, _, _ = check('ChangeBase("RobotBase")\nQueueTag(1)\r\nQueueTag(2)')
    assert errors == [1]


def test_empty_lines_and_trailing_crlf_are_tolerated():
    errors, _, lines = check("\r\nQueueTag(1)\r\n")
    assert errors == [] and len(lines) == 3


def test_parser_builds_calls_and_declarations():
    lines = split_lines('float[] p = {1,2}\r\nPTP("JPP",p,1,2,3,false)')
    assert isinstance(lines[0].stmt, Decl) and lines[0].stmt.is_array
    assert isinstance(lines[1].stmt.expr, Call) and lines[1].stmt.expr.name == "PTP"


def test_deeply_nested_expression_is_an_error_not_a_crash():
    errors, _, lines = check("int x = " + "(" * 5000 + "1" + ")" * 5000)
    assert errors == [1]


@pytest.mark.parametrize("text", [
    'Line("CAR",380,-100,350,180,0,90,400,100,50,true)', ' PTP ( "JPP" , -0.5 ,1e3, .5, 2., - 4, 1E-2 ) ',
    'QueueTag(1)', 'ScriptExit()', 'F( )', 'F(true,false,"")', 'F("a,b")', 'F("x\\"y")', "F('s')", 'F(0x1F)',
    'F(+3)', 'F(--3)', 'F(5x)', 'F(truex)', 'F(1,)', 'F(,1)', 'F({1,2})', 'F(1+2)', 'F(x)', 'true(1)',
    'F(1) // note', 'F(1));', 'F(-0)', 'F(-0.0)', 'F(007)', 'F(.e5)', 'F(1.e5)', 'int(3)',
])
def test_fast_path_for_literal_calls_gives_the_same_tree_as_the_parser(text):
    from tmsim.tmscript.parser import ScriptSyntaxError, _Parser, _simple_call, tokenize
    fast = _simple_call(text)
    try:
        full = repr(_Parser(tokenize(text)).line())
    except ScriptSyntaxError:
        full = None
    assert fast is None or repr(fast) == full
