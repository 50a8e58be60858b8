"""Regenerates the timing diagrams of docs/library/*.md from real runs (virtual PLC + simulator): one diagram per
FB page, drawn from that page's own "## Example" program, plus the blended and error cases of CBT_MoveAbsolute.

    make traces          (or: PYTHONPATH=tests/lib .venv/bin/python docs/library/make_traces.py)
"""
import re
import tempfile
from pathlib import Path

from doc_steps import STEPS, Examples
from rig import SEC, Rig, move_abs

from vplc.api import PathError
from vplc.trace.recorder import Recorder, write_trace

HERE = Path(__file__).resolve().parent

OUT = HERE / "traces"
PINS = ("Busy", "Active", "Connected", "Valid", "Done", "CommandAborted", "Error", "ErrorID")
EXTRA = {"CBT_Connect": ["Cobot.InListenNode", "RobotReady"], "CBT_Stop": ["Cobot.Stopping"],
         "CBT_ReadActualPosition": ["TcpZ"],
         "CBT_RobotStatus": ["fbStatus.Status.ProjectRunning", "fbStatus.Status.Position.TCP.Z", "RobotFault"],
         "CBT_ProjectControl": ["Cobot.Status.ProjectRunning"],
         "CBT_ReadIO": ["PartPresent"], "CBT_SetOverride": ["SpeedShown"],
         "CBT_WaitQueue": ["Cobot.Status.Moving", "Cobot.Status.TCPSpeed"],
         "CBT_ReadVariable": ["PartCount"], "CBT_Jog": ["Cobot.Stopping"],
         "CBT_VisionJob": ["fbVision.Found", "fbVision.ObjectCount"]}
FIRST = {"CBT_ReadActualPosition": ["fbConnect.Connected"], "CBT_RobotStatus": ["fbConnect.Connected"],
         "CBT_ReadIO": ["fbConnect.Connected"]}      # the FB's Enable
HOLD_S = 0.02                   # Execute stays TRUE this long after Done, then falls: both Done cases show
HOLD_PAGE_S = {"CBT_Jog": 0.3}  # a jog button is held a while after Active, then released


def slug(page: str) -> str:
    """CBT_MoveRelative -> move_relative (the file name of its diagram)."""
    return re.sub(r"(?<=[a-z])(?=[A-Z])", "_", page.removeprefix("CBT_")).lower()


def trace_name(page: str) -> str:
    return f"{slug(page)}.svg"


def page_trace(page: str, out: Path, examples: Examples) -> None:
    """Run the page's example as the library tests do and record its trigger inputs and the FB's pins."""
    program = examples.names[page]
    srv = examples.servers[page]
    try:
        plc = examples.plc(page)
        read = lambda name: plc.read(f"{program}.{name}")   # noqa: E731
        pump = lambda now_ns: srv.poll(now_ns / 1e9)        # noqa: E731
        steps = STEPS[page]
        if page not in ("CBT_Connect", "CBT_ReadActualPosition", "CBT_RobotStatus", "CBT_ReadIO"):   # show the connect
            assert plc.run_until(lambda: read("fbConnect.Connected"), 5 * SEC, on_scan=pump)
        paths = list(FIRST.get(page, []))
        for trigger, done in steps:
            fb = done.rpartition(".")[0] or "fbConnect"
            paths += [trigger] if trigger else []
            for pin in PINS:
                try:
                    read(f"{fb}.{pin}")
                    paths.append(f"{fb}.{pin}")
                except PathError:
                    pass
        paths += EXTRA.get(page, [])
        paths = list(dict.fromkeys(paths))
        rec = Recorder(plc, [f"{program}.{p}" for p in paths], labels=paths)
        sample = lambda: rec.sample() and False             # noqa: E731
        plc.run_until(sample, int(0.005 * SEC), on_scan=pump)
        for trigger, done in steps:
            fb = done.rpartition(".")[0] or "fbConnect"
            if trigger:
                plc.write(f"{program}.{trigger}", True)
            plc.run_until(lambda done=done, fb=fb: sample() or read(done) or read(f"{fb}.Error"), 20 * SEC,
                          on_scan=pump)
            plc.run_until(sample, int(HOLD_PAGE_S.get(page, HOLD_S) * SEC), on_scan=pump)
            if trigger:
                plc.write(f"{program}.{trigger}", False)
            plc.run_until(sample, int(HOLD_S * SEC), on_scan=pump)
        write_trace(rec, str(out / trace_name(page)))
        plc.close()
    finally:
        srv.close()


def record(rig, paths, steps, path: Path):
    rec = Recorder(rig.plc, ["Main." + p for p in paths], labels=paths)
    rig.until(lambda: rec.sample() and False, 0.005)
    for action, seconds in steps:
        if action:
            action()
        rig.until(lambda: rec.sample() and False, seconds)
    write_trace(rec, str(path))


def move_absolute_cases(out: Path) -> None:
    """The two cases the example does not show: blended (Done on acceptance) and a parameter error."""
    paths = ["MoveExec", "mover.Busy", "mover.Active", "mover.Done", "mover.CommandAborted", "mover.Error",
             "mover.ErrorID"]
    r = Rig()
    r.set_struct("MoveParam", move_abs(BlendingEnable=True, BlendingValue=50))
    record(r, paths, [(lambda: r.write("MoveExec", True), 0.02), (lambda: r.write("MoveExec", False), 0.01)],
           out / "move_absolute_blended.svg")
    r.set_struct("MoveParam", move_abs(Speed=0))
    record(r, paths, [(lambda: r.write("MoveExec", True), 0.01), (lambda: r.write("MoveExec", False), 0.01)],
           out / "move_absolute_error.svg")
    r.close()


def move_absolute_aborting(out: Path) -> None:
    """BufferMode Aborting: a slow PTP runs, a second one waits behind it; an aborting PTP replaces both (they end
    CommandAborted) and runs to its end."""
    paths = ["MExec[1]", "movers[1].Active", "movers[1].Done", "movers[1].CommandAborted",
             "movers[2].Active", "movers[2].CommandAborted",
             "MExec[3]", "movers[3].Busy", "movers[3].Active", "movers[3].Done"]
    r = Rig(program="Main_Buffer.st")
    r.set_struct("MParam[1]", move_abs(TargetPosition=dict(X=90, Y=0, Z=90, RX=0, RY=90, RZ=0), Speed=10))
    r.set_struct("MParam[2]", move_abs(TargetPosition=dict(X=-90, Y=0, Z=90, RX=0, RY=90, RZ=0), Speed=10))
    r.set_struct("MParam[3]", move_abs(TargetPosition=dict(X=10, Y=10, Z=90, RX=0, RY=90, RZ=0)))
    r.write("MMode[3]", "Aborting")
    steps = [(lambda: (r.write("MExec[1]", True), r.write("MExec[2]", True)), 0.1),
             (lambda: r.write("MExec[3]", True), 0.32),
             (lambda: [r.write(f"MExec[{k}]", False) for k in (1, 2, 3)], 0.02)]
    record(r, paths, steps, out / "move_absolute_aborting.svg")
    r.close()


def main(out: Path = OUT) -> None:
    """Write every diagram into ``out`` (the drift test writes them into a temporary folder and compares)."""
    out.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as sources:      # the examples, pointed at their simulators
        examples = Examples(Path(sources))
        try:
            for page in sorted(STEPS):
                page_trace(page, out, examples)
        finally:
            examples.close()
    move_absolute_cases(out)
    move_absolute_aborting(out)


if __name__ == "__main__":
    main()
    print("traces written to", OUT)
