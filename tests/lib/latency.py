"""Latency measurements in scans (issue 6), shared by tests/lib/test_lib_latency.py and bench/bench_lib.py.

A scan here is what the rig does once per 1 ms tick: the simulator is polled (it reads what the PLC sent and
writes its replies), then the PLC scans. The "user" (this module) reads outputs after a scan and writes
Execute before the next one, as user logic after the FB calls would.
Programs: Main_Bench.st (documented order: command FBs, then CBT_Connect) and Main_BenchTwice.st (fast
order: CBT_Connect, command FBs, CBT_Connect again).
"""
from rig import move_abs

ORDERS = {"documented": "Main_Bench.st", "twice": "Main_BenchTwice.st"}


def scan(r):
    now = r.plc.now_ns + r.plc.period_ns
    r.pump(now)
    r.plc.scan(now)


def settle(r, k=1):
    """Execute of mover k off and the FB idle."""
    r.write(f"MExec[{k}]", False)
    scan(r)
    scan(r)


def execute_to_socket(r, k=1):
    """Scans from the scan that sees the rising edge to the scan in which the frame is handed to SktTCPSend
    (0 = the edge scan itself)."""
    r.set_struct(f"MParam[{k}]", move_abs(BlendingEnable=True))
    before = r.read("Cobot.FramesOut")
    r.write(f"MExec[{k}]", True)
    n = 0
    while r.read("Cobot.FramesOut") == before:
        scan(r)
        n += 1
    while not r.read(f"movers[{k}].Done"):
        scan(r)
    settle(r, k)
    return n - 1


def reply_to_done(r, k=1):
    """Scans from the scan in whose input phase the robot's reply was on the socket (the simulator wrote it
    in the poll before that scan) to the scan in which the FB shows Done (0 = the same scan)."""
    r.set_struct(f"MParam[{k}]", move_abs(BlendingEnable=True))
    n_out = len(r.events("frame_out"))
    r.write(f"MExec[{k}]", True)
    seen, i = None, 0
    while not r.read(f"movers[{k}].Done"):
        scan(r)
        i += 1
        if seen is None and any(e.get("header") == "TMSCT" for e in r.events("frame_out")[n_out:]):
            seen = i
    settle(r, k)
    return i - seen


def sustained(r, instances=1, pulse=False, count=200):
    """Blended absolute moves re-triggered as fast as the user logic allows; returns scans per command for
    the robot, all instances together (one instance: value x ``instances``).

    held  : Execute TRUE until Done is seen, FALSE for one scan, TRUE again (the usual PLCopen handshake);
    pulse : Execute TRUE for the edge scan only, FALSE while the command runs (PLCopen allows resetting
            Execute while Busy: Done then shows for exactly one scan), TRUE again after that Done.
    """
    ks = range(1, instances + 1)
    for k in ks:
        r.set_struct(f"MParam[{k}]", move_abs(BlendingEnable=True))
        r.write(f"MExec[{k}]", False)
    scan(r)
    scan(r)
    for k in ks:
        r.write(f"MExec[{k}]", True)
    stamps = []                                       # scan time of every Done
    while len(stamps) < count + 1:
        scan(r)
        for k in ks:
            ex = r.read(f"MExec[{k}]")
            if r.read(f"movers[{k}].Done"):
                stamps.append(r.plc.now_ns)
                r.write(f"MExec[{k}]", pulse)       # pulse: next edge now; held: one scan FALSE first
            elif r.read(f"movers[{k}].Error") or r.read(f"movers[{k}].CommandAborted"):
                raise AssertionError(f"movers[{k}]: {r.read(f'movers[{k}].ErrorDescrip')}")
            elif pulse and ex:
                r.write(f"MExec[{k}]", False)       # the edge was seen: reset Execute while Busy
            elif not ex and not r.read(f"movers[{k}].Busy"):
                r.write(f"MExec[{k}]", True)
    scans = (stamps[count] - stamps[0]) / r.plc.period_ns     # steady state: first Done to last Done
    for k in ks:
        r.write(f"MExec[{k}]", False)
    scan(r)
    scan(r)
    return scans / count
