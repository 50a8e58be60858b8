"""`make demo`: robot simulator + virtual PLC running the examples in real time + web HMI, stopped by Ctrl-C.

    cbt-demo [--host 127.0.0.1] [--robot-port 5890] [--svr-port 5891] [--hmi-port 8080] [--control-port 5889]
             [--alarm-log FILE] [--project DIR] [--pages DIR]

Also `python3 -m cbt_hmi` and, from a checkout, `python3 examples/run_demo.py` (the launcher kept for existing
users). The demo runs the library and the examples of a project folder: --project, else the current folder when
it holds lib/CBT_Commands_Lib and examples/, else the checkout this package is installed from.
"""
from __future__ import annotations

import argparse
import errno
import os
import pathlib
import signal
import socket
import sys
import threading
from typing import TYPE_CHECKING

from cbt_hmi.web.mapping import Mapping, MappingError
from cbt_hmi.web.pagedesc import load_pages, program_table
from cbt_hmi.web.server import HmiServer, host_argument
from tmsim.net.control import default_port, robot_numbering
from tmsim.net.server import SimServer

if TYPE_CHECKING:
    from vplc.api import Plc

LIBRARY, EXAMPLES = pathlib.Path("lib", "CBT_Commands_Lib"), pathlib.Path("examples")
CONTROL_HOST = "127.0.0.1"     # the simulator's control channel stays on loopback whatever --host says


def is_project(folder: pathlib.Path) -> bool:
    """A folder holding the library and the example programs the demo runs."""
    return (folder / LIBRARY).is_dir() and (folder / EXAMPLES).is_dir()


def find_project(given: str | None) -> pathlib.Path:
    """The project folder: the one given, else the current folder, else the checkout holding this package
    (src/cbt_hmi/ in it: an editable install or a plain checkout)."""
    if given is not None:
        folder = pathlib.Path(given)
        if not is_project(folder):
            raise DemoError(f"error: --project {given}: no {LIBRARY} and {EXAMPLES}/ in that folder.")
        return folder.resolve()
    for folder in (pathlib.Path.cwd(), pathlib.Path(__file__).resolve().parent.parent.parent):
        if is_project(folder):
            return folder
    raise DemoError(f"error: no project here: run the demo in a folder holding {LIBRARY} and {EXAMPLES}/ "
                    "(a checkout of CBT_Commands_Lib), or name it with --project DIR.")


def robot_event_line(event: dict) -> str | None:
    """One console line for a robot-side event of the simulator's event log (what an operator at the robot
    would notice), None for the rest (frames, scripts, motions)."""
    kind, what = event["kind"], None
    if kind == "state":
        change = event.get("event")
        if change == "robot_fault":
            what = f"robot error: {event.get('reason') or 'no reason given'} - project stopped"
        elif change == "stop_project":
            what = "project stopped"
        elif change == "start_project":
            what = "project started"
        elif change == "enter_node":
            what = "flow entered the Listen node"
        elif change == "leave_node":
            what = f"flow left the Listen node ({event.get('path', 'Pass')} exit)"
    elif kind == "stick":
        what = f"stick button {event.get('button')} pressed through the Ethernet Slave"
    elif kind == "stick_refused":
        what = f"stick button {event.get('button')} refused: {event.get('reason')}"
    if what is None:
        return None
    return f"[{event['t']:9.3f} s] robot {event['robot'] + 1}: {what}"


def control_line(port: int) -> str:
    """A command a user can paste into another terminal: stop the robot's project through the control channel."""
    return (f"python3 -c 'import json, socket; s = socket.create_connection((\"{CONTROL_HOST}\", {port})); "
            f"s.sendall(json.dumps({{\"cmd\": \"stop_project\", \"robot\": 0}}).encode() + b\"\\n\"); "
            f"print(s.makefile().readline())'")


def default_control_port(robot_port: int, taken: tuple[int, ...]) -> int:
    """The port before the robot's (5889 for 5890), as the simulator's command line derives it; 0 (any free port,
    printed at start) when that one is in use or is one of the demo's other ports (``taken``)."""
    return default_port(robot_port, CONTROL_HOST, taken)


class DemoError(Exception):
    """A problem the user can fix; str() is printed as it is."""


def check_port_free(host: str, port: int, what: str, option: str) -> None:
    """Fail early, before the programs are compiled, when a port is really taken. The probe binds the way the
    servers do (SO_REUSEADDR): connections of a demo just stopped, still in TIME_WAIT, do not count."""
    probe = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        probe.bind((host, port))
        probe.listen(1)
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE:
            raise DemoError(f"error: port {port} on {host} ({what}) is already in use by {port_holder(port)}. "
                            f"Stop it, or choose another port with {option} PORT.") from None
        raise DemoError(f"error: cannot use {host}:{port} for the {what}: {exc.strerror}") from None
    finally:
        probe.close()


def port_holder(port: int) -> str:
    """``process 1234 (python3 sim/tmflow_listener.py)`` listening on ``port``, found through /proc (Linux);
    a neutral phrase where the process cannot be seen (another user's, or no /proc)."""
    inodes = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            with open(table, encoding="ascii") as f:
                rows = f.read().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            fields = row.split()
            if len(fields) > 9 and fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port:
                inodes.add(f"socket:[{fields[9]}]")          # state 0A = LISTEN
    proc = pathlib.Path("/proc")
    for pid_dir in (proc.iterdir() if inodes and proc.is_dir() else ()):
        if not pid_dir.name.isdigit():
            continue
        try:
            if any(os.readlink(fd) in inodes for fd in (pid_dir / "fd").iterdir()):
                cmd = (pid_dir / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
                return f"process {pid_dir.name} ({cmd[:80]})"
        except OSError:
            continue
    return "another program"


def tcp_port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: '{text}'") from None
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port} is not a TCP port (1..65535)")
    return port


def history_file(text: str) -> str:
    """``--alarm-log``: a file, created when missing. A pipe would hold the start-up for ever, a device fill the
    memory, a folder cannot be written: each is a usage error."""
    path = pathlib.Path(text)
    if not text.strip() or (path.exists() and not path.is_file()):
        raise argparse.ArgumentTypeError(f"{text!r} is not a regular file; name a file (it is created when missing)")
    return text


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="cbt-demo", description=__doc__.splitlines()[0])
    parser.add_argument("--host", type=host_argument, default="127.0.0.1",
                        help="address to bind (default 127.0.0.1; 0.0.0.0: every interface)")
    parser.add_argument("--robot-port", type=tcp_port, default=5890, help="robot Listen Node port (default 5890)")
    parser.add_argument("--svr-port", type=tcp_port, default=None,
                        help="robot Ethernet Slave port (default: the robot port + 1, i.e. 5891)")
    parser.add_argument("--hmi-port", type=tcp_port, default=8080, help="web HMI port (default 8080)")
    parser.add_argument("--control-port", type=tcp_port, default=None,
                        help="simulator control channel port, always on 127.0.0.1 (default: the robot port - 1, "
                             "i.e. 5889; any free port, printed at start, when that one is taken)")
    parser.add_argument("--alarm-log", metavar="FILE", default=None, type=history_file,
                        help="keep the HMI's alarm history in FILE (JSON lines) across restarts (default: in memory "
                             "only; make demo uses build/alarm_history.jsonl)")
    parser.add_argument("--project", metavar="DIR", default=None,
                        help="folder holding lib/CBT_Commands_Lib and examples/ (default: the current folder, else "
                             "the checkout this program is installed from)")
    parser.add_argument("--pages", metavar="DIR", default=None,
                        help="folder of page description files (*.json) over the demo program's global variables: "
                             "their pages show on Main next to the shipped ones (docs/hmi.md, \"Pages for your own "
                             "program\")")
    return parser.parse_args(argv)


def with_user_pages(mapping: Mapping, plc, directory: str) -> tuple[Mapping, list[str]]:
    """The shipped variable table plus the pages described in ``directory`` (cbt_hmi.web.pagedesc) and the
    variables they use; one error text per page left out. A page may show any global variable, but writes (inputs,
    command) only variables the shipped table does not hold: the shipped pages keep their limits and roles."""
    folder = pathlib.Path(directory)
    if not folder.is_dir():
        raise DemoError(f"error: --pages {directory}: not a folder of page description files")
    pages, errors = load_pages(folder, plc)
    table = program_table(plc, pages)           # also gives each item the variable's declared spelling
    shipped = mapping.document
    variables, kept = dict(shipped["variables"]), {}
    for name, page in pages.items():
        written = [item["variable"] for item in page["inputs"] + ([page["command"]] if page["command"] else [])]
        written += [page["parameters"]["variable"]] if "parameters" in page else []
        taken = [variable for variable in written if variable in shipped["variables"]]
        if taken:
            errors.append(f"{folder / (name + '.json')}: '{taken[0]}' belongs to the shipped pages: a page of your "
                          "own may show it under 'status', not write it")
            continue
        kept[name] = page
        shown = [item["variable"] for item in page["inputs"] + page["status"]] + written + \
            ([page["lamp"]] if "lamp" in page else [])
        for variable in shown:
            variables.setdefault(variable, table["variables"][variable])
    document = {**shipped, "types": {**table["types"], **shipped["types"]}, "variables": variables,
                "pages": [*shipped.get("pages", ["index"]), *kept], "custom_pages": kept}
    return Mapping(document, f"{mapping.source} + {folder}"), errors


class Demo:
    def __init__(self, host: str, robot_port: int, hmi_port: int, svr_port: int | None = None,
                 control_port: int | None = None, project: pathlib.Path | None = None,
                 alarm_log: str | None = None, pages: str | None = None):
        self.project, self.alarm_log = project, alarm_log
        self.pages = pages                        # --pages: the user's page descriptions
        self.page_errors: list[str] = []          # the ones left out
        self.host, self.robot_port, self.hmi_port = host, robot_port, hmi_port
        self.svr_port = svr_port or (robot_port + 1 if robot_port < 65535 else robot_port - 1)
        self.control_port = control_port          # None: derived from the robot port at start
        self.stop_event = threading.Event()
        self.sim: SimServer | None = None          # all four exist once start() has returned
        self.plc: Plc | None = None
        self.hmi: HmiServer | None = None
        self.plc_thread: threading.Thread | None = None
        self.fault: str | None = None            # the PLC's major fault: the PLC stopped, the rest stays up
        self._fault_printed = False
        self._seen: dict[int, int] = {}          # robot index -> events already looked at (absolute count)

    def start(self) -> None:
        check_port_free(self.host, self.robot_port, "robot simulator", "--robot-port")
        check_port_free(self.host, self.hmi_port, "web HMI", "--hmi-port")
        check_port_free(self.host, self.svr_port, "robot Ethernet Slave", "--svr-port")
        if self.control_port is None:
            self.control_port = default_control_port(self.robot_port, (self.svr_port, self.hmi_port))
        else:
            check_port_free(CONTROL_HOST, self.control_port, "simulator control channel", "--control-port")
        ports = [("--robot-port", self.robot_port), ("--svr-port", self.svr_port), ("--hmi-port", self.hmi_port),
                 ("--control-port", self.control_port)]
        for i, (option, port) in enumerate(ports):
            for other, same in ports[i + 1:]:
                if port == same:
                    raise DemoError(f"error: {option} and {other} are both {port}; give each server its own port.")
        try:
            mapping = Mapping.load()
        except MappingError as exc:
            raise DemoError(f"error: {exc}") from None
        try:
            from vplc.api import LoadError, load_plc
        except ImportError as exc:
            raise DemoError(f"error: the virtual PLC runtime is missing from this checkout ({exc})") from None
        try:
            project = self.project or find_project(None)
            self.plc = plc = load_plc([str(project / LIBRARY), str(project / EXAMPLES)])
        except LoadError as exc:
            raise DemoError(f"error: the example programs do not compile:\n{exc}") from None
        try:
            if self.pages is not None:
                mapping, self.page_errors = with_user_pages(mapping, plc, self.pages)
            mapping.check_against_plc(plc)
        except MappingError as exc:
            raise DemoError(f"error: {exc}") from None
        with plc.lock:
            plc.write("Connect_AddressIP", self.host)
            plc.write("Connect_Dest_PortIP", self.robot_port)
        self.sim = sim = SimServer(host=self.host, port=self.robot_port, robots=1, svr_port=self.svr_port,
                                   control_port=self.control_port, control_host=CONTROL_HOST)
        try:
            sim.start_background()
        except OSError as exc:
            raise DemoError(f"error: robot simulator: {exc.strerror}") from None
        with plc.lock:
            plc.write("Connect_SvrPort", sim.robots[0].svr_port)
        if self.alarm_log is not None:
            try:
                pathlib.Path(self.alarm_log).parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise DemoError(f"error: --alarm-log {self.alarm_log}: {exc.strerror}") from None
        self.hmi = hmi = HmiServer(plc, mapping, host=self.host, port=self.hmi_port, alarm_log=self.alarm_log)
        try:
            hmi.start()
        except OSError as exc:
            raise DemoError(f"error: web HMI on {self.host}:{self.hmi_port}: {exc.strerror}") from None
        self.plc_thread = threading.Thread(target=self._run_plc, name="vplc-realtime", daemon=True)
        self.plc_thread.start()

    def _started(self) -> tuple[Plc, SimServer, HmiServer]:
        """The PLC, the simulator and the HMI server of a started demo."""
        if self.plc is None or self.sim is None or self.hmi is None:
            raise RuntimeError("the demo has not been started (Demo.start)")
        return self.plc, self.sim, self.hmi

    def _run_plc(self) -> None:
        """Scan until the demo stops. A major fault stops the PLC alone: the simulator and the web HMI go on,
        and the HMI shows the fault on every page (docs/hmi.md, "PLC fault") until Ctrl-C."""
        from vplc.api import PlcFault
        plc, _, _ = self._started()
        try:
            # sleep to each due time instead of spinning its last 0.3 ms (run_realtime's default, for the lowest
            # lateness): the demo is a desk tool, and a scan ~0.1 ms late costs nothing here; idle, the demo
            # process uses ~5 % of a core instead of ~17 %
            plc.run_realtime(self.stop_event, spin_ns=0)
        except PlcFault as exc:
            self.fault = f"PLC major fault - the virtual PLC stopped:\n{exc}"

    def banner(self) -> str:
        plc, sim, hmi = self._started()
        if sim.control is None:                    # start() always opens it
            raise RuntimeError("the simulator's control channel is not open")
        control_port = sim.control.port
        period_ms = plc.period_ns / 1e6
        return "\n".join([
            "CBT_Commands_Lib demo is running:",
            f"  robot simulator   TM Listen Node, 1 robot on {self.host}:{self.robot_port}, "
            f"Ethernet Slave on {self.host}:{sim.robots[0].svr_port}",
            f"  control channel   {CONTROL_HOST}:{control_port}, the simulator's JSON-line requests "
            f"({robot_numbering(1)}):",
            "                    E-stop, project stop/start, cut the link (docs/simulator.md \"Control channel\")",
            f"  virtual PLC       PnP_Example, JogTeach_Example, Commands_Example (ladder) in a {period_ms:g} ms task "
            "(real time)",
            f"  web HMI           {hmi.url} (without a key: monitor only)",
            "",
            "Open the operator address in a browser, press Connect, then try the Motion pages:",
            f"  operator          {hmi.page_url('index', 'operator')}",
            f"  engineer          {hmi.page_url('index', 'engineer')}"
            "   (also robot address, base, tool, outputs)",
            "The keys are new at every start; keep them to the people who may move the robot.",
            "The Program (Ladder) page shows Commands_Example's rungs live.",
            *([(f"Your pages from {self.pages}: {', '.join(hmi.mapping.document['custom_pages']) or 'none'} "
                "(tiles under \"Your cell\" on Main).")] if self.pages is not None else []),
            "Robot-side events (robot error, project stopped, Listen node left) are printed below as they happen.",
            "Stop the robot's project from another terminal (then press Play on the main page):",
            f"  {control_line(control_port)}",
            "Press Ctrl-C to stop.",
        ])

    def console_lines(self) -> list[str]:
        """What to print since the last call: the robot-side events, and the PLC's major fault once."""
        lines = self.robot_events()
        if self.fault is not None and not self._fault_printed:
            self._fault_printed = True
            lines.append(f"{self.fault}\nThe web HMI stays up and shows the fault (values no longer valid, writes "
                         f"refused); restart the demo to run the PLC again. Press Ctrl-C to stop.")
        return lines

    def robot_events(self) -> list[str]:
        """Console lines of the robot-side events logged since the last call."""
        lines: list[str] = []
        _, sim, _ = self._started()
        with sim.lock:
            for robot in sim.robots:
                seen = self._seen.get(robot.index, 0)
                for event in robot.events[max(0, seen - robot.events_dropped):]:
                    line = robot_event_line(event)
                    if line:
                        lines.append(line)
                self._seen[robot.index] = robot.events_dropped + len(robot.events)
        return lines

    def stop(self) -> None:
        self.stop_event.set()
        if self.plc_thread is not None:
            self.plc_thread.join(timeout=5)
        if self.hmi is not None:
            self.hmi.stop()
        if self.plc is not None:
            self.plc.close()
        if self.sim is not None:
            self.sim.close()


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        project = find_project(args.project)
    except DemoError as exc:
        print(exc, file=sys.stderr)
        return 2
    demo = Demo(args.host, args.robot_port, args.hmi_port, args.svr_port, args.control_port, project, args.alarm_log,
                args.pages)
    signal.signal(signal.SIGTERM, lambda *_: demo.stop_event.set())
    try:
        demo.start()
        # From here Ctrl-C only sets the stop event: a KeyboardInterrupt raised inside Event.wait can leave its
        # lock held, and the shutdown would then wait on it for ever
        signal.signal(signal.SIGINT, lambda *_: demo.stop_event.set())
        for error in demo.page_errors:             # a bad page description: left out, the others are served
            print(f"error: {error}", file=sys.stderr, flush=True)
        print(demo.banner(), flush=True)
        while not demo.stop_event.wait(0.5):
            for line in demo.console_lines():
                print(line, flush=True)
    except DemoError as exc:
        print(exc, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)     # a second Ctrl-C must not interrupt the shutdown
        demo.stop()
    if demo.fault:
        print(f"Demo stopped after a {demo.fault}", file=sys.stderr)
        return 1
    print("Demo stopped: simulator, virtual PLC and web HMI are shut down.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
