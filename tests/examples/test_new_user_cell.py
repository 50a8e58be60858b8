"""A new user's whole cell, written from the docs alone (issue 27's check): a TM robot tends a press fed by a servo
shuttle (tests/examples/new_user_cell/). It is run the way docs/toolchain/commissioning.md tells a user to run it:
the simulator started as its own command (`python -m tmsim`, i.e. `tmflow-sim --speedup 20 --log ...`), its ports
read from its start-up lines, then `vplc run` with the axis configuration, the commissioning scenario and
`--sim-control`. Real time: the simulator runs on its own clock in its own process (commissioning.md section 2).

The scenario cuts the robot's link once, presses and releases its E-stop once, opens the shuttle's guard once
(MC_Stop, then MC_Reset) and plays the operator, the conveyor and the press; the run must exit 0 with every
expectation held, and the robot's own event log must show every move once, in order."""
from __future__ import annotations

import json
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CELL = ROOT / "tests" / "examples" / "new_user_cell"
SCENARIO = CELL / "press.scn"

SHUTTLE_UP, SHUTTLE_DOWN = (350, -250, 300), (350, -250, 200)
PRESS_IN, PRESS_OUT = (450, 150, 220), (450, 150, 320)
PART = [SHUTTLE_UP, SHUTTLE_DOWN, SHUTTLE_UP, PRESS_IN, PRESS_OUT]   # the five Line moves of one part


SLEEP_TO_DUE = ["--spin-us", "0"]     # no busy wait before each scan: the cell is checked here, not the lateness


class Simulator:
    """`tmflow-sim` in its own process, as a user starts it; ports read from what it prints."""

    def __init__(self, log: pathlib.Path) -> None:
        self.log = log
        self.proc = subprocess.Popen([sys.executable, "-u", "-m", "tmsim", "--port", "0", "--control-port", "0",
                                      "--speedup", "20", "--log", str(log)],
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        assert self.proc.stdout is not None
        printed = []
        for line in self.proc.stdout:
            printed.append(line)
            if line.startswith("control channel:"):
                break
        text = "".join(printed)
        robot = re.search(r"robot 1: .* listening on 127\.0\.0\.1:(\d+) .*Ethernet Slave on 127\.0\.0\.1:(\d+)", text)
        control = re.search(r"control channel: 127\.0\.0\.1:(\d+)", text)
        assert robot and control, f"simulator did not start:\n{text}"
        self.port, self.svr_port = int(robot.group(1)), int(robot.group(2))
        self.control = int(control.group(1))

    def events(self, kind: str) -> list[dict]:
        with self.log.open() as f:
            return [e for e in map(json.loads, f) if e["kind"] == kind]

    def close(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        if self.proc.stdout is not None:
            self.proc.stdout.close()


@pytest.fixture
def simulator(tmp_path):
    sim = Simulator(tmp_path / "sim.jsonl")
    yield sim
    sim.close()


def vplc_run(sim: Simulator, program: pathlib.Path = CELL) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "vplc", "run", str(ROOT / "lib" / "CBT_Commands_Lib"), str(program),
                           "--axes", str(program / "press_axes.toml"), "--scenario", str(program / "press.scn"),
                           "--sim-control", f"127.0.0.1:{sim.control}", f"--set=PressCell.Port={sim.port}",
                           f"--set=PressCell.SvrPort={sim.svr_port}",
                           "--watch", "PressCell.Parts,PressCell.Alarm,Tm.Connected,MC_Shuttle.Status.Stopping",
                           *SLEEP_TO_DUE],
                          capture_output=True, text=True, timeout=300)


def line_of(text: str) -> int:
    return next(n for n, line in enumerate(SCENARIO.read_text().splitlines(), 1) if line.startswith(text))


def arrivals(sim: Simulator) -> list[tuple[int, int, int]]:
    """(x, y, z) of every motion the robot completed, in order: its own witness of what ran."""
    return [tuple(round(v) for v in e["pose"][:3]) for e in sim.events("motion_end")]


@pytest.mark.slow
def test_the_new_users_cell_passes_its_commissioning_with_every_move_once(simulator):
    r = vplc_run(simulator)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1].endswith("; 9 of 9 expectation(s) held"), r.stdout
    assert f"robot 1: cut_link ({SCENARIO}:{line_of('when PressCell.WaitShuttle = TRUE robot 1 cut_link')})" \
        in r.stdout
    assert "robot 1: estop (" in r.stdout and "robot 1: release_estop (" in r.stdout
    assert "MC_Shuttle.Status.Stopping = TRUE" in r.stdout      # the guard's MC_Stop held the shuttle
    # the robot's log: every move once, in order; the gripper closed and opened once per part
    assert arrivals(simulator) == PART * 3, arrivals(simulator)
    gripper = [e["value"] for e in simulator.events("io") if e.get("point") == "EndModule.DO[0]"]
    assert gripper == [1, 0] * 3
    # the scenario's requests, with the controller time, after the ping of the first scan
    assert [e["cmd"] for e in simulator.events("control")] == ["ping", "inject", "estop", "estop"]


@pytest.mark.slow
def test_resuming_the_shuttle_while_mc_stop_still_holds_it_fails_at_once(simulator, tmp_path):
    """A new user's first version: the interrupted move is restarted in the scan MC_Stop's Execute falls. The move
    is called before MC_Stop in the scan, so the axis is still Stopping and the move ends in CommandAborted
    (runtime_sysmac.md 5.2); the program faults and the run ends with the `always` expectation that broke."""
    broken = tmp_path / "new_user_cell"
    broken.mkdir()
    for f in CELL.iterdir():
        if f.is_file():
            (broken / f.name).write_text(f.read_text())
    source = (broken / "PressCell.st").read_text()
    waits = "            ShStep := 91;"
    assert source.count(waits) == 1
    (broken / "PressCell.st").write_text(source.replace(
        waits, "            GuardAlarm := FALSE; ShMoveExec := TRUE; ShStep := ShResume;"))
    r = vplc_run(simulator, broken)
    assert r.returncode == 1, r.stdout + r.stderr
    last = r.stderr.strip().splitlines()[-1]
    assert re.fullmatch(r"vplc run: FAILED: expectation failed at \d+\.\d{3} s: expect PressCell\.Faulted = FALSE "
                        rf"always \({re.escape(str(broken / 'press.scn'))}:{line_of('expect PressCell.Faulted')}\); "
                        r"PressCell\.Faulted is TRUE; \d+ overrun\(s\)", last), last
    assert len(arrivals(simulator)) < 15
