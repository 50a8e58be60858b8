"""The two-robot palletizer example driven by its commissioning scenario: `vplc run` (the real command line, in
real time) against two simulated robots over loopback. The run exits 0 when all 24 boxes were placed, in order
and once each, and 1 with the reason when one placement is broken."""
from __future__ import annotations

import pathlib
import re
import subprocess
import sys

import pytest

from tmsim.net.server import SimServer

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "palletizer"


SLEEP_TO_DUE = ["--spin-us", "0"]     # no busy wait before each scan: the cell is checked here, not the lateness


@pytest.fixture
def robots():
    sim = SimServer(port=0, robots=2, speedup=20)
    sim.start_background()
    yield sim
    sim.close()


def vplc_run(sim, *extra):
    ports = [f"--set=Palletizer.Port[{i + 1}]={port}" for i, port in enumerate(sim.ports)]
    return subprocess.run([sys.executable, "-m", "vplc", "run", str(ROOT / "lib" / "CBT_Commands_Lib"), str(EXAMPLE),
                           "--scenario", str(EXAMPLE / "commissioning.scn"), *ports, *extra, *SLEEP_TO_DUE],
                          capture_output=True, text=True, timeout=300)


def placements(robot):
    """(x, y, z) of every place move, in the order the robot received them: the low Line moves over the pallet."""
    out = []
    for e in robot.events:
        if e["kind"] == "frame_in" and e.get("header") == "TMSCT":
            m = re.search(r'Line\("CPP",([-\d.]+),([-\d.]+),([-\d.]+)', e["data"])
            if m and float(m.group(2)) >= 150 and float(m.group(3)) < 260:
                out.append(tuple(round(float(v)) for v in m.groups()))
    return out


def test_scenario_passes_when_all_24_boxes_are_placed_in_order_once_each(robots):
    r = vplc_run(robots)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1].endswith("5 of 5 expectation(s) held")
    expected = [(300 + 60 * (b % 3), 150 + 80 * (b // 3 % 2), 150 + 50 * (b // 6)) for b in range(12)]
    for robot in robots.robots:
        assert placements(robot) == expected


def test_scenario_fails_with_the_reason_when_one_placement_is_broken(robots):
    r = vplc_run(robots, "--set", "Palletizer.PickPoint[2].Z=2000@0.5s")     # robot 2's next pick: out of reach
    assert r.returncode == 1
    reason, _, overruns = r.stderr.strip().splitlines()[-1].rpartition("; ")     # a real-time run ends with its
    assert overruns.endswith(" overrun(s)")                                      # overruns (issue 27)
    assert reason.startswith("vplc run: FAILED: expectation failed at ")
    assert "expect Palletizer.Error = FALSE always (" in reason and reason.endswith("Palletizer.Error is TRUE")
    assert len(placements(robots.robots[1])) < 12
