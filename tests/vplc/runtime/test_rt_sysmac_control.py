"""W502 control instructions (PIDAT, TimeProportionalOut) and system control instructions (user-defined errors,
controller errors) on the virtual controller, with the values of docs/toolchain/runtime_sysmac.md sections 2b, 2c."""
import pytest
from rt_helpers import plc_from

from vplc.api import LoadError, PlcFault

MS = 1_000_000


def scans(plc, period_ns: int, count: int, start: int = 0):
    """Scan ``count`` times, one task period apart; yield the index after each scan."""
    for i in range(start, start + count):
        plc.scan(i * period_ns)
        yield i


# ---- TimeProportionalOut (W560 2-728, the NY-series edition of the W502 page) ----------------------------------

TPO = "tpo : TimeProportionalOut; en : BOOL := TRUE; ain : REAL := 20.0; d, err : BOOL; prd : TIME := T#10s;"


def test_time_proportional_out_is_on_for_ain_percent_of_each_period_as_w560_2_728_shows(tmp_path):
    """W560 2-728: CtlPrd 10 s, AIn 20 %: DOut TRUE for 2 s, then FALSE for 8 s, repeated (positional call of the
    page: Enable, AIn, CtlPrd, MinPlsWidth, Delay, DOut, Error)."""
    plc = plc_from(tmp_path, "tpo(en, ain, prd, REAL#0, REAL#0, d, err);", TPO, task="Main@100ms")
    seen = {i: plc.read("Main.d") for i in scans(plc, 100 * MS, 221)}
    assert [seen[i] for i in (0, 19, 20, 99, 100, 119, 120, 200, 219, 220)] == \
        [True, True, False, False, True, True, False, True, True, False]
    assert sum(seen[i] for i in range(100)) == 20 and plc.read("Main.err") is False


def test_time_proportional_out_resolution_is_task_period_over_ctlprd(tmp_path):
    """W560 2-728: 1 ms task and CtlPrd 1 s give a resolution of 0.1 %: AIn 12.34 % is 12.3 % -> 123 ms ON."""
    plc = plc_from(tmp_path, "tpo(Enable := en, AIn := ain, CtlPrd := T#1s, DOut => d, Error => err);",
                   TPO.replace("20.0", "12.34"), task="Main@1ms")
    assert sum(plc.read("Main.d") for _ in scans(plc, MS, 1000)) == 123


def test_time_proportional_out_enable_false_resets_dout_and_error(tmp_path):
    plc = plc_from(tmp_path, "tpo(en, ain, prd, REAL#0, REAL#0, d, err);", TPO, task="Main@100ms")
    plc.scan(0)
    assert plc.read("Main.d") is True
    plc.write("Main.en", False)
    plc.scan(100 * MS)
    assert (plc.read("Main.d"), plc.read("Main.err")) == (False, False)


def test_time_proportional_out_ctlprd_changes_only_at_the_rising_edge_of_enable(tmp_path):
    """W560 2-728: CtlPrd, MinPlsWidth and Delay are updated when Enable changes from FALSE to TRUE."""
    plc = plc_from(tmp_path, "tpo(en, ain, prd, REAL#0, REAL#0, d, err);", TPO, task="Main@100ms")
    plc.scan(0)
    plc.write("Main.prd", 1_000_000_000)            # T#1s: not taken while Enable stays TRUE
    seen = [plc.read("Main.d") for _ in scans(plc, 100 * MS, 30, start=1)]
    assert seen[18] is True and seen[19] is False       # still the 10 s period: ON until 2 s


def test_time_proportional_out_ctlprd_shorter_than_the_task_is_an_error(tmp_path):
    plc = plc_from(tmp_path, "tpo(en, ain, T#10ms, REAL#0, REAL#0, d, err);", TPO, task="Main@100ms")
    plc.scan(0)
    assert (plc.read("Main.err"), plc.read("Main.d")) == (True, False)
    assert "CtlPrd" in plc.engine.instruction_errors[-1]


def test_time_proportional_out_min_pulse_width_is_refused_as_not_modelled(tmp_path):
    plc = plc_from(tmp_path, "tpo(en, ain, prd, REAL#5, REAL#0, d, err);", TPO, task="Main@100ms")
    with pytest.raises(PlcFault, match="MinPlsWidth 5 is not modelled by vplc"):
        plc.scan(0)


# ---- PIDAT -----------------------------------------------------------------------------------------------------

PID_DECLS = """pid : PIDAT; run : BOOL := TRUE; man : BOOL; at : BOOL; pv : REAL := 40.0; sp : REAL := 50.0;
opr : _sOPR_SET_PARAMS; ini : _sINIT_SET_PARAMS; pb : REAL := 10.0; ti : TIME := T#10s; td : TIME;
manmv : REAL := 30.0; mv : REAL; err : BOOL; eid : WORD;"""
PID_CALL = """pid(Run := run, ManCtl := man, StartAT := at, PV := pv, SP := sp, OprSetParams := opr,
    InitSetParams := ini, ProportionalBand := pb, IntegrationTime := ti, DerivativeTime := td, ManMV := manmv,
    Error => err, ErrorID => eid, MV => mv);"""


def pid_plc(tmp_path, body: str = PID_CALL, task: str = "Main@100ms"):
    return plc_from(tmp_path, body, PID_DECLS, task=task)


def test_pidat_structures_have_their_documented_defaults(tmp_path):
    plc = pid_plc(tmp_path)
    assert (plc.read("Main.opr.MVLowLmt"), plc.read("Main.opr.MVUpLmt"), plc.read("Main.ini.RngUpLmt")) == \
        (0.0, 100.0, 100.0)
    assert plc.read("Main.opr.Alpha") == pytest.approx(0.65) and plc.read("Main.ini.DirOpr") is False


def test_pidat_integral_action_starts_from_the_stop_mv_without_a_bump(tmp_path):
    """PB 10 % (Kp 10), error 10 %, Ti 10 s, 100 ms samples: MV starts at StopMV 0 and the integral adds
    Kp * e * dt / Ti = 1 % per sample while PV and SP stay."""
    plc = pid_plc(tmp_path)
    mvs = [plc.read("Main.mv") for _ in scans(plc, 100 * MS, 5)]
    assert mvs == pytest.approx([1.0, 2.0, 3.0, 4.0, 5.0])


def test_pidat_mv_stays_within_the_limits_and_does_not_wind_up(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.opr.MVUpLmt", 20.0)
    for _ in scans(plc, 100 * MS, 200):
        pass
    assert plc.read("Main.mv") == pytest.approx(20.0)
    plc.write("Main.pv", 60.0)                          # the error changes sign: MV leaves the limit at once
    plc.scan(200 * 100 * MS)
    assert plc.read("Main.mv") < 20.0


def test_pidat_proportional_only_uses_the_manual_reset_value(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.ti", 0)
    plc.write("Main.opr.ManResetVal", 50.0)
    plc.write("Main.opr.MVUpLmt", 200.0)
    plc.scan(0)
    assert plc.read("Main.mv") == pytest.approx(50.0 + 10.0 * 10.0)      # ManResetVal + Kp * e


def test_pidat_direct_operation_lowers_mv_when_pv_is_below_sp(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.ti", 0)
    plc.write("Main.opr.ManResetVal", 50.0)
    plc.write("Main.pb", 100.0)                         # Kp 1: MV = 50 + 1 * (PV - SP) = 40
    plc.write("Main.ini.DirOpr", True)
    plc.scan(0)
    assert plc.read("Main.mv") == pytest.approx(40.0)


def test_pidat_manual_mode_outputs_man_mv_and_returns_without_a_bump(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.man", True)
    plc.scan(0)
    assert plc.read("Main.mv") == pytest.approx(30.0)
    plc.write("Main.man", False)
    plc.scan(100 * MS)
    assert plc.read("Main.mv") == pytest.approx(31.0)  # continues from 30 % with one integral step


def test_pidat_run_false_outputs_stop_mv(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.opr.StopMV", 12.5)
    plc.write("Main.run", False)
    plc.scan(0)
    assert plc.read("Main.mv") == pytest.approx(12.5)


def test_pidat_a_range_without_width_is_an_error_with_error_mv(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.ini.RngUpLmt", 0.0)
    plc.write("Main.opr.ErrorMV", 7.0)
    plc.scan(0)
    assert (plc.read("Main.err"), plc.read("Main.eid"), plc.read("Main.mv")) == (True, 0x0400, 7.0)
    assert "RngUpLmt" in plc.engine.instruction_errors[-1]


def test_pidat_sampling_period_is_samp_time_or_the_task_period(tmp_path):
    plc = pid_plc(tmp_path, task="Main@10ms")
    plc.write("Main.ini.SampTime", 100 * MS)           # one PID computation per 10 scans of 10 ms
    mvs = [plc.read("Main.mv") for _ in scans(plc, 10 * MS, 21)]
    assert mvs[0] == pytest.approx(1.0) and mvs[9] == pytest.approx(1.0) and mvs[10] == pytest.approx(2.0)
    assert mvs[20] == pytest.approx(3.0)


def test_pidat_autotuning_is_refused_as_not_modelled(tmp_path):
    plc = pid_plc(tmp_path)
    plc.write("Main.at", True)
    with pytest.raises(PlcFault, match=r"PIDAT: autotuning \(StartAT TRUE\) is not modelled by vplc"):
        plc.scan(0)


# ---- user-defined errors and controller errors ------------------------------------------------------------------

ALARMS = """sa : SetAlarm; ra : ResetAlarm; set1, set2, res : BOOL; code : UDINT := 16#100; lvl : UINT;
got : UDINT; has : BOOL; done : BOOL;"""
ALARM_BODY = """sa(Execute := set1, Code := code, Info1 := 16#11, Info2 := 16#22, Done => done);
ra(Execute := res, Code := code);
has := GetAlarm(lvl, got);"""


def test_set_alarm_creates_a_user_defined_error_that_get_alarm_reports(tmp_path):
    from vplc.runtime.sysmac_errors import user_alarms
    plc = plc_from(tmp_path, ALARM_BODY, ALARMS)
    plc.scan(0)
    assert (plc.read("Main.has"), plc.read("Main.lvl"), plc.read("Main.got")) == (False, 0, 0)
    plc.write("Main.set1", True)
    plc.scan(MS)
    assert (plc.read("Main.has"), plc.read("Main.lvl"), plc.read("Main.got"), plc.read("Main.done")) == \
        (True, 1, 0x100, True)
    alarm = user_alarms(plc.engine)[0x100]
    assert (alarm.info1, alarm.info2, alarm.time_ns) == (0x11, 0x22, MS)
    plc.write("Main.set1", False)
    plc.write("Main.res", True)
    plc.scan(2 * MS)
    assert (plc.read("Main.has"), plc.read("Main.done")) == (False, False) and user_alarms(plc.engine) == {}


def test_get_alarm_reports_the_oldest_of_several(tmp_path):
    plc = plc_from(tmp_path, ALARM_BODY, ALARMS)
    plc.write("Main.set1", True)
    plc.scan(0)
    plc.write("Main.set1", False)
    plc.scan(MS)
    plc.write("Main.code", 0x200)
    plc.write("Main.set1", True)
    plc.scan(2 * MS)
    assert plc.read("Main.got") == 0x100


def test_plc_and_ethercat_errors_are_none_in_the_virtual_controller(tmp_path):
    plc = plc_from(tmp_path, """a := GetPLCError(l1, c1); b := GetECError(l2, c2);
rp(Execute := TRUE); re(Execute := TRUE);""",
                   "a, b : BOOL := TRUE; l1, l2 : UINT := 9; c1, c2 : DWORD := 9; rp : ResetPLCError; "
                   "re : ResetECError;")
    plc.scan(0)
    assert [plc.read(f"Main.{v}") for v in ("a", "b", "l1", "l2", "c1", "c2")] == [False, False, 0, 0, 0, 0]
    assert (plc.read("Main.rp.Done"), plc.read("Main.re.Done"), plc.read("Main.re.Failure")) == (True, True, False)


def test_get_mc_error_without_axes_is_no_error(tmp_path):
    plc = plc_from(tmp_path, "a := GetMCError(l, c); r(Execute := TRUE);",
                   "a : BOOL := TRUE; l : UINT; c : DWORD; r : ResetMCError;")
    plc.scan(0)
    assert (plc.read("Main.a"), plc.read("Main.r.Done"), plc.read("Main.r.Failure")) == (False, True, False)


def test_an_unknown_instruction_name_still_fails_to_load(tmp_path):
    with pytest.raises(LoadError):
        plc_from(tmp_path, "x := CheckReal(1.0);", "x : BOOL;")


def test_get_mc_error_reports_the_error_of_a_virtual_axis_and_reset_mc_error_clears_it(tmp_path):
    """The Motion Control Function Module's errors are those of the virtual axes: a move refused for its
    velocity (axis error 16#5410, runtime_sysmac.md section 5) is reported until ResetMCError."""
    (tmp_path / "axes.toml").write_text("[[axis]]\nnumber = 0\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n"
                                        "max_deceleration = 1000.0\n", encoding="utf-8")
    plc = plc_from(tmp_path, """pwr(Axis := _MC_AX[0], Enable := TRUE);
mv(Axis := _MC_AX[0], Execute := go, Position := 10.0, Velocity := -1.0);
rst(Execute := doReset);
has := GetMCError(lvl, code);""", "pwr : MC_Power; mv : MC_MoveAbsolute; rst : ResetMCError; go, doReset : BOOL; "
                   "has : BOOL; lvl : UINT; code : DWORD;", task="Main@1ms", axes=str(tmp_path / "axes.toml"))
    plc.scan(0)
    plc.write("Main.go", True)
    plc.scan(MS)
    plc.scan(2 * MS)
    assert (plc.read("Main.has"), plc.read("Main.lvl"), plc.read("Main.code")) == (True, 3, 0x5410)
    plc.write("Main.doReset", True)
    plc.scan(3 * MS)
    plc.scan(4 * MS)
    assert (plc.read("Main.rst.Done"), plc.read("Main.rst.Failure"), plc.read("Main.has")) == (True, False, False)
