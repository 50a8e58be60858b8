"""Issue 27: the virtual axes held against the manuals rule by rule. Each test pins one documented rule that vplc
did not follow before: the English W507 page that defines the member (read at easymanua.ls, "NJ/NX-series CPU
Unit Motion Control User's Manual (W507)", page 6-28), or PLCopen Part 1, which W508 implements, where W508's own
page (1-1, multi-execution of instructions) was not readable."""
from itertools import pairwise

import pytest
from motion_rig import Rig, files


@pytest.fixture
def rig(tmp_path_factory):
    return Rig(files(tmp_path_factory)).powered()


def _run_to_done(rig, fb, limit=5000):
    seen = []
    while not rig.r(f"{fb}.Done"):
        rig.scan()
        seen.append((rig.ax("Cmd.Vel"), rig.ax("Cmd.AccDec"), rig.ax("Cmd.Jerk")))
        assert len(seen) < limit
    return seen


@pytest.mark.parametrize("target", [60.0, -60.0])
def test_acc_dec_is_plus_while_accelerating_and_minus_while_decelerating_in_either_direction(rig, target):
    """W507 6-28, Cmd.AccDec: "A plus sign is added for acceleration, and a minus sign is added for deceleration"
    (the sign of the velocity is the direction of travel, that of AccDec is not). Before: AccDec was the signed
    rate of change of Cmd.Vel, so a move in the negative direction showed -Acceleration while speeding up."""
    rig.set(pos1=target, doAbs1=True)
    rig.scan()
    seen = _run_to_done(rig, "abs1")
    rates = {a for v, a, _ in seen if v != 0.0}
    assert rates == {1000.0, 0.0, -500.0}, rates             # a1 = 1000 speeding up, d1 = 500 slowing down
    for (v0, _, _), (v, a, _) in pairwise(seen):
        if a > 0:
            assert abs(v) >= abs(v0), "plus: the speed grows"
        elif a < 0:
            assert abs(v) <= abs(v0), "minus: the speed falls"
    assert rig.ax("Cmd.AccDec") == 0.0 and rig.ax("Cmd.Jerk") == 0.0


@pytest.mark.parametrize("target", [40.0, -40.0])
def test_jerk_is_plus_while_the_rate_grows_and_minus_while_it_falls(rig, target):
    """W507 6-28, Cmd.Jerk: "A plus sign is added when the absolute value of acceleration/deceleration is
    increasing, and a minus sign is added when it is decreasing"; 0 when the instruction's rates are 0. Before:
    Cmd.Jerk stayed 0."""
    rig.set(pos1=target, d1=1000.0, jerk=50_000.0, doAbs1=True)
    rig.scan()
    seen = _run_to_done(rig, "abs1")
    assert {j for _, _, j in seen} == {50_000.0, 0.0, -50_000.0}
    for (_, a0, _), (_, a1, j) in pairwise(seen):
        if j > 0 and abs(a1 - a0) > 1e-9:
            assert abs(a1) > abs(a0) - 1e-9
        if j < 0 and abs(a1 - a0) > 1e-9:
            assert abs(a1) < abs(a0) + 1e-9
    rig.set(doAbs1=False, pos1=0.0)
    rig.scan()
    rig.set(jerk=0.0, doAbs1=True)
    rig.scan()
    assert {j for _, _, j in _run_to_done(rig, "abs1")} == {0.0}, "a trapezoid has no jerk"


def test_an_aborting_move_clears_the_buffered_move_waiting(rig):
    """PLCopen Part 1, BufferMode _mcAborting: the new instruction takes over at once and the buffer is cleared;
    the waiting instruction ends in CommandAborted. Before: the buffered move stayed queued and ran after the
    aborting one, from the aborted move's target (the axis ended at 105 instead of 20)."""
    rig.set(pos1=100.0, doAbs1=True)
    rig.scan(2)
    rig.set(dist=5.0, bufRel=1, doRel=True)
    rig.scan()
    assert rig.outputs("rel") == (True, False, False, False, False), "buffered: Busy, not yet Active"
    rig.set(pos2=20.0, doAbs2=True)
    rig.scan()
    assert rig.outputs("rel") == (False, False, False, True, False)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, True, False)
    _run_to_done(rig, "abs2")
    rig.scan(500)
    assert (rig.ax("Cmd.Pos"), rig.state()) == (20.0, "Standstill")
    assert rig.outputs("rel") == (False, False, False, True, False), "CommandAborted while Execute is TRUE"


def test_a_buffered_relative_move_after_move_velocity_counts_from_where_it_starts(rig):
    """PLCopen Part 1 MC_MoveRelative: the distance is relative to the position at the time the motion starts;
    buffered after MC_MoveVelocity it starts when InVelocity comes (W508 (zh) MC_MoveVelocity, section 5.2), so
    from where the axis is then. Before: counted from the position at the Execute edge (it stopped 0.198 short)."""
    rig.set(vv=20.0, doVel=True)                     # reaches 20 after 20 ms at a1 = 1000: 0.2 travelled
    rig.scan(2)
    rig.set(dist=10.0, bufRel=1, doRel=True)
    rig.scan()
    assert rig.outputs("rel") == (True, False, False, False, False)
    while not rig.r("rel.Active"):
        rig.scan()
        assert rig.k < 100
    _run_to_done(rig, "rel")
    assert rig.ax("Cmd.Pos") == pytest.approx(10.2, abs=1e-12)
    assert rig.state() == "Standstill"


def test_a_move_to_where_the_axis_already_is_is_done_in_the_next_call(rig):
    """W508 (zh) MC_MoveAbsolute / MC_MoveRelative output timing: Busy and Active from the Execute edge, Done once
    the motion is complete, which for no distance is the motion processing of that same period."""
    rig.set(pos1=0.0, doAbs1=True)
    rig.scan()
    assert rig.outputs("abs1") == (True, True, False, False, False)
    rig.scan()
    assert rig.outputs("abs1") == (False, False, True, False, False) and rig.state() == "Standstill"
    rig.set(dist=0.0, doRel=True)
    rig.scan(2)
    assert rig.outputs("rel") == (False, False, True, False, False) and rig.ax("Cmd.Pos") == 0.0


def test_move_velocity_zero_is_accepted_and_holds_the_axis_in_continuous(rig):
    """W508 (zh) MC_MoveVelocity: Velocity "positive or 0". Velocity 0 is no error: the axis is in Continuous,
    InVelocity comes once it runs at 0, and the instruction keeps Busy and Active (it still controls the axis)."""
    rig.set(vv=0.0, doVel=True)
    rig.scan()
    assert rig.outputs("vel", ("Busy", "Active", "InVelocity", "Error")) == (True, True, False, False)
    rig.scan(3)
    assert rig.outputs("vel", ("Busy", "Active", "InVelocity", "Error")) == (True, True, True, False)
    assert (rig.state(), rig.ax("Cmd.Vel")) == ("Continuous", 0.0)


def test_halt_at_rest_is_done_at_once_and_a_buffered_halt_waits_for_the_move(rig):
    """PLCopen Part 1 MC_Halt (W508's page was not readable): Done once the velocity is 0 (at rest: in the next
    call), the axis back in Standstill; Buffered, it starts when the running positioning is Done."""
    rig.set(doHalt=True)
    rig.scan()
    assert rig.outputs("hlt") == (True, True, False, False, False)
    rig.scan()
    assert rig.outputs("hlt") == (False, False, True, False, False) and rig.state() == "Standstill"
    rig.set(doHalt=False)
    rig.scan()
    rig.set(pos1=10.0, doAbs1=True)
    rig.scan(2)
    rig.plc.write("Main.hlt.BufferMode", 1)
    rig.set(doHalt=True)
    rig.scan()
    assert rig.outputs("hlt") == (True, False, False, False, False), "waiting: Busy, not Active"
    _run_to_done(rig, "abs1")
    assert rig.r("hlt.Done") and rig.ax("Cmd.Pos") == 10.0


def test_servo_off_while_mc_stop_holds_the_axis_aborts_the_stop(rig):
    """W508 (zh) MC_Power: servo OFF aborts the instructions running on the axis (CommandAborted) and the axis is
    Disabled; with the servo ON again the axis is in Standstill, MC_Stop no longer holds it."""
    rig.set(doVel=True)
    rig.scan(30)
    rig.set(doStop=True)
    rig.scan(5)
    assert rig.state() == "Stopping"
    rig.set(power=False)
    rig.scan()
    assert rig.state() == "Disabled"
    rig.scan()
    assert rig.outputs("stp") == (False, False, False, True, False)
    rig.set(power=True)
    rig.scan(2)
    assert rig.state() == "Standstill"


def test_an_instruction_error_aborts_the_running_and_the_waiting_move(rig):
    """Section 5.2 (an instruction error is an error of the axis, W508 (zh) output timing of MC_Power and MC_Stop):
    the running and the buffered instruction both end in CommandAborted, the axis goes to ErrorStop."""
    rig.set(pos1=100.0, doAbs1=True)
    rig.scan(2)
    rig.set(dist=5.0, bufRel=1, doRel=True)
    rig.scan()
    rig.set(doSetPos=True)                           # refused while the axis moves
    rig.scan()
    assert rig.r("setp.Error") and rig.state() == "ErrorStop"
    rig.scan()
    assert rig.outputs("abs1") == (False, False, False, True, False)
    assert rig.outputs("rel") == (False, False, False, True, False)


def test_a_new_execute_edge_while_busy_goes_to_the_new_position_without_command_aborted(rig):
    """Re-execution with new inputs (W508 1-1 "changing input variables during execution" was not readable; the
    rule vplc chose, section 5.2): the instance takes the new Position from where the axis is, reports no
    CommandAborted, and is Done once, on the new target."""
    rig.set(pos1=100.0, doAbs1=True)
    rig.scan(50)
    rig.set(doAbs1=False)
    rig.scan()
    rig.set(pos1=5.0, doAbs1=True)
    rig.scan()
    assert rig.outputs("abs1") == (True, True, False, False, False)
    aborted = False
    while not rig.r("abs1.Done"):
        rig.scan()
        aborted = aborted or rig.r("abs1.CommandAborted")
        assert rig.k < 5000
    assert not aborted and rig.ax("Cmd.Pos") == 5.0 and rig.state() == "Standstill"
