"""Project API: resolved types, symbols, call bindings, conversions, namespaces, prelude (frontend_api.md)."""
from __future__ import annotations

from fe_helpers import check_text, program

from vplc.checker.symbols import EnumValueSymbol, VarSymbol
from vplc.frontend import ast as A
from vplc.frontend import types as T
from vplc.project import load_project


def stmts(proj, name="Main"):
    return [p for p in proj.programs if p.name == name][0].pou.body


def test_expressions_get_types_and_implicit_widening_is_recorded(tmp_path):
    proj = check_text(tmp_path, program("d := i + d; r := i; x := i * 2;", "i : INT; d : DINT; r : REAL; x : INT;"))
    assert not proj.has_errors, proj.render_diagnostics()
    s1, s2, s3 = stmts(proj)
    assert s1.value.ty is T.DINT and s1.value.left.conv is T.DINT and s1.value.right.conv is None
    assert s2.value.ty is T.INT and s2.value.conv is T.REAL
    assert s3.value.right.ty is T.INT       # untyped literal takes the type of its context


def test_names_resolve_to_symbols_including_globals_and_enum_values(tmp_path):
    (tmp_path / "gvl.st").write_text("VAR_GLOBAL Cobot : INT; END_VAR\n")
    check_text(tmp_path, "TYPE eStep : (Idle, Run := 10); END_TYPE\n"
               + program("Cobot := 1; s := Run; IF s = eStep#Idle THEN ; END_IF;", "s : eStep;"))
    proj = load_project([str(tmp_path)], dialect="iec")     # a global read without VAR_EXTERNAL: IEC allows it
    assert not proj.has_errors, proj.render_diagnostics()
    a, b, c = stmts(proj)
    assert isinstance(a.target.sym, VarSymbol) and a.target.sym.section == "VAR_GLOBAL"
    assert a.target.sym.global_list == "gvl"
    assert isinstance(b.value.sym, EnumValueSymbol) and b.value.sym.value == 10
    assert c.branches[0].cond.right.sym.name == "Idle"
    assert proj.global_lists[0].name == "gvl" and "COBOT" in proj.globals


def test_fb_call_binding_with_outputs_inouts_and_sysmac_array_element_rule(tmp_path):
    proj = check_text(tmp_path, program(
        "snd(Execute := TRUE, Socket := sock, SendDat := buf[2], Size := 4, Done => ok);"
        "n := ToAryByte(In := 'AB', Order := _eBYTE_ORDER#_LOW_HIGH, AryOut := buf[0]);",
        "snd : SktTCPSend; sock : _sSOCKET; buf : ARRAY[0..9] OF BYTE; ok : BOOL; n : UINT;"))
    assert not proj.has_errors, proj.render_diagnostics()
    call = stmts(proj)[0].call
    b = call.binding
    assert b.kind == "fb" and b.pou.name == "SktTCPSend" and b.pou.native
    assert [(a.param.name, a.param.direction) for a in b.args] == [
        ("Execute", "in"), ("Socket", "in"), ("Size", "in"), ("Done", "out"), ("SendDat", "inout")]
    send_dat = [a for a in b.args if a.param.name == "SendDat"][0]
    assert send_dat.from_element and isinstance(send_dat.expr, A.Index)
    fcall = stmts(proj)[1].value
    assert fcall.binding.kind == "function" and fcall.binding.ty is T.UINT


def test_builtin_calls_bind_with_result_type(tmp_path):
    proj = check_text(tmp_path, program("d := MAX(i, d, 5); s := CONCAT(s, 'x', s); r := INT_TO_REAL(i);",
                                        "i : INT; d : DINT; s : STRING[20]; r : REAL;"))
    assert not proj.has_errors, proj.render_diagnostics()
    a, b, c = stmts(proj)
    assert a.value.binding.kind == "builtin" and a.value.binding.builtin.name == "MAX" and a.value.ty is T.DINT
    assert a.value.args[0].value.conv is T.DINT
    assert len(b.value.binding.args) == 3 and T.is_string(b.value.ty)
    assert c.value.ty is T.REAL


def test_library_folder_is_a_namespace_and_bare_names_resolve_when_unique(tmp_path):
    lib = tmp_path / "CBT_Commands_Lib" / "types"
    lib.mkdir(parents=True)
    (lib / "stCBT_Connection.st").write_text("TYPE stCBT_Connection : STRUCT Connected : BOOL; END_STRUCT; END_TYPE\n")
    (tmp_path / "main.st").write_text(program("a.Connected := b.Connected;",
                                              "a : CBT_Commands_Lib\\stCBT_Connection; b : stCBT_Connection;"))
    proj = load_project([str(tmp_path)])
    assert not proj.has_errors, proj.render_diagnostics()
    assert proj.lookup_type("CBT_Commands_Lib\\stCBT_Connection") is proj.lookup_type("stCBT_Connection")
    assert "CBT_COMMANDS_LIB\\STCBT_CONNECTION" in proj.types


def test_same_name_in_two_namespaces_is_ambiguous_unless_qualified(tmp_path):
    for ns in ("A_Lib", "B_Lib"):
        (tmp_path / ns).mkdir()
        (tmp_path / ns / "t.st").write_text("TYPE T1 : INT; END_TYPE\n")
    (tmp_path / "m.st").write_text(program("", "x : T1; y : A_Lib\\T1;"))
    proj = load_project([str(tmp_path)])
    assert [d.code for d in proj.diagnostics if d.is_error] == ["ST1003"]


def test_configuration_tasks_are_checked_and_programs_listed(tmp_path):
    proj = check_text(tmp_path, program("x := x + 1;", "x : INT;") + """
        CONFIGURATION Cfg
            RESOURCE R ON PLC
                TASK Fast(INTERVAL := T#1ms, PRIORITY := 1);
                PROGRAM P1 WITH Fast : Main;
                PROGRAM P2 WITH Slow : Nothing;
            END_RESOURCE
        END_CONFIGURATION
        """)
    errs = [d.message for d in proj.diagnostics if d.is_error]
    assert len(errs) == 2 and "Slow" in errs[0] + errs[1]
    assert proj.configurations[0].resources[0].tasks[0].props[0].value.ty is T.TIME


def test_types_have_iec_ranges_and_sysmac_string_capacity(tmp_path):
    assert (T.SINT.lo, T.SINT.hi, T.UDINT.hi, T.LWORD.bits) == (-128, 127, 2**32 - 1, 64)
    proj = check_text(tmp_path, program("", "s : STRING[24]; a : ARRAY[-1..1, 0..2] OF INT; d : STRING;"))
    decls = [d.sym.type for d in proj.programs[0].pou.sections[0].vars]
    assert decls[0].length == 24 and decls[0].capacity == 23
    assert decls[1].dims == [(-1, 1), (0, 2)] and decls[1].count() == 9
    assert decls[2].length == 1986
    iec = check_text(tmp_path, program("", "s : STRING[24]; d : STRING;"), "iec.st", dialect="iec")
    t = [d.sym.type for d in iec.programs[0].pou.sections[0].vars]
    assert t[0].capacity == 24 and t[1].length == 254


def test_prelude_declares_sysmac_types_and_native_instructions():
    proj = load_project([])
    for name in ("_sSOCKET", "_sSOCKET_ADDRESS", "_eCONNECTION_STATE", "_eBYTE_ORDER"):
        assert proj.lookup_type(name) is not None, name
    for name in ("SktTCPConnect", "SktTCPSend", "SktTCPRcv", "SktClearBuf", "SktGetTCPStatus", "SktClose",
                 "ToAryByte", "AryToString", "AryByteTo", "StringToAry", "RealToFormatString", "GetTime",
                 "SecToDt", "DtToSec", "NanoSecToTime", "TimeToNanoSec"):
        pou = proj.lookup_pou(name)
        assert pou is not None and pou.native, name
    assert not proj.has_errors, proj.render_diagnostics()


def test_var_external_fb_initializer_and_input_array_from_element(tmp_path):
    (tmp_path / "gvl.st").write_text("VAR_GLOBAL CONSTANT Max : INT := 10; END_VAR\n")
    check_text(tmp_path, """
        FUNCTION Sum : DINT
        VAR_INPUT Data : ARRAY[0..3] OF INT; END_VAR
        Sum := Data[0] + Data[3];
        END_FUNCTION
        FUNCTION_BLOCK Timer
        VAR_INPUT PT : TIME; END_VAR
        END_FUNCTION_BLOCK
        """ + program("d := Sum(Data := buf[2]) + Max;",
                      "d : DINT; buf : ARRAY[0..9] OF INT; t : Timer := (PT := T#2s); END_VAR "
                      "VAR_EXTERNAL CONSTANT Max : INT;"))
    proj = load_project([str(tmp_path)])
    assert not [d for d in proj.diagnostics if d.severity == "error"], proj.render_diagnostics()
    value = stmts(proj)[0].value
    call = value.left
    assert call.binding.args[0].from_element and value.right.sym.target is proj.globals["MAX"]


def test_crlf_tabs_and_bom_render_with_the_caret_under_the_error(tmp_path):
    path = tmp_path / "w.st"
    path.write_bytes("\ufeffPROGRAM P\r\nVAR x : INT; END_VAR\r\n\tx := y;\r\nEND_PROGRAM\r\n".encode("utf-8"))
    proj = load_project([str(path)])
    text = proj.render_diagnostics()
    lines = text.splitlines()
    assert lines[0].endswith("w.st:3:7: error[ST1001]: `y` is not declared; declare it in a VAR section or check "
                             "the spelling")
    assert lines[2].index("^") == lines[1].index("y;")


def test_an_unknown_task_property_has_its_own_code(tmp_path):
    """ST1010, not ST1201: a task property is not a formal parameter of a call."""
    proj = check_text(tmp_path, """
        PROGRAM Main
        END_PROGRAM
        CONFIGURATION C
            RESOURCE R ON PLC
                TASK Fast(INTERVL := T#10ms, PRIORITY := 1);
                PROGRAM P WITH Fast : Main;
            END_RESOURCE
        END_CONFIGURATION
        """)
    errors = [d for d in proj.diagnostics if d.is_error]
    assert [d.code for d in errors] == ["ST1010"]
    assert errors[0].message == "unknown task property `INTERVL`; use INTERVAL, PRIORITY or SINGLE"


def test_program_instance_arguments_are_bound_to_program_inputs(tmp_path):
    proj = check_text(tmp_path, """
        PROGRAM Main
        VAR_INPUT Speed : INT; END_VAR
        Speed := Speed;
        END_PROGRAM
        CONFIGURATION C
            VAR_GLOBAL g : INT; END_VAR
            RESOURCE R ON PLC
                TASK T(INTERVAL := T#10ms);
                PROGRAM P WITH T : Main(Speed := g);
                PROGRAM Q WITH T : Main(Sped := g);
            END_RESOURCE
        END_CONFIGURATION
        """)
    assert [d.code for d in proj.diagnostics if d.is_error] == ["ST1201"]
    inst = proj.configurations[0].resources[0].programs[0]
    assert inst.binding.kind == "program" and inst.binding.args[0].param.name == "Speed"
