"""Test rig: the library on the virtual PLC against the simulator, scan by scan on virtual time (Contract D)."""
from __future__ import annotations

from pathlib import Path

from tmsim.net.server import SimServer
from vplc.api import load_plc

ROOT = Path(__file__).resolve().parents[2]
LIB = ROOT / "lib" / "CBT_Commands_Lib"
ST = Path(__file__).resolve().parent / "st"
SEC = 1_000_000_000

HOME_JOINTS = dict(X=0, Y=0, Z=90, RX=0, RY=90, RZ=0)


MULTI_ROBOT = {"Main_Tags.st"}     # programs of several robots: Ports[r], Robots and conns[r], r = 1..robots


class Rig:
    """The simulator's robot(s) + a library test program (Main_Lib.st unless named), pumped once per PLC scan.
    ``sim_args`` go to the SimServer (``robots=4`` for a program of MULTI_ROBOT)."""

    def __init__(self, program="Main_Lib.st", connect=True, load_args=None, **sim_args):
        sim_args.setdefault("auto_enter", True)
        self.srv = SimServer(host="127.0.0.1", port=0, **sim_args)
        self.srv.start()
        self.robot = self.srv.robots[0]
        self.plc = load_plc([str(LIB), str(ST / program)], task="Main@1ms", **(load_args or {}))
        if program in MULTI_ROBOT:
            for r, port in enumerate(self.srv.ports, start=1):
                self.plc.write(f"Main.Ports[{r}]", port)
            self.plc.write("Main.Robots", len(self.srv.ports))
            links = [f"conns[{r}]" for r in range(1, len(self.srv.ports) + 1)]
        else:
            self.plc.write("Main.Port", self.srv.ports[0])
            links = ["conn"]
        if sim_args.get("svr_port") is not None:
            self.plc.write("Main.SvrPort", self.robot.svr_port)
        if connect:
            self.write("ConnExec", True)
            assert self.until(lambda: all(self.read(f"{link}.Connected") for link in links), 5), \
                "; ".join(self.read(f"{link}.ErrorDescrip") for link in links)

    # --- access -------------------------------------------------------------------------------
    def read(self, path):
        return self.plc.read("Main." + path)

    def write(self, path, value, raw=False):
        """raw=True: an integer into an enumeration, also an undefined one (an HMI writing a number)."""
        self.plc.write("Main." + path, value, raw=raw)

    def set_struct(self, path, values: dict):
        for key, value in values.items():
            if isinstance(value, dict):
                self.set_struct(f"{path}.{key}", value)
            else:
                self.write(f"{path}.{key}", value)

    # --- time ---------------------------------------------------------------------------------
    def pump(self, now_ns):
        self.srv.poll(now_ns / 1e9)

    def until(self, pred, seconds, on_scan=None):
        def hook(now_ns):
            self.pump(now_ns)
            if on_scan:
                on_scan(now_ns)
        return self.plc.run_until(pred, timeout_ns=int(seconds * SEC), on_scan=hook)

    def scans(self, n):
        for _ in range(n):
            now = self.plc.now_ns + self.plc.period_ns
            self.pump(now)
            self.plc.scan(now)

    # --- simulator log ------------------------------------------------------------------------
    def events(self, kind):
        return [e for e in self.robot.events if e["kind"] == kind]

    def scripts_in(self):
        """(id, script) of every TMSCT frame the robot received, in order."""
        out = []
        for e in self.events("frame_in"):
            if e.get("header") == "TMSCT":
                ident, _, script = e["data"].partition(",")
                out.append((ident, script))
        return out

    def close(self):
        self.plc.close()
        self.srv.close()


def move_abs(**kw):
    """stCBT_MovAbsParam values: PTP JPP to the home joints at 50 %, non-blended, unless overridden."""
    p = dict(MovementCommand=1, DataFormat=0, TargetPosition=dict(HOME_JOINTS), Speed=50, AccelTime=200,
             BlendingEnable=False, BlendingValue=0, PrecisePositioning=False, RobotPoseEnable=False,
             ExitNode=False)
    p.update(kw)
    return p


def run(rig, fb, exec_, param, values, seconds=5):
    """Set the FB's parameter structure, raise its Execute, wait for Done or Error; the last script the robot got."""
    rig.set_struct(param, values)
    rig.write(exec_, True)
    assert rig.until(lambda: rig.read(f"{fb}.Done") or rig.read(f"{fb}.Error"), seconds)
    return rig.scripts_in()[-1][1] if rig.scripts_in() else None


def rel(**kw):
    """stCBT_MovRelParam values: a 20.5 mm line down in the base, 50 %, unless overridden."""
    p = dict(MovementCommand=0, DataFormat=1, TargetPosition=dict(X=0, Y=0, Z=-20.5, RX=0, RY=0, RZ=0),
             Speed=50, AccelTime=200, BlendingEnable=False, BlendingValue=0, PrecisePositioning=True, ExitNode=False)
    p.update(kw)
    return p


def circ(**kw):
    """stCBT_MovCircleParam values: an arc through two Cartesian points at 100 %, unless overridden."""
    p = dict(DataFormat=1, ArcPoint=dict(X=417.5, Y=-72.3, Z=359.7, RX=180, RY=0, RZ=90),
             EndPoint=dict(X=467.5, Y=-122.3, Z=359.7, RX=180, RY=0, RZ=90), Speed=100, AccelTime=200,
             BlendingEnable=False, BlendingValue=0, ArcAngle=0, PrecisePositioning=False, ExitNode=False)
    p.update(kw)
    return p
