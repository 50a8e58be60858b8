"""The machine-tending cell example driven by its commissioning scenario: `vplc run` (the real command line, in
real time, the shuttle on a virtual servo axis) against the simulated robot at --speedup 20 over loopback, the
conveyor and the CNC played by the scenario's reactions, one cut link and one E-stop sent by the scenario on the
simulator's control channel. The run exits 0 when the batch is complete and every move happened once (the
program's counters, and the robot's own event log); a broken program fails with a one-line reason."""
from __future__ import annotations

import pathlib
import shutil
import subprocess
import sys

import pytest

from tmsim.net.server import SimServer

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "cell"
SCENARIO = EXAMPLE / "commissioning.scn"
ABOVE = 120.0


# The 1 ms task sleeps to each due time instead of busy-waiting its last 0.3 ms (`vplc run`'s default, for the
# lowest lateness): these runs check the cell, not the lateness, and the spin cost ~30 % of a core for each.
SLEEP_TO_DUE = ["--spin-us", "0"]


@pytest.fixture
def robot():
    sim = SimServer(port=0, robots=1, speedup=20, control_port=0, svr_port=0)
    sim.start_background()
    yield sim
    sim.close()


def vplc_run(sim, program=EXAMPLE):
    return subprocess.run([sys.executable, "-m", "vplc", "run", str(ROOT / "lib" / "CBT_Commands_Lib"), str(program),
                           "--axes", str(EXAMPLE / "cell_axes.toml"), "--scenario", str(SCENARIO),
                           "--sim-control", f"127.0.0.1:{sim.control.port}", f"--set=Cell.Port={sim.ports[0]}",
                           f"--set=Cell.SvrPort={sim.robots[0].svr_port}", *SLEEP_TO_DUE],
                          capture_output=True, text=True, timeout=300)


def line_of(text):
    """The scenario's line number of ``text``."""
    return next(n for n, line in enumerate(SCENARIO.read_text().splitlines(), 1) if line.startswith(text))


def expected_moves(parts):
    pick, chuck, out = (350, -250, 200), (450, 0, 250), (300, 200, 200)

    def up(p):
        return (p[0], p[1], p[2] + ABOVE)
    part = [up(pick), pick, up(pick), up(chuck), chuck, up(chuck), chuck, up(chuck), up(out), out]
    return part * parts


def arrivals(sim):
    """(x, y, z) of every motion the robot completed, in order: its own witness of what ran."""
    return [tuple(round(v) for v in e["pose"][:3]) for e in sim.robots[0].events if e["kind"] == "motion_end"]


@pytest.mark.slow
def test_commissioning_passes_with_a_cut_link_and_an_estop_and_every_move_once(robot):
    r = vplc_run(robot)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "; 9 of 9 expectation(s) held" in r.stdout.splitlines()[-1]
    assert f"robot 1: cut_link ({SCENARIO}:{line_of('when Cell.CncBusy = TRUE robot 1 cut_link')})" in r.stdout
    assert "robot 1: estop (" in r.stdout and "robot 1: release_estop (" in r.stdout
    assert arrivals(robot) == expected_moves(3)
    # the robot's log carries the controller time of every request the scenario sent, next to its own clock
    marks = [(e["cmd"], e["plc_time"]) for e in robot.robots[0].events if e["kind"] == "control"]
    assert [cmd for cmd, _ in marks] == ["ping", "inject", "estop", "estop"] and marks[0][1] < 0.01    # 1st scan
    assert all(0 < a[1] < b[1] for a, b in zip(marks[1:], marks[2:], strict=False))


def test_a_broken_program_fails_with_a_one_line_reason(robot, tmp_path):
    """The CNC started as soon as the part is in the chuck, the robot still in the machine: the scenario's CNC
    reports the crash and the run ends at once with the expectation, its line and the value."""
    broken = tmp_path / "cell"
    shutil.copytree(EXAMPLE, broken)
    source = (broken / "Cell.st").read_text()
    fixed = "ELSIF Segment = 6 THEN\n            CncStart := TRUE;"
    assert fixed in source
    (broken / "Cell.st").write_text(source.replace(fixed, fixed.replace("Segment = 6", "Segment = 5")))
    r = vplc_run(robot, broken)
    assert r.returncode == 1
    last = r.stderr.strip().splitlines()[-1]
    reason, _, overruns = last.rpartition("; ")
    assert overruns.endswith(" overrun(s)")
    assert reason.startswith("vplc run: FAILED: expectation failed at ")
    assert reason.endswith(f": expect Cell.CncCrash = FALSE always ({SCENARIO}:"
                           f"{line_of('expect Cell.CncCrash')}); Cell.CncCrash is TRUE")
    assert arrivals(robot)[:5] == expected_moves(1)[:5]   # stopped in part 1: in the chuck, or the move out of
    assert len(arrivals(robot)) <= 6                       # it already sent when the run ended
