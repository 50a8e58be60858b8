"""Single-axis motion instructions on a virtual axis: documented outputs scan by scan, profiles against the closed
form, state transitions and refused transitions. Each test names the W508 instruction (NJ/NX-series Motion Control
Instructions Reference Manual) or the W507 axis-state chart it pins. The English pages were not readable in our
manual corpus; the instruction pages of W508's Chinese edition were (links in docs/toolchain/runtime_sysmac.md
section 5, "W508 (zh)"), so the citations name the instruction and its table (input ranges, output timing)."""
import pytest
from motion_rig import Rig, duration, files, s_curve, s_curve_duration, trapezoid

from vplc.api import PlcFault
from vplc.runtime import motion as M


@pytest.fixture
def rig(tmp_path_factory):
    return Rig(files(tmp_path_factory))


def test_power_status_comes_one_period_after_enable_and_servo_off_disables(rig):
    """W508 MC_Power: Busy while Enable; Status once the servo is ON (after the motion processing)."""
    rig.scan()
    assert (rig.r("pwr.Busy"), rig.r("pwr.Status")) == (True, False)
    assert rig.state() == "Standstill" and rig.ax("DrvStatus.ServoOn")
    rig.scan()
    assert rig.r("pwr.Status")
    rig.set(power=False)
    rig.scan()
    assert (rig.r("pwr.Busy"), rig.r("pwr.Status"), rig.state()) == (False, False, "Disabled")


def test_move_absolute_follows_the_closed_form_trapezoid_and_reports_done(rig):
    """W508 MC_MoveAbsolute: Busy and Active from the Execute edge, Done once the target is reached; the command
    position is the trapezoid of Velocity, Acceleration and Deceleration (Discrete, then Standstill)."""
    rig.powered()
    rig.set(doAbs1=True)
    rig.scan()
    t0 = rig.t
    assert rig.outputs("abs1") == (True, True, False, False, False) and rig.state() == "Discrete"
    total = duration(100.0, 50.0, 1000.0, 500.0)
    worst = 0.0
    while not rig.r("abs1.Done"):
        x, v = trapezoid(rig.t - t0, 100.0, 50.0, 1000.0, 500.0)
        worst = max(worst, abs(rig.ax("Cmd.Pos") - x), abs(rig.ax("Cmd.Vel") - v) * 1e-3)
        assert rig.ax("Act.Pos") == rig.ax("Cmd.Pos")
        rig.scan()
        assert rig.k < 5000
    assert worst < 1e-9
    # Done in the first call after the motion processing that reached the target
    assert rig.t == pytest.approx(t0 + total, abs=2.001e-3) and rig.t > t0 + total
    assert rig.outputs("abs1") == (False, False, True, False, False)
    assert (rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel"), rig.state()) == (100.0, 0.0, "Standstill")
    rig.scan(3)
    assert rig.r("abs1.Done"), "Done stays TRUE while Execute is TRUE"
    rig.set(doAbs1=False)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, False, False)


def test_short_move_is_a_triangle_below_the_velocity(rig):
    """W508 MC_MoveAbsolute: a distance too short to reach Velocity gives a triangular profile."""
    rig.powered()
    rig.set(pos1=1.0, doAbs1=True)
    rig.scan()
    t0 = rig.t
    peak = 0.0
    while not rig.r("abs1.Done"):
        rig.scan()
        x, v = trapezoid(rig.t - t0, 1.0, 50.0, 1000.0, 500.0)
        assert rig.ax("Cmd.Pos") == pytest.approx(x, abs=1e-9)
        assert rig.ax("Cmd.Vel") == pytest.approx(v, abs=1e-9)
        peak = max(peak, rig.ax("Cmd.Vel"))
    assert peak < 50.0 and peak == pytest.approx((1.0 / (1 / 2000 + 1 / 1000)) ** 0.5, rel=0.05)


def test_done_shows_for_one_call_when_execute_dropped_before_the_end(rig):
    """W508 common timing: if Execute is FALSE when the instruction completes, Done is TRUE for one period."""
    rig.powered()
    rig.set(pos1=2.0, doAbs1=True)
    rig.scan()
    rig.set(doAbs1=False)
    seen = []
    for _ in range(300):
        rig.scan()
        seen.append(rig.r("abs1.Done"))
    assert seen.count(True) == 1
    assert rig.ax("Cmd.Pos") == 2.0


def test_move_relative_adds_distance_to_the_command_position(rig):
    """W508 MC_MoveRelative: the target is Distance from the command current position."""
    rig.powered()
    rig.set(setTo=5.0, doSetPos=True)
    rig.scan(2)
    assert rig.ax("Cmd.Pos") == 5.0 and rig.r("setp.Done")
    rig.set(dist=-3.0, doRel=True)
    rig.scan()
    t0 = rig.t
    while not rig.r("rel.Done"):
        rig.scan()
        x, _ = trapezoid(rig.t - t0, 3.0, 50.0, 1000.0, 500.0)
        assert rig.ax("Cmd.Pos") == pytest.approx(5.0 - x, abs=1e-9)
    assert rig.ax("Cmd.Pos") == 2.0


def test_move_velocity_ramps_to_in_velocity_and_reverses_through_zero(rig):
    """W508 MC_MoveVelocity: InVelocity once the velocity is reached (Continuous state); a new velocity command
    in the other direction decelerates with Deceleration to 0, then accelerates with Acceleration."""
    rig.powered()
    rig.set(doVel=True, vv=20.0)
    rig.scan()
    t0 = rig.t
    assert rig.state() == "Continuous" and rig.outputs("vel", ("Busy", "Active", "InVelocity")) == (True, True, False)
    while not rig.r("vel.InVelocity"):
        rig.scan()
        assert rig.ax("Cmd.Vel") == pytest.approx(min(20.0, 1000.0 * (rig.t - t0)), abs=1e-9)
    assert rig.t == pytest.approx(t0 + 0.02 + 0.001, abs=1e-9)
    rig.scan(100)
    assert rig.ax("Cmd.Vel") == 20.0 and rig.r("vel.Busy")
    x_before = rig.ax("Cmd.Pos")
    assert x_before == pytest.approx(20.0 * (rig.t - t0) - 20.0 * 0.02 / 2, abs=1e-9)
    # re-execution with the other direction (W508: the running velocity command takes the new values)
    rig.set(doVel=False)
    rig.scan()
    rig.set(doVel=True, dir="_mcNegativeDirection")
    rig.scan()
    t1 = rig.t
    rig.scan(20)
    assert rig.ax("Cmd.Vel") == pytest.approx(20.0 - 500.0 * (rig.t - t1), abs=1e-9)
    rig.scan(30)
    assert rig.ax("Cmd.Vel") == pytest.approx(-1000.0 * (rig.t - t1 - 0.04), abs=1e-9)


def test_a_second_move_aborts_the_first_which_reports_command_aborted(rig):
    """W508 BufferMode _mcAborting: the new instruction takes over at once; the aborted one shows
    CommandAborted (Busy and Active FALSE) in its next call; the profile continues from the current motion."""
    rig.powered()
    rig.set(doAbs1=True)
    rig.scan(200)
    x, v = rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel")
    rig.set(pos2=20.0, doAbs2=True)
    rig.scan()
    assert rig.outputs("abs2") == (True, True, False, False, False)
    assert rig.ax("Cmd.Pos") == pytest.approx(x + v * 0.001, abs=1e-6)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, True, False)
    while not rig.r("abs2.Done"):
        rig.scan()
        assert rig.k < 5000
    assert rig.ax("Cmd.Pos") == 20.0 and rig.r("abs1.CommandAborted")
    rig.set(doAbs1=False)
    rig.scan()
    assert not rig.r("abs1.CommandAborted")


def test_a_buffered_move_starts_exactly_when_the_first_is_done(rig):
    """W508 BufferMode _mcBuffered: the instruction waits (Busy, not Active) until the running one is Done, then
    starts from its end; the first's Done and the second's Active appear in the same call."""
    rig.powered()
    rig.set(pos1=10.0, doAbs1=True)
    rig.scan(5)
    rig.set(pos2=4.0, buf2="_mcBuffered", doAbs2=True)
    rig.scan()
    assert rig.outputs("abs2") == (True, False, False, False, False)
    t_end1 = 0.002 + duration(10.0, 50.0, 1000.0, 500.0)          # abs1 started in the scan at 2 ms
    while not rig.r("abs1.Done"):
        assert not rig.r("abs2.Active")
        rig.scan()
    assert rig.r("abs2.Active") and not rig.r("abs1.CommandAborted")
    while not rig.r("abs2.Done"):
        rig.scan()
        x, _ = trapezoid(rig.t - t_end1, 6.0, 50.0, 1000.0, 500.0)
        if not rig.r("abs2.Done"):
            assert rig.ax("Cmd.Pos") == pytest.approx(10.0 - x, abs=1e-9)
    assert rig.ax("Cmd.Pos") == 4.0


def test_buffered_relative_move_counts_from_the_target_of_the_running_one(rig):
    """W508 MC_MoveRelative with _mcBuffered: the distance is added to the target of the move before it."""
    rig.powered()
    rig.set(pos1=10.0, doAbs1=True)
    rig.scan(3)
    rig.set(dist=5.0, bufRel="_mcBuffered", doRel=True)
    while not rig.r("rel.Done"):
        rig.scan()
        assert rig.k < 5000
    assert rig.ax("Cmd.Pos") == 15.0


def test_stop_holds_the_axis_in_stopping_while_execute_is_true(rig):
    """W508 MC_Stop and the W507 state chart: Stopping until MC_Stop is Done and its Execute FALSE; every other
    motion instruction is refused meanwhile; the running move reports CommandAborted."""
    rig.powered()
    rig.set(doVel=True, vv=100.0)
    rig.scan(200)
    v0 = rig.ax("Cmd.Vel")
    rig.set(doStop=True, stopDec=1000.0)
    rig.scan()
    t0 = rig.t
    assert rig.state() == "Stopping" and rig.outputs("stp") == (True, True, False, False, False)
    rig.scan()
    assert rig.r("vel.CommandAborted")
    while not rig.r("stp.Done"):
        rig.scan()
        if not rig.r("stp.Done"):
            assert rig.ax("Cmd.Vel") == pytest.approx(max(v0 - 1000.0 * (rig.t - t0), 0.0), abs=1e-9)
    assert rig.ax("Cmd.Vel") == 0.0
    rig.scan(50)
    assert rig.state() == "Stopping" and rig.r("stp.Done")
    rig.set(doStop=False)
    rig.scan()
    assert rig.state() == "Standstill" and not rig.r("stp.Done")


def test_an_instruction_started_while_mc_stop_runs_ends_in_command_aborted(rig):
    """W508 MC_Home / MC_SetPosition output timing (CommandAborted "when started while MC_Stop is executed") and
    the W507 state chart: in Stopping only MC_Stop is accepted; the axis stays in Stopping."""
    rig.powered()
    rig.set(doStop=True)
    rig.scan(3)
    rig.set(doAbs1=True, doHome=True, doSetPos=True)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, True, False)
    assert rig.r("home.CommandAborted") and rig.r("setp.CommandAborted") and not rig.r("setp.Error")
    assert rig.state() == "Stopping"
    rig.set(doAbs1=False)
    rig.scan()
    assert not rig.r("abs1.CommandAborted")


@pytest.mark.parametrize("fb,flag", [("abs1", "doAbs1"), ("vel", "doVel"), ("hlt", "doHalt"), ("home", "doHome")])
def test_motion_from_disabled_is_refused(rig, fb, flag):
    """W508 MC_Power: a motion instruction on an axis that is not enabled ends in an error (of the axis)."""
    rig.set(power=False, **{flag: True})
    rig.scan()
    assert rig.r(f"{fb}.Error") and rig.r(f"{fb}.ErrorID") == M.ERR_DISABLED and not rig.r(f"{fb}.Busy")
    assert rig.state() == "ErrorStop" and not rig.ax("DrvStatus.ServoOn")
    rig.set(doReset=True)
    rig.scan()
    assert rig.state() == "Disabled"


def test_an_instruction_started_while_the_axis_has_an_error_ends_in_command_aborted(rig):
    """W508 MC_Stop output timing: CommandAborted when the instruction is started while an error is present."""
    rig.powered()
    rig.set(v1=0.0, doAbs1=True)
    rig.scan()
    assert rig.state() == "ErrorStop"
    rig.set(doStop=True, doVel=True)
    rig.scan()
    assert rig.outputs("stp") == (False, False, False, True, False)
    assert rig.outputs("vel", ("Busy", "Active", "CommandAborted", "Error")) == (False, False, True, False)


def test_home_defines_home_at_standstill_and_is_refused_while_moving(rig):
    """W508 MC_Home (zero position preset): Homing for the call, then Standstill with Details.Homed and the
    command position at home; from Discrete or Continuous the instruction is refused."""
    rig.powered()
    rig.set(setTo=7.0, doSetPos=True)
    rig.scan(2)
    assert rig.ax("Details.Homed")                    # W508 MC_SetPosition defines home
    rig.set(doHome=True)
    rig.scan()
    assert rig.r("home.Busy")
    rig.scan()
    assert rig.r("home.Done") and rig.ax("Cmd.Pos") == 0.0 and rig.ax("Details.InHome")
    rig.set(doHome=False, doVel=True)
    rig.scan(5)
    rig.set(doHome=True)
    rig.scan()
    assert rig.r("home.Error") and rig.r("home.ErrorID") == M.ERR_MOVING and rig.state() == "ErrorStop"
    rig.scan(100)
    assert rig.r("vel.CommandAborted") and rig.ax("Cmd.Vel") == 0.0


@pytest.mark.parametrize("reference", ["_mcCommand", "_mcFeedback"])
def test_set_position_accepts_the_command_and_the_feedback_reference(rig, reference):
    """W508 (zh) MC_SetPosition, input variables: ReferenceType 0 _mcCommand or 1 _mcFeedback (initial value
    _mcCommand); on a virtual servo both set the command and the actual position."""
    rig.powered()
    rig.plc.write("Main.setp.ReferenceType", reference)
    rig.set(setTo=-42.5, doSetPos=True)
    rig.scan(2)
    assert rig.r("setp.Done") and not rig.r("setp.Error")
    assert rig.ax("Cmd.Pos") == -42.5 and rig.ax("Act.Pos") == -42.5 and rig.state() == "Standstill"


def test_set_position_refuses_a_reference_type_outside_its_valid_range(rig):
    """W508 (zh) MC_SetPosition: _mcLatestCommand (2) is a value of _eMC_REFERENCE_TYPE but not in the
    instruction's valid range: Error with ErrorID in the call of the Execute edge, nothing changed, an axis error
    until MC_Reset like every instruction error."""
    rig.powered()
    rig.plc.write("Main.setp.ReferenceType", "_mcLatestCommand")
    rig.set(setTo=30.0, doSetPos=True)
    rig.scan()
    assert rig.outputs("setp", ("Busy", "Done", "CommandAborted", "Error")) == (False, False, False, True)
    assert rig.r("setp.ErrorID") == M.ERR_REFERENCE_TYPE and rig.ax("Cmd.Pos") == 0.0
    assert rig.state() == "ErrorStop" and rig.ax("MFaultLvl.Code") == M.ERR_REFERENCE_TYPE
    rig.set(doSetPos=False, doReset=True)
    rig.scan(2)
    assert not rig.r("setp.Error") and rig.state() == "Standstill"


def test_override_scales_the_velocity_and_zero_holds_the_axis_in_motion(rig):
    """W508 MC_SetOverride: VelFactor % of the target velocity while Enabled (above 500 counts as 500, below 0.01 as
    0.01, only 0 as 0, never above the axis maximum); 0 % stops the axis without ending the instruction; back to
    100 % when Enable is FALSE."""
    rig.powered()
    rig.set(doOvr=True, factor=50.0)
    rig.scan()
    assert rig.r("ovr.Enabled")
    rig.set(doVel=True, vv=40.0)
    rig.scan(100)
    assert rig.ax("Cmd.Vel") == 20.0
    rig.set(factor=0.0)
    rig.scan(100)
    assert rig.ax("Cmd.Vel") == 0.0 and rig.state() == "Continuous" and rig.r("vel.Busy")
    rig.set(doOvr=False)
    rig.scan()
    assert rig.r("ovr.Enabled") and not rig.r("ovr.Busy"), "Enabled goes FALSE one period after Enable"
    rig.scan()
    assert not rig.r("ovr.Enabled")
    rig.scan(100)
    assert rig.ax("Cmd.Vel") == 40.0
    rig.set(doOvr=True, factor=300.0)             # 120 mm/s
    rig.scan(200)
    assert rig.ax("Cmd.Vel") == 120.0 and not rig.ax("Details.VelLimit")
    rig.set(factor=600.0, vv=50.0)                # counts as 500 %: 250 mm/s, limited to the axis maximum
    rig.set(doVel=False)
    rig.scan()
    rig.set(doVel=True)
    rig.scan(200)
    assert rig.ax("Cmd.Vel") == 200.0 and rig.ax("Details.VelLimit") and not rig.r("ovr.Error")
    rig.set(vv=40.0, doVel=False)
    rig.scan()
    rig.set(doVel=True)
    rig.set(factor=-5.0)                          # counts as 0.01 %
    rig.scan(500)
    assert rig.ax("Cmd.Vel") == pytest.approx(40.0 * 0.0001)


def test_velocity_above_the_axis_maximum_is_limited_and_flagged(rig):
    """W507 Details.VelLimit: the command velocity is limited to the axis' maximum velocity (200 mm/s here)."""
    rig.powered()
    rig.set(doVel=True, vv=500.0)
    rig.scan(400)
    assert rig.ax("Cmd.Vel") == 200.0 and rig.ax("Details.VelLimit")


@pytest.mark.parametrize("values,code", [
    ({"v1": 0.0}, M.ERR_VELOCITY), ({"v1": -1.0}, M.ERR_VELOCITY), ({"a1": -1.0}, M.ERR_ACCELERATION),
    ({"d1": -5.0}, M.ERR_DECELERATION), ({"jerk": -1.0}, M.ERR_JERK)])
def test_out_of_range_parameters_end_in_error_in_the_execute_call(rig, values, code):
    """W508 MC_MoveAbsolute input ranges (Velocity positive — "always set the target velocity", Acceleration,
    Deceleration and Jerk positive or 0): Error and ErrorID in the call of the Execute edge; the error is the
    axis' (ErrorStop, MFaultLvl.Code, MC_ReadAxisError) until MC_Reset."""
    rig.powered()
    rig.set(doAbs1=True, **values)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, False, True) and rig.r("abs1.ErrorID") == code
    assert rig.state() == "ErrorStop" and rig.ax("MFaultLvl.Code") == code
    rig.set(doAbs1=False)
    rig.scan()
    assert rig.r("abs1.Error") and rig.r("err.AxisErrorID") == code
    rig.set(doReset=True)
    rig.scan(2)
    assert not rig.r("abs1.Error") and rig.r("abs1.ErrorID") == 0 and rig.state() == "Standstill"


def test_move_velocity_accepts_only_aborting_and_buffered(rig):
    """W508 MC_MoveVelocity: the valid BufferMode values are _mcAborting and _mcBuffered."""
    rig.powered()
    rig.plc.write("Main.vel.BufferMode", "_mcBlendingLow")
    rig.set(doVel=True)
    rig.scan()
    assert rig.r("vel.Error") and rig.r("vel.ErrorID") == M.ERR_BUFFER_MODE


def test_move_absolute_with_jerk_follows_the_closed_form_s_curve(rig):
    """W508 MC_MoveAbsolute Jerk (positive or 0): with a jerk the acceleration rises and falls at that rate and
    never exceeds Acceleration; the position is the closed-form S-curve, Done once it is at rest on the target."""
    rig.powered()
    rig.set(d1=1000.0, jerk=50_000.0, doAbs1=True)
    rig.scan()
    t0 = rig.t
    total = s_curve_duration(100.0, 50.0, 1000.0, 50_000.0)
    prev_a, worst = 0.0, 0.0
    while not rig.r("abs1.Done"):
        x, v = s_curve(rig.t - t0, 100.0, 50.0, 1000.0, 50_000.0)
        worst = max(worst, abs(rig.ax("Cmd.Pos") - x), abs(rig.ax("Cmd.Vel") - v) * 1e-3)
        a = rig.ax("Cmd.AccDec")
        assert abs(a) <= 1000.0 + 1e-9 and abs(a - prev_a) <= 50_000.0 * 0.001 + 1e-9
        prev_a = a
        rig.scan()
        assert rig.k < 5000
    assert worst < 1e-9
    assert rig.t > t0 + total and rig.t == pytest.approx(t0 + total, abs=2.001e-3)
    assert (rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel")) == (100.0, 0.0)


def test_short_jerk_limited_move_lands_on_its_target_with_continuous_acceleration(rig):
    """A distance too short to reach Velocity or Acceleration: a lower peak, still jerk-limited, exactly on the
    target; taken over mid-ramp by another jerk-limited move, the acceleration stays continuous."""
    rig.powered()
    rig.set(pos1=0.3, d1=1000.0, jerk=50_000.0, doAbs1=True)
    prev_a, peak = 0.0, 0.0
    rig.scan()
    while not rig.r("abs1.Done"):
        rig.scan()
        a = rig.ax("Cmd.AccDec")
        assert abs(a - prev_a) <= 50.0 + 1e-9
        prev_a, peak = a, max(peak, rig.ax("Cmd.Vel"))
        assert rig.k < 2000
    assert rig.ax("Cmd.Pos") == 0.3 and peak < 50.0
    rig.set(doAbs1=False, pos1=50.0)
    rig.scan()
    rig.set(doAbs1=True)
    rig.scan(15)                                  # in the first jerk phase
    rig.plc.write("Main.abs2.Jerk", 50_000.0)
    rig.set(pos2=-20.0, doAbs2=True)
    prev_a = rig.ax("Cmd.AccDec")
    while not rig.r("abs2.Done"):
        rig.scan()
        a = rig.ax("Cmd.AccDec")
        assert abs(a - prev_a) <= 50.0 + 1e-9, "acceleration continuous across the takeover"
        prev_a = a
        assert rig.k < 5000
    assert rig.ax("Cmd.Pos") == -20.0


def test_velocity_and_stop_with_jerk_are_s_curves(rig):
    """W508 MC_MoveVelocity and MC_Stop with Jerk: the velocity follows the jerk-limited ramp (v = J t^2 / 2 at
    first), InVelocity once reached; MC_Stop brings it to 0 the same way."""
    rig.powered()
    rig.set(vv=50.0, jerkV=50_000.0, doVel=True)
    rig.scan()
    t0 = rig.t
    rig.scan(10)
    assert rig.ax("Cmd.Vel") == pytest.approx(50_000.0 * (rig.t - t0) ** 2 / 2, abs=1e-9)
    while not rig.r("vel.InVelocity"):
        rig.scan()
    ramp = 50.0 / 1000.0 + 1000.0 / 50_000.0     # seen in the call after the processing that reached it
    assert t0 + ramp < rig.t <= t0 + ramp + 0.002 + 1e-9
    rig.set(doStop=True, stopDec=1000.0, jerkS=50_000.0)
    rig.scan()
    t1 = rig.t
    rig.scan(10)
    assert rig.ax("Cmd.Vel") == pytest.approx(50.0 - 50_000.0 * (rig.t - t1) ** 2 / 2, abs=1e-9)
    while not rig.r("stp.Done"):
        rig.scan()
    assert rig.ax("Cmd.Vel") == 0.0 and rig.state() == "Stopping"


def test_a_jerk_above_the_axis_maximum_runs_at_the_maximum(tmp_path_factory):
    """Axis configuration `max_jerk`: an instruction's Jerk above it runs at it (like Acceleration)."""
    rig = Rig(files(tmp_path_factory), "axes_jerk.toml").powered()
    rig.set(vv=50.0, jerkV=1e9, doVel=True)
    rig.scan()
    t0 = rig.t
    rig.scan(10)
    assert rig.ax("Cmd.Vel") == pytest.approx(20_000.0 * (rig.t - t0) ** 2 / 2, abs=1e-9)


def test_blending_buffer_modes_are_refused_as_not_modelled(rig):
    """W508 BufferMode: only _mcAborting and _mcBuffered are modelled; the blending modes fault clearly."""
    rig.powered()
    rig.set(doAbs1=True, buf1="_mcBlendingLow")
    with pytest.raises(PlcFault, match=r"BufferMode _mcBlendingLow is not modelled"):
        rig.scan()


def test_a_second_buffered_command_is_refused(rig):
    """One buffered command per axis; a further one ends in Error."""
    rig.powered()
    rig.set(pos1=50.0, doAbs1=True)
    rig.scan(2)
    rig.set(pos2=10.0, buf2="_mcBuffered", doAbs2=True)
    rig.scan()
    rig.set(dist=1.0, bufRel="_mcBuffered", doRel=True)
    rig.scan()
    assert rig.r("rel.Error") and rig.r("rel.ErrorID") == M.ERR_BUFFER_FULL
