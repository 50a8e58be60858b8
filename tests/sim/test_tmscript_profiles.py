"""Version profiles (--tmflow 1.8 / 2.24) from the one function table tmsim.tmscript.functions: every function, data
format and Robot[0] attribute passes where its version has it and is refused (ERROR;line, as an unknown
name) where it does not; values print as a 32-bit TM float does."""
import pytest
from session_rig import S, sct

from tmsim.protocol import codec
from tmsim.robot.camera import camera_of
from tmsim.tmscript import functions as tmscript
from tmsim.tmscript.interp import float_text
from tmsim.tmscript.profiles import Profile

# one call per overload that the checker accepts, and one it refuses (wrong type or arity)
EXAMPLES = {
    "PTP": ('PTP("JPP",0,0,90,0,90,5,50,200,0,false)', 'PTP("JPP",0,0,90)'),
    "Line": ('Line("CAP",417.5,-122.3,343.9,180,0,90,100,200,0,false)', 'Line("CAP",{1,2,3,4,5,6},"x",200,0,false)'),
    "Circle": ('Circle("CPP",{417.5,-100,343.9,180,0,90},{417.5,-80,343.9,180,0,90},50,200,0,0,false)',
               'Circle("CPP",{1,2,3,4,5,6},50,200,0,0,false)'),
    "PLine": ('PLine("CAP",417.5,-122.3,343.9,180,0,90,100,200,0)', 'PLine("CAP",true,100,200,0)'),
    "Move_PTP": ('Move_PTP("JPP",0,0,0,0,0,5,50,200,0,false)', 'Move_PTP("JPP",0,0,0,0,0,5)'),
    "Move_Line": ('Move_Line("CAP",0,0,-5,0,0,0,100,200,0,false)', 'Move_Line("CAP",{0,0,5})'),
    "Move_PLine": ('Move_PLine("CAP",0,0,-5,0,0,0,100,200,0)', 'Move_PLine()'),
    "ChangeBase": ('ChangeBase("RobotBase")', 'ChangeBase(true)'),
    "ChangeTCP": ('ChangeTCP("NOTOOL")', 'ChangeTCP(1,2)'),
    "ChangeLoad": ("ChangeLoad(1.5)", 'ChangeLoad("a")'),
    "PVTEnter": ("PVTEnter(0)", 'PVTEnter("joint")'),
    "PVTPoint": ("PVTPoint({0,0,90,0,90,0},{0,0,0,0,0,0},0.5)", 'PVTPoint("JPP",{0,0,90,0,90,0},{0,0,0,0,0,0},500)'),
    "PVTExit": ("PVTExit()", "PVTExit(1)"),
    "PVTPause": ("PVTPause()", "PVTPause(1)"),
    "PVTResume": ("PVTResume()", "PVTResume(1)"),
    "QueueTag": ("QueueTag(3)", 'QueueTag("3")'),
    "WaitQueueTag": ("WaitQueueTag(3, 0)", 'WaitQueueTag("3")'),
    "CheckQueueTag": ("CheckQueueTag(3)", "CheckQueueTag()"),
    "StopAndClearBuffer": ("StopAndClearBuffer()", 'StopAndClearBuffer("x")'),
    "Pause": ("Pause()", "Pause(1)"),
    "Resume": ("Resume()", "Resume(1)"),
    "ScriptExit": ("ScriptExit()", 'ScriptExit("x")'),
    "ListenSend": ('ListenSend(90, "x")', "ListenSend()"),
    "ListenPacket": ('ListenPacket("x")', "ListenPacket(1,2,3)"),
    "GetString": ("GetString(1.5)", "GetString()"),
    "Sleep": ("Sleep(0)", 'Sleep("1")'),
    "Vision_DoJob": ('Vision_DoJob("job1")', "Vision_DoJob(1)"),
    "Vision_DoJob_PTP": ('Vision_DoJob_PTP("job1",100,500)', 'Vision_DoJob_PTP("job1")'),
    "Vision_DoJob_Line": ('Vision_DoJob_Line("job1",100)', 'Vision_DoJob_Line("job1","x")'),
    "Vision_IsJobAvailable": ('Vision_IsJobAvailable("job1")', "Vision_IsJobAvailable()"),
    "Vision_GetOutputArraySize": ('Vision_GetOutputArraySize("job1_Base_TM")', "Vision_GetOutputArraySize(1)"),
    "Vision_GetOutputArrayValue": ('Vision_GetOutputArrayValue("job1_Base_TM",0,1)',
                                   'Vision_GetOutputArrayValue("job1_Base_TM")'),
}


def reply(node, script):
    return node.send(1, sct("T", script))[-1]


def node_of(version):
    n = S(profile=Profile(tmflow=version))
    n.connect(1)
    n.out(1)
    camera = camera_of(n.s.robot)             # a vision job that has run: the vision examples have its output
    camera.define("job1", objects=[[1, 2, 3, 4, 5, 6]], seconds=0)
    camera.finish(camera.jobs["job1"])
    return n


def ok(status):
    return codec.encode("TMSCT", f"T,{status}").decode()


def test_every_function_of_the_table_has_a_passing_and_a_failing_example():
    assert sorted(EXAMPLES) == sorted(tmscript.FUNCTIONS)


@pytest.mark.parametrize("name", sorted(tmscript.FUNCTIONS))
@pytest.mark.parametrize("version", tmscript.ALL)
def test_each_function_passes_where_its_version_has_it_and_fails_with_bad_arguments(name, version):
    good, bad = EXAMPLES[name]
    node = node_of(version)
    assert reply(node, bad) == ok("ERROR;1"), bad
    assert reply(node, good) == (ok("OK") if tmscript.overloads(name, version) else ok("ERROR;1")), good


@pytest.mark.parametrize("script", ['Line("CDP",417.5,-122.3,343.9,180,0,90,100,200,0,false)',
                                    'Line("CDR",{417.5,-122.3,343.9,180,0,90},100,200,0,false)',
                                    'Move_Line("TDP",{0,0,-5,0,0,0},100,200,0,false)',
                                    'Circle("CDP",{417.5,-100,343.9,180,0,90},{417.5,-80,343.9,180,0,90},50,200,0,0,false)',
                                    "PVTPoint(0,0,90,0,90,0,0,0,0,0,0,0,0.5,false)", "WaitQueueTag()",
                                    "float p = Robot[0].Payload", 'byte[] d = IO["ControlBox"].DI'])
def test_manual_2_24_additions_run_on_2_24_and_are_unknown_on_1_8(script):
    assert reply(node_of("2.24"), script) == ok("OK")
    assert reply(node_of("1.8"), script) == ok("ERROR;1")


def test_cdp_is_an_absolute_speed_in_mm_per_s_like_cap_the_simulator_has_no_project_speed():
    durations = {}
    for fmt in ("CDP", "CAP"):
        node = node_of("2.24")
        node.send(1, sct("A", f'Line("{fmt}",417.5,-122.3,243.9,180,0,90,100,0,0,false)'))
        node.advance(0.1)
        durations[fmt] = [f for kind, f in node.events if kind == "motion_start"][-1]["duration_s"]
    assert durations["CDP"] == durations["CAP"] > 1.0                  # > 100 mm at 100 mm/s


def test_manual_13_10_speed_minus_1_selects_the_acceleration_table_which_a_tm5_700_does_not_have():
    node = node_of("2.24")
    assert reply(node, 'PTP("JPP",0,0,90,0,90,5,-1,500,0,false)') == ok("OK")
    node.advance(0.1)
    assert node.s.state == "project_stopped" and "acceleration table" in node.s.last_error


def test_manual_11_5_whole_io_arrays_read_as_arrays_and_are_read_only():
    node = node_of("2.24")
    node.send(1, sct("A", 'IO["ControlBox"].DO[2] = 1\r\nIO["ControlBox"].AO[1] = 2.5'))
    node.advance(0.1)
    node.out(1)
    frames = node.send(1, sct("B", 'byte[] d = IO["ControlBox"].DO\r\nfloat[] a = IO["ControlBox"].AO\r\n'
                                   'ListenSend(90, GetString(d) + "|" + GetString(a))'))
    assert frames[0].split(",", 3)[3].startswith("{0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0}|{0,2.5}")
    assert reply(node, 'IO["ControlBox"].DO = {1,1}') == ok("ERROR;1")
    assert reply(node, 'float[] x = IO["Nowhere"].DI') == ok("ERROR;1")


def test_manual_11_6_robot_attributes_payload_and_instant_camera_light():
    node = node_of("2.24")
    node.send(1, sct("A", "ChangeLoad(2.5)"))
    node.advance(0.1)
    node.out(1)
    frames = node.send(1, sct("B", "Robot[0].InstantCameraLight = 1\r\n"
                                   'ListenSend(90, GetString(Robot[0].Payload) + ","'
                                   ' + GetString(Robot[0].CameraLight))'))
    assert frames[0].split(",", 3)[3].startswith("2.5,1,")
    assert reply(node, "Robot[0].Payload = 1") == ok("ERROR;1")


@pytest.mark.parametrize("value,text", [(0.1, "0.1"), (417.5, "417.5"), (1 / 3, "0.33333334"),
                                        (399.99999999999994, "400"), (-122.30000000000001, "-122.3"),
                                        (1e15, "1E+15"), (1.5e-7, "1.5E-07"), (0.0001, "0.0001"), (-0.0, "0")])
def test_floats_print_as_a_32_bit_tm_float(value, text):
    assert float_text(value) == text


def test_get_string_of_a_pose_prints_32_bit_floats():
    node = node_of("2.24")
    frames = node.send(1, sct("B", "float f = 0.1 + 0.2\r\nListenSend(90, GetString(f) + \";\" + 1.1)"))
    assert frames[0].split(",", 3)[3].startswith("0.3;1.1,")


def test_a_pvt_mode_outside_0_and_1_is_a_run_time_error_as_in_the_manual():
    node = node_of("2.24")
    assert reply(node, "PVTEnter(2)") == ok("ERROR;1")                  # §13.17: 0 joint, 1 Cartesian only


def test_the_docs_profile_table_names_every_function_format_and_attribute_of_the_table():
    from pathlib import Path
    text = (Path(__file__).resolve().parents[2] / "docs" / "simulator.md").read_text(encoding="utf-8")
    section = text[text.index("### Version profiles"):text.index("### Third-party clients")]
    missing = [name for name in tmscript.FUNCTIONS if f"`{name}" not in section and f" {name}" not in section]
    missing += [fmt for table in tmscript.FORMATS.values() for fmt, versions in table.items()
                if versions == tmscript.NEW and fmt not in section]
    missing += [attr for attr in tmscript.ROBOT if attr not in section]
    assert missing == []


def test_overloads_of_one_arity_agree_on_their_int_parameters():
    """The interpreter converts int arguments by arity (tmsim.tmscript.functions.INT_ARGUMENTS): that needs one set of
    int positions per arity of every function."""
    assert all(len(kinds) == 1 for kinds in tmscript.int_parameter_kinds().values())


def _call_with(name, params, position, bad):
    """A call of ``name`` with valid arguments of types ``params``, ``bad`` at ``position``."""
    fmt = [f for f in (tmscript.formats(name, tmscript.V224) or ("RobotBase",)) if f.startswith("C")] or ["CAP"]
    valid = {"string": f'"{fmt[0]}"', "float": "0", "float[]": "{417,0,300,180,0,90}", "int": "1",
             "int[]": "{0,2,4}", "bool": "false", "any": '"x"'}
    args = [valid[p] for p in params]
    args[position] = f"{{0,2,{bad}}}" if params[position] == "int[]" else bad
    return f"{name}({','.join(args)})"


INT_CASES = [(name, params, position) for name, (_queued, entries) in sorted(tmscript.FUNCTIONS.items())
             for params, _ret, versions in entries if tmscript.V224 in versions
             for position, kind in enumerate(params) if kind in ("int", "int[]")]


@pytest.mark.parametrize("bad", ["1e30", "2147483648", "-1e30"])
@pytest.mark.parametrize("name,params,position", INT_CASES)
def test_manual_2_2_a_value_outside_int_in_any_int_parameter_is_an_error_of_its_line(name, params, position, bad):
    """docs/simulator.md "Limits": a float outside int converted to int is ERROR;n - for variables and, in one
    place (the interpreter's argument conversion), for every int parameter of every function: Sleep(1e30) once
    waited 10^27 s and the robot served no script after it. A decimal constant beyond int is a float constant
    [MAN 2.24 §2.2]."""
    node = node_of("2.24")
    script = _call_with(name, params, position, bad)
    assert reply(node, script) == ok("ERROR;1"), script
    reason = [f for kind, f in node.events if kind == "runtime_error"][-1]["reason"]
    assert f"{name} argument {position + 1}: value" in reason and "does not fit int" in reason, reason
    assert reply(node, "Sleep(0)") == ok("OK")                 # the robot keeps serving scripts


@pytest.mark.parametrize("script", ["ListenSend(90, GetString(WaitQueueTag()))", "int k = WaitQueueTag()",
                                    "bool b = !WaitQueueTag()", "int k = 1 + Sleep(1)",
                                    'string s = "t" + GetString(Sleep(0))', "int[] a = {1, Sleep(1)}",
                                    "int k = 0\r\nk = WaitQueueTag()", "QueueTag(Sleep(1))"])
def test_manual_13_2_syntax_3_a_void_result_in_an_expression_is_an_error_and_nothing_runs(script):
    """WaitQueueTag() (TMscript 2.24 §13.2 syntax 3) and Sleep() return void: used as a value - an argument,
    an operand, an initial or assigned value - the line is refused (ERROR;line) and no Python None reaches
    the wire ($TMSTA,7,90,None once)."""
    node = node_of("2.24")
    status = reply(node, script)
    assert status == ok("ERROR;" + str(script.count("\r\n") + 1)), status
    reason = [f for kind, f in node.events if kind == "script_error"][-1]["reason"]
    assert "returns no value" in reason, reason
    assert node.out(1) == [] and not any(kind == "script_line" for kind, _ in node.events)


def test_a_void_call_as_a_statement_of_its_own_runs():
    node = node_of("2.24")
    assert reply(node, "WaitQueueTag()\r\nSleep(0)") == ok("OK")
