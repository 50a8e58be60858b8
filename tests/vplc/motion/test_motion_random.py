"""Random sequences of motion instructions on one axis (fixed seeds): whatever the program does, the command
position stays continuous, the velocity within the axis maximum, the acceleration within the axis maximum
and a positioning given at the end lands exactly on its target. MOTION_SEEDS=800 runs more seeds."""
import random

import pytest
from motion_rig import Rig, files

VMAX, AMAX, DT = 200.0, 2000.0, 0.001


@pytest.mark.parametrize("seed", range(int(__import__("os").environ.get("MOTION_SEEDS", "6"))))
@pytest.mark.parametrize("axes", ["axes.toml", "axes_limited.toml"])
def test_random_instruction_sequences_keep_the_motion_physical(tmp_path_factory, seed, axes):
    rnd = random.Random(seed)
    rig = Rig(files(tmp_path_factory), axes).powered()
    limited = axes == "axes_limited.toml"
    flags = ["doAbs1", "doAbs2", "doRel", "doVel", "doHalt", "doStop", "doOvr"]
    prev_x, prev_v = rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel")
    travelled = 0.0
    for step in range(60):
        choice = rnd.choice(flags)
        values = {choice: True}
        if choice in ("doAbs1", "doAbs2"):
            key = "pos1" if choice == "doAbs1" else "pos2"
            values[key] = rnd.uniform(-300, 300)
            values["buf1" if choice == "doAbs1" else "buf2"] = rnd.choice(["_mcAborting", "_mcBuffered"])
        elif choice == "doRel":
            values.update(dist=rnd.uniform(-50, 50), bufRel=rnd.choice(["_mcAborting", "_mcBuffered"]))
        elif choice == "doVel":
            values.update(vv=rnd.uniform(0, 300), dir=rnd.choice(["_mcPositiveDirection", "_mcNegativeDirection"]))
        elif choice == "doOvr":
            values.update(factor=rnd.choice([0.0, 30.0, 100.0, 250.0]))
        values.update(v1=rnd.uniform(5, 300), v2=rnd.uniform(5, 300), a1=rnd.uniform(0, 3000),
                      d1=rnd.uniform(0, 3000), jerk=rnd.choice([0.0, 20_000.0, 200_000.0]))
        rig.set(**values)
        for _ in range(rnd.randint(1, 120)):
            rig.scan()
            x, v = rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel")
            assert abs(v) <= VMAX * (1 + 1e-12), (seed, step, v)
            assert not limited or -10.0 <= x <= 150.0, (seed, step, x)
            assert abs(x - prev_x) <= VMAX * DT * (1 + 1e-9) + 1e-9, (seed, step, prev_x, x)
            assert abs(v - prev_v) <= AMAX * DT * (1 + 1e-9) + 1e-9 or rig.state() in ("ErrorStop", "Disabled"), \
                (seed, step, prev_v, v)
            travelled += abs(x - prev_x)
            prev_x, prev_v = x, v
        rig.set(**{choice: False})
        if rig.state() == "ErrorStop":
            rig.set(doReset=True)
            rig.scan(2)
            rig.set(doReset=False)
            rig.scan()
            prev_x, prev_v = rig.ax("Cmd.Pos"), rig.ax("Cmd.Vel")
        assert rig.r("pwr.Status")
    assert travelled > 1.0
    rig.set(doAbs1=False, doAbs2=False, doRel=False, doVel=False, doHalt=False, doOvr=False, doStop=True)
    rig.scan()                                    # MC_Stop aborts whatever runs or waits
    rig.set(doStop=False)
    for _ in range(1000):
        rig.scan()
        if rig.state() == "ErrorStop":
            rig.set(doReset=True)
        elif rig.state() == "Standstill":
            break
    assert rig.state() == "Standstill"
    rig.set(doReset=False, pos1=12.5, v1=100.0, buf1="_mcAborting", jerk=50_000.0, doAbs1=True)
    while not rig.r("abs1.Done"):
        rig.scan()
        assert rig.k < 100_000
    assert rig.ax("Cmd.Pos") == 12.5 and rig.ax("Cmd.Vel") == 0.0 and rig.state() == "Standstill"
