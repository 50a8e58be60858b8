"""Statements per scan of the issue 26 function blocks (CBT_ReadIO, CBT_SetOverride, CBT_WaitQueue, the motion
status of CBT_RobotStatus, CBT_ReadVariable, CBT_WriteVariable, an aborting CBT_MoveAbsolute, CBT_Jog,
CBT_Teach, CBT_VisionJob) against an idle CBT_MoveAbsolute, on the virtual PLC (1 ms task) with the simulator's
Listen node and Ethernet Slave (data table every 100 ms).

    PYTHONPATH=tests/lib .venv/bin/python bench/bench_cell.py

Each figure is one FB instance: (CBT_Connect + the FB) minus CBT_Connect alone, both connected, the Ethernet
Slave streaming; mean over 2,000 scans (an Enable FB copies a data table once per 100 scans, so the median would
hide that). Target (issue 26): every new FB idle <= an idle CBT_MoveAbsolute.
"""
import statistics
import tempfile
from pathlib import Path

from rig import Rig

HEAD = """PROGRAM Main
VAR
    Cobot : stCBT_Connection;
    Port : UINT;
    SvrPort : UINT;
    ConnExec : BOOL;
    conn : CBT_Connect;
    On : BOOL;
    MoveParam : stCBT_MovAbsParam;
    Variable : stCBT_Variable;
    Point : stCBT_TeachPoint;
    VisParam : stCBT_VisionParam;
    fb : {fb};
END_VAR
"""
CALLS = {
    "CBT_MoveAbsolute": "fb(CBT := Cobot, Execute := On, Parameters := MoveParam);",
    "CBT_WaitQueue": "fb(CBT := Cobot, Execute := On);",
    "CBT_SetOverride": "fb(CBT := Cobot, Execute := On, Override := 50);",
    "CBT_ReadIO": "fb(CBT := Cobot, Enable := On);",
    "CBT_RobotStatus": "fb(CBT := Cobot, Enable := On);",
    "CBT_ReadVariable": "fb(CBT := Cobot, Variable := Variable, Execute := On);",
    "CBT_WriteVariable": "fb(CBT := Cobot, Variable := Variable, Execute := On);",
    "CBT_MoveAbsolute Aborting": "fb(CBT := Cobot, Execute := On, Parameters := MoveParam, "
                                 "BufferMode := eCBT_BufferMode#Aborting);",
    "CBT_Jog": "fb(CBT := Cobot, JogForward := On, JogBackward := FALSE, Frame := eCBT_JogFrame#JogBase, Axis := 3, "
               "Velocity := 10);",
    "CBT_Teach": "fb(CBT := Cobot, Execute := On, Name := 'P1', Point := Point);",
    "CBT_VisionJob": "fb(CBT := Cobot, Execute := On, Parameters := VisParam);",
}
TAIL = """conn(CBT := Cobot, Execute := ConnExec, IPAddress := '127.0.0.1', IPPort := Port, Time_Out := 10,
     SvrPort := SvrPort);
END_PROGRAM
"""


def program(folder: Path, fb: str | None) -> str:
    path = folder / f"Main_{(fb or 'Connect').replace(' ', '_')}.st"
    if fb is None:
        text = HEAD.replace("    fb : {fb};\n", "") + TAIL
    else:
        text = HEAD.format(fb=fb.split()[0]) + CALLS[fb] + "\n" + TAIL
    path.write_text(text, encoding="utf-8")
    return str(path)


def mean_statements(rig, n=2000):
    counts = []
    for _ in range(n):
        now = rig.plc.now_ns + rig.plc.period_ns
        rig.pump(now)
        c0 = rig.plc.statements_executed
        rig.plc.scan(now)
        counts.append(rig.plc.statements_executed - c0)
    return statistics.fmean(counts)


def measure(source: str, enable: bool) -> float:
    rig = Rig(program=source, svr_port=0, load_args=dict(count_statements=True))
    try:
        rig.write("On", enable)
        rig.until(lambda: rig.read("Cobot.Status.SlaveLink"), 1)
        rig.until(lambda: False, 0.3)                  # past the first data tables
        return mean_statements(rig)
    finally:
        rig.close()


def main():
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        base = measure(program(folder, None), False)
        rows = [("CBT_MoveAbsolute", "idle (Execute FALSE)", measure(program(folder, "CBT_MoveAbsolute"), False))]
        for fb in ("CBT_MoveAbsolute Aborting", "CBT_WaitQueue", "CBT_SetOverride", "CBT_ReadVariable",
                   "CBT_WriteVariable", "CBT_Teach", "CBT_VisionJob"):
            rows.append((fb, "idle (Execute FALSE)", measure(program(folder, fb), False)))
        rows.append(("CBT_Jog", "idle (not held)", measure(program(folder, "CBT_Jog"), False)))
        for fb in ("CBT_ReadIO", "CBT_RobotStatus"):
            rows.append((fb, "Enable FALSE", measure(program(folder, fb), False)))
            rows.append((fb, "Enable TRUE, Valid", measure(program(folder, fb), True)))
    target = rows[0][2] - base
    print("Statements per scan of one FB instance (mean of 2,000 scans, CBT_Connect with Ethernet Slave subtracted: "
          f"{base:.1f})")
    for fb, state, total in rows:
        own = total - base
        mark = "ok " if own <= target + 1e-9 else "-- "
        print(f"  {fb:<27}{state:<24}{own:6.2f}  {mark}(target <= idle CBT_MoveAbsolute {target:.2f})")


if __name__ == "__main__":
    main()
