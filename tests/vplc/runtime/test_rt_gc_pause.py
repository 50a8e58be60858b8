"""Each engine owns the gc callback that keeps Python's collector pauses out of its watchdog (runtime/engine.py):
it is registered with the engine, credits only a scan in progress, and goes away with the engine."""
import gc
import math

from vplc.runtime.engine import gc_pause_callback


def test_a_collection_moves_the_deadline_of_a_scan_in_progress_only():
    scanning, idle = [100.0], [math.inf]
    probation = [100.0, 0.0]                     # a probation this scan started: it moves with the deadline
    callbacks = [gc_pause_callback(scanning, probation), gc_pause_callback(idle, [math.nan, 0.0])]
    for cb in callbacks:
        cb("start", {})
    for cb in callbacks:
        cb("stop", {})
    assert scanning[0] > 100.0 and probation[0] == scanning[0]
    assert idle[0] == math.inf


def test_the_callback_goes_away_with_its_engine(tmp_path):
    from rt_helpers import plc_from
    gc.collect()
    before = len(gc.callbacks)
    plc = plc_from(tmp_path, "n := n + 1;", "n : INT;")
    assert len(gc.callbacks) == before + 1
    plc.scan(0)
    plc.close()
    del plc
    gc.collect()
    assert len(gc.callbacks) == before
