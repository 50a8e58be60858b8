"""Benchmarks of the CBT_Commands_Lib function blocks on the virtual PLC (1 ms task) against the simulator.

    PYTHONPATH=src:. python bench/bench_lib.py

Figures (issue 6): scans from Execute to the frame handed to the socket, scans from reply bytes to Done,
sustained blended commands per FB instance, library cost per scan with 7 idle / 7 busy FBs.
"""
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "src"), str(ROOT), str(ROOT / "tests" / "lib")]

from rig import Rig, move_abs  # noqa: E402


def scan(r):
    now = r.plc.now_ns + r.plc.period_ns
    r.pump(now)
    r.plc.scan(now)


def execute_to_socket(r):
    r.set_struct("MParam[1]", move_abs(BlendingEnable=True))
    before = r.read("Cobot.FramesOut")
    r.write("MExec[1]", True)
    n = 0
    while r.read("Cobot.FramesOut") == before:
        scan(r)
        n += 1
    return n - 1          # 0 = the scan that saw the rising edge


def reply_to_done(r):
    """Scans between the scan in whose input phase the robot's reply was on the socket and the scan
    in which the FB shows Done."""
    seen = None
    k = 0
    n_out = len(r.events("frame_out"))
    while not r.read("movers[1].Done"):
        scan(r)
        k += 1
        if seen is None and any(e.get("header") == "TMSCT" for e in r.events("frame_out")[n_out:]):
            seen = k
    r.write("MExec[1]", False)
    scan(r)
    return k - seen


def sustained(r, count=200):
    start = r.plc.now_ns
    done = 0
    while done < count:
        r.set_struct("MParam[1].TargetPosition", dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=float(done % 20)))
        r.write("MExec[1]", True)
        while not r.read("movers[1].Done"):
            scan(r)
        r.write("MExec[1]", False)
        scan(r)
        done += 1
    return (r.plc.now_ns - start) / r.plc.period_ns / count


def sustained_rotating(r, count=400):
    """Four FB instances, each re-triggered as soon as it is Done: commands per scan for one robot."""
    for k in range(1, 5):
        r.set_struct(f"MParam[{k}]", move_abs(BlendingEnable=True))
        r.write(f"MExec[{k}]", False)
    scan(r)
    start = r.plc.now_ns
    done = 0
    while done < count:
        for k in range(1, 5):
            if r.read(f"movers[{k}].Done"):
                done += 1
                r.write(f"MExec[{k}]", False)
            elif not r.read(f"movers[{k}].Busy"):
                r.write(f"MExec[{k}]", True)
        scan(r)
    return (r.plc.now_ns - start) / r.plc.period_ns / count


def cost(r, n=400):
    times, stmts = [], []
    for _ in range(n):
        now = r.plc.now_ns + r.plc.period_ns
        r.pump(now)
        c0 = r.plc.statements_executed
        t0 = time.perf_counter_ns()
        r.plc.scan(now)
        times.append((time.perf_counter_ns() - t0) / 1000)
        stmts.append(r.plc.statements_executed - c0)
    return statistics.median(times), statistics.median(stmts)


def main():
    r = Rig(program="Main_Bench.st")
    try:
        print("CBT_Commands_Lib benchmarks (virtual PLC, 1 ms task, simulator on loopback)")
        print(f"  Execute rising -> frame handed to SktTCPSend : {execute_to_socket(r)} scan(s) after the edge scan")
        print(f"  reply on the socket -> FB Done              : {reply_to_done(r)} scan(s)")
        print(f"  sustained blended commands, one FB instance  : one per {sustained(r):.2f} scans")
        print(f"  sustained blended commands, 4 FB instances   : one per {sustained_rotating(r):.2f} scans (per robot)")
    finally:
        r.close()
    r = Rig(program="Main_Bench.st", load_args=dict(count_statements=True))
    plc = r.plc
    try:
        idle_us, idle_st = cost(r)
        for k in range(1, 5):
            r.set_struct(f"MParam[{k}]", move_abs(Speed=5, TargetPosition=dict(X=60.0 + k, Y=0, Z=90, RX=0, RY=90, RZ=0)))
            r.write(f"MExec[{k}]", True)
        r.set_struct("RelParam", dict(MovementCommand=0, DataFormat=1, Speed=5, AccelTime=200,
                                      TargetPosition=dict(X=0, Y=0, Z=-10, RX=0, RY=0, RZ=0)))
        r.write("RelExec", True)
        r.write("BaseExec", True)
        r.write("PrgParam.Command", 1)
        r.write("PrgExec", True)
        scan(r)
        busy_us, busy_st = cost(r)
        print(f"  library cost per scan, 7 idle FBs + Connect  : {idle_us:.0f} us, {idle_st:.0f} statements (median)")
        print(f"  library cost per scan, 7 busy FBs + Connect  : {busy_us:.0f} us, {busy_st:.0f} statements (median)")
    finally:
        r.close()


if __name__ == "__main__":
    main()
