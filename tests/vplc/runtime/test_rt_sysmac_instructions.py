"""W502 instructions beyond sockets and byte arrays (docs/toolchain/runtime_sysmac.md), with documented values."""
import struct

from rt_helpers import plc_from, run1

from vplc.api import load_plc


def test_enum_to_num_gives_the_number_of_the_value(tmp_path):
    plc = run1(tmp_path, "n := EnumToNum(c); m := EnumToNum(eColor#Red);", "c : eColor := Blue; n, m : DINT;",
               "TYPE eColor : (Red, Green := 5, Blue); END_TYPE\n")
    assert plc.read("Main.n") == 6 and plc.read("Main.m") == 0


def test_ary_move_copies_size_elements_from_the_elements_given(tmp_path):
    plc = run1(tmp_path, "ok := AryMove(a[1], b[2], 3);",
               "a : ARRAY[0..4] OF INT := [1, 2, 3, 4, 5]; b : ARRAY[1..6] OF INT; ok : BOOL;")
    assert plc.read("Main.b") == [0, 2, 3, 4, 0, 0] and plc.read("Main.ok") is True


def test_ary_move_beyond_the_array_is_an_instruction_error_and_copies_nothing(tmp_path):
    plc = run1(tmp_path, "ok := AryMove(a[3], b[0], 3);",
               "a : ARRAY[0..4] OF INT := [1, 2, 3, 4, 5]; b : ARRAY[0..5] OF INT; ok : BOOL := TRUE;")
    assert plc.read("Main.b") == [0] * 6 and plc.read("Main.ok") is False
    assert "AryMove" in plc.engine.instruction_errors[-1]


def test_ary_move_of_structures_copies_the_members(tmp_path):
    plc = run1(tmp_path, "AryMove(a[0], b[0], 2); a[0].X := 9;",
               "a : ARRAY[0..1] OF stP := [(X := 1), (X := 2)]; b : ARRAY[0..1] OF stP;",
               "TYPE stP : STRUCT X : INT; END_STRUCT; END_TYPE\n")
    assert plc.read("Main.b[0].X") == 1 and plc.read("Main.b[1].X") == 2


def test_size_of_ary_counts_the_elements(tmp_path):
    plc = run1(tmp_path, "k := SizeOfAry(b);", "b : ARRAY[1..6] OF INT; k : UDINT;")
    assert plc.read("Main.k") == 6


def test_inc_and_dec_add_one_and_wrap_like_an_assignment(tmp_path):
    plc = run1(tmp_path, "Inc(i); Inc(u); Dec(r); Dec(w);", "i : SINT := 127; u : UINT := 7; r : REAL := 1.5; "
               "w : UDINT;")
    assert [plc.read(f"Main.{v}") for v in "iurw"] == [-128, 8, 0.5, 0xFFFF_FFFF]


def test_mod_real_keeps_the_sign_of_in1(tmp_path):
    plc = run1(tmp_path, "a := ModReal(-7.5, 2.0); b := ModReal(7.5, -2.0); c := ModReal(1.0, 0.0);",
               "a, b, c : LREAL;")
    assert (plc.read("Main.a"), plc.read("Main.b"), plc.read("Main.c")) == (-1.5, 1.5, 0.0)


def test_clear_string_empties_the_string(tmp_path):
    plc = run1(tmp_path, "ClearString(s);", "s : STRING[10] := 'abc';")
    assert plc.read("Main.s") == ""


def test_sec_to_time_and_time_to_sec(tmp_path):
    plc = run1(tmp_path, "t := SecToTime(90); n := TimeToSec(T#2m30s500ms); m := TimeToSec(T#-1s999ms);",
               "t : TIME; n, m : LINT;")
    assert plc.read("Main.t") == 90_000_000_000 and plc.read("Main.n") == 150 and plc.read("Main.m") == -1


def test_copy_dword_to_real_keeps_the_bit_pattern(tmp_path):
    plc = run1(tmp_path, "d := CopyRealToDword(1.0); x := CopyDwordToReal(16#40490FDB); "
               "l := CopyLrealToLword(-2.0); y := CopyLwordToLreal(l);", "d : DWORD; x : REAL; l : LWORD; y : LREAL;")
    assert plc.read("Main.d") == 0x3F800000
    assert plc.read("Main.x") == struct.unpack("<f", bytes.fromhex("db0f4940"))[0]
    assert plc.read("Main.l") == 0xC000000000000000 and plc.read("Main.y") == -2.0


def test_get_my_task_interval_is_the_period_of_the_task(tmp_path):
    (tmp_path / "cfg.st").write_text("""CONFIGURATION C
RESOURCE R ON NJ
TASK Fast(INTERVAL := T#2ms, PRIORITY := 4);
TASK Slow(INTERVAL := T#10ms, PRIORITY := 16);
PROGRAM A WITH Fast : Main;
PROGRAM B WITH Slow : Other;
END_RESOURCE
END_CONFIGURATION
PROGRAM Other
VAR t : TIME; END_VAR
t := GetMyTaskInterval();
END_PROGRAM
""")
    (tmp_path / "main.st").write_text("PROGRAM Main\nVAR t : TIME; END_VAR\nt := GetMyTaskInterval();\nEND_PROGRAM\n")
    plc = load_plc([str(tmp_path / "cfg.st"), str(tmp_path / "main.st")])
    plc.scan(0)
    assert plc.read("A.t") == 2_000_000 and plc.read("B.t") == 10_000_000


def test_clock_pulse_functions_follow_the_controller_clock(tmp_path):
    plc = plc_from(tmp_path, "a := Get1sClk(); b := Get100msClk();", "a, b : BOOL;")
    seen = []
    for t in (0, 60_000_000, 499_000_000, 500_000_000):
        plc.scan(t)
        seen.append((plc.read("Main.a"), plc.read("Main.b")))
    assert seen == [(True, True), (True, False), (True, False), (False, True)]


def test_current_time_is_the_controller_clock_and_ethernet_ip_is_online(tmp_path):
    """_CurrentTime (W501 system-defined variables) reads the controller clock; the virtual EtherNet/IP port is
    online without error (our choice, docs/toolchain/runtime_sysmac.md)."""
    plc = plc_from(tmp_path, "Now := _CurrentTime; On := _EIP_EtnOnlineSta; Err := _EIP_ErrSta;",
                   "Now : DT; On : BOOL; Err : WORD;", clock_base_ns=1_700_000_000 * 10**9)
    plc.scan(3_000_000_000)
    assert plc.read("Main.Now") == (1_700_000_003) * 10**9
    assert plc.read("Main.On") is True and plc.read("Main.Err") == 0


def test_deg_to_rad_and_rad_to_deg_keep_the_type_of_in(tmp_path):
    """W560 2-209 (Math Instructions): Out := DegToRad(In); / RadToDeg(In);, Out of the type of In (REAL or
    LREAL), called with In formal or not, nested in COS as engineers write it."""
    plc = run1(tmp_path, "r := DegToRad(REAL#180.0); l := RadToDeg(In := LREAL#3.141592653589793); "
               "c := COS(In := DegToRad(In := LREAL#60.0)); back := RadToDeg(DegToRad(REAL#90.0));",
               "r, back : REAL; l, c : LREAL;")
    assert abs(plc.read("Main.r") - 3.1415927) < 1e-6 and plc.read("Main.l") == 180.0
    assert abs(plc.read("Main.c") - 0.5) < 1e-12 and abs(plc.read("Main.back") - 90.0) < 1e-5


def test_free_running_counters_count_microseconds_and_milliseconds_as_ulint(tmp_path):
    """W560 2-1465 (Get**Cnt): Get1usCnt / Get1msCnt, ULINT as ULINT_TO_STRING(Get1usCnt()) in Sysmac code shows;
    vplc counts from the start of the run and reads the scan's time."""
    plc = plc_from(tmp_path, "us := Get1usCnt(); ms := Get1msCnt(); s := ULINT_TO_STRING(Get1usCnt());",
                   "us, ms : ULINT; s : STRING[24];")
    plc.scan(2_500_000_000)
    assert plc.read("Main.us") == 2_500_000 and plc.read("Main.ms") == 2_500 and plc.read("Main.s") == "2500000"


def test_more_clock_pulses_are_true_in_the_first_half_of_their_period(tmp_path):
    """W560 2-1463 (Get**Clk): Get1msClk, Get10msClk and Get1minClk, as Sysmac projects call them."""
    plc = plc_from(tmp_path, "a := Get10msClk(); b := Get1minClk(); c := Get1msClk();", "a, b, c : BOOL;")
    seen = []
    for t_ms in (0, 4, 5, 9, 10, 30_000, 59_999, 60_000):
        plc.scan(t_ms * 1_000_000)
        seen.append((plc.read("Main.a"), plc.read("Main.b"), plc.read("Main.c")))
    assert [s[0] for s in seen] == [True, True, False, False, True, True, False, True]
    assert [s[1] for s in seen] == [True, True, True, True, True, False, False, True]
    assert all(s[2] for s in seen)          # read at whole milliseconds: always in the first half of its period
