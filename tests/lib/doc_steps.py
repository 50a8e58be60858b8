"""The example of every FB page in docs/library/, as steps: the BOOL inputs the example raises one after the
other once connected, and the output that ends each step. test_lib_doc_examples.py runs the examples with them,
test_lib_doc_traces.py draws their timing diagrams; the robot both run the examples against, and the example
taken from a page."""
import re
from pathlib import Path

from rig import LIB, ROOT

from tmsim.net.server import SimServer
from tmsim.protocol.svr_table import parse_variable
from tmsim.robot.camera import camera_of
from vplc.api import LoadError, Plc, compile_program, load_plc

# page -> (BOOL inputs raised one after the other once connected, output that ends each step)
STEPS = {
    "CBT_Connect": [("ConnectSwitch", "RobotReady")],
    "CBT_MoveAbsolute": [("MoveAbsExec", "fbMoveAbs.Done")],
    "CBT_MoveRelative": [("MoveRelExec", "fbMoveRel.Done")],
    "CBT_MoveCircle": [("MoveCircleExec", "fbMoveCircle.Done")],
    "CBT_ChangeBase": [("ChangeBaseExec", "fbChangeBase.Done")],
    "CBT_ChangeTCP": [("ChangeTCPExec", "fbChangeTCP.Done")],
    "CBT_ProgramControl": [("PauseButton", "fbPause.Done"), ("ResumeButton", "fbResume.Done")],
    "CBT_Stop": [("StopButton", "fbStop.Done")],
    "CBT_SetOutput": [("CloseGripper", "fbGripper.Done")],
    "CBT_ReadActualPosition": [(None, "fbReadPos.Valid")],
    "CBT_RobotStatus": [(None, "fbStatus.Valid")],
    "CBT_ProjectControl": [("PlayButton", "fbPlay.Done")],
    "CBT_ReadIO": [(None, "fbIO.Valid")],
    "CBT_SetOverride": [("SlowButton", "fbOverride.Done")],
    "CBT_WaitQueue": [("MoveExec", "fbMove.Done"), ("SyncExec", "fbSync.Done")],
    "CBT_ReadVariable": [("ReadExec", "fbRead.Done")],
    "CBT_WriteVariable": [("WriteExec", "fbWrite.Done")],
    "CBT_Jog": [("JogPlusButton", "fbJog.Active")],
    "CBT_Teach": [("TeachButton", "fbTeach.Done")],
    "CBT_VisionJob": [("CameraButton", "fbVision.Done"), ("PickButton", "fbApproach.Done")],
}


DOCS = ROOT / "docs" / "library"
EXAMPLE = re.compile(r"^## Example\n```\n(.*?)```\n(.*?)(?=^## |\Z)", re.S | re.M)
SCRIPT = re.compile(r"^- `(.*)`$", re.M)

# the global variables of the robot's project that the pages' examples read and write (simulator: --svr-var)
SVR_VARIABLES = ("g_PartCount:int=17", "g_Recipe:string=\"Flange\"", "g_Offset:float[3]={0.5,-1.25,0}")


# the vision job of the robot's project (simulator: --vision-job) and the one part its camera finds
VISION_JOB, VISION_OBJECT = "job1", [417.5, -122.3, 300, 0, 0, 0]


def simulator() -> SimServer:
    """The robot the examples run against: Listen node, Ethernet Slave, the variables and the vision job above."""
    srv = SimServer(host="127.0.0.1", port=0, auto_enter=True, svr_port=0,
                    svr_options={"variables": [parse_variable(spec) for spec in SVR_VARIABLES]})
    camera_of(srv.robots[0].session.robot).define(VISION_JOB, objects=[VISION_OBJECT])
    return srv


def example_of(page: str) -> tuple[str, list[str]]:
    text = (DOCS / f"{page}.md").read_text(encoding="utf-8")
    m = EXAMPLE.search(text)
    assert m, f"{page}.md has no '## Example' section with a code block"
    return m.group(1), SCRIPT.findall(m.group(2))


def on_simulator(code: str, srv) -> str:
    """The example as the page shows it, pointed at the simulator's robot and Ethernet Slave on loopback."""
    return (code.replace("'192.168.1.10'", "'127.0.0.1'").replace("IPPort := 5890", f"IPPort := {srv.ports[0]}")
            .replace("SvrPort := 5891", f"SvrPort := {srv.robots[0].svr_port}"))


class Examples:
    """The examples of ``pages``, each pointed at a simulator of its own (started, not yet polled), written into
    ``folder`` and compiled with the library as one program: the library, most of the work, is compiled once
    for all pages instead of once per page. The examples are PROGRAMs of distinct names; ``plc(page)`` runs
    only its page's, in a PLC instance of its own. Should they not check clean together, each page is compiled
    alone with the library, so its own diagnostics are what its run reports."""

    def __init__(self, folder: Path, pages=None) -> None:
        self.servers: dict[str, SimServer] = {}
        self.sources: dict[str, Path] = {}
        self.names: dict[str, str] = {}          # page -> its example's PROGRAM
        try:
            for page in pages or sorted(STEPS):
                srv = self.servers[page] = simulator()
                srv.start()
                code, _ = example_of(page)
                self.names[page] = re.search(r"^PROGRAM (\w+)", code, re.M).group(1)
                self.sources[page] = folder / f"{page}_example.st"
                self.sources[page].write_text(on_simulator(code, srv), encoding="utf-8")
            try:
                self.compiled = compile_program([str(LIB), *map(str, self.sources.values())])
            except LoadError:
                self.compiled = None
        except BaseException:
            self.close()
            raise

    def plc(self, page: str) -> Plc:
        if self.compiled is None:
            return load_plc([str(LIB), str(self.sources[page])], task="Main@1ms")
        return Plc(self.compiled, "Main@1ms", [self.names[page]])

    def close(self) -> None:
        for srv in self.servers.values():
            srv.close()
