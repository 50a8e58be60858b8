"""Regenerates the timing diagrams of docs/library/*.md from real runs (virtual PLC + simulator).

    PYTHONPATH=src:. python docs/library/make_traces.py
"""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1] / "src"), str(HERE.parents[1]), str(HERE.parents[1] / "tests" / "lib")]

from rig import Rig, move_abs  # noqa: E402
from vplc.trace.recorder import Recorder, write_trace  # noqa: E402

OUT = HERE / "traces"
PINS = ("Execute", "Busy", "Active", "Done", "CommandAborted", "Error")


def record(rig, paths, steps, name):
    rec = Recorder(rig.plc, ["Main." + p for p in paths])
    rig.until(lambda: rec.sample() and False, 0.005)
    for action, seconds in steps:
        if action:
            action()
        rig.until(lambda: rec.sample() and False, seconds)
    write_trace(rec, str(OUT / name))


def fb_paths(fb, exec_var, active=True):
    return [exec_var] + [f"{fb}.{p}" for p in PINS[1:] if active or p != "Active"] + [f"{fb}.ErrorID"]


def main():
    OUT.mkdir(exist_ok=True)
    r = Rig(connect=False)
    record(r, ["ConnExec", "conn.Busy", "conn.Connected", "conn.Error", "Cobot.InListenNode", "Cobot.QueueDepth"],
           [(lambda: r.write("ConnExec", True), 0.05), (lambda: r.write("ConnExec", False), 0.02)], "connect.svg")
    r.close()

    r = Rig()
    r.set_struct("MoveParam", move_abs(TargetPosition=dict(X=10, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    record(r, fb_paths("mover", "MoveExec"),
           [(lambda: r.write("MoveExec", True), 0.05), (lambda: r.write("MoveExec", False), 0.3)],
           "move_absolute_non_blended.svg")
    r.set_struct("MoveParam", move_abs(BlendingEnable=True, BlendingValue=50))
    record(r, fb_paths("mover", "MoveExec"),
           [(lambda: r.write("MoveExec", True), 0.02), (lambda: r.write("MoveExec", False), 0.01)],
           "move_absolute_blended.svg")
    r.set_struct("MoveParam", move_abs(Speed=0))
    record(r, fb_paths("mover", "MoveExec"),
           [(lambda: r.write("MoveExec", True), 0.01), (lambda: r.write("MoveExec", False), 0.01)],
           "move_absolute_error.svg")
    r.close()

    r = Rig()
    r.set_struct("MParam[1]", move_abs(Speed=20, TargetPosition=dict(X=40, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    r.set_struct("StopParam", dict(Mode=1))
    record(r, ["MExec[1]", "movers[1].Busy", "movers[1].Active", "movers[1].CommandAborted",
               "StopExec", "stop.Busy", "stop.Done", "Cobot.Stopping"],
           [(lambda: r.write("MExec[1]", True), 0.1), (lambda: r.write("StopExec", True), 0.03),
            (lambda: (r.write("StopExec", False), r.write("MExec[1]", False)), 0.02)], "stop.svg")
    r.set_struct("MParam[2]", move_abs(Speed=20, TargetPosition=dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=0)))
    record(r, ["MExec[2]", "movers[2].Busy", "movers[2].Active", "movers[2].Done", "PrgExec", "prg.Done",
               "PrgParam.Command"],
           [(lambda: r.write("MExec[2]", True), 0.1),
            (lambda: (r.write("PrgParam.Command", 0), r.write("PrgExec", True)), 0.3),
            (lambda: r.write("PrgExec", False), 0.01),
            (lambda: (r.write("PrgParam.Command", 1), r.write("PrgExec", True)), 0.6)], "program_control.svg")
    record(r, ["ReadEnable", "rd.Busy", "rd.Valid", "rd.Error", "rd.Position.TCP.X"],
           [(lambda: r.write("ReadEnable", True), 0.03), (lambda: r.write("ReadEnable", False), 0.01)],
           "read_actual_position.svg")
    r.close()
    print("traces written to", OUT)


if __name__ == "__main__":
    main()
