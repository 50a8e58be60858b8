"""`vplc run --axes` and `vplc test --axes`: virtual axes from the command line, traced axis positions, and a bad
axis configuration as a usage error (docs/toolchain/runtime.md section 6, runtime_sysmac.md section 5)."""

PROG = """PROGRAM Main
VAR pwr : MC_Power; mv : MC_MoveAbsolute; END_VAR
pwr(Axis := _MC_AX[0], Enable := TRUE);
mv(Axis := _MC_AX[0], Execute := pwr.Status, Position := 10.0, Velocity := 100.0, Acceleration := 1000.0,
   Deceleration := 1000.0);
END_PROGRAM
"""
AXES = "[[axis]]\nnumber = 0\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n"


def test_run_with_axes_moves_the_axis_and_traces_its_position(tmp_path, run_cli):
    (tmp_path / "m.st").write_text(PROG)
    (tmp_path / "axes.toml").write_text(AXES)
    vcd = tmp_path / "axis.vcd"
    r = run_cli("run", str(tmp_path / "m.st"), "--axes", str(tmp_path / "axes.toml"), "--virtual-time",
                "--duration", "300ms", "--watch", "Main.mv.Done", "--trace", "_MC_AX[0].Cmd.Pos,_MC_AX[0].Cmd.Vel",
                "--trace-out", str(vcd))
    assert r.returncode == 0, r.stderr
    assert "Main.mv.Done = TRUE" in r.stdout
    text = vcd.read_text()
    assert "_MC_AX[0].Cmd.Pos" in text and "r10.0 " in text
    assert "motion control of 1 axis" in r.stdout + r.stderr


def test_run_with_a_bad_axis_configuration_is_a_usage_error_naming_file_axis_and_key(tmp_path, run_cli):
    (tmp_path / "m.st").write_text(PROG)
    (tmp_path / "axes.toml").write_text(AXES.replace("1000.0", "0"))
    r = run_cli("run", str(tmp_path / "m.st"), "--axes", str(tmp_path / "axes.toml"), "--virtual-time",
                "--cycles", "3")
    assert r.returncode == 2
    assert f"{tmp_path / 'axes.toml'}: axis 0: `max_acceleration` must be greater than 0 (got 0)" in r.stderr
    assert "Traceback" not in r.stderr


def test_unit_tests_can_use_virtual_axes(tmp_path, run_cli):
    (tmp_path / "axes.toml").write_text(AXES)
    (tmp_path / "Axis_Test.st").write_text("""FUNCTION_BLOCK Axis_Test
VAR pwr : MC_Power; mv : MC_MoveRelative; END_VAR
TEST('moves 5 mm');
pwr(Axis := _MC_AX[0], Enable := TRUE);
mv(Axis := _MC_AX[0], Execute := pwr.Status, Distance := 5.0, Velocity := 50.0);
IF mv.Done THEN
    AssertEquals_LREAL(Expected := 5.0, Actual := _MC_AX[0].Cmd.Pos, Delta := 0.0, Message := 'position');
    TEST_FINISHED();
END_IF;
END_FUNCTION_BLOCK
""")
    r = run_cli("test", str(tmp_path / "Axis_Test.st"), "--axes", str(tmp_path / "axes.toml"))
    assert r.returncode == 0, r.stdout + r.stderr
