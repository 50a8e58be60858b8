"""The Sysmac system-defined variables are a hook of the scan loop (runtime/sysmac_system.py), not code of the
generic engine: a PLC whose globals hold them gets the hook, one without them scans with none."""
from vplc.runtime import sysmac_system


class _NoSystemVariables:
    i__vars = {"SPEED": ("Speed", None)}


def test_globals_without_system_variables_get_no_hook():
    assert sysmac_system.task_hook(object(), _NoSystemVariables()) is None


def test_the_hook_sets_current_time_first_run_and_pulses_before_each_task_execution(tmp_path):
    from rt_helpers import plc_from
    plc = plc_from(tmp_path, "IF P_First_Run THEN runs := runs + 1; END_IF; t := _CurrentTime;",
                   "runs : INT; t : DATE_AND_TIME;", clock_base_ns=5_000_000_000)
    try:
        assert plc.engine.before_task is not None
        plc.scan(0)
        plc.scan(30_000_000)
        assert plc.read("Main.runs") == 1
        assert plc.read("Main.t") == 5_030_000_000                 # the clock base plus the scan time
        assert plc.read("P_0_02s") is False and plc.read("P_0_1s") is True   # 30 ms into 20 ms / 100 ms periods
    finally:
        plc.close()
