"""The PLCopen edges of every command FB and the link lost at each step, the robot's own log as the witness (the
maintainers' probe, part 2; part 1, the values, is test_lib_input_edges.py): Execute held, pulsed for one scan,
re-raised while Busy, inputs changed while Busy, several FBs started in one scan on one connection (Listen node and
Ethernet Slave channel, in a user's call order), the Listen-node and Ethernet Slave links lost before the edge, in
the edge scan, with the reply outstanding, while moving and after Done. One frame per accepted edge, Done only
once the robot did it, otherwise a documented ErrorID. Virtual time; helpers: edges.py."""
from __future__ import annotations

import pytest
from edges import (
    ERRORS,
    NAN,
    SVR_FBS,
    ZERO_POSE,
    abs_call,
    command,
    script_frames,
    set_variable,
    svr_order_rig,
    svr_writes,
    tcp_values,
)
from rig import HOME_JOINTS, ROOT, Rig, circ, move_abs, rel

# ---- PLCopen: Execute held, pulsed, re-raised; inputs changed while Busy; two FBs in one scan ---------------------
SLOW = dict(TargetPosition={**HOME_JOINTS, "RZ": 60.0}, Speed=20)         # about 1 s of motion


def setup_command(rig, fb: str) -> tuple[str, str]:
    """Valid parameters for one FB of Main_Lib.st; (instance, Execute variable)."""
    if fb == "mover":
        rig.set_struct("MoveParam", move_abs(**SLOW))
        return "mover", "MoveExec"
    if fb == "rel":
        rig.set_struct("RelParam", rel())
        return "rel", "RelExec"
    if fb == "circ":
        rig.set_struct("CircParam", circ())
        return "circ", "CircExec"
    if fb == "base":
        rig.set_struct("BaseParam.Transformation", dict(ZERO_POSE, X=10.5))
        return "base", "BaseExec"
    if fb == "tcp":
        rig.set_struct("TcpParam", tcp_values())
        return "tcp", "TcpExec"
    if fb == "dout":
        rig.set_struct("OutParam", dict(Module="EndModule", Channel=2, Value=True))
        return "dout", "OutExec"
    if fb == "prg":
        rig.write("PrgParam.Command", "Resume")
        return "prg", "PrgExec"
    rig.write("StopParam.Mode", "StopNormal")
    return "stop", "StopExec"


FBS = ["mover", "rel", "circ", "base", "tcp", "dout", "prg", "stop"]
OUTS = ("Done", "Busy", "Error", "CommandAborted")


def trace(rig, fb: str, scans: int, on_scan=None) -> list[dict]:
    """The FB's outputs after each of ``scans`` scans."""
    rows = []
    for n in range(scans):
        if on_scan:
            on_scan(n)
        rig.scans(1)
        rows.append({o: rig.read(f"{fb}.{o}") for o in OUTS})
    return rows


@pytest.mark.parametrize("fb", FBS)
def test_execute_held_sends_once_and_done_stays_until_it_falls(rig, fb):
    inst, execute = setup_command(rig, fb)
    rig.write(execute, True)
    rows = trace(rig, inst, 3000)                                        # 3 s held
    first = next(i for i, r in enumerate(rows) if r["Done"])
    assert all(r["Done"] and not r["Busy"] and not r["Error"] for r in rows[first:])
    assert all(r["Busy"] and not r["Done"] for r in rows[:first])
    assert len(script_frames(rig)) == 1
    if inst in ("mover", "rel"):
        assert len(rig.events("motion_end")) == 1
    rig.write(execute, False)
    rig.scans(1)
    assert not any(rig.read(f"{inst}.{o}") for o in OUTS)
    rig.scans(500)
    assert len(script_frames(rig)) == 1


@pytest.mark.parametrize("fb", FBS)
def test_execute_pulsed_for_one_scan_sends_once_and_shows_done_for_one_scan(rig, fb):
    inst, execute = setup_command(rig, fb)
    rows = trace(rig, inst, 3000, on_scan=lambda n: rig.write(execute, n == 0))
    assert [r["Done"] for r in rows].count(True) == 1, "Done must show for exactly one scan"
    assert not any(r["Error"] or r["CommandAborted"] for r in rows)
    done_at = next(i for i, r in enumerate(rows) if r["Done"])
    assert all(r["Busy"] for r in rows[:done_at]) and not any(r["Busy"] for r in rows[done_at:])
    assert len(script_frames(rig)) == 1
    if inst in ("mover", "rel"):
        assert len(rig.events("motion_end")) == 1


@pytest.mark.parametrize("fb,member,raw,code", [("mover", "MoveParam.Speed", 0, 0x1013),
                                                ("base", "BaseParam.Transformation.X", NAN, 0x101E),
                                                ("dout", "OutParam.Channel", 99, 0x1025),
                                                ("stop", "StopParam.Mode", 9, 0x1023)])
def test_a_refused_pulse_shows_error_for_one_scan(rig, fb, member, raw, code):
    inst, execute = setup_command(rig, fb)
    rig.write(member, raw, raw=isinstance(raw, int) and fb == "stop")
    rows = trace(rig, inst, 5, on_scan=lambda n: rig.write(execute, n == 0))
    assert [r["Error"] for r in rows] == [True, False, False, False, False]
    assert not any(r["Busy"] or r["Done"] for r in rows)
    assert script_frames(rig) == []


def test_execute_re_raised_while_busy_starts_one_new_command_per_edge(rig):
    """R5: the new edge replaces the running command; the first motion was sent and runs (it is the robot's), the
    second is sent once, and Done comes when the robot finished the second."""
    inst, execute = setup_command(rig, "mover")
    rig.write(execute, True)
    assert rig.until(lambda: rig.read("mover.Active"), 1)
    rig.write(execute, False)
    rig.scans(1)
    rig.set_struct("MoveParam.TargetPosition", {**HOME_JOINTS, "RZ": -30.0})
    rig.write(execute, True)
    rig.scans(1)
    assert rig.read("mover.Busy") and not rig.read("mover.Done")
    assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 10)
    assert rig.read("mover.Done"), rig.read("mover.ErrorDescrip")
    ends = [round(e["joints"][5]) for e in rig.events("motion_end")]
    assert ends == [60, -30], ends                                     # both ran, in order, Done after the second
    scripts = script_frames(rig)
    assert len(scripts) == 2 and "60" in scripts[0].split(",")[6] and "-30" in scripts[1].split(",")[6]
    rig.write(execute, False)
    rig.scans(500)
    assert len(script_frames(rig)) == 2


def test_inputs_changed_while_busy_are_not_taken(rig):
    """R4: the parameters are latched at the edge: what the robot gets and where it ends are the edge's values."""
    inst, execute = setup_command(rig, "mover")
    rig.write(execute, True)
    rig.scans(1)
    rig.set_struct("MoveParam", move_abs(TargetPosition={**HOME_JOINTS, "RZ": -45.0}, Speed=100, DataFormat="CPR_Abs"))
    rig.write("mover.BufferMode", "Aborting")
    assert rig.until(lambda: rig.read("mover.Done") or rig.read("mover.Error"), 10)
    assert rig.read("mover.Done"), rig.read("mover.ErrorDescrip")
    assert [round(e["joints"][5]) for e in rig.events("motion_end")] == [60]
    scripts = script_frames(rig)
    assert len(scripts) == 1 and scripts[0].split("\r\n")[0] == abs_call(move_abs(**SLOW)), scripts


def test_write_variable_text_changed_while_busy_is_not_taken(var):
    set_variable(var, "WrVar", "g_text", "VarString", 1, "StringValue", ["first"])
    var.write("WrExec", True)
    var.scans(1)
    var.write("WrVar.StringValue[1]", "second")
    var.write("WrVar.Name", "g_n")
    assert var.until(lambda: var.read("wr.Done") or var.read("wr.Error"), 3)
    assert var.read("wr.Done") and var.robot.svr.variables["g_text"] == "first"
    assert [w["items"] for w in svr_writes(var)] == [{"g_text": "first"}]


def test_execute_re_raised_while_a_write_is_busy_is_ignored(var):
    set_variable(var, "WrVar", "g_text", "VarString", 1, "StringValue", ["one"])
    var.write("WrExec", True)
    var.scans(1)
    assert var.read("wr.Busy")
    var.write("WrExec", False)
    var.scans(1)
    var.write("WrExec", True)
    assert var.until(lambda: var.read("wr.Done") or var.read("wr.Error"), 3)
    var.write("WrExec", False)
    var.scans(100)
    assert len(svr_writes(var)) == 1


def test_every_fb_started_in_the_same_scan_sends_once_each_in_call_order(rig):
    """Main_Lib.st calls mover, rel, circ, base, tcp, prg, stop, dout, ..., movers[1..4]: every one started in one
    scan goes out once, in that order, and each ends Done (the stop last would abort the motions: left out)."""
    started = [setup_command(rig, fb) for fb in ("mover", "base", "tcp", "dout")]
    for k in (1, 2):
        rig.set_struct(f"MParam[{k}]", move_abs(TargetPosition={**HOME_JOINTS, "RZ": 10.0 * k}))
        started.append((f"movers[{k}]", f"MExec[{k}]"))
    for _, execute in started:
        rig.write(execute, True)
    assert rig.until(lambda: all(rig.read(f"{i}.Done") or rig.read(f"{i}.Error") for i, _ in started), 20)
    assert all(rig.read(f"{i}.Done") for i, _ in started), {i: rig.read(f"{i}.ErrorDescrip") for i, _ in started}
    heads = [s.split("(")[0] for s in script_frames(rig)]
    assert heads == ["PTP", "ChangeBase", "ChangeTCP", 'IO["EndModule"].DO[2]=1', "PTP", "PTP"], heads
    assert len(rig.events("motion_end")) == 3


# ---- the link lost at each step of a command ---------------------------------------------------------------------
def lose_link(rig) -> None:
    rig.robot.inject("disconnect")


STEPS = ["before_the_edge", "in_the_edge_scan", "reply_held_back", "while_moving", "after_done"]


@pytest.mark.parametrize("fb,step", [(fb, step) for fb in ("mover", "base", "dout") for step in STEPS
                                     if fb == "mover" or step != "while_moving"])
def test_link_lost_at_each_step_never_reports_what_the_robot_did_not_do(rig, fb, step):
    """At most one frame; the FB ends (never Busy for good); Done only if the robot did it, else Error with a
    documented ErrorID and its text. A command refused before the edge sends nothing."""
    inst, execute = setup_command(rig, fb)
    if step == "before_the_edge":
        lose_link(rig)
        assert rig.until(lambda: not rig.read("Cobot.Connected"), 2)
    if step == "reply_held_back":
        rig.robot.inject("reply_delay", seconds=0.3, count=1)
    rig.write(execute, True)
    if step == "in_the_edge_scan":
        lose_link(rig)
    rig.scans(1)
    if step == "reply_held_back":
        assert rig.until(lambda: len(script_frames(rig)) == 1, 1)
        lose_link(rig)
    if step == "while_moving":
        assert rig.until(lambda: rig.read(f"{inst}.Active") or rig.read(f"{inst}.Done"), 2)
        lose_link(rig)
    if step == "after_done":
        assert rig.until(lambda: rig.read(f"{inst}.Done"), 10)
        lose_link(rig)
    assert rig.until(lambda: not rig.read(f"{inst}.Busy"), 12), f"{inst} still Busy"
    done, error_id = rig.read(f"{inst}.Done"), rig.read(f"{inst}.ErrorID")
    rig.scans(3000)                                             # CBT_Connect reconnects; nothing is sent again
    scripts = script_frames(rig)
    assert len(scripts) <= 1, scripts
    if step == "before_the_edge":
        assert scripts == [] and error_id in (0x2001, 0x200C), hex(error_id)
    if done:
        assert len(scripts) == 1
        if inst == "mover":
            assert len(rig.events("motion_end")) == 1
        elif inst == "base":
            assert rig.events("setting")
    else:
        assert rig.read(f"{inst}.Error") and error_id in ERRORS, hex(error_id)
        assert rig.read(f"{inst}.ErrorDescrip") == ERRORS[error_id][:80]


# ---- the Ethernet Slave channel: two FBs started close together, in a user's call order ------------------------
@pytest.mark.parametrize("gap", range(0, 7))
@pytest.mark.parametrize("first,second", [(a, b) for a in SVR_FBS for b in SVR_FBS if a != b])
def test_ethernet_slave_fbs_started_close_together_send_each_request_once(first, second, gap):
    """tests/lib/st/Main_SvrOrder.st calls CBT_ProjectControl, CBT_SetOverride, CBT_WriteVariable, CBT_ReadVariable
    in that order; ``second`` starts ``gap`` scans after ``first``, so at some gap its first call sees the answer
    to ``first``'s request before ``first`` took it. Each request reaches the robot exactly once and both FBs end
    Done (before: CBT_ProjectControl, and CBT_SetOverride in its edge scan, took the channel over an answer its
    owner had not taken yet, and the owner sent its request a second time)."""
    r = svr_order_rig()
    try:
        before = len(r.robot.events)
        r.write(SVR_FBS[first][0], True)
        r.scans(gap)
        r.write(SVR_FBS[second][0], True)
        assert r.until(lambda: all(r.read(f"{fb}.Done") or r.read(f"{fb}.Error") for fb in (first, second)), 10)
        assert r.read(f"{first}.Done") and r.read(f"{second}.Done"), \
            [r.read(f"{fb}.ErrorDescrip") for fb in (first, second)]
        requests = [(e["kind"], e["items"]) for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        expected = [SVR_FBS[fb][1:] for fb in (first, second)]
        assert sorted(map(repr, requests)) == sorted(map(repr, expected)), requests
    finally:
        r.close()


SVR_STEPS = ["before_the_edge", "in_the_edge_scan", "request_unanswered", "after_done"]


@pytest.mark.parametrize("step", SVR_STEPS)
@pytest.mark.parametrize("fb", ["proj", "ovr", "wr", "rd"])
def test_ethernet_slave_link_lost_at_each_step(fb, step):
    """The Ethernet Slave link lost around one request: at most one request reaches the robot, the FB ends, Done
    only when the robot answered it (a write: the robot's value changed), else a documented ErrorID and its text;
    nothing is sent again once the link is back."""
    r = svr_order_rig()
    try:
        execute, kind, items = SVR_FBS[fb]
        before = len(r.robot.events)
        if step == "before_the_edge":                                  # a silent Ethernet Slave: link down
            r.robot.svr.inject("stall")
            assert r.until(lambda: not r.read("Cobot.Status.SlaveLink"), 3)
        if step == "request_unanswered":
            r.robot.svr.inject("stall")
        r.write(execute, True)
        if step == "in_the_edge_scan":
            r.robot.svr.inject("disconnect")
        r.scans(1)
        if step == "request_unanswered":
            r.scans(50)
            r.robot.svr.inject("disconnect")
            r.robot.svr.clear_faults()
        if step == "after_done":
            assert r.until(lambda: r.read(f"{fb}.Done"), 10)
            r.robot.svr.inject("disconnect")
        assert r.until(lambda: not r.read(f"{fb}.Busy"), 10), f"{fb} still Busy"
        done, error_id = r.read(f"{fb}.Done"), r.read(f"{fb}.ErrorID")
        r.until(lambda: False, 3)                                      # the link comes back; nothing is resent
        requests = [(e["kind"], e["items"]) for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(requests) <= 1, requests
        if step == "before_the_edge":                                  # refused in the edge scan, not sent
            assert requests == [] and not done and error_id in (0x2011, 0x2020, 0x2021), hex(error_id)
            assert r.read("Cobot.SvrCmdState") != "SvrCmdSent"
        if done:
            assert requests == [(kind, items)]
            if fb == "wr":
                assert r.robot.svr.variables["g_n"] == 7
        else:
            assert r.read(f"{fb}.Error") and error_id in ERRORS
            assert r.read(f"{fb}.ErrorDescrip") == ERRORS[error_id][:80]
    finally:
        r.close()


# ---- CBT_Teach: the entry selected at the edge, also when the selection changes while Busy ------------------------
@pytest.mark.parametrize("svr", [False, True], ids=["listen_node", "ethernet_slave"])
def test_teach_page_example_stores_into_the_entry_selected_at_the_edge(svr, tmp_path):
    """CBT_Teach.md's example holds the index while Busy: the operator selecting entry 2 in the scan after pressing
    Teach on entry 1 leaves entry 2 untouched (Point is an in-out, written in the scan the reading arrives; the
    plain TeachTable[TeachIndex] wrote the position into entry 2)."""
    from doc_steps import example_of, on_simulator, simulator

    from vplc.api import load_plc
    code, _ = example_of("CBT_Teach")
    if svr:
        code = code.replace("Time_Out := 30);", "Time_Out := 30, SvrPort := SVRPORT);")
    srv = simulator() if not svr else None
    if svr:
        from tmsim.net.server import SimServer
        srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, svr_port=0)
    srv.start()
    try:
        source = tmp_path / "teach_example.st"
        source.write_text(on_simulator(code, srv).replace("SVRPORT", str(srv.robots[0].svr_port)), encoding="utf-8")
        plc = load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(source)], task="Main@1ms")
        pump = lambda now_ns: srv.poll(now_ns / 1e9)  # noqa: E731
        assert plc.run_until(lambda: plc.read("Teach_Example.fbConnect.Connected"), 5_000_000_000, on_scan=pump)
        plc.write("Teach_Example.TeachIndex", 1)
        plc.write("Teach_Example.TeachButton", True)
        plc.scan(plc.now_ns + plc.period_ns)
        assert plc.read("Teach_Example.fbTeach.Busy") or plc.read("Teach_Example.fbTeach.Done")
        plc.write("Teach_Example.TeachIndex", 2)
        assert plc.run_until(lambda: plc.read("Teach_Example.fbTeach.Done"), 2_000_000_000, on_scan=pump)
        assert plc.read("Teach_Example.TeachTable[1].Taught") and plc.read("Teach_Example.TeachTable[1].Name") == "Pick"
        assert not plc.read("Teach_Example.TeachTable[2].Taught") and plc.read("Teach_Example.TeachTable[2].Name") == ""
        plc.close()
    finally:
        srv.close()


# ---- Execute re-raised while Busy: one command per accepted edge, each reaching the robot once -----------------
def reraise(rig, execute: str, busy: str, scans_after: int) -> None:
    rig.write(execute, True)
    assert rig.until(lambda: rig.read(busy), 1)
    rig.scans(scans_after)
    rig.write(execute, False)
    rig.scans(1)
    assert rig.read(busy), "ended before the second edge: not a re-raise while Busy"
    rig.write(execute, True)


@pytest.mark.parametrize("after", [0, 5, 60])
def test_vision_job_re_raised_while_busy_runs_the_job_once_per_edge(vis, after):
    """R5 (the command core): the second edge replaces the first, which the robot still runs; Done is the second's."""
    vis.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    reraise(vis, "VisExec", "vis.Busy", after)
    assert vis.until(lambda: vis.read("vis.Done") or vis.read("vis.Error"), 5)
    assert vis.read("vis.Done") and vis.read("vis.Found"), vis.read("vis.ErrorDescrip")
    vis.write("VisExec", False)
    vis.scans(2000)
    assert sum("Vision_DoJob" in s for s in script_frames(vis)) == 2


@pytest.mark.parametrize("fb,after,requests", [("ovr", 0, 1), ("ovr", 3, 1), ("rd", 0, 1), ("wr", 0, 1),
                                               ("proj", 0, 2), ("proj", 3, 2)])
def test_ethernet_slave_fb_re_raised_while_busy(fb, after, requests):
    """CBT_SetOverride, CBT_ReadVariable and CBT_WriteVariable ignore an edge while Busy (the request under way
    ends first: one request); CBT_ProjectControl takes it as a new command (R5: two requests, each once)."""
    r = svr_order_rig()
    try:
        before = len(r.robot.events)
        reraise(r, SVR_FBS[fb][0], f"{fb}.Busy", after)
        assert r.until(lambda: r.read(f"{fb}.Done") or r.read(f"{fb}.Error"), 10)
        assert r.read(f"{fb}.Done"), r.read(f"{fb}.ErrorDescrip")
        r.write(SVR_FBS[fb][0], False)
        r.until(lambda: False, 2)
        sent = [e for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(sent) == requests, sent
    finally:
        r.close()


def test_stop_re_raised_while_busy_sends_one_stop_per_edge_and_releases_stopping(rig):
    rig.write("StopParam.Mode", "StopNormal")
    rig.robot.inject("reply_delay", seconds=0.2, count=1)
    reraise(rig, "StopExec", "stop.Busy", 2)
    assert rig.until(lambda: rig.read("stop.Done") or rig.read("stop.Error"), 3)
    assert rig.read("stop.Done") and rig.read("Cobot.Stopping")
    rig.write("StopExec", False)
    rig.scans(300)
    assert script_frames(rig) == ["StopAndClearBuffer()", "StopAndClearBuffer()"]
    assert not rig.read("Cobot.Stopping") and rig.read("Cobot.StopHolders") == 0


@pytest.mark.parametrize("path,value", [("JogAxis", 1), ("JogFrame", "JogTool"), ("JogVelocity", 100),
                                        ("JogAxis", 0), ("JogVelocity", 0)])
def test_jog_inputs_changed_while_held_are_not_taken(path, value):
    """Frame, Axis and Velocity are taken at the press: changed while the button is held (even to an invalid
    value) the robot keeps getting the pressed axis's increments, and nothing else."""
    r = Rig(program="Main_Jog.st")
    try:
        r.write("JogFrame", "JogBase")
        r.write("JogAxis", 3)
        r.write("JogVelocity", 10)
        r.write("JogFwd", True)
        assert r.until(lambda: r.read("jog.Active"), 1)
        pressed = script_frames(r)[-1].split("\r\n")[0]
        before = len(script_frames(r))
        r.write(path, value, raw=path == "JogFrame" and isinstance(value, int))
        r.scans(400)
        later = [s.split("\r\n")[0] for s in script_frames(r)[before:]]
        assert later and set(later) == {pressed}, later
        assert r.read("jog.Active") and not r.read("jog.Error")
    finally:
        r.close()


@pytest.mark.parametrize("hold", [True, False], ids=["held", "pulsed"])
def test_wait_queue_sends_one_tag_and_is_done_only_after_the_queued_motion(cell, hold):
    """CBT_WaitQueue (an empty script with a queue tag, TMscript 2.24 §15.3 QueueTag): one frame per edge, Done
    when the robot reached the tag, so after the motion queued before it finished."""
    cell.set_struct("MoveParam", move_abs(**SLOW))
    cell.write("MoveExec", True)
    assert cell.until(lambda: cell.read("mover.Active"), 1)
    before = len(script_frames(cell))
    res = command(cell, "wait", "WaitExec", seconds=10, hold=hold)
    assert res.done and res.motion_ends == 1, res
    assert len(script_frames(cell)) - before == 1 and script_frames(cell)[-1].startswith("QueueTag(")


@pytest.mark.parametrize("fb", ["proj", "ovr", "wr", "rd"])
def test_ethernet_slave_fb_pulsed_for_one_scan_shows_done_for_one_scan(fb):
    r = svr_order_rig()
    try:
        before = len(r.robot.events)
        execute = SVR_FBS[fb][0]
        rows = []
        for n in range(2500):
            r.write(execute, n == 0)
            r.scans(1)
            rows.append((r.read(f"{fb}.Done"), r.read(f"{fb}.Busy"), r.read(f"{fb}.Error")))
        assert [d for d, _, _ in rows].count(True) == 1 and not any(e for _, _, e in rows), rows[:5]
        done_at = [d for d, _, _ in rows].index(True)
        assert all(b for _, b, _ in rows[:done_at]) and not any(b for _, b, _ in rows[done_at:])
        sent = [e for e in r.robot.events[before:] if e["kind"] in ("svr_write", "svr_read")]
        assert len(sent) == 1, sent
    finally:
        r.close()


def test_vision_job_and_teach_pulsed_for_one_scan_show_done_for_one_scan(vis):
    vis.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    rows = trace(vis, "vis", 1500, on_scan=lambda n: vis.write("VisExec", n == 0))
    assert [r["Done"] for r in rows].count(True) == 1 and not any(r["Error"] for r in rows)
    assert sum("Vision_DoJob" in s for s in script_frames(vis)) == 1
    r = Rig(program="Main_Jog.st")
    try:
        done = []
        for n in range(300):
            r.write("TeachExec", n == 0)
            r.scans(1)
            done.append(r.read("teach.Done"))
        assert done.count(True) == 1 and r.read("Table[1].Taught")
    finally:
        r.close()


@pytest.mark.parametrize("frames", [1, 2, 3])
@pytest.mark.parametrize("extra", [0, 1, 2])
def test_vision_job_link_lost_at_each_of_its_three_requests(vis, frames, extra):
    """The link lost after the job's script, the object count's or the object's request reached the robot (and
    0..2 scans later): Done with Found only when all three were answered, else a documented ErrorID; nothing is
    sent again when CBT_Connect has reconnected."""
    vis.set_struct("VisParam", dict(JobName="job1", Mode="VisionAtPosition", Speed=100, AccelTime=200,
                                    ObjectVariable="job1_Base_TM", ObjectIndex=0))
    vis.write("VisExec", True)
    assert vis.until(lambda: len(script_frames(vis)) >= frames, 3)
    vis.scans(extra)
    vis.robot.inject("disconnect")
    assert vis.until(lambda: not vis.read("vis.Busy"), 12)
    done, error_id = vis.read("vis.Done"), vis.read("vis.ErrorID")
    sent = len(script_frames(vis))
    vis.until(lambda: False, 3)
    assert len(script_frames(vis)) == sent <= 3
    assert sum("Vision_DoJob" in s for s in script_frames(vis)) == 1
    if done:
        assert sent == 3 and vis.read("vis.Found")
    else:
        assert vis.read("vis.Error") and vis.read("vis.ErrorDescrip") == ERRORS[error_id][:80], hex(error_id)
        assert not vis.read("vis.Found")


@pytest.mark.parametrize("lose_after_ms", [0, 300, 2500])
def test_set_output_wait_until_set_behind_a_motion_with_the_link_lost(rig, lose_after_ms):
    """A queued output with WaitUntilSet waits for its queue tag: the link lost while the motion before it runs
    ends it with a documented ErrorID unless the robot had set the output (its io event); sent once."""
    rig.set_struct("MoveParam", move_abs(**SLOW))
    rig.write("MoveExec", True)
    rig.scans(2)
    rig.set_struct("OutParam", dict(Module="EndModule", Channel=1, Value=True, WaitUntilSet=True))
    rig.write("OutExec", True)
    assert rig.until(lambda: len(script_frames(rig)) == 2, 1)
    rig.until(lambda: False, lose_after_ms / 1000)
    rig.robot.inject("disconnect")
    assert rig.until(lambda: not rig.read("dout.Busy"), 12)
    done, error_id = rig.read("dout.Done"), rig.read("dout.ErrorID")
    set_by_robot = len(rig.events("io")) == 1
    assert not done or set_by_robot, "Done without the robot setting the output"
    assert done or rig.read("dout.Error")
    if not done:
        assert rig.read("dout.ErrorDescrip") == ERRORS[error_id][:80], hex(error_id)
    rig.until(lambda: False, 3)
    assert [s for s in script_frames(rig) if "DO[1]" in s] == ['IO["EndModule"].DO[1]=1\r\nQueueTag(2)']
