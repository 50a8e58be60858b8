"""BufferMode of the motion FBs (issue 26 item 4) on the virtual PLC against the simulator over loopback. Aborting:
one script 'StopAndClearBuffer()' + the motion (TMscript 2.24 §13.4: the robot stops and clears the commands
already in its buffer; the lines after it in the same script run as usual), so nothing else runs in between; the
motion FBs whose motions were running or queued end CommandAborted (PLCopen), the aborting one goes
Busy -> Active -> Done. Buffered (the default) sends what it always sent."""
import itertools

import pytest
from rig import Rig, circ, move_abs, rel

FAR = dict(X=90, Y=0, Z=90, RX=0, RY=90, RZ=0)
BACK = dict(X=-90, Y=0, Z=90, RX=0, RY=90, RZ=0)
NEAR = dict(X=10, Y=10, Z=90, RX=0, RY=90, RZ=0)
PINS = ("Busy", "Active", "Done", "CommandAborted", "Error")


@pytest.fixture
def buf():
    r = Rig(program="Main_Buffer.st")
    yield r
    r.close()


def pins(rig, fb):
    return {p for p in PINS if rig.read(f"{fb}.{p}")}


def motions(rig, kind):
    return [e for e in rig.robot.events if e["kind"] == kind]


def start_two_long_motions(rig):
    """movers[1] runs a slow PTP, movers[2] waits behind it in the robot's queue; both non-blended."""
    rig.set_struct("MParam[1]", move_abs(TargetPosition=FAR, Speed=10))
    rig.set_struct("MParam[2]", move_abs(TargetPosition=BACK, Speed=10))
    rig.write("MExec[1]", True)
    rig.write("MExec[2]", True)
    assert rig.until(lambda: rig.read("movers[1].Active") and rig.read("movers[2].Active"), 1)
    rig.until(lambda: False, 0.5)                           # half a second into the first motion
    assert len(motions(rig, "motion_start")) == 1 and motions(rig, "motion_end") == []


def test_aborting_replaces_the_running_and_the_queued_motion(buf):
    start_two_long_motions(buf)
    buf.set_struct("MParam[3]", move_abs(TargetPosition=NEAR))
    buf.write("MMode[3]", "Aborting")
    buf.write("MExec[3]", True)
    seen = []
    assert buf.until(lambda: buf.read("movers[3].Done") or buf.read("movers[3].Error"), 20,
                     on_scan=lambda _: seen.append(tuple(frozenset(pins(buf, f"movers[{k}]")) for k in (1, 2, 3))))
    assert buf.read("movers[3].Done"), buf.read("movers[3].ErrorDescrip")
    # one frame: the stop and the motion in one script, so nothing else can run in between
    ident, script = buf.scripts_in()[-1]
    assert script.startswith('StopAndClearBuffer()\r\nPTP("JPP",10,10,90,0,90,0,50,200,0,true)\r\nQueueTag(')
    assert int(ident) == buf.read("movers[3].CmdID_Ack")
    # the replaced FBs end CommandAborted (not Done, not Error), in the scan the robot accepted the new motion
    phases = [k for k, _ in itertools.groupby(seen) if k[2]]     # from the edge on (hook runs before a scan)
    assert phases[0] == ({"Busy", "Active"}, {"Busy", "Active"}, {"Busy"})
    assert phases[1] == ({"CommandAborted"}, {"CommandAborted"}, {"Busy", "Active"})
    assert len(phases) == 2                                     # then Done (asserted above)
    # the robot ran the first motion for half a second, never the second, and the aborting one to its end
    assert [e["function"] for e in motions(buf, "motion_start")] == ["PTP", "PTP"]
    assert len(motions(buf, "motion_end")) == 1
    assert list(motions(buf, "motion_end")[-1]["joints"]) == pytest.approx([10, 10, 90, 0, 90, 0], abs=1e-6)
    assert buf.read("Cobot.QueueDepth") == 0


def test_aborting_behind_a_motion_queued_in_the_same_scan_aborts_it_too(buf):
    """Two edges in one scan: the buffered motion leaves first, in the same frame burst, and the aborting script
    behind it clears it on the robot: CommandAborted."""
    buf.set_struct("MParam[1]", move_abs(TargetPosition=FAR, Speed=10))
    buf.set_struct("MParam[3]", move_abs(TargetPosition=NEAR))
    buf.write("MMode[3]", "Aborting")
    buf.write("MExec[1]", True)
    buf.write("MExec[3]", True)
    assert buf.until(lambda: buf.read("movers[3].Done"), 20)
    assert buf.read("movers[1].CommandAborted") and not buf.read("movers[1].Done")
    assert [s.partition("\r\n")[0] for _, s in buf.scripts_in()] == ['PTP("JPP",90,0,90,0,90,0,10,200,0,true)',
                                                                      "StopAndClearBuffer()"]
    assert list(motions(buf, "motion_end")[-1]["joints"]) == pytest.approx([10, 10, 90, 0, 90, 0], abs=1e-6)


def test_aborting_with_nothing_running_is_a_normal_motion(buf):
    buf.set_struct("MParam[1]", move_abs(TargetPosition=NEAR))
    buf.write("MMode[1]", "Aborting")
    buf.write("MExec[1]", True)
    assert buf.until(lambda: buf.read("movers[1].Active"), 0.1)
    assert buf.until(lambda: buf.read("movers[1].Done"), 20)
    assert len(motions(buf, "motion_end")) == 1


def test_buffered_is_the_default_and_sends_the_motion_alone(buf):
    assert buf.read("movers[1].BufferMode") == buf.read("MMode[1]")
    start_two_long_motions(buf)
    buf.set_struct("MParam[3]", move_abs(TargetPosition=NEAR))
    buf.write("MExec[3]", True)
    assert buf.until(lambda: buf.read("movers[3].Done"), 60)
    assert buf.read("movers[1].Done") and buf.read("movers[2].Done")
    assert all("StopAndClearBuffer" not in s for _, s in buf.scripts_in())
    assert len(motions(buf, "motion_end")) == 3


def test_a_wait_queue_mark_behind_the_replaced_motions_ends_command_aborted(buf):
    start_two_long_motions(buf)
    buf.write("WaitExec", True)
    assert buf.until(lambda: buf.read("wait.Active"), 0.1)
    buf.set_struct("MParam[3]", move_abs(TargetPosition=NEAR))
    buf.write("MMode[3]", "Aborting")
    buf.write("MExec[3]", True)
    assert buf.until(lambda: buf.read("movers[3].Done"), 20)
    assert buf.read("wait.CommandAborted") and not buf.read("wait.Done")


@pytest.mark.parametrize("running,aborting,script", [
    (("movers[1]", "MExec[1]", "MParam[1]", move_abs(TargetPosition=FAR, Speed=10)),
     ("rel", "RelExec", "RelParam", "RelMode",
      rel(MovementCommand=1, DataFormat=0, TargetPosition=dict(X=5, Y=0, Z=0, RX=0, RY=0, RZ=0))),
     'StopAndClearBuffer()\r\nMove_PTP("JPP",5,0,0,0,0,0,50,200,0,false)\r\nQueueTag('),
    (("rel", "RelExec", "RelParam", rel(Speed=1)),                   # a slow 20.5 mm line down
     ("circ", "CircExec", "CircParam", "CircMode", circ()),
     'StopAndClearBuffer()\r\nCircle("CAP",417.5,-72.3,359.7,'),
], ids=["MoveRelative", "MoveCircle"])
def test_move_relative_and_circle_aborting_replace_a_running_move(buf, running, aborting, script):
    fb, execute, param, values = running
    buf.set_struct(param, values)
    buf.write(execute, True)
    assert buf.until(lambda: buf.read(f"{fb}.Active"), 1)
    buf.until(lambda: False, 0.2)
    new_fb, new_execute, new_param, mode, new_values = aborting
    buf.set_struct(new_param, new_values)
    buf.write(mode, "Aborting")
    buf.write(new_execute, True)
    assert buf.until(lambda: buf.read(f"{new_fb}.Done") or buf.read(f"{new_fb}.Error"), 20)
    assert buf.read(f"{new_fb}.Done"), buf.read(f"{new_fb}.ErrorDescrip")
    assert buf.read(f"{fb}.CommandAborted")
    assert buf.scripts_in()[-1][1].startswith(script)


@pytest.mark.parametrize("fb,exec_,mode,param,values", [
    ("movers[1]", "MExec[1]", "MMode[1]", "MParam[1]", move_abs()),
    ("rel", "RelExec", "RelMode", "RelParam", rel()),
    ("circ", "CircExec", "CircMode", "CircParam", circ()),
])
@pytest.mark.parametrize("raw", [2, -1, 32767])
def test_an_undefined_buffer_mode_is_16_1030_and_nothing_is_sent(buf, fb, exec_, mode, param, values, raw):
    buf.set_struct(param, values)
    buf.write(mode, raw, raw=True)
    out = buf.read("Cobot.FramesOut")
    buf.write(exec_, True)
    buf.scans(1)                                            # the scan of the rising edge
    assert buf.read(f"{fb}.Error") and buf.read(f"{fb}.ErrorID") == 0x1030
    assert buf.read(f"{fb}.ErrorDescrip") == "BufferMode invalid: Buffered or Aborting"
    buf.scans(5)
    assert buf.read("Cobot.FramesOut") == out and buf.scripts_in() == []


def test_aborting_while_a_stop_holds_the_robot_is_16_4005(buf):
    buf.write("StopExec", True)
    assert buf.until(lambda: buf.read("stop.Done"), 1)
    buf.write("MMode[1]", "Aborting")
    buf.set_struct("MParam[1]", move_abs(TargetPosition=NEAR))
    buf.write("MExec[1]", True)
    buf.scans(1)
    assert buf.read("movers[1].Error") and buf.read("movers[1].ErrorID") == 0x4005
    assert [s for _, s in buf.scripts_in()] == ["StopAndClearBuffer()"]


def test_without_a_connection_it_is_16_2001():
    r = Rig(program="Main_Buffer.st", connect=False)
    try:
        r.write("MMode[1]", "Aborting")
        r.write("MExec[1]", True)
        r.scans(1)
        assert r.read("movers[1].Error") and r.read("movers[1].ErrorID") == 0x2001
    finally:
        r.close()


def test_the_parameters_and_the_mode_are_latched_at_the_rising_edge(buf):
    """R4: BufferMode changed while Busy changes nothing of the command under way."""
    buf.set_struct("MParam[1]", move_abs(TargetPosition=NEAR))
    buf.write("MExec[1]", True)
    buf.scans(1)
    buf.write("MMode[1]", "Aborting")
    assert buf.until(lambda: buf.read("movers[1].Done"), 20)
    assert [s for _, s in buf.scripts_in()] == ['PTP("JPP",10,10,90,0,90,0,50,200,0,true)\r\nQueueTag(1)']
