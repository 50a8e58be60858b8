"""Statements per scan of the vision pick example (examples/vision_pick/VisionPick: 15 library FB instances,
CBT_Connect with the Ethernet Slave, the cell's step machine) on the virtual PLC (1 ms task) against the
simulator, on virtual time: idle (connected, Start not given) and over a whole cell of 3 parts found by the camera
(the test's table plays the part-present sensor).

    make bench       (or: PYTHONPATH=tests/examples .venv/bin/python bench/bench_vision_pick.py)

Idle is the mean of 2,000 scans (the Enable FBs copy a data table once per 100 scans, so a median would hide it);
the cell's figures are the mean and the largest scan from Start to Done.
"""
import statistics

from test_vision_pick import PARTS, SEC, Cell  # the test's cell: simulator, camera, table (make bench finds it)


def per_scan(cell, pred, seconds):
    """Statements of each scan until pred() holds (or seconds of virtual time have run)."""
    counts, last = [], [None]

    def hook(_now_ns):
        now = cell.plc.statements_executed
        if last[0] is not None:
            counts.append(now - last[0])
        last[0] = now

    cell.run_until(pred, seconds, on_scan=hook)
    return counts


def main():
    cell = Cell(PARTS, count_statements=True)
    try:
        assert cell.run_until(lambda: cell.read("fbConnect.Connected") and cell.read("fbIO.Valid"), 5)
        cell.run_until(lambda: False, 0.3)                  # past the first data tables
        idle = per_scan(cell, lambda: False, 2.0)
        cell.plc.write("VisionPick.Start", True)
        running = per_scan(cell, lambda: cell.read("Done") or cell.read("Error"), 120)
        assert cell.read("Done") and cell.read("Picked") == 3, cell.read("ErrorText")
    finally:
        cell.close()
    print("Statements per scan of examples/vision_pick (VisionPick, 1 ms task, simulator on virtual time)")
    print(f"  idle, connected, Start not given   mean {statistics.fmean(idle):7.1f}   over {len(idle)} scans")
    print(f"  cell of 3 parts, Start to Done     mean {statistics.fmean(running):7.1f}   largest {max(running)}"
          f"   over {len(running)} scans ({len(running) / (SEC / cell.plc.period_ns):.1f} s)")


if __name__ == "__main__":
    main()
