"""The code generator's optimisations change nothing a program can observe: the same ST compiled with them
(inlined FBs, FOR loops with known ranges, constant divisors, single string cuts) and without them gives the
same value in every variable after every scan."""
import os

from vplc.api import Plc, load_plc
from vplc.compiler.codegen import CodeGen
from vplc.project import load_project

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "golden")
MIX = os.path.join(HERE, "inline_mix.st")


def variables(value, prefix="", out=None):
    out = {} if out is None else out
    info = getattr(type(value), "i__vars", None)
    if isinstance(value, list):
        for k, item in enumerate(value):
            variables(item, f"{prefix}[{k}]", out)
    elif info is not None:
        for name, (attr, _t) in sorted(info.items()):
            if hasattr(value, attr):
                variables(getattr(value, attr), f"{prefix}.{name}", out)
    else:
        out[prefix] = value
    return out


def trace(plc, scans):
    return [variables(plc.instances["MAIN"], "Main") for _ in range(scans) if not plc.scan(plc.now_ns + 1_000_000)]


def test_optimised_and_plain_code_give_the_same_variables_after_every_scan():
    plain = Plc(CodeGen(load_project([MIX]), optimise=False).generate())
    fast = load_plc([MIX])
    assert "B1_R_TRIG(_i" not in fast.program.source and "B1_R_TRIG(_i" in plain.program.source
    expected, got = trace(plain, 400), trace(fast, 400)
    assert len(got) == 400
    for scan, (want, have) in enumerate(zip(expected, got, strict=False)):
        assert have == want, f"scan {scan}: " + ", ".join(k for k in want if have.get(k) != want[k])
    assert got[-1]["Main.HITS"] > 0 and got[-1]["Main.SINGLE.COUNT"] > 0


def test_a_long_scan_with_only_short_loops_still_trips_the_watchdog(tmp_path):
    """Short constant FOR loops are checked once when they end instead of in every iteration (the first check past
    the limit starts the watchdog's probation, the next one faults)."""
    path = tmp_path / "main.st"
    path.write_text("PROGRAM Main\nVAR i, n : INT; END_VAR\nFOR i := 1 TO 10 DO n := n + 1; END_FOR;\n"
                    "FOR i := 1 TO 10 DO n := n + 1; END_FOR;\nEND_PROGRAM\n")
    plc = load_plc([str(path)], watchdog_ms=0.000001)
    try:
        plc.scan(0)
    except Exception as exc:       # noqa: BLE001 - the PlcFault is what the test expects
        assert "watchdog" in str(exc)
    else:
        raise AssertionError("the watchdog did not trip")
