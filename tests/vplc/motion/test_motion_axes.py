"""Virtual axes: software limits and axis errors (MC_Reset, MC_ReadAxisError), the axis configuration file and
its errors, axes that are not configured, axis names, and tracing _MC_AX members. W507/W508 sections as named in
each test (the English pages were not readable in our manual corpus; W508's Chinese edition pages are linked in
docs/toolchain/runtime_sysmac.md section 5)."""
import os

import pytest
from motion_rig import Rig, files

from vplc.api import LoadError, load_plc
from vplc.runtime import motion as M
from vplc.trace.recorder import Recorder, write_trace


@pytest.fixture
def limited(tmp_path_factory):
    return Rig(files(tmp_path_factory), "axes_limited.toml")


def test_velocity_motion_stops_on_the_software_limit_and_the_axis_goes_to_errorstop(limited):
    """W507 software limits and state chart: the axis decelerates onto the limit, a minor fault is raised
    (MFaultLvl), the running instruction reports CommandAborted, the axis is in ErrorStop."""
    rig = limited.powered()
    rig.set(doVel=True, vv=100.0)
    for _ in range(3000):
        rig.scan()
        assert rig.ax("Cmd.Pos") <= 150.0
        if rig.state() == "ErrorStop" and rig.ax("Cmd.Vel") == 0.0:
            break
    assert rig.ax("Cmd.Pos") == 150.0
    assert rig.ax("MFaultLvl.Active") and rig.ax("MFaultLvl.Code") == M.AXIS_SW_LIMIT_POS
    assert rig.r("vel.CommandAborted") and rig.r("err.AxisErrorID") == M.AXIS_SW_LIMIT_POS
    # the stop is the axis' fault, not the instruction's: Error FALSE, ErrorID 0 (as a limit input ends a move on
    # the Sysmac simulator in kmu2030/UAMotionLink's tests, docs/toolchain/runtime_sysmac.md section 5.3)
    assert not rig.r("vel.Error") and rig.r("vel.ErrorID") == 0
    rig.set(doVel=False)
    rig.scan()
    rig.set(doAbs1=True, pos1=0.0)
    rig.scan()
    assert rig.r("abs1.CommandAborted") and not rig.r("abs1.Error")


def test_reset_clears_the_axis_error_and_returns_to_standstill(limited):
    """W508 MC_Reset and MC_ReadAxisError: after the reset the axis is in Standstill, the error code is 0."""
    rig = limited.powered()
    rig.set(doVel=True, vv=150.0)
    for _ in range(3000):
        rig.scan()
        if rig.state() == "ErrorStop" and rig.ax("Cmd.Vel") == 0.0:
            break
    rig.set(doVel=False, doReset=True)
    rig.scan()
    assert rig.r("rst.Done") and not rig.r("rst.Failure") and rig.state() == "Standstill"
    rig.scan()
    assert rig.r("err.Valid") and rig.r("err.AxisErrorID") == 0 and not rig.ax("MFaultLvl.Active")
    rig.set(doAbs1=True, pos1=100.0)
    rig.scan(3)
    assert rig.r("abs1.Active")


def test_reset_without_an_axis_error_is_done_and_changes_nothing(limited):
    """W508 MC_Reset on an axis without error: Done, no Failure, the axis keeps its state and position (as the
    UAMotionLink tests expect on the Sysmac simulator, section 5.3)."""
    rig = limited.powered()
    rig.set(doAbs1=True, pos1=40.0)
    rig.scan(2000)
    assert rig.r("abs1.Done") and rig.state() == "Standstill"
    rig.set(doReset=True)
    rig.scan()
    assert rig.outputs("rst", ("Busy", "Done", "Failure", "Error")) == (False, True, False, False)
    assert rig.state() == "Standstill" and rig.ax("Cmd.Pos") == 40.0 and not rig.ax("MFaultLvl.Active")


def test_reset_waits_until_an_axis_stopping_on_a_limit_has_stopped(limited):
    """MC_Reset stays Busy while the axis still decelerates onto the limit."""
    rig = limited.powered()
    rig.set(doVel=True, vv=200.0)
    while rig.state() != "ErrorStop":
        rig.scan()
    rig.set(doReset=True)
    rig.scan()
    if rig.ax("Cmd.Vel") != 0.0:
        assert rig.r("rst.Busy") and not rig.r("rst.Done")
    while not rig.r("rst.Done"):
        rig.scan()
    assert rig.state() == "Standstill" and rig.ax("Cmd.Pos") == 150.0


def test_a_target_outside_the_software_limits_is_refused(limited):
    """W507 software limits: a positioning to a target beyond a limit ends in Error and does not move."""
    rig = limited.powered()
    rig.set(doAbs1=True, pos1=151.0)
    rig.scan()
    assert rig.r("abs1.Error") and rig.r("abs1.ErrorID") == M.ERR_POSITION and rig.ax("Cmd.Pos") == 0.0
    assert rig.state() == "ErrorStop"


def test_software_limits_apply_only_once_home_is_defined(tmp_path_factory):
    """W507: software limits are active while home is defined (a configured axis without `homed` is not)."""
    folder = files(tmp_path_factory)
    text = (folder / "axes_limited.toml").read_text().replace("homed = true", "homed = false")
    (folder / "axes_unhomed.toml").write_text(text)
    rig = Rig(folder, "axes_unhomed.toml").powered()
    rig.set(doAbs1=True, pos1=160.0, v1=200.0)
    while not rig.r("abs1.Done"):
        rig.scan()
    assert rig.ax("Cmd.Pos") == 160.0 and not rig.ax("Details.Homed")


def test_an_axis_that_is_not_configured_gives_error_and_says_why(tmp_path):
    """An instruction on _MC_AX[n] without a virtual axis behind it ends in Error 16#5401 and names the reason
    in the PLC's instruction errors (vplc run prints them)."""
    (tmp_path / "Main.st").write_text("""PROGRAM Main
VAR pwr : MC_Power; mv : MC_MoveRelative; END_VAR
pwr(Axis := _MC_AX[3], Enable := TRUE);
mv(Axis := _MC_AX[3], Execute := TRUE, Distance := 1.0, Velocity := 1.0);
END_PROGRAM
""")
    plc = load_plc([str(tmp_path / "Main.st")], task="Main@1ms")
    plc.scan(0)
    assert plc.read("Main.pwr.Error") and plc.read("Main.pwr.ErrorID") == M.ERR_AXIS_UNUSED
    assert plc.read("Main.mv.Error") and plc.read("Main.mv.ErrorID") == M.ERR_AXIS_UNUSED
    count, messages = plc.instruction_errors
    assert count == 2 and "no axis configuration was given" in messages[0] and "Main.st:3" in messages[0]
    assert plc.read("_MC_AX[3].Cfg.AxEnable") == "_mcNoneAxis"


def test_configured_axis_shows_its_configuration_in_the_axis_variable(tmp_path_factory):
    """W507 axis variable: Cfg.AxNo, AxEnable, AxType (virtual servo), Scale.Units."""
    rig = Rig(files(tmp_path_factory))
    assert rig.ax("Cfg.AxNo") == 0 and rig.ax("Cfg.AxEnable") == "_mcUsedAxis"
    assert rig.ax("Cfg.AxType") == "_mcVirServo" and rig.ax("Scale.Units") == "_mcMm"
    assert rig.state() == "Disabled"


def test_a_named_axis_is_the_same_axis_as_its_mc_ax_element(tmp_path):
    """Sysmac programs use the axis variable names of their configuration (MC_Axis000 ...): a global _sAXIS_REF
    named in the axis configuration is the same variable as _MC_AX[n]."""
    (tmp_path / "Globals.st").write_text("VAR_GLOBAL\n    MC_Shuttle : _sAXIS_REF;\nEND_VAR\n")
    (tmp_path / "Main.st").write_text("""PROGRAM Main
VAR_EXTERNAL MC_Shuttle : _sAXIS_REF; END_VAR
VAR pwr : MC_Power; mv : MC_MoveAbsolute; END_VAR
pwr(Axis := MC_Shuttle, Enable := TRUE);
mv(Axis := MC_Shuttle, Execute := pwr.Status, Position := 3.0, Velocity := 100.0);
END_PROGRAM
""")
    (tmp_path / "axes.toml").write_text('[[axis]]\nnumber = 2\nname = "MC_Shuttle"\nmax_velocity = 100.0\n'
                                        'max_acceleration = 1000.0\n')
    plc = load_plc([str(tmp_path / "Globals.st"), str(tmp_path / "Main.st")], axes=str(tmp_path / "axes.toml"))
    assert plc.run_until(lambda: plc.read("Main.mv.Done"), 1_000_000_000)
    assert plc.read("_MC_AX[2].Cmd.Pos") == 3.0 and plc.read("MC_Shuttle.Cmd.Pos") == 3.0


def test_axis_positions_can_be_traced(tmp_path_factory, tmp_path):
    """vplc run --trace _MC_AX[0].Cmd.Pos: the recorder reads axis members like any variable (VCD and SVG)."""
    rig = Rig(files(tmp_path_factory)).powered()
    rec = Recorder(rig.plc, ["_MC_AX[0].Cmd.Pos", "_MC_AX[0].Cmd.Vel", "_MC_AX[0].Status.Discrete"])
    rig.set(pos1=5.0, doAbs1=True)
    for _ in range(300):
        rig.scan()
        rec.sample()
    assert rec.kinds[0] == ("real", 64) and rec.changes[0][-1][1] == 5.0 and len(rec.changes[0]) > 100
    write_trace(rec, str(tmp_path / "axis.svg"))
    write_trace(rec, str(tmp_path / "axis.vcd"))
    assert "_MC_AX[0].Cmd.Pos" in (tmp_path / "axis.svg").read_text()


BASE = 'number = 1\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n'


@pytest.mark.parametrize("body,message", [
    ("[[axis]]\n" + BASE.replace("100.0", "-5.0", 1), "axis 1: `max_velocity` must be greater than 0 (got -5.0)"),
    ("[[axis]]\n" + BASE.replace("max_acceleration = 1000.0\n", ""), "axis 1: `max_acceleration` is missing"),
    ("[[axis]]\n" + BASE + "max_jerk = -1\n", "axis 1: `max_jerk` must not be negative"),
    ("[[axis]]\n" + BASE + "software_limit_positive = 5.0\n", "axis 1: give both `software_limit_negative`"),
    ("[[axis]]\n" + BASE + "software_limit_negative = 5.0\nsoftware_limit_positive = 1.0\n",
     "axis 1: `software_limit_negative` 5 must be below `software_limit_positive` 1"),
    ("[[axis]]\n" + BASE + "units = 'furlong'\n", "axis 1: `units` 'furlong' is not one of"),
    ("[[axis]]\n" + BASE + "max_speed = 3\n", "axis 1: unknown key `max_speed`"),
    ("[[axis]]\n" + BASE.replace("number = 1", "number = 64"), "axis number 64 is outside _MC_AX[0..63]"),
    ("[[axis]]\n" + BASE + "[[axis]]\n" + BASE, "axis 1: declared twice"),
    ("[[axis]]\n" + BASE + "max_velocity = 3\n", "not a TOML file"),
    ("", "no axis declared"),
])
def test_bad_axis_configuration_names_the_file_the_axis_and_the_limit(tmp_path_factory, tmp_path, body, message):
    folder = files(tmp_path_factory)
    cfg = tmp_path / "cell_axes.toml"
    cfg.write_text(body)
    with pytest.raises(LoadError) as info:
        load_plc([str(folder / "Main.st")], axes=str(cfg))
    text = str(info.value)
    assert str(cfg) in text and message in text and "Traceback" not in text


def test_hostile_axis_configurations_are_refused_without_traceback(tmp_path_factory, tmp_path):
    """Bad input: a file nested 100,000 levels deep and a file of 2 MB end in a clear load error."""
    main = str(files(tmp_path_factory) / "Main.st")
    deep, big = tmp_path / "deep.toml", tmp_path / "big.toml"
    deep.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    big.write_text("# " + "x" * 2_000_000 + "\n")
    with pytest.raises(LoadError, match="nests too deeply"):
        load_plc([main], axes=str(deep))
    with pytest.raises(LoadError, match="larger than 1,000,000 bytes"):
        load_plc([main], axes=str(big))
    os.symlink("/dev/zero", tmp_path / "zero.toml")   # refused before it is read (it never ends)
    with pytest.raises(LoadError, match="the axis configuration is not a regular file or a pipe"):
        load_plc([main], axes=str(tmp_path / "zero.toml"))


def test_a_missing_axis_configuration_file_is_a_load_error(tmp_path_factory, tmp_path):
    with pytest.raises(LoadError, match="cannot read the axis configuration"):
        load_plc([str(files(tmp_path_factory) / "Main.st")], axes=str(tmp_path / "none.toml"))


def test_a_named_axis_the_program_does_not_declare_is_a_load_error(tmp_path_factory, tmp_path):
    cfg = tmp_path / "axes.toml"
    cfg.write_text("[[axis]]\n" + BASE + 'name = "MC_Nowhere"\n')
    with pytest.raises(LoadError, match=r"axis 1: the program declares no global variable `MC_Nowhere`"):
        load_plc([str(files(tmp_path_factory) / "Main.st")], axes=str(cfg))


def test_the_errorid_table_of_the_docs_is_the_one_the_runtime_uses():
    """One fact, one home: the "condition → ErrorID (source)" table of docs/toolchain/runtime_sysmac.md section 5.3
    lists exactly the ERR_* codes of motion.py, each once and each with the source of its value."""
    import pathlib
    import re
    doc = (pathlib.Path(__file__).resolve().parents[3] / "docs" / "toolchain" / "runtime_sysmac.md").read_text()
    section = doc[doc.index("#### ErrorIDs: condition → ErrorID (source)"):doc.index("### 5.4")]
    rows = re.findall(r"^\|[^|\n]+\|[^|\n]+\| 16#([0-9A-F]{4}) \| ([^|\n]+) \|$", section, re.MULTILINE)
    listed = [int(code, 16) for code, _ in rows]
    assert sorted(listed) == sorted({v for k, v in vars(M).items() if k.startswith("ERR_")})
    assert all(source.startswith("chosen") for _, source in rows)     # no Omron value found yet (section 5.3)
    assert f"16#{M.AXIS_SW_LIMIT_POS:04X} positive and 16#{M.AXIS_SW_LIMIT_NEG:04X} negative" in section
