"""Contract A surface: load errors, read/write checks, var_type, run_until, run_realtime, lock."""
import threading

import pytest
from rt_helpers import plc_from

from vplc.api import LoadError, load_plc

TYPES = """
TYPE eMode : (Off, Auto); stP : STRUCT X : REAL; Name : STRING[8]; END_STRUCT; END_TYPE
"""


def test_load_error_renders_diagnostics(tmp_path):
    p = tmp_path / "bad.st"
    p.write_text("PROGRAM Main\nVAR x : INT; END_VAR\nx := y;\nEND_PROGRAM\n")
    with pytest.raises(LoadError, match=r"bad\.st:3:6: error\[ST"):
        load_plc([str(p)])


def test_bad_task_specification_is_a_load_error(tmp_path):
    with pytest.raises(LoadError, match="Name@period"):
        plc_from(tmp_path, "", "x : INT;", task="Main")


def test_write_is_type_checked(tmp_path):
    plc = plc_from(tmp_path, "", "i : INT; b : BOOL; s : STRING[4]; m : eMode; p : stP;", TYPES)
    with pytest.raises(ValueError, match="outside the range"):
        plc.write("Main.i", 40000)
    with pytest.raises(ValueError, match="BOOL"):
        plc.write("Main.b", 1)
    with pytest.raises(ValueError, match="at most 3"):
        plc.write("Main.s", "abcd")
    with pytest.raises(ValueError, match="members one by one"):
        plc.write("Main.p", {})
    plc.write("Main.m", "Auto")
    plc.write("Main.p.X", 1)
    assert plc.read("Main.m") == "Auto" and plc.read("Main.p") == {"X": 1.0, "Name": ""}
    with pytest.raises(ValueError, match="is not a variable of Main"):
        plc.read("Main.nope")


def test_var_type_names_iec_types(tmp_path):
    plc = plc_from(tmp_path, "", "s : STRING[50]; p : stP; a : ARRAY[1..3] OF INT;", TYPES)
    assert plc.var_type("Main.s") == "STRING[50]"
    assert plc.var_type("Main.p") == "stP"
    assert plc.var_type("Main.a[2]") == "INT"


def test_run_until_calls_on_scan_before_each_scan_and_stops_on_the_predicate(tmp_path):
    plc = plc_from(tmp_path, "n := n + 1;", "n : INT;")
    seen = []
    assert plc.run_until(lambda: plc.read("Main.n") == 3, 10_000_000, on_scan=seen.append)
    assert seen == [0, 1_000_000, 2_000_000] and plc.now_ns == 2_000_000
    assert not plc.run_until(lambda: False, 3_000_000)
    assert plc.now_ns == 5_000_000


def test_run_realtime_scans_until_the_stop_event(tmp_path):
    plc = plc_from(tmp_path, "n := n + 1;", "n : DINT;")
    stop = threading.Event()

    def on_scan(now):
        with plc.lock:
            if plc.read("Main.n") >= 5:
                stop.set()
    th = threading.Thread(target=plc.run_realtime, args=(stop,), kwargs={"on_scan": on_scan})
    th.start()
    th.join(10)
    assert not th.is_alive()
    assert plc.read("Main.n") >= 5


def test_raw_write_puts_an_undefined_value_into_an_enumeration(tmp_path):
    body = "CASE m OF Off: k := 1; Auto: k := 2; ELSE k := 99; END_CASE;"
    plc = plc_from(tmp_path, body, "m : eMode; k : INT; i : INT;", TYPES)
    with pytest.raises(ValueError, match="cannot write 7"):
        plc.write("Main.m", 7)                          # checked write: only declared values
    plc.write("Main.m", 7, raw=True)
    plc.scan(0)
    assert plc.read("Main.m") == 7 and plc.read("Main.k") == 99   # read back as the bare integer
    plc.write("Main.m", 1, raw=True)
    plc.scan(1_000_000)
    assert plc.read("Main.m") == "Auto" and plc.read("Main.k") == 2
    with pytest.raises(ValueError, match="takes an integer"):
        plc.write("Main.m", "Auto", raw=True)
    with pytest.raises(ValueError, match="outside the range"):
        plc.write("Main.m", 40000, raw=True)            # still within the storage type (INT)
    with pytest.raises(ValueError, match="outside the range"):
        plc.write("Main.i", 40000, raw=True)            # other types keep their normal checks


def test_reading_through_the_program_type_name_points_to_the_configured_instance(tmp_path):
    config = """CONFIGURATION Cfg
    RESOURCE R ON PLC
        TASK Fast (INTERVAL := T#1ms, PRIORITY := 1);
        PROGRAM Cell1 WITH Fast : Main;
    END_RESOURCE
END_CONFIGURATION
"""
    plc = plc_from(tmp_path, "n := n + 1;", "n : INT;", config)
    plc.scan(0)
    assert plc.read("Cell1.n") == 1
    with pytest.raises(ValueError, match=r"`Main` is a PROGRAM type; the configuration runs it as the instance "
                                         r"`Cell1`: use `Cell1\.n`"):
        plc.read("Main.n")
    with pytest.raises(ValueError, match="PROGRAM type"):
        plc.write("Main.n", 5)


def test_a_path_read_again_follows_the_program_and_a_bad_path_fails_every_time(tmp_path):
    """Paths are parsed once and walked at every read: values, array elements and references passed to a
    VAR_IN_OUT follow the program; a wrong path or index gives the same error on every attempt."""
    extra = """
FUNCTION_BLOCK Fb
VAR_IN_OUT r : INT; END_VAR
VAR_OUTPUT seen : INT; END_VAR
seen := r;
END_FUNCTION_BLOCK
"""
    plc = plc_from(tmp_path, """
n := n + 1;
a[n MOD 3] := n;
IF n MOD 2 = 1 THEN fb(r := x); ELSE fb(r := y); END_IF;
""", "n : INT; a : ARRAY[0..2] OF INT; x : INT := 10; y : INT := 20; fb : Fb; m : eMode; p : stP;", extra + TYPES)
    seen = []
    for now in range(0, 4_000_000, 1_000_000):
        plc.scan(now)
        seen.append((plc.read("Main.n"), plc.read("Main.a[1]"), plc.read("Main.fb.r"), plc.read("Main.fb.seen")))
    assert seen == [(1, 1, 10, 10), (2, 1, 20, 20), (3, 1, 10, 10), (4, 4, 20, 20)]
    plc.write("Main.m", "Auto")
    plc.write("Main.p.Name", "ab")
    assert plc.read("Main.m") == "Auto" and plc.read("Main.p") == {"X": 0.0, "Name": "ab"}
    plc.write("Main.m", "Off")
    assert plc.read("Main.m") == "Off"
    for _ in range(2):
        with pytest.raises(ValueError, match="is not a variable of Main"):
            plc.read("Main.nope")
        with pytest.raises(ValueError, match=r"index|range"):
            plc.read("Main.a[7]")
        with pytest.raises(ValueError, match="not a list of integers"):
            plc.read("Main.a[x]")
