"""Runtime faults stop the controller with the ST location, instance path and values; never a traceback."""
import pytest
from rt_helpers import plc_from

from vplc.api import PlcFault

FB = """
FUNCTION_BLOCK Divider
VAR_INPUT d : INT; END_VAR
VAR_OUTPUT q : INT; END_VAR
    q := 100 / d;
END_FUNCTION_BLOCK
"""


def test_division_by_zero_names_file_line_instance_and_values(tmp_path):
    plc = plc_from(tmp_path, "div(d := z);", "div : Divider; z : INT;", FB)
    with pytest.raises(PlcFault) as ei:
        plc.scan(0)
    msg = str(ei.value)
    assert "main.st:11:" in msg and "Main.div" in msg and "(100 / 0)" in msg
    assert "Traceback" not in msg and ".py" not in msg
    assert ei.value.line == 11 and ei.value.instance == "Main.div"


def test_index_out_of_range_reports_index_and_bounds(tmp_path):
    plc = plc_from(tmp_path, "a[i] := 1;", "a : ARRAY[1..4] OF INT; i : INT := 5;")
    with pytest.raises(PlcFault, match=r"index 5 out of range 1\.\.4 of a"):
        plc.scan(0)



def test_a_computed_index_is_evaluated_once_and_out_of_range_reports_its_value(tmp_path):
    extra = "FUNCTION Next : INT\nVAR_IN_OUT n : INT; END_VAR\nn := n + 1; Next := n;\nEND_FUNCTION\n"
    plc = plc_from(tmp_path, "a[i + 1] := a[Next(k) - 1] + 10; IF go THEN b := a[i * 3]; END_IF;",
                   "a : ARRAY[1..4] OF INT := [1, 2, 3, 4]; b, i : INT := 1; k : INT := 2; go : BOOL;", extra=extra)
    plc.scan(0)
    assert plc.read("Main.a") == [1, 12, 3, 4] and plc.read("Main.k") == 3     # Next ran once: a[2] read
    plc.write("Main.go", True)
    plc.write("Main.i", 2)
    with pytest.raises(PlcFault, match=r"index 6 out of range 1\.\.4 of a"):
        plc.scan(1_000_000)

def test_endless_while_trips_the_watchdog(tmp_path):
    plc = plc_from(tmp_path, "WHILE TRUE DO n := n + 1; END_WHILE;", "n : DINT;", watchdog_ms=50)
    with pytest.raises(PlcFault, match="watchdog") as ei:
        plc.scan(0)
    assert ei.value.kind == "watchdog"


def test_a_faulted_controller_stays_stopped(tmp_path):
    plc = plc_from(tmp_path, "n := n / z;", "n, z : INT;")
    with pytest.raises(PlcFault):
        plc.scan(0)
    with pytest.raises(PlcFault):
        plc.scan(1_000_000)


def test_scan_time_going_backwards_is_rejected(tmp_path):
    plc = plc_from(tmp_path, "n := n + 1;", "n : INT;")
    plc.scan(5_000_000)
    with pytest.raises(ValueError, match="backwards"):
        plc.scan(1_000_000)


def _pausing(plc, seconds, how):
    """Make the program spend ``seconds`` of wall time before its body: ``gc`` (reported as a collection) or
    ``sleep`` (the thread waits: a host busy with other work)."""
    import gc
    import time
    task = plc.engine.tasks[0]
    inst, body = task.programs[0]

    def paused(s):
        if how == "gc":
            for callback in gc.callbacks:
                callback("start", {})
        time.sleep(seconds)
        if how == "gc":
            for callback in gc.callbacks:
                callback("stop", {})
        body(s)
    task.programs[0] = (inst, paused)


def test_a_garbage_collection_during_a_scan_does_not_count_against_the_watchdog(tmp_path):
    """The watchdog guards the program; a pause of Python's collector (host time) moves the deadline."""
    plc = plc_from(tmp_path, "FOR i := 1 TO 10 DO n := n + 1; END_FOR;", "n, i : INT;", watchdog_ms=50)
    _pausing(plc, 0.2, "gc")                                   # a 200 ms collection inside a 50 ms watchdog
    plc.scan(0)
    assert plc.read("Main.n") == 10


def test_a_host_busy_with_other_work_does_not_trip_the_watchdog(tmp_path):
    """Only the scan's own CPU time counts: 200 ms of wall time in which the scan's thread did not run (a loaded
    CI machine, parallel tests) is not an endless loop."""
    plc = plc_from(tmp_path, "FOR i := 1 TO 100 DO n := n + 1; END_FOR;", "n, i : INT;", watchdog_ms=50)
    _pausing(plc, 0.2, "sleep")
    plc.scan(0)
    assert plc.read("Main.n") == 100


def test_an_endless_loop_that_started_late_still_trips_the_watchdog(tmp_path):
    """Wall time first starts a probation; the program's own CPU time then faults it: an endless loop in a scan
    that began 200 ms late (the host busy) still ends with the watchdog, at most twice the limit of CPU later."""
    plc = plc_from(tmp_path, "WHILE TRUE DO n := n + 1; END_WHILE;", "n : DINT;", watchdog_ms=50)
    _pausing(plc, 0.2, "sleep")
    with pytest.raises(PlcFault, match="watchdog"):
        plc.scan(0)
