"""Runtime benchmarks (issue 4): per-scan cost, virtual scans/s, real-time lateness, compile time, memory.

Run alone: ``python3 bench/bench_runtime.py`` (prints human-readable figures, exits 0).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import threading
import time

import engine_compare

from vplc.api import load_plc
from vplc.runtime.stats import ScanStats, percentile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

EMPTY = "PROGRAM Main\nVAR x : BOOL; END_VAR\n;\nEND_PROGRAM\n"


def trig_program(n: int = 100) -> str:
    return (f"PROGRAM Main\nVAR\n  edges : ARRAY[1..{n}] OF R_TRIG;\n  timers : ARRAY[1..{n}] OF TON;\n"
            f"  i : INT; clk : BOOL; cnt : DINT;\nEND_VAR\nclk := NOT clk;\n"
            f"FOR i := 1 TO {n} DO\n  edges[i](CLK := clk);\n  timers[i](IN := clk, PT := T#5ms);\n"
            f"  IF edges[i].Q OR timers[i].Q THEN cnt := cnt + 1; END_IF;\nEND_FOR;\nEND_PROGRAM\n")


def sequence_fb(name: str, states: int = 22) -> str:
    """A typical ~300-line sequence: CASE state machine with timers, counters and string building."""
    lines = [f"FUNCTION_BLOCK {name}", "VAR_INPUT", "    Start : BOOL;", "    Speed : INT;", "END_VAR",
             "VAR_OUTPUT", "    Busy : BOOL;", "    Done : BOOL;", "    Msg : STRING[80];", "END_VAR", "VAR",
             "    Step : INT;", "    Wait : TON;", "    Edge : R_TRIG;", "    Count : DINT;", "    Pos : REAL;",
             "    Line : STRING[120];", "    Retries : INT;", "END_VAR",
             "Edge(CLK := Start);", "IF Edge.Q AND Step = 0 THEN", "    Step := 10;", "END_IF;",
             "Wait(IN := FALSE);", "CASE Step OF"]
    for k in range(1, states + 1):
        s = k * 10
        lines += [f"{s}:", "    Busy := TRUE;", f"    Pos := Pos + INT_TO_REAL(Speed) * 0.{k % 9 + 1};",
                  f"    Line := CONCAT('step {s} pos=', REAL_TO_STRING(Pos));",
                  "    Line := CONCAT(Line, ' n=');", "    Line := CONCAT(Line, DINT_TO_STRING(Count));",
                  "    Count := Count + 1;",
                  f"    IF Count MOD {k + 2} = 0 THEN", "        Retries := Retries + 1;", "    END_IF;",
                  f"    IF Pos > {k * 100}.0 OR Retries > {k} THEN",
                  f"        Step := {s + 10 if k < states else 0};", "        Retries := 0;",
                  "        Msg := LEFT(Line, 40);", "    END_IF;"]
    lines += ["ELSE", "    Busy := FALSE;", "    Done := Step = 0 AND Count > 0;", "END_CASE;",
              "END_FUNCTION_BLOCK"]
    return "\n".join(lines) + "\n"


def sequence_program() -> str:
    return sequence_fb("Sequence") + ("PROGRAM Main\nVAR\n  seq : Sequence;\n  go : BOOL;\nEND_VAR\n"
                                      "go := NOT go;\nseq(Start := go, Speed := 7);\nEND_PROGRAM\n")


def big_source(lines_wanted: int = 5000) -> str:
    parts, n, i = [], 0, 0
    while n < lines_wanted:
        fb = sequence_fb(f"Seq{i}")
        parts.append(fb)
        n += fb.count("\n")
        i += 1
    decl = "\n".join(f"  s{k} : Seq{k};" for k in range(i))
    calls = "\n".join(f"s{k}(Start := TRUE, Speed := {k % 9 + 1});" for k in range(i))
    parts.append(f"PROGRAM Main\nVAR\n{decl}\nEND_VAR\n{calls}\nEND_PROGRAM\n")
    return "".join(parts)


def load(tmp: str, name: str, text: str, **kw):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(text)
    return load_plc([path], **kw)


def per_scan(tmp, label, text, scans=5000):
    plc = load(tmp, label.replace(" ", "_") + ".st", text, count_statements=True)
    counted = ScanStats()
    for k in range(scans // 5):
        c0 = plc.statements_executed
        plc.scan(k * 1_000_000)
        counted.record(0, 0, plc.statements_executed - c0)
    plc = load(tmp, label.replace(" ", "_") + ".st", text)
    times = []
    t = 0
    for _ in range(scans):
        s0 = time.perf_counter_ns()
        plc.scan(t)
        times.append(time.perf_counter_ns() - s0)
        t += 1_000_000
    med, p99 = percentile(times, .5) / 1000, percentile(times, .99) / 1000
    print(f"  {label:<32} median {med:7.1f} us   p99 {p99:7.1f} us   statements/scan "
          f"{percentile(counted.statements, .5)}")
    return plc


AXES_N = 16


def axes_program(n: int = AXES_N) -> str:
    """n axes moving back and forth between 0 and 100 mm, each with one MC_Power and one MC_MoveAbsolute."""
    return f"""PROGRAM Main
VAR pwr : ARRAY[0..{n - 1}] OF MC_Power; mv : ARRAY[0..{n - 1}] OF MC_MoveAbsolute; i : INT;
    go : ARRAY[0..{n - 1}] OF BOOL; tgt : ARRAY[0..{n - 1}] OF LREAL; END_VAR
FOR i := 0 TO {n - 1} DO
    pwr[i](Axis := _MC_AX[i], Enable := TRUE);
    mv[i](Axis := _MC_AX[i], Execute := go[i], Position := tgt[i], Velocity := 500.0);
    IF mv[i].Done THEN tgt[i] := 100.0 - tgt[i]; go[i] := FALSE; ELSE go[i] := pwr[i].Status; END_IF;
END_FOR;
END_PROGRAM
"""


def axes_cost(tmp: str, n: int = AXES_N, scans: int = 5000) -> None:
    """Issue 27: what a virtual servo axis costs per scan: the motion processing alone (timed around it) and the
    whole scan with the two instructions each axis is given."""
    cfg = os.path.join(tmp, "axes.toml")
    with open(cfg, "w") as f:
        f.write("".join(f"[[axis]]\nnumber = {k}\nmax_velocity = 1000.0\nmax_acceleration = 5000.0\n"
                        for k in range(n)))
    plc = load(tmp, "axes.st", axes_program(n), axes=cfg)
    ctl = plc.motion
    task = plc.engine.tasks[0]
    cycle, spent = type(ctl).cycle, []

    def timed(c):
        s0 = time.perf_counter_ns()
        cycle(c)
        spent.append(time.perf_counter_ns() - s0)
    task.programs[-1] = (ctl, timed)
    scan_times, t = [], 0
    for _ in range(scans):
        s0 = time.perf_counter_ns()
        plc.scan(t)
        scan_times.append(time.perf_counter_ns() - s0)
        t += 1_000_000
    moving = sum(1 for a in ctl.axes if a.profile is not None)
    print(f"  virtual servo axes ({n}, {moving} moving at the end): motion processing median "
          f"{percentile(spent, .5) / 1000 / n:5.2f} us, p99 {percentile(spent, .99) / 1000 / n:5.2f} us per axis "
          f"and scan (target <= 2 us); whole scan with MC_Power + MC_MoveAbsolute per axis "
          f"{percentile(scan_times, .5) / 1000 / n:5.2f} us per axis")


def versus_baseline(rev: str) -> None:
    """Issue 15, target 3: this engine against the engine of commit ``rev`` on the same programs, same run."""
    targets = {"100 R_TRIG + 100 TON": 2.5, "300-line CASE sequence": 1.5}
    rows = engine_compare.compare({"100 R_TRIG + 100 TON": trig_program(),
                                   "300-line CASE sequence": sequence_program()}, rev)
    print(f"this engine against commit {rev}'s (best of 9 rounds of 1000 scans each, taken in turns):")
    for row in rows:
        target = targets[row["label"]]
        mark = "ok" if row["speedup"] >= target and row["identical"] else "--"
        print(f"  {row['label']:<24} {row['old']:7.1f} us -> {row['new']:6.1f} us per scan   "
              f"{mark} {row['speedup']:.2f}x (target >= {target}x)   "
              f"variables after each of 2000 scans: {'identical' if row['identical'] else 'DIFFERENT'}")


CELL_SIGNALS = ("Cell.Parts >= 2", "Cell.Connected = FALSE", "Cell.Alarm = TRUE", "Cell.CncBusy = TRUE",
                "Cell.ConveyorRun = TRUE", "Cell.ShuttleAtLoad = TRUE", "Cell.MovesDone > 12", "Cell.RobotInCnc = TRUE",
                "Cell.Segment = 7", "Cell.RobotError = TRUE")


def scenario_cost(when_lines: int = 100, scans: int = 4000) -> None:
    """Issue 27: what a scenario's `when` lines add to a scan of the cell example (examples/cell): the cell runs
    its batch against the simulator in this process (polled between scans, not timed) on virtual time, driven by
    its commissioning scenario's reactions plus ``when_lines`` more (each on one of ten cell signals, `every
    time`); the scenario's work before and after each scan is timed apart from the scan."""
    from tmsim.net.server import SimServer
    from vplc.cli import scenario as scn
    from vplc.cli.scenario_run import Runner
    cell = os.path.join(ROOT, "examples", "cell")
    sim = SimServer(port=0, robots=1, svr_port=0, speedup=1)
    sim.start()
    try:
        plc = load_plc([os.path.join(ROOT, "lib", "CBT_Commands_Lib"), cell],
                       axes=os.path.join(cell, "cell_axes.toml"))
        sc = scn.Scenario()
        with open(os.path.join(cell, "commissioning.scn"), encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if " robot " not in line:                   # the faults need the control channel: left out
                    scn.parse_line(line, f"commissioning.scn:{n}", sc)
        own = len(sc.reactions)
        for k in range(when_lines):
            scn.parse_line(f"when {CELL_SIGNALS[k % 10]} for {k % 5}ms then set Cell.Batch 3 every time",
                           f"bench:{k}", sc)
        for path, value in (("Cell.Port", sim.ports[0]), ("Cell.SvrPort", sim.robots[0].svr_port)):
            plc.write(path, value)
        scn.resolve(plc, sc)
        runner = Runner(plc, sc)
        scan_ns, hooks_ns, t = [], [], 0
        for _ in range(scans):
            sim.poll(t / 1e9)
            h0 = time.perf_counter_ns()
            runner.finished(t)                              # asked before every scan, as vplc run does
            runner.before_scan(t)
            s0 = time.perf_counter_ns()
            plc.scan(t)
            s1 = time.perf_counter_ns()
            runner.after_scan(t)
            h1 = time.perf_counter_ns()
            scan_ns.append(s1 - s0)
            hooks_ns.append((s0 - h0) + (h1 - s1))
            t += plc.period_ns
        parts = plc.read("Cell.Parts")
        plc.close()
    finally:
        sim.close()
    scan, hooks = percentile(scan_ns, .5) / 1000, percentile(hooks_ns, .5) / 1000
    print(f"  cell example with a scenario of {own} + {when_lines} `when` lines ({parts} parts in {scans} scans): "
          f"scan median {scan:6.1f} us, scenario median {hooks:5.1f} us = {hooks / scan * 100:4.1f} % of the scan "
          f"(target <= 10 %)")


def main() -> int:
    print(f"vplc runtime benchmark (Python {sys.version.split()[0]})")
    rev = sys.argv[sys.argv.index("--against") + 1] if "--against" in sys.argv else engine_compare.BASELINE
    versus_baseline(rev)
    with tempfile.TemporaryDirectory() as tmp:
        print("per-scan cost (virtual time, 1 ms task):")
        per_scan(tmp, "empty program", EMPTY)
        per_scan(tmp, "100 R_TRIG + 100 TON", trig_program())
        seq_text = sequence_program()
        print(f"  (sequence program: {seq_text.count(chr(10))} lines)")
        plc = per_scan(tmp, "300-line CASE sequence", seq_text)
        axes_cost(tmp)
        scenario_cost()

        n, t0 = 20000, time.perf_counter()
        plc.run_until(lambda: False, n * plc.period_ns)
        rate = n / (time.perf_counter() - t0)
        print(f"virtual time: {rate:,.0f} scans/s for the sequence program (run_until)")

        base = []
        due = time.monotonic_ns()
        for _ in range(1000):
            due += 1_000_000
            time.sleep(max(0, due - time.monotonic_ns()) / 1e9)
            base.append(time.monotonic_ns() - due)
        print(f"machine baseline, plain 1 ms sleep loop: lateness p99 {percentile(base, .99) / 1000:.1f} us, "
              f"max {max(base) / 1000:.1f} us (jitter of the OS/VM, not of the PLC)")
        for spin in (300_000, 800_000):
            stop, stats = threading.Event(), ScanStats()
            rt = load(tmp, "rt.st", seq_text)
            timer = threading.Timer(3.0, stop.set)
            timer.start()
            cpu0 = time.process_time()
            rt.run_realtime(stop, stats=stats, spin_ns=spin)
            cpu = (time.process_time() - cpu0) / 3.0 * 100
            timer.cancel()
            print(f"real time, 1 ms task, 3 s, spin {spin // 1000} us: lateness median "
                  f"{percentile(stats.lateness, .5) / 1000:.1f} us, "
                  f"p99 {percentile(stats.lateness, .99) / 1000:.1f} us, "
                  f"max {max(stats.lateness) / 1000:.1f} us, overruns {stats.overruns} of {len(stats.lateness)} scans, "
                  f"CPU {cpu:.0f} %")

        big = big_source()
        path = os.path.join(tmp, "big.st")
        with open(path, "w") as f:
            f.write(big)
        code = ("import resource, time; from vplc.api import load_plc; "
                f"t0 = time.perf_counter(); p = load_plc([{path!r}]); dt = time.perf_counter() - t0; "
                "[p.scan(k * 1000000) for k in range(100)]; "
                "print(dt, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        dt, rss = (float(x) for x in out.stdout.split())
        print(f"compile (load + check + codegen + instantiate) of {big.count(chr(10))} lines: {dt:.2f} s")
        print(f"peak RSS of a fresh process with that program loaded and scanned 100 times: {rss:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
